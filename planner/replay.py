"""Geometric plan replay for the validator: every step re-run in pybullet, finer than the planner checks.

Nothing here comes from the planner's search or grounding: configurations are read from the plan, forward
kinematics and signed distances are pybullet's (:class:`mrgc.geometry.replay_world.ReplayScene`: the robots'
URDF collision meshes, the objects as pybullet shapes), grasp frames come from their specification
(:mod:`mrgc.geometry.grasps`), the planar-robot model from :mod:`mrgc.geometry.planar`'s docstring.  Each
action's geometry is read and checked by :mod:`mrgc.planner.replay_actions`; this module sweeps it.

**Execution model** (what a plan means; the checks follow it).  Robots start each step at home (their
kind's ``:home``; a planar robot at its ``:base`` pose) and robots that wait stay there.  A step runs in
synchronised phases:

1. *to-pick* (paths ``to-pick``): pick robots move from home to their first pick configuration;
2. *pick*: every pick robot follows its ``configs.pick`` (pre-grasp first, grasp last) and grasps its object
   at the last one; the other robots are at home; every object is where the earlier steps left it;
3. *to-handover* (holding: ``to-handover``; empty-handed: ``taker-to-handover``);
4. *handover*: each giver at ``configs.handover[0]``, each taker at ``configs.handover[1]``, both holding
   the object;
5. *to-place* (paths ``to-place``, holding): from the grasp (or a taker's exchange) to the pre-place;
6. *place*: every place robot follows its ``configs.place`` (pre-place first) holding its object and
   releases it at ``place_pose``; the other robots are at home;
7. *home* (paths ``home``, ``giver-home``): back home, every object at its new pose.

**The motion model** (the plan's ``motion_model``) says which motions the plan holds.  Planar robots
(``paths``): ``to-pick``, ``to-place`` and ``home`` are required of every action.  Arms, ``full``: every
path of the action's kind is required.  Arms, ``configurations`` (the paper's packaging model): no path is
required; a *holding* transfer without a path (``to-handover``, ``to-place``) is the straight joint-space
move between the configurations it connects, checked like a path; empty-handed transit is not modelled.

In phases 3-6 the step's own objects are held or in transit, the other objects in place.  In phases 1, 2
and 6 a robot without a motion in the phase is at home; in phases 3, 4, 5 and 7 only the waiting robots
are, and a robot of the step without a motion in the phase is in transit and not checked (the plan says
nothing about where it is).  Motions of different robots in one phase are paired by index and sampled at
the union of their sample times (:mod:`mrgc.planner.sampling`): between two samples no joint moves more
than the resolution (:data:`RESOLUTION`, or the plan's finer one, never below :data:`MIN_RESOLUTION`).

**Checks** (codes in brackets; tolerances as module constants here and in :mod:`~mrgc.planner.replay_actions`):

- what :mod:`~mrgc.planner.replay_actions` checks per action: ``[motion-model]``, ``[missing]``,
  ``[config]``, ``[joint-limits]``, ``[pose]``, ``[grasp]``, ``[approach]``, ``[handover]``, ``[path]``;
- no collision (penetration deeper than :data:`CONTACT_TOL`) robot-robot, robot-object, robot-fixed
  (except an arm's base link, see :class:`~mrgc.geometry.replay_world.ReplayScene`), held object-object and held
  object-fixed, at every sample of every phase ``[collision-...]``; a robot is exempt from the object it
  holds, and from the object it picks only in the *contact segment* of its pick approach (between its last
  two configurations); a collision is reported once per step, phase and pair, at its deepest;
- a motion longer than :data:`MAX_SAMPLES` samples, or a plan whose motions need more than
  :data:`MAX_PLAN_SAMPLES` robot samples in all, is not checked and so not valid ``[too-long]``;
- every placement lies inside its action's region ``[outside-region]``, is free of fixed objects, other
  objects and the robots at home, to :data:`CONTACT_TOL` ``[collision-...]``, and rests on something
  ``[floating]``: its lowest point at most :data:`SUPPORT_TOL` above the floor of a region under it, or
  lowered by :data:`SUPPORT_TOL` it would sink into a fixed or movable object (one beside it does not
  count); an object that rested on one a step moves away must still rest on something;
- at the end every goal object lies entirely inside its goal region ``[goal]``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from mrgc.geometry.replay_world import ReplayScene
from mrgc.geometry.scene import SceneSpec, inside, outline, scene_from_problem
from mrgc.geometry.transforms import translation
from mrgc.language.model import Problem
from mrgc.planner.plan import MotionModel
from mrgc.planner.plan_reader import Action
from mrgc.planner.replay_actions import PATH_PHASES, ActionGeometry, ActionReader
from mrgc.planner.sampling import config_at, sample_count, sample_times, where
from mrgc.planner.violation import Violation

RESOLUTION = 0.01  # largest joint (rad) or planar base (m, rad) motion between samples
MIN_RESOLUTION = 1e-3  # a plan's finer resolution is followed down to this
CONTACT_TOL = 1e-3  # m of penetration tolerated (resting contact, numerical noise)
SUPPORT_TOL = 0.01  # m: a released object's lowest point may stand this far above what it rests on
MAX_SAMPLES = 100_000  # per motion: one needing more is too long to check (and reported)
MAX_PLAN_SAMPLES = 1_000_000  # robot samples of the whole plan (samples x robots moving)
BOX_PAD = 1e-3  # m: bounding boxes closer than this are handed to pybullet's distance query


@dataclass
class _Track:
    """A robot moving through configurations during a phase, maybe holding an object.  ``carries``: the
    track puts the held object where its tool holds it (a taker at a handover does not: the giver does);
    ``exempt``: an object the robot may touch from time ``exempt_from`` on (the pick's contact segment)."""

    robot: str
    configs: np.ndarray  # (m, dof)
    label: str
    holding: str | None = None
    grasp: str | None = None
    fingers: float | None = None  # finger opening (m) while approaching or holding; None: fully open
    carries: bool = True
    exempt: str | None = None
    exempt_from: float = 2.0


class _Stop(Exception):
    """The first violation is known and no more are wanted."""


def replay(
    problem: Problem,
    model: MotionModel,
    steps: Sequence[Sequence[Action]],
    usable: set[int],
    stats: dict[str, Any],
    first_only: bool = False,
) -> list[Violation]:
    """The geometric violations of a plan whose actions (``usable``: ids of the name-checked ones) are
    ``steps``, under motion model ``model``; fills ``stats`` with the configurations and distance queries
    checked.  ``first_only``: stop at the end of the first phase or check that finds a violation (a
    referee that only needs to know whether the plan is valid)."""
    scene, rs = _world(problem)
    queries = rs.queries
    r = _Replayer(scene, rs, model)
    r.first_only = first_only
    try:
        r.check_model()
        r.stop_if_found()
        for t, step in enumerate(steps, 1):
            acts = [r.parse(t, a) for a in step if id(a) in usable]
            r.stop_if_found()
            r.run_step(t, acts)
        r.goals()
    except _Stop:
        r.flush()
    stats["configurations"] = r.samples
    stats["distance_queries"] = rs.queries - queries
    return r.out


_WORLD: dict[str, Any] = {}


def _world(problem: Problem) -> tuple[SceneSpec, ReplayScene]:
    """The pybullet world of ``problem``, built once per problem and process and kept for the next plan of
    the same problem (loading a robot's URDF costs about 0.2 s; the planner's referee and the tests validate
    many plans of one problem).  A replay sets every pose and configuration it reads, so nothing of one
    plan's replay reaches the next."""
    if _WORLD.get("pid") == os.getpid() and _WORLD.get("problem") is problem:
        return _WORLD["scene"], _WORLD["rs"]
    if _WORLD.get("pid") == os.getpid():
        _WORLD["rs"].close()
    _WORLD.clear()
    scene = scene_from_problem(problem)
    rs = ReplayScene(scene)
    _WORLD.update(pid=os.getpid(), problem=problem, scene=scene, rs=rs)
    return scene, rs


class _Replayer(ActionReader):
    def __init__(self, scene: SceneSpec, rs: ReplayScene, model: MotionModel) -> None:
        super().__init__(scene, rs, model)
        self.fixed = [b.name for b in scene.fixed]
        self.movable = [b.name for b in scene.movable]
        self.resolution = max(MIN_RESOLUTION, min(RESOLUTION, model.resolution))
        self.samples = 0
        self.budget_spent = False
        self._worst: dict[tuple[Any, ...], tuple[float, str, str]] = {}
        self.first_only = False
        #: bounding boxes (min x y z, max x y z) of the bodies of the phase being swept
        self._boxes: dict[str, tuple[float, ...]] = {}
        self._placements_state()
        self.support = {o: self._supports(o) for o in self.movable}  # what each object rests on

    # ------------------------------------------------------------------ one step
    def run_step(self, t: int, acts: list[ActionGeometry]) -> None:
        """Replay step ``t``: the phases of the module docstring."""
        geo = [a for a in acts if a.geometry]
        robots = list(self.planar)
        in_step = {a.obj for a in acts}
        busy = {r for a in acts for r in a.action.robots()}
        waiting = [r for r in robots if r not in busy]
        everything = list(self.movable)
        present = [o for o in self.movable if o not in in_step]

        def paths(*names: str) -> list[_Track]:
            out = []
            for a in geo:  # an action with broken geometry is reported, its motions are not replayed
                for name in names:
                    if name in a.paths:
                        role, grasp_role = PATH_PHASES[name][:2]
                        robot, grasp = a.robot(role), a.grasp(grasp_role)
                        label = f"straight {name} transfer" if name in a.straight else f"{name} path"
                        out.append(
                            _Track(
                                robot,
                                a.paths[name],
                                label,
                                a.obj if grasp else None,
                                grasp,
                                self.fingers(robot, a.obj, grasp),
                            )
                        )
            return out

        def others(tracks: list[_Track]) -> list[str]:
            return [r for r in robots if r not in {tr.robot for tr in tracks}]

        tracks = paths("to-pick")
        self._sweep(t, "to-pick", tracks, others(tracks), everything)
        tracks = []
        for a in geo:
            qs, robot = a.configs["pick"], a.action.pick_robot
            contact = max(0.0, (len(qs) - 2) / (len(qs) - 1)) if len(qs) > 1 else 0.0
            tracks.append(
                _Track(
                    robot,
                    qs,
                    "pick",
                    fingers=self.fingers(robot, a.obj, a.action.pick_grasp),
                    exempt=None if self.planar[robot] else a.obj,
                    exempt_from=contact,
                )
            )
        self._sweep(t, "pick", tracks, others(tracks), everything)
        self._sweep(t, "to-handover", paths("to-handover", "taker-to-handover"), waiting, present)
        tracks = []
        for a in geo:
            if a.handover:
                h, (giver, taker), (g1, g2) = (
                    a.configs["handover"],
                    a.action.robots(),
                    (a.action.pick_grasp, a.action.place_grasp),
                )
                tracks.append(_Track(giver, h[:1], "handover (giver)", a.obj, g1, self.fingers(giver, a.obj, g1)))
                tracks.append(
                    _Track(taker, h[1:], "handover (taker)", a.obj, g2, self.fingers(taker, a.obj, g2), carries=False)
                )
        self._sweep(t, "handover", tracks, waiting, present)
        self._sweep(t, "to-place", paths("to-place"), waiting, present)
        tracks = [
            _Track(
                a.action.place_robot,
                a.configs["place"],
                "place",
                a.obj,
                a.action.place_grasp,
                self.fingers(a.action.place_robot, a.obj, a.action.place_grasp),
            )
            for a in geo
        ]
        self._sweep(t, "place", tracks, others(tracks), present)
        for a in acts:
            if a.place_pose is None:
                continue
            self.poses[a.obj] = a.place_pose
            if not inside(self.scene.region(a.action.region), self.shapes[a.obj], a.place_pose):
                p = a.place_pose[:3, 3]
                self._v(
                    t,
                    a.obj,
                    "outside-region",
                    f"the placement of {a.obj} at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) "
                    f"is not entirely inside region {a.action.region}",
                )
        self._sweep(t, "home", paths("home", "giver-home"), waiting, everything)
        placed = [a for a in acts if a.place_pose is not None]
        self._placements(t, placed)
        self._rests(t, placed)
        self._on_tops(t, placed)
        self.flush()

    # ------------------------------------------------------------------ sweeping a phase
    def _sweep(self, t: int, phase: str, tracks: list[_Track], static: list[str], present: list[str]) -> None:
        if not tracks or self.budget_spent or not self._within_budget(t, phase, tracks):
            return
        others = self._stage(tracks, static, present)
        times = np.unique(
            np.concatenate([sample_times(tr.configs, self.planar[tr.robot], self.resolution) for tr in tracks])
        )
        for s in times:
            self._sample(t, phase, tracks, static, others, float(s))
            if self.first_only and self._worst:
                break
        self.stop_if_found()

    def _within_budget(self, t: int, phase: str, tracks: list[_Track]) -> bool:
        """Whether the phase's motions can be checked: no motion longer than :data:`MAX_SAMPLES` samples,
        the plan's samples in all at most :data:`MAX_PLAN_SAMPLES` ``[too-long]`` (then the rest of the
        plan's motions are not checked)."""
        counts = [sample_count(tr.configs, self.planar[tr.robot], self.resolution) for tr in tracks]
        n = max(counts)
        if n > MAX_SAMPLES:
            tr = tracks[counts.index(n)]
            self._v(
                t,
                tr.robot,
                "too-long",
                f"{phase}: the {tr.label} motion of {tr.robot} is too long to check "
                f"({n} samples at {self.resolution:g} rad or m each; at most {MAX_SAMPLES})",
            )
            return False
        if self.samples + sum(counts) * len(tracks) > MAX_PLAN_SAMPLES:
            self._v(
                t,
                None,
                "too-long",
                f"{phase}: the plan's motions need more than {MAX_PLAN_SAMPLES} robot "
                f"samples in all; the rest of the plan's motions are not checked",
            )
            self.budget_spent = True
            return False
        return True

    def _stage(self, tracks: list[_Track], static: list[str], present: list[str]) -> list[str]:
        """Set the world up for a phase: robots not moving at home with open fingers, moving robots' fingers
        at their opening, objects present where they are (the others and none held parked), bounding boxes
        of what does not move; the objects present and not held."""
        rs = self.rs
        for r in static:
            rs.set_config(r, self.home[r])
            rs.set_fingers(r, None)
        for tr in tracks:  # fingers: at the grasp's opening while approaching or holding, else fully open
            rs.set_fingers(tr.robot, tr.fingers)
        held = {tr.holding for tr in tracks if tr.holding}
        for o in self.movable:
            if o in present:
                rs.set_pose(o, self.poses[o])
            elif o not in held:
                rs.set_pose(o, None)
        others = [o for o in present if o not in held]
        # bounding boxes: a pair whose boxes are apart cannot overlap, and is not asked of pybullet
        self._boxes = {b: self.rs.aabb(b) for b in (*self.fixed, *others, *static)}
        return others

    def _sample(self, t: int, phase: str, tracks: list[_Track], static: list[str], others: list[str], s: float) -> None:
        """Every moving robot (and what it holds) at time ``s`` of the phase, checked against the scene, the
        other moving robots and the robots at home."""
        rs = self.rs
        states = []
        for tr in tracks:
            q = config_at(tr.configs, s, self.planar[tr.robot])
            rs.set_config(tr.robot, q)
            self._boxes[tr.robot] = self.rs.aabb(tr.robot)
            if tr.holding and tr.grasp and tr.carries:  # a handed-over object is where the giver holds it
                rs.set_pose(tr.holding, self.held_pose(tr.robot, q, tr.holding, tr.grasp))
                self._boxes[tr.holding] = self.rs.aabb(tr.holding)
            states.append(where(tr.label, len(tr.configs), s))
        self.samples += len(tracks)
        for tr, at in zip(tracks, states):
            self._robot_scene(t, phase, tr, at, others, s)
        for i, tr in enumerate(tracks):
            for j in range(i + 1, len(tracks)):
                self._pair(t, phase, tr, states[i], tracks[j], states[j])
            for r in static:
                self._pair(t, phase, tr, states[i], _Track(r, np.zeros((1, 1)), "home"), "at home")

    def stop_if_found(self) -> None:
        """With ``first_only``, end the replay once a violation is known."""
        if self.first_only and (self.out or self._worst):
            raise _Stop

    def _closest(self, a: str, b: str) -> Any:
        """pybullet's deepest overlap of ``a`` and ``b``, None when they do not overlap (at once when their
        bounding boxes, grown by 1 mm, are apart)."""
        a0, a1, a2, a3, a4, a5 = self._boxes[a]
        b0, b1, b2, b3, b4, b5 = self._boxes[b]
        if (
            a0 > b3 + BOX_PAD
            or a1 > b4 + BOX_PAD
            or a2 > b5 + BOX_PAD
            or b0 > a3 + BOX_PAD
            or b1 > a4 + BOX_PAD
            or b2 > a5 + BOX_PAD
        ):
            return None
        return self.rs.closest(a, b)

    def _robot_scene(self, t: int, phase: str, tr: _Track, at: str, others: list[str], s: float) -> None:
        me = (tr.robot, at)
        for f in self.fixed:
            self._hit(t, phase, tr.robot, f, self._closest(tr.robot, f), me, (f, ""), "robot-fixed")
        for o in others:
            if o == tr.holding or (o == tr.exempt and s >= tr.exempt_from - 1e-12):
                continue
            self._hit(t, phase, tr.robot, o, self._closest(tr.robot, o), me, (o, ""), "robot-object")
        if tr.holding and tr.carries:
            h = tr.holding
            held = (f"{h} held by {tr.robot}", at)
            for f in self.fixed:
                self._hit(t, phase, h, f, self._closest(h, f), held, (f, ""), "object-fixed")
            for o in others:
                if o != h:
                    self._hit(t, phase, h, o, self._closest(h, o), held, (o, ""), "object-object")

    def _pair(self, t: int, phase: str, a: _Track, wa: str, b: _Track, wb: str) -> None:
        da, db = (a.robot, wa), (b.robot, wb)
        self._hit(t, phase, a.robot, b.robot, self._closest(a.robot, b.robot), da, db, "robot-robot")
        ha = a.holding if a.holding and a.carries else None
        hb = b.holding if b.holding and b.carries else None
        if hb and hb != a.holding:
            self._hit(
                t, phase, a.robot, hb, self._closest(a.robot, hb), da, (f"{hb} held by {b.robot}", wb), "robot-object"
            )
        if ha and ha != b.holding:
            self._hit(
                t, phase, b.robot, ha, self._closest(b.robot, ha), db, (f"{ha} held by {a.robot}", wa), "robot-object"
            )
        if ha and hb and ha != hb:
            self._hit(
                t,
                phase,
                ha,
                hb,
                self._closest(ha, hb),
                (f"{ha} held by {a.robot}", wa),
                (f"{hb} held by {b.robot}", wb),
                "object-object",
            )

    def _hit(
        self, t: int, phase: str, a: str, b: str, c: Any, da: tuple[str, str], db: tuple[str, str], kind: str
    ) -> None:
        """Record a penetration deeper than CONTACT_TOL between ``a`` and ``b`` (described by (label, when)),
        keeping the deepest per (step, phase, pair)."""
        if c is None or c.distance >= -CONTACT_TOL:
            return
        key = (t, phase, kind, a, b)
        if key in self._worst and self._worst[key][0] <= c.distance:
            return

        def side(d: tuple[str, str], link: str | None) -> str:
            return (f"{link} of {d[0]}" if link else d[0]) + (f" ({d[1]})" if d[1] else "")

        msg = f"{phase}: {side(da, c.link_a)} and {side(db, c.link_b)} overlap by {-c.distance * 1e3:.1f} mm"
        self._worst[key] = (c.distance, a, msg)

    def flush(self) -> None:
        for (t, _, kind, _, _), (_, subject, msg) in self._worst.items():
            self._v(t, subject, f"collision-{kind}", msg)
        self._worst.clear()

    # ------------------------------------------------------------------ after the step
    def _placements_state(self) -> None:
        """Every object at its current pose, every robot at home."""
        for o in self.movable:
            self.rs.set_pose(o, self.poses[o])
        for r in self.planar:
            self.rs.set_config(r, self.home[r])
            self.rs.set_fingers(r, None)

    def _placements(self, t: int, acts: list[ActionGeometry]) -> None:
        rs = self.rs
        self._placements_state()
        done: set[frozenset[str]] = set()
        for a in acts:
            o = a.obj
            for f in self.fixed:
                self._hit(t, "placement", o, f, rs.closest(o, f), (f"{o} placed", ""), (f, ""), "object-fixed")
            for other in self.movable:
                if other != o and frozenset((o, other)) not in done:
                    done.add(frozenset((o, other)))
                    self._hit(
                        t,
                        "placement",
                        o,
                        other,
                        rs.closest(o, other),
                        (f"{o} placed", ""),
                        (other, ""),
                        "object-object",
                    )
            for r in self.planar:
                self._hit(t, "placement", o, r, rs.closest(o, r), (f"{o} placed", ""), (r, "at home"), "robot-object")

    def _floor_gap(self, obj: str) -> tuple[float, str] | None:
        """How far the object's lowest point stands above the floor of the nearest region under its centre
        (negative: below it), and that region; None when no region lies under it."""
        pose = self.poses[obj]
        pts = outline(self.shapes[obj]) @ pose[:3, :3].T + pose[:3, 3]
        low = float(pts[:, 2].min())
        best: tuple[float, str] | None = None
        for region in self.scene.regions:
            corners = outline(region.shape) @ region.pose[:3, :3].T + region.pose[:3, 3]
            inv = np.linalg.inv(region.pose)
            local = inv[:3, :3] @ pose[:3, 3] + inv[:3, 3]
            half = np.abs(outline(region.shape)).max(axis=0)
            if np.all(np.abs(local[:2]) <= half[:2] + 1e-9):
                gap = low - float(corners[:, 2].min())
                if gap >= -CONTACT_TOL and (best is None or gap < best[0]):
                    best = (gap, region.name)
        return best

    def _supports(self, obj: str) -> set[str]:
        """What ``obj`` rests on at its current pose (every other object at its pose, robots at home): region
        floors (``floor of R``) and the fixed and movable objects it would sink into when lowered by
        SUPPORT_TOL (sinking deeper by at least half of that: an object beside it does not count)."""
        out: set[str] = set()
        floor = self._floor_gap(obj)
        if floor is not None and floor[0] <= SUPPORT_TOL:
            out.add(f"floor of {floor[1]}")
        rs, pose = self.rs, self.poses[obj]
        rs.set_pose(obj, translation(0.0, 0.0, -SUPPORT_TOL) @ pose)
        sunk = {}
        for b in (*self.fixed, *self.movable):
            if b != obj:
                c = rs.closest(obj, b, 0.0)
                if c is not None:
                    sunk[b] = c.distance
        rs.set_pose(obj, pose)
        for b, d1 in sunk.items():
            c = rs.closest(obj, b, SUPPORT_TOL)
            d0 = SUPPORT_TOL if c is None else c.distance
            if d0 - d1 >= SUPPORT_TOL / 2:
                out.add(b)
        return out

    def _on_tops(self, t: int, acts: list[ActionGeometry]) -> None:
        """A relay move onto a fixed object's top sets its object down resting on that object
        ``[outside-region]`` (inside its :func:`~mrgc.geometry.scene.surface` box is not enough: a slab under
        the table has one too)."""
        fixed = set(self.fixed)
        for a in acts:
            top = a.action.region
            if a.action.relay and top in fixed and top not in self._supports(a.obj):
                self._v(t, a.obj, "outside-region", f"{a.obj} is set down on {top} but does not rest on it")

    def _rests(self, t: int, acts: list[ActionGeometry]) -> None:
        """Every placement rests on something, and so does every object whose support the step moved away
        ``[floating]`` (objects unsupported in the problem's initial state are not the plan's fault)."""
        self._placements_state()
        moved = {a.obj for a in acts}
        for a in acts:
            o = a.obj
            self.support[o] = self._supports(o)
            if not self.support[o]:
                floor = self._floor_gap(o)
                p = self.poses[o][:3, 3]
                above = (
                    f"its lowest point is {floor[0] * 1e3:.1f} mm above the floor of {floor[1]}"
                    if floor
                    else "no region lies under it"
                )
                self._v(
                    t,
                    o,
                    "floating",
                    f"{o} is released at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) resting on "
                    f"nothing: {above}, and nothing is within {SUPPORT_TOL * 1e3:g} mm under it",
                )
        for o in self.movable:
            lost = self.support[o] & moved
            if o in moved or not lost:
                continue
            self.support[o] = self._supports(o)
            if not self.support[o]:
                self._v(
                    t,
                    o,
                    "floating",
                    f"{o} rested on {', '.join(sorted(lost))}, which the step moves away: nothing holds it up now",
                )

    def goals(self) -> None:
        for obj, region in sorted(self.scene.goal.items()):
            if not inside(self.scene.body(region), self.shapes[obj], self.poses[obj]):
                p = self.poses[obj][:3, 3]
                self._v(
                    None,
                    obj,
                    "goal",
                    f"goal (in-region {obj} {region}) does not hold at the end: {obj} is at "
                    f"({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}), not entirely inside {region}",
                )
