"""The collaborative manipulation task graph (CMTG): Alg. 1 of the paper.

Object nodes are the objects that must or may move; action nodes are partially grounded pick-and-place
actions (object, target region, pick robot, place robot, pick grasp, place grasp); block-pick and
block-place edges say which objects obstruct an action (beyond the paper, the objects in the way of a
handover's exchange, ``occludes-handover``, are block-pick edges of the handover action: they must be gone
before the object is picked).  Beyond the paper, a *relay* action sets a goal
object down in another region (``via``) and picks it up there with another robot or grasp
(``enable-relay``); like a handover it occupies both robots for its step, and has the same obstacles (the
pick's and the goal placement's) and those in the way at its spot (``occludes-relay``: block-pick edges).
A goal object's target region is its goal region, any other object's its current region (it is only
moved out of the way).  Handover actions exist only for goal objects.  Objects already moved (the grounded
suffix during search) get no node: each object moves at most once, and an action obstructed by such an
object is dropped, because that object is still in place when the action runs (the suffix runs later).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from functools import cached_property
from typing import Iterable

from mrgc.compiler.facts import FactBase


@dataclass(frozen=True)
class Action:
    """A partially grounded pick-and-place action; a handover when the two robots differ, a relay when the
    object is set down in region ``via`` on its way (then picked up again there by ``place_robot`` with
    ``place_grasp``)."""

    obj: str
    region: str
    pick_robot: str
    place_robot: str
    pick_grasp: str
    place_grasp: str
    via: str | None = None

    @property
    def robots(self) -> tuple[str, ...]:
        """The robots the action occupies for its whole step (one, or two for a handover)."""
        if self.pick_robot == self.place_robot:
            return (self.pick_robot,)
        return (self.pick_robot, self.place_robot)

    @property
    def handover(self) -> bool:
        """Whether the object changes hands in the air (two robots, no relay)."""
        return self.pick_robot != self.place_robot and self.via is None

    @property
    def halves(self) -> tuple["Action", "Action"]:
        """A relay as two pick-and-place actions: setting the object down in ``via``, and the onward move
        from there to ``region``."""
        assert self.via is not None, "only a relay has halves"
        return (
            Action(self.obj, self.via, self.pick_robot, self.pick_robot, self.pick_grasp, self.pick_grasp),
            Action(self.obj, self.region, self.place_robot, self.place_robot, self.place_grasp, self.place_grasp),
        )

    def __str__(self) -> str:
        two = self.pick_robot != self.place_robot
        who = self.pick_robot if not two else f"{self.pick_robot}->{self.place_robot}"
        grasp = (
            self.pick_grasp
            if self.pick_grasp == self.place_grasp and not two
            else f"{self.pick_grasp}->{self.place_grasp}"
        )
        via = f" via {self.via}" if self.via is not None else ""
        return f"{who} moves {self.obj} to {self.region}{via} ({grasp})"


@dataclass(frozen=True)
class TaskGraph:
    """A CMTG.  ``actions[i]`` is action node i; edges refer to actions by index.

    ``must_move`` is M* (objects the skeleton has to move); ``objects`` are all object nodes in the order
    they were added.  ``block_pick[i]`` / ``block_place[i]`` are the objects obstructing action i.
    """

    robots: tuple[str, ...]
    objects: tuple[str, ...]
    must_move: tuple[str, ...]
    goal: dict[str, str]
    actions: tuple[Action, ...]
    block_pick: tuple[tuple[str, ...], ...]
    block_place: tuple[tuple[str, ...], ...]
    #: the number of handover points when it is one: then at most one handover per step (beyond the paper:
    #: two objects cannot be passed at the same point at once); None: no limit
    single_handover_point: bool = False
    #: robots whose place obstacles must move strictly earlier (they drive through them; beyond the paper,
    #: whose place obstacles may move in the same step: right for arms, which pick before they place)
    strict_place: frozenset[str] = frozenset()

    @cached_property
    def _by_object(self) -> dict[str, list[int]]:
        out: dict[str, list[int]] = {o: [] for o in self.objects}
        for i, a in enumerate(self.actions):
            out.setdefault(a.obj, []).append(i)
        return out

    def actions_of(self, obj: str) -> list[int]:
        """Indices of the actions that move ``obj``."""
        return self._by_object.get(obj, [])

    def blockers(self, i: int) -> tuple[str, ...]:
        """Objects obstructing action i (pick first, then place), without repeats."""
        return tuple(dict.fromkeys(self.block_pick[i] + self.block_place[i]))

    def obstacles(self, i: int) -> list[tuple[str, bool]]:
        """(obstacle, strict) for action i: pick obstacles move strictly before it, place obstacles no later
        (strictly before too when the placing robot drives through them: :attr:`strict_place`)."""
        out = [(o, True) for o in self.block_pick[i]]
        strict = self.actions[i].place_robot in self.strict_place
        out += [(o, strict) for o in self.block_place[i] if o not in self.block_pick[i]]
        return out

    @cached_property
    def _blocks(self) -> dict[str, list[int]]:
        out: dict[str, list[int]] = {o: [] for o in self.objects}
        for i in range(len(self.actions)):
            for o in self.blockers(i):
                out.setdefault(o, []).append(i)
        return out

    def blocked_by(self, obj: str) -> list[int]:
        """Indices of the actions ``obj`` obstructs (the block edges into ``obj``)."""
        return self._blocks.get(obj, [])


def build_task_graph(facts: FactBase, must_move: Iterable[str], moved: Iterable[str] = ()) -> TaskGraph:
    """Alg. 1 (AddObject) applied to every object of ``must_move``, skipping objects in ``moved``.

    The recursion of the paper is run with a work queue, so graphs of thousands of objects cannot overflow
    the Python stack; the resulting graph is the same.
    """
    done = set(moved)
    must = tuple(dict.fromkeys(m for m in must_move if m not in done))
    nodes: dict[str, None] = {}
    actions: list[Action] = []
    block_pick: list[tuple[str, ...]] = []
    block_place: list[tuple[str, ...]] = []
    queue = deque(must)
    while queue:
        obj = queue.popleft()
        if obj in nodes or obj in done:
            continue
        nodes[obj] = None
        for act in actions_for(facts, obj):
            pick_obs = pick_obstacles(facts, act)
            place_obs: tuple[str, ...] = ()
            if obj in facts.goal:
                place_obs = facts.occludes_place.get((obj, act.region, act.place_grasp, act.place_robot), ())
            if any(o in done for o in pick_obs + place_obs):
                continue  # obstructed by an object that moves only later: never executable now
            actions.append(act)
            block_pick.append(pick_obs)
            block_place.append(place_obs)
            queue.extend(o for o in pick_obs + place_obs if o not in nodes)
    return TaskGraph(
        robots=facts.robots,
        objects=tuple(nodes),
        must_move=must,
        goal={o: r for o, r in facts.goal.items() if o in nodes},
        actions=tuple(actions),
        block_pick=tuple(block_pick),
        block_place=tuple(block_place),
        single_handover_point=facts.handover_capacity == 1,
        strict_place=facts.drivers,
    )


def pick_obstacles(facts: FactBase, act: Action) -> tuple[str, ...]:
    """The objects that must be gone before ``act`` picks its object: its pick's ``occludes-pick`` obstacles,
    for a handover those in the way of the exchange (``occludes-handover``, beyond the paper), and for a relay
    those in the way at its spot (``occludes-relay``, beyond the paper: the relay sets the object down there in
    the step it picks it)."""
    out = facts.occludes_pick.get((act.obj, act.pick_grasp, act.pick_robot), ())
    if act.handover:
        key = (act.obj, act.pick_grasp, act.place_grasp, act.pick_robot, act.place_robot)
        out += tuple(o for o in facts.occludes_handover.get(key, ()) if o not in out)
    if act.via is not None:
        spot = (act.obj, act.via, act.pick_grasp, act.place_grasp, act.pick_robot, act.place_robot)
        out += tuple(o for o in facts.occludes_relay.get(spot, ()) if o not in out)
    return out


def actions_for(facts: FactBase, obj: str) -> list[Action]:
    """Lines 5-20 of Alg. 1: the direct and handover actions moving ``obj`` to its target region (and the
    relays of a goal object, after them)."""
    is_goal = obj in facts.goal
    region = facts.goal[obj] if is_goal else facts.region.get(obj)
    if region is None:
        return []  # an object with no known region cannot be put back anywhere
    grasps = facts.grasps.get(obj, ())
    out: list[Action] = []
    for r_pick in facts.robots:
        for g_pick in grasps:
            if (obj, g_pick, r_pick) not in facts.reachable_pick:
                continue
            if (obj, region, g_pick, r_pick) in facts.reachable_place:
                out.append(Action(obj, region, r_pick, r_pick, g_pick, g_pick))
            if not is_goal:
                continue
            for r_place in facts.robots:
                if r_place == r_pick:
                    continue
                for g_place in grasps:
                    if (obj, g_pick, g_place, r_pick, r_place) in facts.handover and (
                        obj,
                        region,
                        g_place,
                        r_place,
                    ) in facts.reachable_place:
                        out.append(Action(obj, region, r_pick, r_place, g_pick, g_place))
    if is_goal:
        out += _relays_for(facts, obj, region)
    return out


def _relays_for(facts: FactBase, obj: str, region: str) -> list[Action]:
    """The relay actions of goal object ``obj``: picked, set down in another region, picked up there and
    placed in its goal ``region`` (``enable-relay`` with the pick's and the goal placement's facts)."""
    out = []
    for o, via, g_pick, g_place, r_pick, r_place in sorted(facts.relay):
        if (
            o == obj
            and via != region
            and (obj, g_pick, r_pick) in facts.reachable_pick
            and (obj, region, g_place, r_place) in facts.reachable_place
        ):
            out.append(Action(obj, region, r_pick, r_place, g_pick, g_place, via))
    return out
