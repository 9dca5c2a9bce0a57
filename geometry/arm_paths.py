"""Arm paths: an arm's joint-space motions between configurations, holding an object or not, remembered.

A *transfer* carries a held object from one configuration to another: straight up first from where the
object rests (:meth:`ArmPaths.lift_height`: above its neighbours, and above anything that may stand on the
table), then the straight joint-space line with its low points raised (:meth:`ArmPaths._over`), or the plain
line, or when that collides an RRTConnect path (:meth:`ArmPaths.arm_path`, a budget of
:data:`TRANSFER_CHECKS` validity checks, seeded from the query: no clock decides), and with ``lower`` straight
down onto the goal.  A *transit* is an empty-handed motion (``--motions full``: home to a pre-grasp, a release
back home, a giver backing off the object it let go).  Every path is at
:data:`~mrgc.geometry.conventions.PATH_RESOLUTION` (:func:`joint_line`), free of fixed objects, of the other
arms where they stand in its phase, of the objects to avoid and of what the step's other robots sweep
meanwhile.  Transfers are remembered (:meth:`ArmPaths.transfer`): the same question gets the same answer
without a second search.
"""

from __future__ import annotations

from functools import cached_property
from typing import Callable, Iterable

import numpy as np

from mrgc.geometry.answers import BUSY, Answer, GroundStatus
from mrgc.geometry.collision import Posed, posed_collide
from mrgc.geometry.conventions import PATH_RESOLUTION, seed_for
from mrgc.geometry.grasps import APPROACH
from mrgc.geometry.ik import IKResult, solve_ik_many
from mrgc.geometry.motion import MAX_CHECKS, plan_joint_path
from mrgc.geometry.robot import Pieces
from mrgc.geometry.scene import half_extents
from mrgc.geometry.transforms import translation
from mrgc.geometry.volumes import Volumes

#: how far a transfer raises the tool straight up before it moves off (m): the approach's back-off, or more
#: when taller objects stand around the one picked (see :meth:`ArmPaths.lift_height`), up to MAX_LIFT
TRANSFER_LIFT = 0.08
MAX_LIFT = 0.30
#: a carry's joint-space line is checked for low points (and they are raised) every this much of the tool's
#: horizontal travel (m)
CARRY_STEP = 0.08
#: objects whose footprint comes this close (m, horizontally) to the picked one's count as its neighbours
NEIGHBOURHOOD = 0.10
#: validity checks an arm's transfer or transit path may spend when its straight line collides: a failed
#: search costs all of them, at 0.5-1.5 ms a check (an arm holding an object, 1 cm steps), and a step tries
#: several placements; 20,000 (motion.MAX_CHECKS) let one grounding run for minutes on a loaded machine
TRANSFER_CHECKS = 4_000
#: the budget when the path must also keep clear of what the step's other robots sweep meanwhile (``busy``):
#: the grounding asks for that search only when its motion, searched as if the others were not there, meets
#: them as they pass (sample by sample), and among four or five arms of one step it rarely ends: on PA18 with
#: 5 arms (seed 7) 43 such searches spent 1,750 checks each, none found a path, 40 of the grounding's 55 s of
#: CPU; those that succeed on PA10 and PA18 with 3-4 arms used 162-866 checks
BUSY_TRANSFER_CHECKS = 2_000
#: joint-space distance (rad) between the states an arm's path search checks when a finer path is asked
#: for (:meth:`ArmPaths.arm_path`): the path found is checked again, densely, before it is used
COARSE_RESOLUTION = 0.04
#: the share of the budget of checks the coarse search may spend (each of its checks covers 4x the motion)
COARSE_BUDGET = 0.5


class ArmPaths(Volumes):
    """An arm's transfers, transits and joint-space paths (see the module docstring)."""

    #: coarse arm paths that collided between their states (searched again, finely)
    coarse_misses = 0

    def arm_path(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        holding: tuple[str, str] | None = None,
        avoid: Iterable[str] = (),
        max_checks: int = MAX_CHECKS,
        resolution: float = 0.05,
        busy: Pieces = (),
        phase: str = "to-place",
        fingers: tuple[str, str] | None = None,
    ) -> Answer:
        """A joint-space path (RRTConnect, at most ``max_checks`` validity checks: no clock decides) free of
        fixed objects, of the other arms where they stand in ``phase`` (:meth:`step`), of ``avoid`` and of
        ``busy`` (and of the held object's collisions with them), no two of its
        configurations more than ``resolution`` apart.  A ``resolution`` finer than
        :data:`COARSE_RESOLUTION` is searched coarsely first (:data:`COARSE_BUDGET` of the checks) and the
        result checked at ``resolution``."""
        arm = self.arm(robot)
        against = (
            "fixed",
            *self._others(robot, phase),
            *[a for a in avoid if not holding or a != holding[0]],
        )
        ignore = (holding[0],) if holding else ()
        moving = self._busy(busy)

        def clear(posed: Posed) -> bool:
            if moving is not None and posed_collide(posed, moving):
                return False
            return not self.world.probe_collides(posed, against=against, ignore=ignore)

        def free(configs: np.ndarray) -> bool:
            self.queries += 1
            return self.free_posed(robot, configs, holding, fingers, clear=clear) is not None

        def all_free(configs: np.ndarray) -> bool:
            ok = free(configs)  # counted as the single checks it stands for (on a collision, those that follow)
            self.queries += len(configs) - 1 if ok else -1
            return ok

        def solve(step: float, budget: int) -> list[np.ndarray]:
            res = plan_joint_path(
                arm.model.lower,
                arm.model.upper,
                start,
                goal,
                lambda q: free(q[None]),
                max_checks=budget,
                seed=seed_for(robot, "arm-path", seed=self.seed),
                resolution=step,
                deadline=self.deadline,
                all_valid=all_free,
            )
            self.late()  # a solve the deadline stopped has set nothing: it is read here
            return list(res.path)

        if resolution < COARSE_RESOLUTION:
            # the search checks states COARSE_RESOLUTION apart; the path it finds is then checked at every
            # ``resolution`` (one batch) and returned at that density; a path that collides between the coarse
            # states sends the search back to ``resolution`` with the whole budget
            coarse = solve(COARSE_RESOLUTION, max(1, round(max_checks * COARSE_BUDGET)))
            if self.cut:
                return Answer(GroundStatus.TIME_LIMIT)
            if coarse:
                dense = joint_line(np.array(coarse), resolution)
                if free(dense):
                    return Answer(GroundStatus.OK, path=list(dense))
                self.coarse_misses += 1
            else:
                return Answer(GroundStatus.NO_PATH)
        path = solve(resolution, max_checks)
        if self.cut:
            return Answer(GroundStatus.TIME_LIMIT)
        return Answer(GroundStatus.OK if path else GroundStatus.NO_PATH, path=path)

    def transfer(
        self,
        robot: str,
        obj: str,
        grasp: str,
        start: np.ndarray,
        goal: np.ndarray,
        avoid: Iterable[str] = (),
        lift: bool = False,
        busy: Pieces = (),
        lower: bool = False,
        phase: str = "to-place",
    ) -> Answer:
        """:meth:`_transfer`, remembered: the same question (same configurations, objects at the same poses,
        the same moving robots and arms where they stand) gets the same answer without a second search (the
        reverse search asks again when it splits a step or grounds a skeleton that shares a suffix)."""
        avoid = tuple(sorted(set(avoid)))
        poses = [self.poses[o] for o in sorted(self.poses)]  # lift_height reads every object's pose
        key = (
            "transfer",
            robot,
            obj,
            grasp,
            avoid,
            lift,
            lower,
            phase,
            self._presence(),
        ) + self.fingerprint([start, goal, *poses], busy)
        return self._remembered(
            key, lambda: self._transfer(robot, (obj, grasp), (start, goal), avoid, lift, busy, lower, phase)
        )

    def _transfer(
        self,
        robot: str,
        held: tuple[str, str],
        ends: tuple[np.ndarray, np.ndarray],
        avoid: tuple[str, ...],
        lift: bool,
        busy: Pieces,
        lower: bool,
        phase: str,
    ) -> Answer:
        """How ``robot`` carries ``held`` (object, grasp) between ``ends``, configuration ``start`` to ``goal``:
        when ``lift`` (``start`` grasps the object where it rests), first straight up by :meth:`lift_height`
        (tool poses every centimetre, each by IK from the one before; as far as the way up is free); then the
        straight joint-space line (the validator's reading of a plan that gives no transfer) or, when that line
        collides, an RRTConnect path (a budget of checks, seeded from the query); with ``lower``, that
        motion ends as high above ``goal`` and the carry comes straight down onto it (so the arm crosses
        a bin above what will stand in it, not through it).  Free of fixed objects, of the other arms
        where they stand in ``phase`` (:meth:`step`), of ``avoid`` and of ``busy`` (what the step's other
        robots do meanwhile).
        ``path`` is every configuration, ``start`` first, no joint moving more than
        :data:`PATH_RESOLUTION` between two; ``blockers`` the avoided objects in the way."""
        (obj, grasp), (start, goal) = held, ends
        others = tuple(a for a in avoid if a != obj)
        against = ("fixed", *self._others(robot, phase), *others)
        moving = self._busy(busy)

        crossed = [False]  # did the last blocked motion cross what another robot of the step sweeps?

        def hits(configs: np.ndarray, holding: tuple[str, str] | None = held) -> set[str] | None:
            """None when free, else the avoided objects hit (empty: a fixed one, a moving robot or the arm
            itself)."""
            self.queries += 1
            posed = self.free_posed(robot, configs, holding=holding, grasp=held)
            crossed[0] = posed is not None and moving is not None and posed_collide(posed, moving)
            if crossed[0] or posed is None:
                return set()
            if not self.world.probe_collides(posed, against=against, ignore=(obj,)):
                return None
            return self.world.probe_hits(posed, against=others, ignore=(obj,)) if others else set()

        back = np.asarray(start, dtype=float)[None]
        if lift:
            up = self._lift(robot, back[0], self.lift_height(obj, start=True))
            if up is None:
                return Answer(GroundStatus.NO_IK)
            first = joint_line(up[:2], PATH_RESOLUTION)  # the object leaves what it rests on: arm alone
            blocked = hits(first, holding=None)
            if blocked is None:  # held from the end of the first centimetre on
                blocked = hits(first[-1:])
            if blocked is not None:
                return Answer(GroundStatus.COLLISION, blockers=blocked, detail=BUSY if crossed[0] else "")
            # then centimetre by centimetre as far as the way up is free (an arm waiting at home above the
            # table may stop it early; the carry goes on from there)
            back = joint_line(up[: _free_run(up, hits, 1) + 1], PATH_RESOLUTION)
        # with ``lower``, the carry ends above the goal and comes straight down onto it (the mirror of the lift)
        tail = (
            self._descent(robot, np.asarray(goal, dtype=float), self.lift_height(obj, goal=(robot, grasp, goal)), hits)
            if lower
            else np.asarray(goal, dtype=float)[None]
        )
        # across the table above whatever may stand in a region by then (a bin filled earlier in the plan,
        # which the reverse search has not placed yet): the line's low points raised, else the plain line
        over = self._over(robot, held, back[-1], tail[0])
        if over is not None and hits(over) is None:
            return Answer(GroundStatus.OK, path=[*back, *over[1:], *tail[1:]])
        middle, blocked = self._line_or_path(robot, (back[-1], tail[0]), hits, (others, busy, phase), holding=held)
        if not middle:
            return Answer(GroundStatus.NO_PATH, blockers=blocked or set(), detail=BUSY if crossed[0] else "")
        return Answer(GroundStatus.OK, path=[*back, *middle[1:], *tail[1:]])

    def _line_or_path(
        self,
        robot: str,
        ends: tuple[np.ndarray, np.ndarray],
        blocked: Callable[[np.ndarray], set[str] | None],
        motion: tuple[tuple[str, ...], Pieces, str],
        holding: tuple[str, str] | None = None,
        fingers: tuple[str, str] | None = None,
    ) -> tuple[list[np.ndarray], set[str] | None]:
        """How a transfer or a transit of ``robot`` moves between ``ends`` (configurations): the straight
        joint-space line at :data:`PATH_RESOLUTION` when ``blocked`` finds it free (None), else an RRTConnect
        path (:meth:`arm_path`, a budget of :data:`TRANSFER_CHECKS`) avoiding ``motion``'s objects, free of its
        busy pieces, among the other arms where they stand in its phase; ``holding`` and ``fingers`` as for
        :meth:`arm_path`.  The configurations (empty when neither is free) and what ``blocked`` found on the
        line."""
        line = joint_line(np.stack(ends), PATH_RESOLUTION)
        hit = blocked(line)
        if hit is None:
            return list(line), None
        avoid, busy, phase = motion
        budget = BUSY_TRANSFER_CHECKS if len(busy) else TRANSFER_CHECKS
        planned = self.arm_path(
            robot, *ends, holding, avoid, budget, PATH_RESOLUTION, busy, phase=phase, fingers=fingers
        )
        return (planned.path if planned.ok else []), hit

    def _descent(
        self, robot: str, goal: np.ndarray, height: float, hits: Callable[[np.ndarray], set[str] | None]
    ) -> np.ndarray:
        """Configurations coming straight down onto ``goal`` from up to ``height`` above it (the tool's pose
        at ``goal`` raised centimetre by centimetre, as far as IK follows and ``hits`` finds the way free),
        ``goal`` last, at :data:`PATH_RESOLUTION`; ``goal`` alone when not even one centimetre is free."""
        return joint_line(self._straight(robot, goal, height, hits)[::-1], PATH_RESOLUTION)

    def _straight(
        self,
        robot: str,
        q: np.ndarray,
        distance: float,
        hits: Callable[[np.ndarray], set[str] | None],
        direction: np.ndarray | None = None,
    ) -> np.ndarray:
        """Configurations moving the tool straight along ``direction`` (world; default up) from its pose at
        ``q`` by up to ``distance``, ``q`` first, one per centimetre (:meth:`_lift`), as far as IK follows and
        ``hits`` finds each motion between two free; ``q`` alone when not even one centimetre is."""
        up = self._lift(robot, q, distance, direction)
        if up is None:
            return q[None]
        return up[: _free_run(up, hits) + 1]

    def transit(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        avoid: Iterable[str] = (),
        busy: Pieces = (),
        via: np.ndarray | None = None,
        phase: str = "home",
        fingers: tuple[str, str] | None = None,
        retreat: np.ndarray | None = None,
    ) -> Answer:
        """An empty-handed motion of ``robot`` from ``start`` to ``goal``, its fingers at the opening of
        ``fingers`` (object, grasp: a giver letting go) or fully open, as the validator replays it: along ``via``
        first when given (configurations, ``start`` first, joined by straight joint-space lines: a release
        backing off along its approach), or with ``retreat`` (a world direction) first straight along it by
        up to :data:`~mrgc.geometry.grasps.APPROACH` as far as the way is free (a giver backing its open
        fingers off the object the taker holds, along its approach axis); then the straight line or, when that
        collides, an RRTConnect path.  Free of fixed objects, of the other arms where they stand in ``phase``
        (``to-pick``, ``giver-home`` ...: :meth:`step`), of ``avoid`` and of ``busy``; ``path`` as for
        :meth:`transfer`."""
        against = ("fixed", *self._others(robot, phase), *avoid)
        moving = self._busy(busy)

        def free(configs: np.ndarray) -> bool:
            self.queries += 1
            volume = self.free_volume(robot, configs, grasp=fingers)
            if volume is None:
                return False
            posed = Posed.of(volume)
            if moving is not None and posed_collide(posed, moving):
                return False
            return not self.world.probe_collides(posed, against=against)

        def blocked(configs: np.ndarray) -> set[str] | None:
            return None if free(configs) else set()

        if retreat is not None:
            start = np.asarray(start, dtype=float)
            via = self._straight(robot, start, APPROACH, blocked, retreat)
        back = joint_line(np.asarray(via if via is not None else [start], dtype=float), PATH_RESOLUTION)
        if not free(back):
            return Answer(GroundStatus.COLLISION)
        ends = (back[-1], np.asarray(goal, dtype=float))
        middle, _ = self._line_or_path(robot, ends, blocked, (tuple(avoid), busy, phase), fingers=fingers)
        if not middle:
            return Answer(GroundStatus.NO_PATH)
        return Answer(GroundStatus.OK, path=[*back, *middle[1:]])

    def lift_height(self, obj: str, start: bool = False, goal: tuple[str, str, np.ndarray] | None = None) -> float:
        """How far to raise ``obj`` straight up from where it rests before carrying it off: until its bottom
        clears the tops of its neighbours (other objects within :data:`NEIGHBOURHOOD` of its footprint) by
        1 cm, at least :data:`TRANSFER_LIFT`, at most :data:`MAX_LIFT`.  Among taller neighbours (a dense
        start grid) a lift of a few centimetres leaves the object boxed in, and every carry from there has
        to find the way up by sampling.  With ``start`` (lifting it where it rests now) or ``goal`` (the
        robot, grasp and configuration holding it above its placement), at least until its bottom clears
        :attr:`standing_top` by 1 cm: a carry crosses the table above anything that may stand there."""
        pose, h = self.poses[obj], half_extents(self.scene.body(obj).shape)
        bottom, reach = pose[2, 3] - h[2], float(np.hypot(h[0], h[1])) + NEIGHBOURHOOD
        top = bottom
        for body in self.scene.movable:
            if body.name == obj:
                continue
            other, g = self.poses[body.name], half_extents(body.shape)
            if np.hypot(*(other[:2, 3] - pose[:2, 3])) <= reach + float(np.hypot(g[0], g[1])):
                top = max(top, other[2, 3] + g[2])
        lift = top - bottom + 0.01
        if start or goal is not None:
            if goal is not None:
                robot, grasp, q = goal
                bottom = self._held_bottom(robot, (obj, grasp), np.asarray(q)[None])[0]
            lift = max(lift, self.standing_top - bottom + 0.01)
        return float(np.clip(lift, TRANSFER_LIFT, MAX_LIFT))

    @cached_property
    def standing_top(self) -> float:
        """The highest top of a movable object standing on the lowest region floor (the top of the tallest
        object wherever it is placed), world z."""
        floor = (
            min(float(r.pose[2, 3] - half_extents(r.shape)[2]) for r in self.scene.regions)
            if self.scene.regions
            else 0.0
        )
        return floor + max((2 * float(half_extents(b.shape)[2]) for b in self.scene.movable), default=0.0)

    def _held_bottom(self, robot: str, held: tuple[str, str], configs: np.ndarray) -> np.ndarray:
        """The world z of the lowest point of the bounding box of ``held`` (object, grasp) in ``robot``'s hand
        at each of ``configs``."""
        obj, grasp = held
        h = half_extents(self.scene.body(obj).shape)
        poses = self.arm(robot).tool_world(configs) @ self._grip(robot, obj, grasp)[1]
        out: np.ndarray = poses[:, 2, 3] - np.abs(poses[:, 2, :3]) @ h
        return out

    def _over(self, robot: str, held: tuple[str, str], a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
        """The joint-space line from ``a`` to ``b`` (both holding ``held``) with its points every
        :data:`CARRY_STEP` of the tool's horizontal travel raised (the tool straight up, by IK from the
        line's configuration) where the held object's bottom dips below :attr:`standing_top` + 1 cm or
        below both ends, whichever is lower; at :data:`PATH_RESOLUTION`.  None when the line does not dip
        or a raised point has no IK solution near the line."""
        arm = self.arm(robot)
        ends = arm.tool_world(np.stack([a, b]))
        n = int(np.ceil(np.linalg.norm(ends[1][:2, 3] - ends[0][:2, 3]) / CARRY_STEP))
        if n < 2:
            return None
        s = np.linspace(0.0, 1.0, n + 1)[:, None]
        configs = a[None] * (1 - s) + b[None] * s
        bottoms = self._held_bottom(robot, held, configs)
        floor = min(self.standing_top + 0.01, max(bottoms[0], bottoms[-1]))
        low = [k for k in range(1, n) if bottoms[k] < floor - 0.005]
        if not low:
            return None
        tools = arm.tool_world(configs)
        for k in low:
            target = arm.ee_target(translation(0.0, 0.0, float(floor - bottoms[k])) @ tools[k])
            ik = solve_ik_many(arm.model, target[None], 0, q_init=configs[k], restarts=0)[0]
            if not ik.solved or ik.q is None or float(np.abs(ik.q - configs[k]).max()) > 0.5:
                return None
            configs[k] = ik.q
        return joint_line(configs, PATH_RESOLUTION)

    def _lift(
        self, robot: str, q: np.ndarray, height: float = TRANSFER_LIFT, direction: np.ndarray | None = None
    ) -> np.ndarray | None:
        """Configurations moving the tool straight along ``direction`` (world, a unit vector; default up) from
        its pose at ``q`` by up to ``height``, one per centimetre, as far as none fails or jumps (None when not
        even the first centimetre can be solved).  Every centimetre is first solved from ``q`` in one batch
        (a third of the time of solving each from the one before); from the first that fails or jumps from the
        one before, each is solved from the one before, as far as that goes."""
        arm = self.arm(robot)
        tool = arm.tool_world(q[None])[0]
        way = np.array((0.0, 0.0, 1.0) if direction is None else direction, dtype=float)
        steps = np.arange(1, round(height / 0.01) + 1) * 0.01
        if self.late() or not len(steps):
            return None
        targets = arm.ee_target(np.stack([translation(*(way * dz)) @ tool for dz in steps]))
        out = [q]
        for ik in solve_ik_many(arm.model, targets, 0, q_init=np.repeat(q[None], len(steps), axis=0), restarts=0):
            nxt = _following(ik, out[-1])
            if nxt is None:
                break
            out.append(nxt)
        for target in targets[len(out) - 1 :]:
            if self.late():
                break
            ik = solve_ik_many(arm.model, target[None], 0, q_init=out[-1], restarts=0)[0]
            nxt = _following(ik, out[-1])
            if nxt is None:
                break  # as high as the arm goes straight up (at the edge of its reach: less)
            out.append(nxt)
        return np.array(out) if len(out) > 1 else None


def _following(ik: IKResult, before: np.ndarray) -> np.ndarray | None:
    """A straight motion's next configuration: the one ``ik`` solved, when no joint is farther than 0.2 rad
    from ``before``; else None."""
    if not ik.solved or ik.q is None or float(np.abs(ik.q - before).max()) > 0.2:
        return None
    return ik.q


def _free_run(up: np.ndarray, hits: Callable[[np.ndarray], set[str] | None], top: int = 0) -> int:
    """How far a straight motion through the configurations ``up`` is free from ``up[top]`` on: the last index
    ``k`` such that ``hits`` finds each motion between two of ``up[top : k + 1]`` free (None), a centimetre at a
    time.  Most such motions are free all the way (a lift, a descent onto a placement: 25 of 30 on PA5 and
    PA10 presets), so the whole rest is asked first in one batch (the same configurations: :func:`joint_line`
    of the points is that of each pair in turn), and only when something is in the way one by one."""
    if len(up) - top > 2 and hits(joint_line(up[top:], PATH_RESOLUTION)) is None:
        return len(up) - 1
    while top + 1 < len(up) and hits(joint_line(up[top : top + 2], PATH_RESOLUTION)) is None:
        top += 1
    return top


def joint_line(configs: np.ndarray, step: float) -> np.ndarray:
    """The configurations of the straight joint-space motion through ``configs`` (C, dof), first and last
    included, no joint moving more than ``step`` between two."""
    out = [configs[:1]]
    for a, b in zip(configs[:-1], configs[1:]):
        n = max(1, int(np.ceil(float(np.abs(b - a).max()) / step - 1e-9)))
        s = np.arange(1, n + 1)[:, None] / n
        out.append(a[None] * (1 - s) + b[None] * s)
    return np.concatenate(out)
