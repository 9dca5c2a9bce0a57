"""Task-skeleton grounding by reverse search (the paper's Key Component 2), for fixed-base arms.

Steps are grounded from the last to the first.  At step t, placements avoid the fixed objects, the objects
that are never moved (M_out), the objects moved later (M_fut, still at their initial poses at t), the
objects moved in the same step, and the future volume V_fut (everything later grounded steps sweep,
including objects at their final placements).  Pick, handover and place configurations avoid the same
objects; robots of one step must not collide with each other.  If step t fails, it is retried allowing
collisions with M_out: on success grounding stops and returns the grounded suffix S' and M* = the goal
objects not moved in S' plus the M_out objects that obstruct S'; otherwise it fails.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.collision import CollisionWorld
from mrgc.geometry.grounding import Answer, Grounder, Volume
from mrgc.geometry.predicates import refine
from mrgc.geometry.planar import to_se2
from mrgc.planner.plan import PlannedAction

PLACEMENT_TRIES = 6  # placements sampled per place before the step gives up


class Outcome(str, enum.Enum):
    SUCCESS = "success"
    PARTIAL = "partial"
    FAIL = "fail"


@dataclass
class GroundedStep:
    """A grounded joint action: its actions, the volume it sweeps, and the objects it moves."""

    actions: list[PlannedAction]
    volume: Volume
    moved: tuple[str, ...]


@dataclass
class Grounding:
    """The outcome of grounding a skeleton: the grounded steps (a suffix when PARTIAL) and M*."""

    outcome: Outcome
    steps: list[GroundedStep] = field(default_factory=list)
    must_move: set[str] = field(default_factory=set)
    reason: str = ""


def _matrix(t: np.ndarray) -> list[list[float]]:
    return [[float(v) for v in row] for row in t]


def _configs(c: np.ndarray | None) -> list[list[float]]:
    return [] if c is None else [[float(v) for v in q] for q in np.atleast_2d(c)]


class ReverseGrounder:
    """Grounds skeletons on a scene (see the module docstring)."""

    def __init__(self, grounder: Grounder, goal: dict[str, str]) -> None:
        self.g = grounder
        self.goal = goal
        self.movable = [b.name for b in grounder.scene.movable]

    def ground(self, skeleton: Skeleton, suffix: list[GroundedStep], key: str = "") -> Grounding:
        fut_objs = {o for s in suffix for o in s.moved}
        skel_objs = set(skeleton.moved)
        out_objs = set(self.movable) - fut_objs - skel_objs
        volume: Volume = [p for s in suffix for p in s.volume]
        grounded: list[GroundedStep] = []
        for t in range(skeleton.makespan - 1, -1, -1):
            step = skeleton.steps[t]
            same = {a.obj for a in step}
            strict = self._step(step, fut_objs | out_objs, same, volume, f"{key}:{t}")
            if strict is None:
                relaxed = self._step(step, fut_objs, same, volume, f"{key}:{t}:relaxed")
                if relaxed is None:
                    return Grounding(Outcome.FAIL, reason=f"step {t + 1} cannot be grounded")
                grounded.insert(0, relaxed)
                steps = grounded + suffix
                moved = {o for s in steps for o in s.moved}
                # the grounded steps assumed the objects of the discarded earlier steps were out of the way:
                # those are blockers too when the steps hit them, just like the never-moved ones
                earlier = {a.obj for step in skeleton.steps[:t] for a in step}
                blockers = self.g.hits([p for s in grounded for p in s.volume], among=sorted(out_objs | earlier))
                must = {o for o in self.goal if o not in moved} | blockers
                return Grounding(Outcome.PARTIAL, steps, must, reason=f"step {t + 1} needs {sorted(blockers)} moved")
            grounded.insert(0, strict)
            volume = volume + strict.volume
            fut_objs |= same
        return Grounding(Outcome.SUCCESS, grounded + suffix)

    # ------------------------------------------------------------ one joint action
    def _step(self, step: tuple[Action, ...], avoid: set[str], same: set[str], v_fut: Volume,
              key: str) -> GroundedStep | None:
        actions: list[PlannedAction] = []
        step_volume: Volume = []
        motions: dict[str, dict[str, list[Volume]]] = {}  # robot -> phase -> volume at each sample
        for a in step:
            avoid_a = sorted((avoid | same) - {a.obj})
            action = self._action(a, avoid_a, v_fut + step_volume, f"{key}:{a.obj}")
            if action is None:
                return None
            mine = self._motions(action)
            # robots of one step move at once: phase by phase (pick, handover, place; drives), samples paired
            # by index as the validator replays them, they must not collide with each other
            for robot, phases in mine.items():
                for other, their in motions.items():
                    if other != robot and _phases_collide(phases, their):
                        return None
            for robot, phases in mine.items():
                motions.setdefault(robot, {}).update(phases)
            for phases in mine.values():  # the step's volume is every sample of every motion
                for samples in phases.values():
                    for vol in samples:
                        step_volume.extend(vol)
            assert action.place_pose is not None
            step_volume.append((self.g.shape(a.obj), np.array(action.place_pose)))
            actions.append(action)
        return GroundedStep(actions, step_volume, tuple(a.obj for a in step))

    def _motions(self, action: PlannedAction) -> dict[str, dict[str, list[Volume]]]:
        """Each robot's volume at every sample of every phase of a planned action, arm approaches on the
        validator's finer interpolation (so later placements keep clear between samples too)."""
        g, obj = self.g, action.object
        out: dict[str, dict[str, list[Volume]]] = {}
        if g.is_planar(action.pick_robot):
            held = {"to-pick": None, "to-place": (obj, action.pick_grasp), "home": None}
            out[action.pick_robot] = {ph: [g.base_volume(action.pick_robot, [q], held[ph]) for q in np.array(path)]
                                      for ph, path in action.paths.items()}
            return out
        out.setdefault(action.pick_robot, {})["pick"] = [
            g.arm_volume(action.pick_robot, q[None]) for q in refine(np.array(action.configs["pick"]))]
        if "handover" in action.configs:
            giver, taker = np.array(action.configs["handover"])
            out[action.pick_robot]["handover"] = [g.arm_volume(action.pick_robot, giver[None], (obj, action.pick_grasp))]
            out.setdefault(action.place_robot, {})["handover"] = [
                g.arm_volume(action.place_robot, taker[None], (obj, action.place_grasp))]
        out.setdefault(action.place_robot, {})["place"] = [
            g.arm_volume(action.place_robot, q[None], (obj, action.place_grasp))
            for q in refine(np.array(action.configs["place"]))]
        return out

    def _action(self, a: Action, avoid: list[str], v_fut: Volume, key: str) -> PlannedAction | None:
        if self.g.is_planar(a.pick_robot):
            return self._drive(a, avoid, v_fut, key)
        g = self.g
        pick = g.pick(a.pick_robot, a.obj, a.pick_grasp, avoid=avoid)
        if not pick.ok:
            return None
        planned = PlannedAction(a.obj, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp)
        planned.configs["pick"] = _configs(pick.configs)
        if a.handover:
            hand = self._handover(a, avoid)
            if hand is None:
                return None
            point, answer = hand
            assert answer.configs is not None
            planned.handover_point = point
            planned.configs["handover"] = _configs(answer.configs)
        for k in range(PLACEMENT_TRIES):
            spot = g.placement(a.obj, a.region, avoid=avoid, volume=v_fut, key=key, skip=k)
            if not spot.ok:
                return None
            assert spot.pose is not None
            place = g.place(a.place_robot, a.obj, a.place_grasp, spot.pose, avoid=avoid)
            if place.ok:
                planned.place_pose = _matrix(spot.pose)
                planned.configs["place"] = _configs(place.configs)
                return planned
        return None

    def _drive(self, a: Action, avoid: list[str], v_fut: Volume, key: str) -> PlannedAction | None:
        """A planar robot's action (path mode): drive from its start pose to the pick pose, carry the object
        to the place pose, drive back; every path free of fixed objects and of ``avoid``."""
        g, robot = self.g, a.pick_robot
        if a.handover:
            return None  # planar robots do not hand over (no such facts are computed)
        pr = g.planar(robot)
        shape = g.scene.body(a.obj).shape
        home = to_se2(g.scene.robot(robot).base)
        q_pick = pr.grasp_base(g.poses[a.obj], shape, a.pick_grasp)
        to_pick = g.base_path(robot, home, q_pick, avoid=avoid)
        if not to_pick.ok:
            return None
        for k in range(PLACEMENT_TRIES):
            spot = g.placement(a.obj, a.region, avoid=avoid, volume=v_fut, key=key, skip=k)
            if not spot.ok:
                return None
            assert spot.pose is not None
            q_place = pr.grasp_base(spot.pose, shape, a.place_grasp)
            carry = g.base_path(robot, q_pick, q_place, holding=(a.obj, a.pick_grasp), avoid=avoid)
            if not carry.ok:
                continue
            back = g.base_path(robot, q_place, home, avoid=avoid)
            if not back.ok:
                continue
            planned = PlannedAction(a.obj, a.region, robot, robot, a.pick_grasp, a.place_grasp,
                                    place_pose=_matrix(spot.pose))
            planned.configs = {"pick": _configs(q_pick), "place": _configs(q_place)}
            planned.paths = {"to-pick": _configs(np.array(to_pick.path)), "to-place": _configs(np.array(carry.path)),
                             "home": _configs(np.array(back.path))}
            return planned
        return None

    def _handover(self, a: Action, avoid: list[str]) -> tuple[str, Answer] | None:
        for point in self.g.scene.handover_of.get(a.obj, ()):
            if point not in self.g.scene.handover_points:
                continue
            ans = self.g.handover(a.obj, point, a.pick_robot, a.pick_grasp, a.place_robot, a.place_grasp, avoid=avoid)
            if ans.ok:
                return point, ans
        return None


def _phases_collide(mine: dict[str, list[Volume]], theirs: dict[str, list[Volume]]) -> bool:
    """Do two robots collide in a phase both move in, their samples paired by index (resampled)?"""
    for phase, samples in mine.items():
        other = theirs.get(phase)
        if not other:
            continue
        n = max(len(samples), len(other))
        for i in range(n):
            if _volumes_collide(samples[i * len(samples) // n], other[i * len(other) // n]):
                return True
    return False


def _volumes_collide(a: Volume, b: Volume) -> bool:
    if not a or not b:
        return False
    world = CollisionWorld()
    for i, (shape, t) in enumerate(b):
        world.add(f"b{i}", shape, t, "b")
    return world.probe_collides(a, against="b")


def moved_objects(steps: Iterable[GroundedStep]) -> set[str]:
    return {o for s in steps for o in s.moved}
