"""Geometric plan replay for the validator: every step re-run in pybullet, finer than the planner checks.

Nothing here comes from the planner's search or grounding: configurations are read from the plan, forward
kinematics and signed distances are pybullet's (:class:`mrgc.geometry.bullet.ReplayScene`: the robots'
URDF collision meshes, the objects as pybullet shapes), grasp frames come from their specification
(:mod:`mrgc.geometry.grasps`), the planar-robot model from :mod:`mrgc.geometry.planar`'s docstring.

**Execution model** (what a plan means; the checks follow it).  Robots start each step at home (their
kind's ``:home``; a planar robot at its ``:base`` pose) and robots that wait stay there.  A step runs in
synchronised phases; phases of ``paths`` exist only when the plan gives such paths (:data:`PATH_PHASES`):

1. *to-pick* (paths ``to-pick``): pick robots drive or move from home to their first pick configuration;
2. *pick*: every pick robot follows its ``configs.pick`` (pre-grasp first, grasp last) and grasps its object
   at the last one; the other robots are at home; every object is where the earlier steps left it;
3. *to-handover* (paths ``to-handover``, holding; ``taker-to-handover``, empty-handed);
4. *handover*: each giver at ``configs.handover[0]``, each taker at ``configs.handover[1]``, both holding
   the object;
5. *to-place* (paths ``to-place``, holding): from the grasp (or a taker's exchange) to the pre-place;
6. *place*: every place robot follows its ``configs.place`` (pre-place first) holding its object and
   releases it at ``place_pose``; the other robots are at home;
7. *home* (paths ``home``, ``giver-home``): back home, every object at its new pose.

In phases 3–6 the step's own objects are held or in transit, the other objects in place.  In phases 1, 2
and 6 a robot without a motion in the phase is at home; in phases 3, 4, 5 and 7 only the waiting robots
are, and a robot of the step without a motion in the phase is in transit and not checked (the plan says
nothing about where it is).  Motions of different robots in one phase are paired by index: each is resampled to a
common number of samples, ≥ :data:`SUBSTEPS` per segment between consecutive configurations and at most
:data:`RESOLUTION` (rad, or m for a planar base) of motion per sample, linear in joint space (the shortest
way round for a planar yaw).  Retreats after a grasp or a release are not checked unless given as paths.

**Checks** (codes in brackets; tolerances as module constants):

- configurations have one value per joint ``[config]`` and lie within the URDF joint limits as pybullet
  reads them, to :data:`LIMIT_TOL` ``[joint-limits]``; the plan gives what its actions need
  ``[missing]``; ``place_pose`` is a rigid transform ``[pose]``;
- arms: the tool (``base · FK_ee(q) · tcp``, pybullet's FK) at the last pick configuration is at the
  object's pose at that time composed with the pick grasp, and at the last place configuration at
  ``place_pose`` composed with the place grasp, to :data:`POS_TOL` / :data:`ROT_TOL` ``[grasp]``;
  planar robots: the last pick/place base pose is the model's grasp base pose for that object pose
  ``[grasp]``;
- handovers: both exchange configurations hold the object, with their own grasps, at one pose whose
  position is the handover point, which the object may use ``[handover]``;
- no collision (penetration deeper than :data:`CONTACT_TOL`) robot–robot, robot–object (every object
  but the one a robot grasps or holds), robot–fixed (except an arm's base link, see
  :class:`~mrgc.geometry.bullet.ReplayScene`), held object–object and held object–fixed, at every sample
  of every phase and path ``[collision-...]``; a collision is reported once per step, phase and pair,
  at its deepest; paths must start and end at the configurations they connect ``[path]``;
- every placement lies inside its action's region ``[outside-region]`` and is free of fixed objects,
  other objects and the robots at home, to :data:`CONTACT_TOL` (resting contact) ``[collision-...]``;
- at the end every goal object lies entirely inside its goal region ``[goal]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mrgc.geometry.bullet import ReplayScene
from mrgc.geometry.grasps import finger_opening, fits, grasp_transform
from mrgc.geometry.planar import CLEARANCE, LIFT, PLANAR_GRASPS
from mrgc.geometry.scene import SceneSpec, half_extents, inside, scene_from_problem
from mrgc.geometry.transforms import from_pose, inverse, rot_z, translation
from mrgc.language.model import Problem
from mrgc.planner.validate import Violation

SUBSTEPS = 4  # samples per segment between consecutive configurations, at least
RESOLUTION = 0.01  # largest joint (rad) or planar base (m, rad) motion between samples
POS_TOL = 1e-3  # m: tool vs grasp, handover position, path continuity of planar bases
ROT_TOL = 0.01  # rad
LIMIT_TOL = 1e-6  # rad or m beyond a joint limit
CONTACT_TOL = 1e-3  # m of penetration tolerated (resting contact, numerical noise)
JOINT_TOL = 1e-3  # rad: path ends vs the configurations they connect
WORLD = 1e4  # m: planar base coordinates beyond this are outside the world
MAX_SAMPLES = 200_000  # per phase: a motion needing more is too long to check (and reported)

#: path name -> (robot role, grasp role held on the way or None, where it starts, where it ends); a place is
#: ``home`` or (configs phase, index), ``transfer`` meaning where the object was taken (the last pick
#: configuration, or the taker's exchange configuration of a handover); ends must match to JOINT_TOL
#: (planar bases: POS_TOL and ROT_TOL)
PATH_PHASES: dict[str, tuple[str, str | None, str | tuple[str, int] | None, str | tuple[str, int] | None]] = {
    "to-pick": ("pick_robot", None, "home", ("pick", 0)),
    "to-handover": ("pick_robot", "pick_grasp", ("pick", -1), ("handover", 0)),
    "taker-to-handover": ("place_robot", None, "home", ("handover", 1)),
    "to-place": ("place_robot", "place_grasp", ("transfer", -1), ("place", 0)),
    "home": ("place_robot", None, ("place", -1), "home"),
    "giver-home": ("pick_robot", None, ("handover", 0), "home"),
}
HANDOVER_PATHS = ("to-handover", "taker-to-handover", "giver-home")


@dataclass
class _Action:
    """One action of the plan with its geometry parsed."""

    step: int
    raw: dict[str, Any]
    obj: str
    region: str
    pick_robot: str
    place_robot: str
    g1: str
    g2: str
    place_pose: np.ndarray | None = None
    configs: dict[str, np.ndarray] = field(default_factory=dict)
    paths: dict[str, np.ndarray] = field(default_factory=dict)
    geometry: bool = True  # all needed geometry present and well-formed: run the collision checks

    @property
    def handover(self) -> bool:
        return self.pick_robot != self.place_robot


@dataclass
class _Track:
    """A robot moving through configurations during a phase, maybe holding an object."""

    robot: str
    configs: np.ndarray  # (m, dof)
    label: str
    holding: str | None = None
    grasp: str | None = None
    ignore: frozenset[str] = frozenset()
    fingers: float | None = None  # finger opening (m) while approaching or holding; None: fully open


def replay(problem: Problem, steps: list[list[dict[str, Any]]], usable: set[int], stats: dict[str, Any]
           ) -> list[Violation]:
    """The geometric violations of a plan whose actions (``usable``: ids of the name-checked ones) are
    ``steps``; fills ``stats`` with the configurations and distance queries checked."""
    scene = scene_from_problem(problem)
    with ReplayScene(scene) as rs:
        r = _Replayer(scene, rs)
        for t, step in enumerate(steps, 1):
            acts = [a for a in (r.parse(t, raw) for raw in step if id(raw) in usable) if a is not None]
            r.run_step(t, acts)
        r.goals()
        stats["configurations"] = r.samples
        stats["distance_queries"] = rs.queries
        return r.out


class _Replayer:
    def __init__(self, scene: SceneSpec, rs: ReplayScene) -> None:
        self.scene = scene
        self.rs = rs
        self.out: list[Violation] = []
        self.poses = {b.name: np.array(b.pose, dtype=float) for b in scene.movable}
        self.shapes = {b.name: b.shape for b in (*scene.movable, *scene.fixed)}
        self.fixed = [b.name for b in scene.fixed]
        self.movable = [b.name for b in scene.movable]
        self.planar = {r.name: rs.robots[r.name].planar for r in scene.robots}
        self.tcp = {r.name: from_pose(r.kind.tcp) if r.kind.tcp is not None else np.eye(4) for r in scene.robots}
        self.home = {r.name: self._home(r.name) for r in scene.robots}
        self.samples = 0
        self._worst: dict[tuple[Any, ...], tuple[float, str, str]] = {}

    # ------------------------------------------------------------------ helpers
    def _home(self, name: str) -> np.ndarray:
        rr = self.rs.robots[name]
        spec = self.scene.robot(name)
        if rr.planar:
            b = spec.base
            return np.array([b[0, 3], b[1, 3], math.atan2(b[1, 0], b[0, 0])])
        home = np.array(spec.kind.home, dtype=float)
        if len(home) < rr.dof:
            mid = np.where(np.isfinite(rr.lower) & np.isfinite(rr.upper), (rr.lower + rr.upper) / 2, 0.0)
            return mid  # type: ignore[no-any-return]
        return np.clip(home[: rr.dof], rr.lower, rr.upper)  # type: ignore[no-any-return]

    def _v(self, step: int | None, subject: str | None, code: str, message: str) -> None:
        self.out.append(Violation(step, subject, code, message))

    def _tool(self, robot: str, q: np.ndarray) -> np.ndarray:
        """Arms: the tool centre point in the world (pybullet FK); planar robots: the base frame."""
        self.rs.set_config(robot, q)
        return self.rs.ee_pose(robot) @ self.tcp[robot]

    def _grasp(self, robot: str, obj: str, grasp: str) -> np.ndarray:
        """Arms: the tool pose in the object frame; planar robots: the object's carry pose in the base frame."""
        shape = self.shapes[obj]
        if not self.planar[robot]:
            return grasp_transform(self.scene.grasp(grasp), shape)
        kind = self.scene.robot(robot).kind
        face = rot_z(math.radians(PLANAR_GRASPS[grasp][1]))
        if kind.carry is not None:
            return from_pose(kind.carry) @ face  # type: ignore[no-any-return]
        fp = half_extents(kind.footprint) if kind.footprint is not None else np.zeros(3)
        lift = 2 * float(fp[2]) + 2 * LIFT + float(half_extents(shape)[2])  # on top of the footprint
        return translation(0.0, 0.0, lift) @ face  # type: ignore[no-any-return]

    def _opening(self, obj: str, grasp: str) -> float:
        return finger_opening(self.scene.grasp(grasp), self.shapes[obj])

    def _fingers(self, robot: str, obj: str, grasp: str | None) -> float | None:
        """An arm's finger opening while it approaches or holds ``obj`` with ``grasp`` (None: fully open)."""
        if grasp is None or self.planar[robot] or grasp not in self.scene.grasp_specs:
            return None
        return self._opening(obj, grasp)

    def _held_pose(self, robot: str, q: np.ndarray, obj: str, grasp: str) -> np.ndarray:
        t = self._tool(robot, q)
        g = self._grasp(robot, obj, grasp)
        return t @ g if self.planar[robot] else t @ inverse(g)  # type: ignore[no-any-return]

    def _grasp_base(self, robot: str, obj: str, grasp: str, pose: np.ndarray) -> np.ndarray:
        """The planar model's base pose (x, y, yaw) for grasping ``obj`` at ``pose`` with ``grasp``: facing
        the grasped face, the front CLEARANCE from it."""
        kind = self.scene.robot(robot).kind
        fp = half_extents(kind.footprint) if kind.footprint is not None else np.zeros(3)
        nx, ny = PLANAR_GRASPS[grasp][0]
        n = pose[:2, :2] @ np.array([nx, ny])
        n = n / max(float(np.linalg.norm(n)), 1e-12)
        d = float(fp[0]) + CLEARANCE + float(np.abs([nx, ny]) @ half_extents(self.shapes[obj])[:2])
        return np.array([pose[0, 3] + d * n[0], pose[1, 3] + d * n[1], math.atan2(-n[1], -n[0])])

    # ------------------------------------------------------------------ parsing one action
    def parse(self, t: int, a: dict[str, Any]) -> _Action | None:
        act = _Action(t, a, a["object"], a["region"], a["pick_robot"], a["place_robot"], a["pick_grasp"],
                      a["place_grasp"])
        obj = act.obj
        for robot, grasp in ((act.pick_robot, act.g1), (act.place_robot, act.g2)):
            if self.planar[robot] and grasp not in PLANAR_GRASPS:
                self._v(t, obj, "grasp", f"planar robot {robot} cannot use grasp {grasp!r} "
                                         f"(side grasps only: {', '.join(PLANAR_GRASPS)})")
                act.geometry = False
            elif not self.planar[robot] and grasp not in self.scene.grasp_specs:
                self._v(t, obj, "grasp", f"grasp {grasp!r} has no geometric meaning (known: "
                                         f"{', '.join(sorted(self.scene.grasp_specs))})")
                act.geometry = False
            elif not self.planar[robot] and not fits(self.scene.grasp(grasp), self.shapes[obj],
                                                     self.scene.robot(robot).kind):
                self._v(t, obj, "grasp", f"grasp {grasp!r} needs the fingers "
                                         f"{self._opening(obj, grasp):.3f} m apart; {robot} opens "
                                         f"{self.scene.robot(robot).kind.gripper_opening:g} m")
                act.geometry = False
        if act.handover and (self.planar[act.pick_robot] or self.planar[act.place_robot]):
            self._v(t, obj, "handover", "planar robots cannot hand objects over")
            act.geometry = False
        pose = a.get("place_pose")
        if pose is None:
            self._v(t, obj, "missing", "the action has no place_pose")
            act.geometry = False
        else:
            m = np.array(pose, dtype=float)
            r = m[:3, :3]
            if (np.abs(r.T @ r - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0
                    or np.abs(m[3] - [0, 0, 0, 1]).max() > 1e-9):
                self._v(t, obj, "pose", "place_pose is not a rigid transform (orthonormal rotation, last row 0 0 0 1)")
                act.geometry = False
            elif np.abs(m[:3, 3]).max() > WORLD:
                self._v(t, obj, "pose", f"place_pose lies outside the world (|x|, |y|, |z| <= {WORLD:g} m)")
                act.geometry = False
            else:
                act.place_pose = m
        configs = a.get("configs", {})
        need = ["pick", "place"] + (["handover"] if act.handover else [])
        for phase in need:
            robot = act.pick_robot if phase == "pick" else act.place_robot
            qs = configs.get(phase)
            if not qs:
                self._v(t, obj, "missing", f"the action has no {phase} configurations")
                act.geometry = False
                continue
            if phase == "handover":
                if len(qs) != 2:
                    self._v(t, obj, "missing", f"configs.handover holds {len(qs)} configurations, not 2 "
                                               f"(giver, taker)")
                    act.geometry = False
                    continue
                ok = self._check_configs(t, act.pick_robot, "handover", qs[:1], obj) & \
                    self._check_configs(t, act.place_robot, "handover", qs[1:], obj)
            else:
                ok = self._check_configs(t, robot, phase, qs, obj)
            if ok:
                act.configs[phase] = np.array(qs, dtype=float)
            else:
                act.geometry = False
        if act.handover:
            hp = a.get("handover_point")
            allowed = self.scene.handover_of.get(obj) or tuple(self.scene.handover_points)
            if hp is None:
                self._v(t, obj, "missing", "the handover names no handover_point")
                act.geometry = False
            elif hp not in allowed:
                self._v(t, obj, "handover", f"{obj} may not be handed over at {hp} (allowed: {', '.join(allowed)})")
        for name, qs in a.get("paths", {}).items():
            if name not in PATH_PHASES:
                self._v(t, obj, "path", f"unknown path {name!r} (known: {', '.join(PATH_PHASES)})")
                continue
            role = PATH_PHASES[name][0]
            if name in HANDOVER_PATHS and not act.handover:
                self._v(t, obj, "path", f"path {name!r} belongs to a handover, and this is a pick-and-place")
                continue
            if qs and self._check_configs(t, a[role], f"path {name!r}", qs, obj):
                act.paths[name] = np.array(qs, dtype=float)
        if act.geometry:
            self._check_grasps(act)
        return act

    def _check_configs(self, t: int, robot: str, what: str, qs: list[list[float]], obj: str) -> bool:
        rr = self.rs.robots[robot]
        ok = True
        for i, q in enumerate(qs, 1):
            if len(q) != rr.dof:
                unit = "joints" if not rr.planar else "(x, y, yaw)"
                self._v(t, robot, "config", f"{what} configuration {i} of {len(qs)} (moving {obj}) has {len(q)} "
                                            f"values; {robot} has {rr.dof} {unit}")
                ok = False
                continue
            v = np.asarray(q, dtype=float)
            if rr.planar and max(abs(v[0]), abs(v[1])) > WORLD:
                self._v(t, robot, "config", f"{what} configuration {i} of {len(qs)} (moving {obj}) puts the base "
                                            f"outside the world (|x|, |y| <= {WORLD:g} m)")
                ok = False
                continue
            bad = np.nonzero((v < rr.lower - LIMIT_TOL) | (v > rr.upper + LIMIT_TOL))[0]
            for j in bad:
                self._v(t, robot, "joint-limits", f"{what} configuration {i} of {len(qs)} (moving {obj}): "
                                                  f"{rr.joint_names[j]} = {v[j]:.4f} is outside "
                                                  f"[{rr.lower[j]:.4f}, {rr.upper[j]:.4f}]")
                ok = False
        return ok

    def _check_grasps(self, act: _Action) -> None:
        t, obj = act.step, act.obj
        assert act.place_pose is not None
        checks = [("pick", act.pick_robot, act.g1, self.poses[obj], "the object"),
                  ("place", act.place_robot, act.g2, act.place_pose, "place_pose")]
        for phase, robot, grasp, pose, what in checks:
            q = act.configs[phase][-1]
            if self.planar[robot]:
                want = self._grasp_base(robot, obj, grasp, pose)
                dp = float(np.hypot(q[0] - want[0], q[1] - want[1]))
                dr = abs((q[2] - want[2] + math.pi) % (2 * math.pi) - math.pi)
                if dp > POS_TOL or dr > ROT_TOL:
                    self._v(t, robot, "grasp", f"the last {phase} base pose of {robot} is {dp * 1e3:.1f} mm, "
                                               f"{dr:.3f} rad from where grasp {grasp!r} of {obj} puts it (at "
                                               f"{what}; tolerance {POS_TOL * 1e3:g} mm, {ROT_TOL} rad)")
                continue
            dp, dr = _pose_error(self._tool(robot, q),
                                 pose @ grasp_transform(self.scene.grasp(grasp), self.shapes[obj]))
            if dp > POS_TOL or dr > ROT_TOL:
                self._v(t, robot, "grasp", f"the last {phase} configuration of {robot} puts the tool "
                                           f"{dp * 1e3:.1f} mm, {dr:.3f} rad from grasp {grasp!r} of {obj} at {what} "
                                           f"(tolerance {POS_TOL * 1e3:g} mm, {ROT_TOL} rad)")
        if act.handover:
            point = self.scene.handover_points.get(act.raw.get("handover_point", ""))
            h = act.configs["handover"]
            x1 = self._held_pose(act.pick_robot, h[0], obj, act.g1)
            x2 = self._held_pose(act.place_robot, h[1], obj, act.g2)
            if point is not None:
                for robot, x, grasp in ((act.pick_robot, x1, act.g1), (act.place_robot, x2, act.g2)):
                    d = float(np.linalg.norm(x[:3, 3] - point))
                    if d > POS_TOL:
                        self._v(t, robot, "handover", f"{robot} holds {obj} (grasp {grasp!r}) {d * 1e3:.1f} mm from "
                                                      f"handover point {act.raw['handover_point']} (tolerance "
                                                      f"{POS_TOL * 1e3:g} mm)")
            dp, dr = _pose_error(x1, x2)
            if dp > POS_TOL or dr > ROT_TOL:
                self._v(t, obj, "handover", f"giver {act.pick_robot} and taker {act.place_robot} hold {obj} at poses "
                                            f"{dp * 1e3:.1f} mm, {dr:.3f} rad apart (tolerance {POS_TOL * 1e3:g} mm, "
                                            f"{ROT_TOL} rad)")

    # ------------------------------------------------------------------ one step
    def run_step(self, t: int, acts: list[_Action]) -> None:
        """Replay step ``t``: the phases of the module docstring, paths as phases of their own between them
        (paired by index like approaches; robots of the step without that path are in transit)."""
        geo = [a for a in acts if a.geometry]
        robots = list(self.planar)
        in_step = {a.obj for a in acts}
        busy = {r for a in acts for r in (a.pick_robot, a.place_robot)}
        waiting = [r for r in robots if r not in busy]
        everything = list(self.movable)
        present = [o for o in self.movable if o not in in_step]
        for a in geo:
            for name, qs in a.paths.items():
                self._continuity(a, name, qs)

        def paths(*names: str) -> list[_Track]:
            out = []
            for a in geo:  # an action with broken geometry is reported, its motions are not replayed
                for name in names:
                    if name in a.paths:
                        role, grasp_role = PATH_PHASES[name][:2]
                        grasp = a.raw[grasp_role] if grasp_role else None
                        out.append(_Track(a.raw[role], a.paths[name], f"{name} path", a.obj if grasp_role else None,
                                          grasp, frozenset({a.obj}), self._fingers(a.raw[role], a.obj, grasp)))
            return out

        def others(tracks: list[_Track]) -> list[str]:
            return [r for r in robots if r not in {tr.robot for tr in tracks}]

        tracks = paths("to-pick")
        self._sweep(t, "to-pick", tracks, others(tracks), everything)
        tracks = [_Track(a.pick_robot, a.configs["pick"], "pick", ignore=frozenset({a.obj}),
                         fingers=self._fingers(a.pick_robot, a.obj, a.g1)) for a in geo]
        self._sweep(t, "pick", tracks, others(tracks), everything)
        self._sweep(t, "to-handover", paths("to-handover", "taker-to-handover"), waiting, present)
        hands = [a for a in geo if a.handover]
        tracks = []
        for a in hands:
            h = a.configs["handover"]
            tracks.append(_Track(a.pick_robot, h[:1], "handover (giver)", a.obj, a.g1, frozenset({a.obj}),
                                 self._fingers(a.pick_robot, a.obj, a.g1)))
            tracks.append(_Track(a.place_robot, h[1:], "handover (taker)", a.obj, a.g2, frozenset({a.obj}),
                                 self._fingers(a.place_robot, a.obj, a.g2)))
        self._sweep(t, "handover", tracks, waiting, present)
        self._sweep(t, "to-place", paths("to-place"), waiting, present)
        tracks = [_Track(a.place_robot, a.configs["place"], "place", a.obj, a.g2, frozenset({a.obj}),
                         self._fingers(a.place_robot, a.obj, a.g2)) for a in geo]
        self._sweep(t, "place", tracks, others(tracks), present)
        for a in acts:
            if a.place_pose is None:
                continue
            self.poses[a.obj] = a.place_pose
            if not inside(self.scene.body(a.region), self.shapes[a.obj], a.place_pose):
                p = a.place_pose[:3, 3]
                self._v(t, a.obj, "outside-region", f"the placement of {a.obj} at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) "
                                                    f"is not entirely inside region {a.region}")
        self._sweep(t, "home", paths("home", "giver-home"), waiting, everything)
        self._placements(t, [a for a in acts if a.place_pose is not None])
        self._flush()

    def _continuity(self, a: _Action, name: str, qs: np.ndarray) -> None:
        role, _, start, end = PATH_PHASES[name]
        robot = a.raw[role]
        for which, ref, q in (("starts", start, qs[0]), ("ends", end, qs[-1])):
            if ref is None:
                continue
            if ref == "home":
                want, what = self.home[robot], "home"
            else:
                phase, k = ref
                if phase == "transfer":
                    phase, k = ("handover", 1) if a.handover else ("pick", -1)
                if phase not in a.configs:
                    continue
                want, what = a.configs[phase][k], f"{'first' if k == 0 else 'last'} {phase} configuration"
                if phase == "handover":
                    want, what = a.configs[phase][k], f"{('giver', 'taker')[k]}'s handover configuration"
            if self.planar[robot]:
                dp = float(np.hypot(*(q[:2] - want[:2])))
                dr = abs((q[2] - want[2] + math.pi) % (2 * math.pi) - math.pi)
                bad, gap = dp > POS_TOL or dr > ROT_TOL, f"{dp * 1e3:.1f} mm, {dr:.3f} rad"
            else:
                d = float(np.abs(q - want).max())
                bad, gap = d > JOINT_TOL, f"{d:.4f} rad"
            if bad:
                self._v(a.step, robot, "path", f"path {name!r} (moving {a.obj}) {which} {gap} away from the "
                                               f"{what} (tolerance {JOINT_TOL} rad; planar {POS_TOL * 1e3:g} mm, "
                                               f"{ROT_TOL} rad)")

    # ------------------------------------------------------------------ sweeping a phase
    def _sweep(self, t: int, phase: str, tracks: list[_Track], static: list[str], present: list[str]) -> None:
        if not tracks:
            return
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
        counts = [_samples(tr.configs, self.planar[tr.robot]) for tr in tracks]
        n = max(counts)
        if n > MAX_SAMPLES:
            tr = tracks[counts.index(n)]
            self._v(t, tr.robot, "config", f"{phase}: the {tr.label} motion of {tr.robot} is too long to check "
                                           f"({n} samples at {RESOLUTION} rad or m each; at most {MAX_SAMPLES})")
            return
        others = [o for o in present if o not in held]
        for k in range(n):
            s = k / (n - 1) if n > 1 else 0.0
            states = []
            for tr in tracks:
                q = _at(tr.configs, s, self.planar[tr.robot])
                rs.set_config(tr.robot, q)
                if tr.holding and tr.grasp:
                    if tr.label != "handover (taker)":  # a handed-over object is where the giver holds it
                        rs.set_pose(tr.holding, self._held_pose(tr.robot, q, tr.holding, tr.grasp))
                states.append(_where(tr, s))
            self.samples += len(tracks)
            for tr, where in zip(tracks, states):
                self._robot_scene(t, phase, tr, where, others)
            for i, tr in enumerate(tracks):
                for j in range(i + 1, len(tracks)):
                    self._pair(t, phase, tr, states[i], tracks[j], states[j])
                for r in static:
                    self._pair(t, phase, tr, states[i], _Track(r, np.zeros((1, 1)), "home"), "at home")

    def _robot_scene(self, t: int, phase: str, tr: _Track, where: str, others: list[str]) -> None:
        rs = self.rs
        me = (tr.robot, where)
        for f in self.fixed:
            self._hit(t, phase, tr.robot, f, rs.closest(tr.robot, f), me, (f, ""), "robot-fixed")
        for o in others:
            if o not in tr.ignore:
                self._hit(t, phase, tr.robot, o, rs.closest(tr.robot, o), me, (o, ""), "robot-object")
        if tr.holding and tr.label != "handover (taker)":
            h = tr.holding
            held = (f"{h} held by {tr.robot}", where)
            for f in self.fixed:
                self._hit(t, phase, h, f, rs.closest(h, f), held, (f, ""), "object-fixed")
            for o in others:
                if o != h:
                    self._hit(t, phase, h, o, rs.closest(h, o), held, (o, ""), "object-object")

    def _pair(self, t: int, phase: str, a: _Track, wa: str, b: _Track, wb: str) -> None:
        rs = self.rs
        da, db = (a.robot, wa), (b.robot, wb)
        self._hit(t, phase, a.robot, b.robot, rs.closest(a.robot, b.robot), da, db, "robot-robot")
        ha = a.holding if a.holding and a.label != "handover (taker)" else None
        hb = b.holding if b.holding and b.label != "handover (taker)" else None
        if hb and hb not in a.ignore:
            self._hit(t, phase, a.robot, hb, rs.closest(a.robot, hb), da, (f"{hb} held by {b.robot}", wb),
                      "robot-object")
        if ha and ha not in b.ignore:
            self._hit(t, phase, b.robot, ha, rs.closest(b.robot, ha), db, (f"{ha} held by {a.robot}", wa),
                      "robot-object")
        if ha and hb and ha != hb:
            self._hit(t, phase, ha, hb, rs.closest(ha, hb), (f"{ha} held by {a.robot}", wa),
                      (f"{hb} held by {b.robot}", wb), "object-object")

    def _hit(self, t: int, phase: str, a: str, b: str, c: Any, da: tuple[str, str], db: tuple[str, str],
             kind: str) -> None:
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

    def _flush(self) -> None:
        for (t, _, kind, _, _), (_, subject, msg) in self._worst.items():
            self._v(t, subject, f"collision-{kind}", msg)
        self._worst.clear()

    def _placements(self, t: int, acts: list[_Action]) -> None:
        rs = self.rs
        for o in self.movable:
            rs.set_pose(o, self.poses[o])
        for r in self.planar:
            rs.set_config(r, self.home[r])
        done: set[frozenset[str]] = set()
        for a in acts:
            o = a.obj
            for f in self.fixed:
                self._hit(t, "placement", o, f, rs.closest(o, f), (f"{o} placed", ""), (f, ""), "object-fixed")
            for other in self.movable:
                if other != o and frozenset((o, other)) not in done:
                    done.add(frozenset((o, other)))
                    self._hit(t, "placement", o, other, rs.closest(o, other), (f"{o} placed", ""), (other, ""),
                              "object-object")
            for r in self.planar:
                self._hit(t, "placement", o, r, rs.closest(o, r), (f"{o} placed", ""), (r, "at home"), "robot-object")

    def goals(self) -> None:
        for obj, region in sorted(self.scene.goal.items()):
            if not inside(self.scene.body(region), self.shapes[obj], self.poses[obj]):
                p = self.poses[obj][:3, 3]
                self._v(None, obj, "goal", f"goal (in-region {obj} {region}) does not hold at the end: {obj} is at "
                                           f"({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}), not entirely inside {region}")


# ---------------------------------------------------------------------------------------- numerics
def _pose_error(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Position distance (m) and rotation angle (rad) between two poses."""
    dp = float(np.linalg.norm(a[:3, 3] - b[:3, 3]))
    c = (float(np.trace(a[:3, :3].T @ b[:3, :3])) - 1.0) / 2.0
    return dp, math.acos(max(-1.0, min(1.0, c)))


def _delta(a: np.ndarray, b: np.ndarray, planar: bool) -> np.ndarray:
    d = b - a
    if planar:
        d = d.copy()
        d[2] = (d[2] + math.pi) % (2 * math.pi) - math.pi
    return d


def _samples(configs: np.ndarray, planar: bool) -> int:
    """Samples this approach needs: ≥ SUBSTEPS per segment, ≤ RESOLUTION per sample, uniform over segments."""
    m = len(configs)
    if m < 2:
        return 1
    per = max(max(SUBSTEPS, math.ceil(float(np.abs(_delta(configs[j], configs[j + 1], planar)).max()) / RESOLUTION))
              for j in range(m - 1))
    return 1 + (m - 1) * per


def _at(configs: np.ndarray, s: float, planar: bool) -> np.ndarray:
    """The configuration at parameter ``s`` in [0, 1], consecutive configurations equally spaced."""
    m = len(configs)
    if m == 1:
        return configs[0]  # type: ignore[no-any-return]
    x = s * (m - 1)
    j = min(int(math.floor(x)), m - 2)
    u = x - j
    return configs[j] + u * _delta(configs[j], configs[j + 1], planar)  # type: ignore[no-any-return]


def _where(tr: _Track, s: float) -> str:
    m = len(tr.configs)
    if m == 1:
        return f"at its {tr.label} configuration" if tr.label != "home" else "at home"
    x = s * (m - 1)
    k = round(x)
    if abs(x - k) < 1e-9:
        return f"at {tr.label} configuration {k + 1} of {m}"
    return f"between {tr.label} configurations {math.floor(x) + 1} and {math.floor(x) + 2} of {m}"
