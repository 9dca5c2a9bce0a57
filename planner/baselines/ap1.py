"""Ap1, the paper's first baseline: ResolveSpatialConstraints (Stilman et al., ICRA 2007) for several robots.

The robots form one composite robot whose actions are every single-robot pick-and-place and every handover
the facts allow (phase 1 gives Ap1 the robots' reachability, as the paper gives both baselines; it does not
use the occlusion facts to plan).  The search runs backwards in time, depth first, over a stack of objects
that must still move (at first the goal objects, in the order of the run):

1. an object of the stack (the *primary*: the top one first, Stilman's order, then the others) is moved by
   the step grounded now, which happens **before** every step grounded so far (the suffix).  Its actions
   are tried first strictly (free of every object still in place at that step), then, for those that
   failed, with the objects nothing moves yet ignored (the minimum-constraint retry): the objects such a
   step hits must be cleared **earlier**, so they go on top of the stack;
2. the composite robot fills its idle robots: other objects of the stack join the step when an action of
   theirs grounds beside the primary's without hitting anything new;
3. recurse on the rest; a dead end backtracks to the primary's step without the objects that joined it,
   then to the primary's next action, then to the next primary.  An empty stack is a complete plan, which
   the independent validator must accept before it counts (as in ``mrgc plan``).

Each object moves at most once: objects moved later in time stay where they are for the steps grounded
after them and are always obstacles, so a step that could only run by moving one of them again fails.
Placements avoid the volume every later step sweeps, as in the planner's grounding (planner/ground.py),
whose joint-action grounding, grasps, handovers and collision checks Ap1 reuses unchanged.

Restarts: each run of the depth-first search may ground at most a budget of joint actions
(:data:`RESTART_BUDGET`, doubled at every restart); when it is used up the search restarts with the objects
in another order (seeded): the order the goal objects are stacked in and the hit objects are pushed in.
Nothing but the time limit depends on the clock, so a seed gives the same plan whenever the time limit does
not stop the search first.  Symbolic problems have no geometry: an action's ``occludes-pick`` obstacles are
what its step hits (they must move strictly earlier; a handover's ``occludes-handover`` obstacles too), its
``occludes-goal-place`` obstacles what its place hits (no later).
"""

from __future__ import annotations

import hashlib
import random
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, actions_for, build_task_graph, pick_obstacles
from mrgc.planner.method import Context, Planner, Result
from mrgc.planner.outcome import Failure, PlanStatus, Why
from mrgc.planner.search import planned_action

if TYPE_CHECKING:  # the grounding loads numpy and the geometry: the command line reads Ap1's declaration
    from mrgc.geometry.collision import Posed
    from mrgc.planner.ground import GroundedStep

#: joint-action groundings the first depth-first run may make; every restart doubles it
RESTART_BUDGET = 64
#: actions tried per other object of the stack when filling a step's idle robots
PACK_TRIES = 2

Log = Callable[[str], None]


class _Stop(Exception):
    """The time limit: the search ends with what it has."""


class _Budget(Exception):
    """The restart's budget of groundings is used up."""


@dataclass
class Attempt:
    """A grounded joint action and the objects it hits that nothing moves yet (they must move earlier)."""

    step: GroundedStep
    hits: set[str]


class GeometricSteps:
    """Joint actions grounded on the scene by the planner's reverse grounding (planner/ground.py)."""

    def __init__(self, context: Context) -> None:
        from mrgc.geometry.grounding import Grounder
        from mrgc.geometry.scene import scene_from_problem
        from mrgc.planner.ground import ReverseGrounder

        problem = context.problem
        self.grounder = Grounder(scene_from_problem(problem), seed=context.seed)
        self.reverse = ReverseGrounder(self.grounder, problem.goal_regions, full=context.full)

    def ground(
        self,
        actions: tuple[Action, ...],
        fut: set[str],
        free: set[str],
        strict: bool,
        v_fut: Posed,
        key: str,
        index: int,
    ) -> Attempt | Failure:
        """Ground ``actions`` as one step before the suffix: ``fut`` (moved later) are always obstacles, ``free``
        (moved by nothing yet) too when ``strict``, else the objects of ``free`` the step hits are returned."""
        same = {a.obj for a in actions}
        avoid = fut | free if strict else set(fut)
        step = self.reverse.ground_step(actions, avoid, v_fut, key, index)
        if isinstance(step, Failure):
            return step
        among = sorted(free - same)
        hits = self.grounder.hits(step.volume.posed(), among=among) if among and not strict else set()
        return Attempt(step, hits)


class SymbolicSteps:
    """Joint actions checked against the facts of a symbolic problem (see the module docstring)."""

    def __init__(self, facts: FactBase) -> None:
        self.facts = facts

    def ground(
        self,
        actions: tuple[Action, ...],
        fut: set[str],
        free: set[str],
        strict: bool,
        v_fut: Posed,
        key: str,
        index: int,
    ) -> Attempt | Failure:
        """Ground the step ``actions`` against the future volume (reverse search): an :class:`Attempt` or the
        :class:`~mrgc.planner.outcome.Failure` that stopped it."""
        from mrgc.geometry.collision import Packed
        from mrgc.planner.ground import GroundedStep, label, swept

        facts, same = self.facts, {a.obj for a in actions}
        hits: set[str] = set()
        for a in actions:
            pick = pick_obstacles(facts, a)
            place = (
                facts.occludes_place.get((a.obj, a.region, a.place_grasp, a.place_robot), ())
                if a.obj in facts.goal
                else ()
            )
            for b in pick + place:
                if b in fut:
                    return Failure(index, label(a), "obstructed by an object that moves later", (b,))
                if b in same and b in pick:
                    return Failure(index, label(a), "pick obstructed by an object of the same step", (b,))
                if b in free:
                    hits.add(b)
        if strict and hits:
            return Failure(index, " + ".join(label(a) for a in actions), "obstructed", tuple(sorted(hits)))
        planned = [planned_action(a) for a in actions]
        return Attempt(GroundedStep(planned, Packed.of(swept(())), tuple(a.obj for a in actions)), hits)


@dataclass
class Ap1Search:
    """The reverse-time depth-first search with restarts (see the module docstring)."""

    steps: GeometricSteps | SymbolicSteps
    facts: FactBase
    accept: Callable[[list[GroundedStep]], bool]
    deadline: float
    why: Why
    one_handover: bool = False
    stats: dict[str, float] = field(
        default_factory=lambda: {"groundings": 0, "grounding_seconds": 0.0, "nodes": 0, "restarts": 0}
    )
    left: int = 0  # groundings left in this run
    rank: dict[str, int] = field(default_factory=dict)  # this run's order of the objects
    ordered: bool = False
    _actions: dict[str, list[Action]] = field(default_factory=dict)

    def actions(self, obj: str) -> list[Action]:
        """The composite robot's actions moving ``obj`` (to its goal region, or within its region): the
        single-robot ones first, then the handovers, each in the facts' order (no relays: Ap1 keeps the
        paper's model, each object moved once by one action)."""
        if obj not in self._actions:
            acts = [a for a in actions_for(self.facts, obj) if a.via is None]
            self._actions[obj] = [a for a in acts if not a.handover] + [a for a in acts if a.handover]
        return self._actions[obj]

    def run(self, goals: list[str], seed: int, log: Log) -> tuple[list[GroundedStep] | None, str]:
        """Restart the depth-first search with other orders until a plan is found (``solved``), a run is
        searched to its end (``exhausted``: every node tried every object of its stack, so no other order
        explores anything else) or the time limit (``time limit``).

        An order ranks every movable object: the goal objects are stacked by it (the first on top) and the
        objects a step hits are pushed by it, so it decides what the search tries first.  The first run
        takes the declaration order; each restart draws a random one (seeded) and doubles the budget."""
        rng = random.Random(seed)
        order, budget = list(self.facts.objects), RESTART_BUDGET
        while True:
            self.left, self.rank = budget, {o: k for k, o in enumerate(order)}
            stack = tuple(sorted(goals, key=self.rank.__getitem__))
            head = f"restart {int(self.stats['restarts'])} (goals {' '.join(stack)})"
            try:
                plan = self._resolve(stack, [], ())
            except _Budget:
                log(f"{head}: budget of {budget} groundings used up")
            except _Stop:
                return None, "time limit"
            else:
                if plan is not None:
                    return plan, "solved"
                log(f"{head}: searched to its end")
                return None, "exhausted"  # every object was tried as the next to move at every node
            self.stats["restarts"] += 1
            budget *= 2
            rng.shuffle(order)

    # ------------------------------------------------------------ the recursion
    def _resolve(
        self, pending: tuple[str, ...], suffix: list[GroundedStep], signature: tuple[Any, ...]
    ) -> list[GroundedStep] | None:
        if not pending:
            return suffix if self.accept(suffix) else None
        state = (pending, signature)
        self.stats["nodes"] += 1
        from mrgc.planner.ground import moved_objects, swept

        fut = moved_objects(suffix)
        free = set(self.facts.objects) - fut - set(pending)
        v_fut = swept(suffix)
        index = -(len(suffix) + 1)
        tag = hashlib.sha256(repr(state).encode()).hexdigest()[:16]
        for j, primary in enumerate(pending):
            strict_ok: set[int] = set()
            for strict in (True, False):
                for i, a in enumerate(self.actions(primary)):
                    if not strict and i in strict_ok:
                        continue
                    key = f"{tag}:{j}:{i}:{'s' if strict else 'r'}"
                    got = self._ground((a,), fut, free, strict, v_fut, key, index, record=not strict)
                    if got is None:
                        continue
                    strict_ok.add(i)
                    filled = self._fill((a,), got, pending, fut, free, strict, v_fut, key, index)
                    # the filled step first; the primary alone too, since moving an object together with
                    # the primary can rule out an order that moving it earlier allows
                    for step in (filled, got) if filled is not got else (got,):
                        plan = self._descend(step, pending, suffix, signature)
                        if plan is not None:
                            return plan
        return None

    def _descend(
        self, got: Attempt, pending: tuple[str, ...], suffix: list[GroundedStep], signature: tuple[Any, ...]
    ) -> list[GroundedStep] | None:
        """Recurse below a grounded step: the objects it hits go on top of the stack, by this run's order."""
        rest = tuple(sorted(got.hits, key=self.rank.__getitem__)) + tuple(p for p in pending if p not in got.step.moved)
        # the state names the whole path (each step with the stack it was grounded under); the grounding's
        # random streams derive from it
        step_sig = tuple(
            (x.object, x.region, x.pick_robot, x.place_robot, x.pick_grasp, x.place_grasp) for x in got.step.actions
        )
        return self._resolve(rest, [got.step] + suffix, ((pending, step_sig),) + signature)

    def _fill(
        self,
        actions: tuple[Action, ...],
        got: Attempt,
        pending: tuple[str, ...],
        fut: set[str],
        free: set[str],
        strict: bool,
        v_fut: Posed,
        key: str,
        index: int,
    ) -> Attempt:
        """The composite robot's idle robots take other objects of the stack, in stack order, when an action
        of theirs grounds in the same step without hitting anything the step did not hit already."""
        busy = {r for a in actions for r in a.robots}
        handovers = sum(a.handover for a in actions)
        for obj in pending:
            if obj in got.step.moved:
                continue
            if len(busy) >= len(self.facts.robots):
                break
            tried = 0
            for b in self.actions(obj):
                if busy & set(b.robots) or (b.handover and self.one_handover and handovers):
                    continue
                if tried >= PACK_TRIES:
                    break
                tried += 1
                more = self._ground(actions + (b,), fut, free, strict, v_fut, key, index, record=False)
                if more is not None and more.hits <= got.hits:
                    actions, got = actions + (b,), more
                    busy |= set(b.robots)
                    handovers += b.handover
                    break
        return got

    def _ground(
        self,
        actions: tuple[Action, ...],
        fut: set[str],
        free: set[str],
        strict: bool,
        v_fut: Posed,
        key: str,
        index: int,
        record: bool,
    ) -> Attempt | None:
        if time.perf_counter() >= self.deadline:
            raise _Stop()
        if self.left <= 0:
            raise _Budget()
        self.left -= 1
        t0 = time.perf_counter()
        got = self.steps.ground(actions, fut, free, strict, v_fut, key, index)
        self.stats["groundings"] += 1
        self.stats["grounding_seconds"] += time.perf_counter() - t0
        if isinstance(got, Failure):
            if record:
                self.why.add(got)
            return None
        return got


class Ap1(Planner):
    """Ap1 as a planning method (see the module docstring)."""

    name = "ap1"
    title = "baseline Ap1: multi-robot ResolveSpatialConstraints"
    exhausted = (
        "the depth-first search ran to its end (every object of the stack, with every action, at every "
        "step); no valid plan"
    )

    def solve(self, context: Context, deadline: float) -> Result:
        """The facts' diagnosis first (as ``mrgc plan``), then the depth-first search with restarts."""
        base, why = context.base, context.why
        reasons = _infeasible(base, context.goals)
        if reasons:
            why.facts = reasons
            return Result(PlanStatus.INFEASIBLE)

        def accept(steps: list[GroundedStep]) -> bool:
            failure = context.referee([s.actions for s in steps])
            if failure is not None:
                why.add(failure)
            return failure is None

        steps = SymbolicSteps(base) if context.problem.symbolic else GeometricSteps(context)
        search = Ap1Search(steps, base, accept, deadline, why, one_handover=base.handover_capacity == 1)
        stamp = context.started
        try:  # interrupted: the statistics of the search so far are kept
            found, ended = search.run(
                context.goals, context.seed, lambda line: context.log(f"[t={time.perf_counter() - stamp:.1f}s] {line}")
            )
        except KeyboardInterrupt:
            found, ended = None, "interrupted"
        stats: dict[str, Any] = {k: (round(v, 4) if isinstance(v, float) else int(v)) for k, v in search.stats.items()}
        if isinstance(steps, GeometricSteps):
            stats["geometric_queries"] = steps.grounder.queries
        note = None
        if any(f.step < 0 for f in why.failures):  # Ap1 grounds backwards: say how its steps are numbered
            note = "Ap1 numbers steps from the end (step -1: the plan's last, -2: the one before)"
        if found is not None:
            return Result(PlanStatus.SOLVED, [s.actions for s in found], stats=stats, note=note)
        status = {"time limit": PlanStatus.TIME_LIMIT, "interrupted": PlanStatus.INTERRUPTED}.get(
            ended, PlanStatus.EXHAUSTED
        )
        return Result(status, stats=stats, note=note)


def _infeasible(facts: FactBase, goals: list[str]) -> list[str]:
    """The facts' reasons why no plan exists (a goal object no robot can pick or bring to its region, a
    blocking cycle): the same diagnosis ``mrgc plan`` gives, so both methods agree on what is infeasible."""
    from mrgc.compiler.diagnose import explain_infeasible

    return explain_infeasible(build_task_graph(facts, goals), facts)
