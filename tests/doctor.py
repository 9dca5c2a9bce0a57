"""Issue 21's doctored plans: the stored plans of tests/data/round2/ and the edits that break them.

The stored plans (written by tests/make_round2_plans.py from the shipped problems) are physically valid
(:func:`audit` says so); each function below takes one (a plan dict) and returns a :class:`Doctored` copy
that breaks it in one of issue 21's ways, the edit computed from the geometry, with the damage measured here:

1. :func:`self_collision` - one configuration inserted into an arm's path puts its hand 50-75 mm inside its
   own ``panda_link1``, every joint within its limits;
2. :func:`held_in_own_base` - one configuration inserted into the placing arm's ``to-place`` path puts the
   object it holds about 30 mm into that arm's own ``panda_link0``, clear of everything else;
3. :func:`turned_approach` - pick configurations 2..4 of 5 with joint 7 turned +pi/2: the hand turns back
   in the contact segment, where the picked object is exempt, and the fingers cut its corners;
4. :func:`giver_into_taker` - (``--motions full``, a handover) the giver's ``giver-home`` path pushes its
   open hand on into the object its taker holds, standing at the exchange while the giver withdraws;
5. :func:`between_samples` - a cart's ``to-place`` path rebuilt in steps of equal length (just under the
   validator's 0.01 resolution) with two consecutive waypoints on either side of a divider's corner:
   each clear, the straight motion between them cutting into the divider;
8. :func:`digest_changed` and :func:`huge_joint_value`.

What a plan means is validator/replay.py's execution model (docs/validator.md): every robot stands where its
last motion left it, and a giver withdraws home (``giver-home``) before its taker carries the object on.
Everything geometric is measured in a pybullet world of its own (:class:`World`; the planner's geometry
modules give grasp frames, the planar carry pose and IK: tests may use them, the validator may not), never
with the validator's code.  Distances are signed (negative: a penetration), pybullet's 1 mm margin around
mesh shapes added back.
"""

from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from functools import cache
from typing import Any, Iterator, Sequence

import numpy as np
from support import ROOT

from mrgc.geometry import transforms as tf
from mrgc.geometry.bullet import pose_of, private_client, quiet_output
from mrgc.geometry.conventions import PLANAR_LIFT, wrap_angle
from mrgc.geometry.grasps import finger_opening, grasp_transform
from mrgc.geometry.kinematics import model_for_kind
from mrgc.geometry.scene import SceneSpec, half_extents, scene_from_problem
from mrgc.language.loader import parse_file
from mrgc.language.model import Box, Problem

DATA = ROOT / "tests" / "data" / "round2"
#: stored plan name -> (problem file relative to the repository, plan file in DATA)
STORED: dict[str, tuple[str, str]] = {
    "pa5": ("domains/packaging/pa5.mrg", "pa5.json"),
    "pa5-full": ("domains/packaging/pa5.mrg", "pa5-full.json"),
    "pa10": ("domains/packaging/pa10.mrg", "pa10.json"),
    "bo-alcove": ("domains/box-moving/bo-alcove.mrg", "bo-alcove.json"),
}
#: pybullet's margin around each mesh shape (every Panda link, every box hull here)
MESH_MARGIN = 1e-3
#: the validator's resolution (rad, m) and the doctored cart path's step, just under it
RESOLUTION = 0.01


def problem_file(name: str) -> str:
    """The problem file of stored plan ``name`` (an absolute path)."""
    return str(ROOT / STORED[name][0])


def load(name: str) -> dict[str, Any]:
    """A fresh copy of stored plan ``name``."""
    plan: dict[str, Any] = json.loads((DATA / STORED[name][1]).read_text(encoding="utf-8"))
    return plan


@cache
def problem(path: str) -> Problem:
    """The checked problem of a file (its only one)."""
    return parse_file(path).problem(None)


@dataclass
class Doctored:
    """A doctored plan: the ``plan`` dict, what was done (``what``), the bodies that meet (``bodies``) and
    the measured penetration ``depth`` (m, positive) where they meet."""

    plan: dict[str, Any]
    what: str
    bodies: tuple[str, ...]
    depth: float
    extra: dict[str, Any] = field(default_factory=dict)


def action(plan: dict[str, Any], step: int, k: int = 0) -> dict[str, Any]:
    """Action ``k`` of step ``step`` (1-based)."""
    found: dict[str, Any] = plan["steps"][step - 1]["actions"][k]
    return found


# ------------------------------------------------------------------------------------- a pybullet world
@dataclass
class Robot:
    """A robot of a :class:`World`: its pybullet body, chain joints, link names by index, limits and (arms)
    its fingers and tool centre point; planar robots are a footprint box lifted by ``lift``."""

    name: str
    body: int
    planar: bool
    joints: tuple[int, ...] = ()
    links: dict[int, str] = field(default_factory=dict)
    lower: np.ndarray = field(default_factory=lambda: np.zeros(0))
    upper: np.ndarray = field(default_factory=lambda: np.zeros(0))
    fingers: tuple[int, ...] = ()
    ee: int = -1
    tcp: np.ndarray = field(default_factory=lambda: np.eye(4))
    lift: float = 0.0
    #: link pairs a self-collision check asks: those whose tree path crosses two or more chain joints
    pairs: tuple[tuple[int, int], ...] = ()

    def link(self, name: str) -> int:
        """The index of the link called ``name``."""
        return next(i for i, n in self.links.items() if n == name)


class World:
    """A private pybullet world of a problem: arms from their URDFs at their bases, planar robots as their
    footprint boxes, fixed and movable objects as the convex hulls of their boxes' corners."""

    def __init__(self, path: str) -> None:
        self.pb: Any
        self.pb, self.cid = private_client()
        self.scene: SceneSpec = scene_from_problem(problem(path))
        self.bodies: dict[str, int] = {}
        self.robots: dict[str, Robot] = {}
        for b in (*self.scene.fixed, *self.scene.movable):
            self.bodies[b.name] = self._box(b.shape)
            self.set_pose(b.name, b.pose)
        for r in self.scene.robots:
            if r.kind.base == "planar":
                assert r.kind.footprint is not None
                body = self._box(r.kind.footprint)
                lift = float(half_extents(r.kind.footprint)[2]) + PLANAR_LIFT
                self.robots[r.name] = Robot(r.name, body, True, links={-1: "footprint"}, lift=lift)
                self.bodies[r.name] = body
            else:
                self._add_arm(r.name, r.kind, r.base_dir, r.base)

    def reset(self) -> None:
        """Every robot at home (arms: fingers open) or at its base pose, every object at its initial pose."""
        for r in self.scene.robots:
            if self.robots[r.name].planar:
                self.set_q(r.name, [float(r.base[0, 3]), float(r.base[1, 3]), math.atan2(r.base[1, 0], r.base[0, 0])])
            else:
                self.set_q(r.name, r.kind.home)
                self.set_fingers(r.name, None)
        for b in (*self.scene.fixed, *self.scene.movable):
            self.set_pose(b.name, b.pose)

    def close(self) -> None:
        """Disconnect the client."""
        self.pb.disconnect(physicsClientId=self.cid)

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _box(self, shape: Any) -> int:
        assert isinstance(shape, Box), shape
        h = (shape.sx / 2, shape.sy / 2, shape.sz / 2)
        corners = [[x * h[0], y * h[1], z * h[2]] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
        col = self.pb.createCollisionShape(self.pb.GEOM_MESH, vertices=corners, physicsClientId=self.cid)
        return int(self.pb.createMultiBody(baseMass=0, baseCollisionShapeIndex=col, physicsClientId=self.cid))

    def _add_arm(self, name: str, kind: Any, base_dir: str, base: np.ndarray) -> None:
        pb, cid = self.pb, self.cid
        model = model_for_kind(kind, base_dir)
        pos, orn = tf.to_quaternion(np.asarray(base, dtype=float))
        with quiet_output():
            body = int(pb.loadURDF(model.urdf, pos, orn, useFixedBase=True, physicsClientId=cid))
        info = [
            pb.getJointInfo(body, j, physicsClientId=cid) for j in range(pb.getNumJoints(body, physicsClientId=cid))
        ]
        links = {-1: pb.getBodyInfo(body, physicsClientId=cid)[0].decode()} | {
            int(ji[0]): ji[12].decode() for ji in info
        }
        by_joint = {ji[1].decode(): int(ji[0]) for ji in info}
        joints = tuple(by_joint[j.name] for j in model.joints)
        fingers = tuple(int(ji[0]) for ji in info if ji[2] == pb.JOINT_PRISMATIC and int(ji[0]) not in joints)
        parent = {int(ji[0]): int(ji[16]) for ji in info}

        def up(link: int) -> list[int]:
            path = [link]
            while link != -1:
                link = parent[link]
                path.append(link)
            return path

        def crossed(a: int, b: int) -> int:  # chain joints on the tree path between links a and b
            pa, pb_ = up(a), up(b)
            common = next(x for x in pa if x in pb_)
            return sum(1 for x in pa[: pa.index(common)] + pb_[: pb_.index(common)] if x in joints)

        shaped = [i for i in links if pb.getCollisionShapeData(body, i, physicsClientId=cid)]
        pairs = tuple((a, b) for k, a in enumerate(shaped) for b in shaped[k + 1 :] if crossed(a, b) >= 2)
        assert kind.tcp is not None
        self.robots[name] = Robot(
            name,
            body,
            False,
            joints=joints,
            links=links,
            lower=np.array([float(info[j][8]) for j in joints]),
            upper=np.array([float(info[j][9]) for j in joints]),
            fingers=fingers,
            ee=next(i for i, n in links.items() if n == kind.end_effector),
            tcp=tf.from_pose(kind.tcp),
            pairs=pairs,
        )
        self.bodies[name] = body
        self.set_fingers(name, None)

    # ------------------------------------------------------------------ state
    def set_pose(self, name: str, pose: np.ndarray | None) -> None:
        """Put object ``name`` at ``pose`` (None: far below the scene)."""
        t = np.asarray(pose, dtype=float) if pose is not None else tf.translation(0, 0, -1000)
        pos, orn = tf.to_quaternion(t)
        self.pb.resetBasePositionAndOrientation(self.bodies[name], pos, orn, physicsClientId=self.cid)

    def set_q(self, robot: str, q: Sequence[float] | np.ndarray) -> None:
        """Put ``robot`` at configuration ``q`` (arms: chain joints; planar: x, y, yaw)."""
        r = self.robots[robot]
        if r.planar:
            x, y, yaw = (float(v) for v in q[:3])
            t = tf.rot_z(yaw)
            t[0, 3], t[1, 3], t[2, 3] = x, y, r.lift
            pos, orn = tf.to_quaternion(t)
            self.pb.resetBasePositionAndOrientation(r.body, pos, orn, physicsClientId=self.cid)
            return
        for j, v in zip(r.joints, q):
            self.pb.resetJointState(r.body, j, float(v), physicsClientId=self.cid)

    def set_fingers(self, robot: str, opening: float | None) -> None:
        """Open an arm's fingers ``opening`` m apart (None: fully open)."""
        r = self.robots[robot]
        for j in r.fingers:
            hi = float(self.pb.getJointInfo(r.body, j, physicsClientId=self.cid)[9])
            v = hi if opening is None else min(max(opening / 2, 0.0), hi)
            self.pb.resetJointState(r.body, j, v, physicsClientId=self.cid)

    def link_pose(self, robot: str, link: int) -> np.ndarray:
        """The world frame of link ``link`` of an arm."""
        r = self.robots[robot]
        if link == -1:
            pos, orn = self.pb.getBasePositionAndOrientation(r.body, physicsClientId=self.cid)
        else:
            st = self.pb.getLinkState(r.body, link, computeForwardKinematics=True, physicsClientId=self.cid)
            pos, orn = st[4], st[5]
        return pose_of(pos, orn)

    def tool(self, robot: str) -> np.ndarray:
        """The arm's tool frame (end-effector link frame times tcp) in the world."""
        r = self.robots[robot]
        return self.link_pose(robot, r.ee) @ r.tcp

    # ------------------------------------------------------------------ distances
    def closest(
        self, a: str, b: str, link_a: int | None = None, link_b: int | None = None, reach: float = 0.05
    ) -> tuple[float, str, str] | None:
        """The least signed distance between bodies ``a`` and ``b`` (robots or objects; optionally one link
        of each) within ``reach``, with the links' names (the object's own name for an object)."""
        ba, bb = self.bodies[a], self.bodies[b]
        kw: dict[str, int] = {}
        if link_a is not None:
            kw["linkIndexA"] = link_a
        if link_b is not None:
            kw["linkIndexB"] = link_b
        pts = self.pb.getClosestPoints(ba, bb, reach + 2 * MESH_MARGIN, physicsClientId=self.cid, **kw)
        best: tuple[float, str, str] | None = None
        for p in pts:
            d = float(p[8]) + 2 * MESH_MARGIN  # every shape here is a mesh (URDF meshes, box hulls)
            if best is None or d < best[0]:
                best = (d, self._name(a, int(p[3])), self._name(b, int(p[4])))
        return best

    def _name(self, body: str, link: int) -> str:
        r = self.robots.get(body)
        return r.links[link] if r is not None and not r.planar else body

    def self_distance(self, robot: str, reach: float = 0.02) -> tuple[float, str, str] | None:
        """The least distance between two links of an arm that the self-collision check asks."""
        r = self.robots[robot]
        best: tuple[float, str, str] | None = None
        for a, b in r.pairs:
            c = self.closest(robot, robot, a, b, reach)
            if c is not None and (best is None or c[0] < best[0]):
                best = c
        return best

    def link_box_distances(self, robot: str, obj: str, reach: float = 0.05) -> dict[str, float]:
        """Signed distances from object ``obj`` to each link of ``robot`` within ``reach``."""
        r = self.robots[robot]
        out: dict[str, float] = {}
        for link in r.links:
            c = self.closest(robot, obj, link, None, reach)
            if c is not None:
                out[r.links[link]] = c[0]
        return out


# ------------------------------------------------------------------------------------- reading a plan
@cache
def world(path: str) -> World:
    """One :class:`World` per problem file for the session."""
    return World(path)


def world_of(plan: dict[str, Any]) -> World:
    """The world of the problem ``plan`` was made for (its ``problem_file``, relative to the repository),
    reset: robots at home, objects at their initial poses."""
    w = world(str(ROOT / plan["problem_file"]))
    w.reset()
    return w


def poses_before(w: World, plan: dict[str, Any], step: int) -> dict[str, np.ndarray]:
    """Every movable object's pose at the start of ``step`` (1-based): initial poses, then each earlier
    step's placements."""
    poses = {b.name: b.pose for b in w.scene.movable}
    for s in plan["steps"][: step - 1]:
        for a in s["actions"]:
            poses[a["object"]] = np.array(a["place_pose"], dtype=float)
    return poses


def place_objects(w: World, poses: dict[str, np.ndarray], held: str | None = None) -> None:
    """Put every movable object at its pose (``held``: parked, its owner moves it)."""
    for name, pose in poses.items():
        w.set_pose(name, None if name == held else pose)


def held_transform(w: World, act: dict[str, Any], robot: str) -> tuple[np.ndarray, float]:
    """(tool -> object transform, finger opening) of ``robot`` holding ``act``'s object with its grasp."""
    grasp = w.scene.grasp(act["pick_grasp"] if robot == act["pick_robot"] else act["place_grasp"])
    shape = w.scene.body(act["object"]).shape
    return tf.inverse(grasp_transform(grasp, shape)), finger_opening(grasp, shape)


#: the phases of a step in the order they run (validator/replay.py's execution model: a giver withdraws home,
#: its taker standing at the exchange, before the taker carries the object on)
PHASES = ("to-pick", "pick", "to-handover", "handover", "giver-home", "to-place", "place", "home")


@dataclass
class Track:
    """An arm's motion in a phase: its configurations (paired by index with the phase's other motions), the
    object it holds (with the tool -> object transform) and its finger opening (None: fully open)."""

    robot: str
    label: str
    configs: np.ndarray
    obj: str | None = None
    tool_obj: np.ndarray | None = None
    opening: float | None = None


def step_phases(w: World, plan: dict[str, Any], step: int) -> Iterator[tuple[str, list[Track], dict[str, Track]]]:
    """The phases of ``step``'s arm actions as validator/replay.py runs them: (phase, the tracks that move, every
    other arm standing as a one-configuration track, holding what it holds).  Every arm starts at home; a
    transit without a path is a jump at the end of its phase; a holding transfer without a path is the straight
    joint-space move; a pick-and-place arm stands at its grasp while the step's handovers run."""
    return iter(_Stepper(w, plan, step))


class _Stepper:
    """:func:`step_phases`' state: where every arm stands, holding what, fingers how."""

    def __init__(self, w: World, plan: dict[str, Any], step: int) -> None:
        self.w = w
        self.acts = [a for a in action_list(plan, step) if not w.robots[a["pick_robot"]].planar]
        self.stand = {r.name: self.home(r.name) for r in w.scene.robots if not w.robots[r.name].planar}

    def home(self, robot: str) -> Track:
        return Track(robot, "home", np.array([self.w.scene.robot(robot).kind.home], dtype=float))

    def track(self, a: dict[str, Any], robot: str, label: str, qs: Any, holding: bool, fingers: bool) -> Track:
        """``robot``'s track of ``a``: holding ``a``'s object or not, its fingers at the grasp's opening or open."""
        tool_obj, opening = held_transform(self.w, a, robot)
        q = np.asarray(qs, dtype=float)
        if holding:
            return Track(robot, label, q, a["object"], tool_obj, opening)
        return Track(robot, label, q, opening=opening if fingers else None)

    def path(self, a: dict[str, Any], name: str, robot: str, straight: list[Any] | None = None) -> Track | None:
        """Path ``name`` of ``a`` (holding when ``straight``, the straight transfer standing in for it)."""
        qs = a.get("paths", {}).get(name, straight)
        return None if qs is None else self.track(a, robot, name, qs, straight is not None, name == "giver-home")

    def run(self, phase: str, tracks: list[Track | None]) -> Iterator[tuple[str, list[Track], dict[str, Track]]]:
        moving = [t for t in tracks if t is not None]
        if moving:
            yield phase, moving, {k: v for k, v in self.stand.items() if k not in {t.robot for t in moving}}
        for t in moving:
            self.stand[t.robot] = Track(t.robot, f"after {phase}", t.configs[-1:], t.obj, t.tool_obj, t.opening)

    def holds(self, a: dict[str, Any], robot: str, holding: bool) -> None:
        """``robot`` (standing) takes ``a``'s object, or lets it go."""
        t = self.stand[robot]
        self.stand[robot] = self.track(a, robot, t.label, t.configs, holding, t.opening is not None)

    def __iter__(self) -> Iterator[tuple[str, list[Track], dict[str, Track]]]:
        acts = self.acts
        hands = [a for a in acts if a["kind"] == "handover"]
        yield from self.run("to-pick", [self.path(a, "to-pick", a["pick_robot"]) for a in acts])
        yield from self.run(
            "pick", [self.track(a, a["pick_robot"], "pick", a["configs"]["pick"], False, True) for a in acts]
        )
        for a in acts:
            self.holds(a, a["pick_robot"], True)
        transfer = [self.path(a, "to-handover", a["pick_robot"], _ends(a, "pick", "handover")) for a in hands]
        walk = [self.path(a, "taker-to-handover", a["place_robot"]) for a in hands]
        yield from self.run("to-handover", transfer + walk)
        yield from self.run(
            "handover",
            [
                self.track(a, robot, "handover", a["configs"]["handover"][k : k + 1], True, True)
                for a in hands
                for k, robot in enumerate((a["pick_robot"], a["place_robot"]))
            ],
        )
        for a in hands:  # the taker holds it; the giver lets go
            self.holds(a, a["pick_robot"], False)
        yield from self.run("giver-home", [self.path(a, "giver-home", a["pick_robot"]) for a in hands])
        for a in hands:
            self.stand[a["pick_robot"]] = self.home(a["pick_robot"])
        yield from self.run(
            "to-place",
            [
                self.path(a, "to-place", a["place_robot"], _ends(a, "handover" if a in hands else "pick", "place"))
                for a in acts
            ],
        )
        yield from self.run(
            "place", [self.track(a, a["place_robot"], "place", a["configs"]["place"], True, True) for a in acts]
        )
        for a in acts:  # released
            self.holds(a, a["place_robot"], False)
        yield from self.run("home", [self.path(a, "home", a["place_robot"]) for a in acts])


def _ends(a: dict[str, Any], start: str, end: str) -> list[Any]:
    """The straight transfer from the last configuration of ``configs[start]`` to the first of ``configs[end]``."""
    return [a["configs"][start][-1], a["configs"][end][0]]


def action_list(plan: dict[str, Any], step: int) -> list[dict[str, Any]]:
    """The actions of step ``step`` (1-based)."""
    acts: list[dict[str, Any]] = plan["steps"][step - 1]["actions"]
    return acts


def phase_times(tracks: list[Track]) -> np.ndarray:
    """The times (in [0, 1]) at which a phase is checked: every configuration of every track and enough
    between them that no joint of any track moves more than :data:`RESOLUTION` from one to the next."""
    times = [np.zeros(1), np.ones(1)]
    for t in tracks:
        m = len(t.configs)
        for j in range(m - 1):
            n = max(1, math.ceil(float(np.max(np.abs(t.configs[j + 1] - t.configs[j]))) / RESOLUTION))
            times.append((j + np.arange(n) / n) / (m - 1))
    return np.unique(np.concatenate(times))


def at_time(t: Track, s: float) -> np.ndarray:
    """Track ``t``'s configuration at phase time ``s`` (configurations equally spaced in time)."""
    m = len(t.configs)
    if m == 1:
        return t.configs[0]
    x = s * (m - 1)
    j = min(int(math.floor(x)), m - 2)
    return t.configs[j] + (x - j) * (t.configs[j + 1] - t.configs[j])


# ------------------------------------------------------------------------------------- the audit
def audit(plan: dict[str, Any]) -> dict[str, tuple[float, str]]:
    """What issue 21's new checks ask of a plan's arms, replayed as validator/replay.py's execution model has
    it (:func:`step_phases`) and measured: the least distance found (m, negative: a penetration) and where,
    for ``self`` (two links of one moving arm whose tree path crosses two or more chain joints), ``held``
    (an object against every link but the fingers of the arm or arms holding it) and ``robots`` (a moving
    arm and what it holds against every other arm, moving or standing, and what that holds).  Every phase
    at every configuration and at most 0.01 rad between checked ones (:func:`phase_times`)."""
    w = world_of(plan)
    worst = dict.fromkeys(("self", "held", "robots"), (math.inf, "nothing within 20 mm"))

    def note(kind: str, c: tuple[float, str, str] | None, where: str) -> None:
        if c is not None and c[0] < worst[kind][0]:
            worst[kind] = (c[0], f"{where}: {c[1]} / {c[2]}")

    for s in plan["steps"]:
        for phase, moving, standing in step_phases(w, plan, s["index"]):
            for time in phase_times(moving):
                where = f"step {s['index']} {phase} t={time:.4f}"
                _audit_sample(w, moving, standing, time, where, note)
    w.reset()
    return worst


def _audit_sample(
    w: World, moving: list[Track], standing: dict[str, Track], time: float, where: str, note: Any
) -> None:
    everyone = [*moving, *standing.values()]
    holders: dict[str, list[str]] = {}
    for t in everyone:
        w.set_q(t.robot, at_time(t, time))
        w.set_fingers(t.robot, t.opening)
    for t in everyone:
        if t.obj is not None and t.tool_obj is not None:
            if t.obj not in holders:  # the first holder (a giver at the exchange) places it
                w.set_pose(t.obj, w.tool(t.robot) @ t.tool_obj)
            holders.setdefault(t.obj, []).append(t.robot)
    moved = {t.robot for t in moving}
    for t in moving:
        note("self", w.self_distance(t.robot), f"{where} {t.robot}")
    for obj, arms in holders.items():
        if moved & {*arms}:
            _audit_held(w, obj, arms, where, note)
    for a in moving:
        for b in everyone:
            if b.robot != a.robot:
                _audit_pair(w, a.robot, b.robot, holders, f"{where} {a.robot}/{b.robot}", note)
    for obj in holders:
        w.set_pose(obj, None)


def _audit_held(w: World, obj: str, arms: list[str], where: str, note: Any) -> None:
    """A held object against every link but the fingers of each arm holding it."""
    for robot in arms:
        fingers = {w.robots[robot].links[j] for j in w.robots[robot].fingers}
        for link, d in w.link_box_distances(robot, obj, 0.02).items():
            if link not in fingers:
                note("held", (d, obj, f"{link} of {robot}"), where)


def _audit_pair(w: World, a: str, b: str, holders: dict[str, list[str]], where: str, note: Any) -> None:
    """Arms ``a`` and ``b`` and the objects each holds (that the other does not) against each other."""
    note("robots", w.closest(a, b, reach=0.02), where)
    for obj, arms in holders.items():
        for mine, other in ((a, b), (b, a)):
            if mine in arms and other not in arms:
                note("robots", w.closest(obj, other, reach=0.02), f"{where} ({obj} held by {mine})")


# ------------------------------------------------------------------------------------- class 1: self-collision
PATH_OWNER = {"to-pick": "pick_robot", "to-handover": "pick_robot", "giver-home": "pick_robot"}


def self_collision(plan: dict[str, Any], step: int, path: str, link: str = "panda_link1", seed: int = 21) -> Doctored:
    """Class 1: one configuration inserted in the middle of path ``path`` of ``step``'s action where the
    arm's hand is 50-75 mm deep inside its own ``link`` (the deepest pair of links there), every joint
    within its limits and no link but the base below the table.  Found by sampling joint space (seeded; the
    elbow, joint 4, near its lower limit, where the hand folds back onto the shoulder), the candidate
    nearest the path's middle configuration kept."""
    plan = copy.deepcopy(plan)
    w = world_of(plan)
    act = action(plan, step)
    robot = act[PATH_OWNER.get(path, "place_robot")]
    r = w.robots[robot]
    qs = act["paths"][path]
    k = len(qs) // 2
    q_mid = np.asarray(qs[k], dtype=float)
    hand, target = r.link("panda_hand"), r.link(link)
    lo, hi = r.lower.copy(), r.upper.copy()
    hi[3] = lo[3] + 0.35  # joint 4 folded: the hand comes back to the shoulder
    rng = np.random.default_rng(seed)
    place_objects(w, {b.name: b.pose for b in w.scene.movable})
    w.set_fingers(robot, None)
    best: tuple[float, np.ndarray, float] | None = None
    for q in rng.uniform(lo, hi, size=(4000, len(lo))):
        w.set_q(robot, q)
        c = w.closest(robot, robot, hand, target, 0.0)
        if c is None or not -0.075 < c[0] < -0.05:
            continue
        deepest = w.self_distance(robot, 0.0)
        if deepest is None or deepest[0] < c[0] - 1e-9 or not _links_clear_of_fixed(w, robot):
            continue
        gap = float(np.linalg.norm(q - q_mid))
        if best is None or gap < best[0]:
            best = (gap, q, -c[0])
    assert best is not None, "no configuration puts the hand inside the arm"
    _, q_bad, depth = best
    qs.insert(k + 1, [float(v) for v in q_bad])
    w.reset()
    return Doctored(
        plan,
        f"step {step}: {robot}'s '{path}' path gets configuration {k + 2} of {len(qs)}: "
        f"{[round(float(v), 3) for v in q_bad]}, panda_hand {depth * 1000:.1f} mm inside {link}",
        (robot, "panda_hand", link),
        depth,
        {"index": k + 1, "q": q_bad},
    )


def _links_clear_of_fixed(w: World, robot: str) -> bool:
    """Whether every link of an arm but its base is clear of every fixed object."""
    for b in w.scene.fixed:
        for link in w.robots[robot].links:
            c = w.closest(robot, b.name, link, None, 0.0)
            if link != -1 and c is not None and c[0] < 0:
                return False
    return True


# ------------------------------------------------------------------------------------- class 2: held in own base
def ik(w: World, robot: str, tools: np.ndarray, q_init: np.ndarray) -> list[np.ndarray | None]:
    """Configurations of ``robot`` putting its tool at each of ``tools`` (world, (M, 4, 4)), IK seeded at
    ``q_init`` (the planner's IK: tests may use it, the validator may not)."""
    from mrgc.geometry.ik import solve_ik_many

    spec = w.scene.robot(robot)
    model = model_for_kind(spec.kind, spec.base_dir)
    targets = tf.inverse(spec.base)[None] @ np.asarray(tools) @ tf.inverse(w.robots[robot].tcp)[None]
    res = solve_ik_many(model, targets, 0, q_init=np.asarray(q_init, dtype=float))
    return [np.asarray(x.q, dtype=float) if x.solved else None for x in res]


def held_in_own_base(plan: dict[str, Any], step: int, depth: float = 0.03) -> Doctored:
    """Class 2: one configuration inserted in the middle of the placing arm's ``to-place`` path that puts
    the object it holds (upright) about ``depth`` deep into the arm's own base link ``panda_link0`` from
    behind and above (the base's back, which the shoulder does not cover), the object clear (2 mm) of every
    other link but the fingers and hand, of the table and of every other object, the arm clear of itself and
    of fixed objects.  Candidates: a grid of object positions behind the base, solved by IK."""
    plan = copy.deepcopy(plan)
    w = world_of(plan)
    act = action(plan, step)
    robot, obj = act["place_robot"], act["object"]
    r = w.robots[robot]
    qs = act["paths"]["to-place"]
    k = len(qs) // 2
    q_mid = np.asarray(qs[k], dtype=float)
    tool_obj, opening = held_transform(w, act, robot)
    base = w.scene.robot(robot).base
    poses = [
        base @ tf.translation(x, y, z) @ tf.rot_z(yaw)
        for x in (-0.14, -0.12, -0.10)
        for y in (-0.04, -0.02, 0.0, 0.02, 0.04)
        for z in (0.07, 0.08, 0.09, 0.10)
        for yaw in (0.0, math.pi / 2)
    ]
    qs_ik = ik(w, robot, np.array([p @ tf.inverse(tool_obj) for p in poses]), q_mid)
    others = poses_before(w, plan, step)
    place_objects(w, others, obj)
    w.set_fingers(robot, opening)
    exempt = {r.links[j] for j in r.fingers} | {"panda_hand", "panda_link0"}
    best: tuple[float, float, np.ndarray, float] | None = None
    for pose, q in zip(poses, qs_ik):
        if q is None:
            continue
        w.set_q(robot, q)
        w.set_pose(obj, pose)
        c = w.closest(robot, obj, r.link("panda_link0"), None, 0.0)
        if c is None or abs(-c[0] - depth) > 0.008:
            continue
        if not _held_clear(w, robot, obj, exempt, [n for n in others if n != obj]):
            continue
        score = (abs(-c[0] - depth), float(np.linalg.norm(q - q_mid)))
        if best is None or score < best[:2]:
            best = (*score, q, -c[0])
    w.set_pose(obj, None)
    assert best is not None, "no configuration puts the held object into the base"
    q_bad, found = best[2], best[3]
    qs.insert(k + 1, [float(v) for v in q_bad])
    return Doctored(
        plan,
        f"step {step}: {robot}'s 'to-place' path gets configuration {k + 2} of {len(qs)}: "
        f"{[round(float(v), 3) for v in q_bad]}, {obj} {found * 1000:.1f} mm inside panda_link0 of {robot}",
        (robot, obj, "panda_link0"),
        found,
        {"index": k + 1, "q": q_bad},
    )


def _held_clear(w: World, robot: str, obj: str, exempt: set[str], others: list[str], gap: float = 0.002) -> bool:
    """Whether the held object is ``gap`` clear of the arm's links but ``exempt``, of fixed objects and of
    ``others``, and the arm clear of itself and (links but the base) of fixed objects."""
    if any(d < gap for link, d in w.link_box_distances(robot, obj, gap).items() if link not in exempt):
        return False
    for b in [*(f.name for f in w.scene.fixed), *others]:
        c = w.closest(obj, b, reach=gap)
        if c is not None and c[0] < gap:
            return False
    s = w.self_distance(robot, gap)
    return (s is None or s[0] >= gap) and _links_clear_of_fixed(w, robot)


# ------------------------------------------------------------------------------------- class 3: turned approach
def turned_approach(plan: dict[str, Any], step: int, phase: str = "pick", turn: float = math.pi / 2) -> Doctored:
    """Class 3: configurations 2..4 of the ``phase`` approach with joint 7 turned by ``turn``: the hand
    turns back in the contact segment (configurations 4 to 5).  Measured: the tool's turn at configuration
    4 and how deep the fingers (at the grasp's opening) cut into the object along the contact segment."""
    plan = copy.deepcopy(plan)
    w = world_of(plan)
    act = action(plan, step)
    robot = act["pick_robot" if phase == "pick" else "place_robot"]
    qs = act["configs"][phase]
    r = w.robots[robot]
    for q in qs[1:-1]:
        q[6] += turn
        assert r.lower[6] <= q[6] <= r.upper[6], "joint 7 would leave its limits"
    tool_obj, opening = held_transform(w, act, robot)
    poses = poses_before(w, plan, step)
    obj = act["object"]
    place_objects(w, poses)
    if phase == "place":
        w.set_pose(obj, np.array(act["place_pose"], dtype=float))
    w.set_fingers(robot, opening)
    a, b = np.asarray(qs[-2], dtype=float), np.asarray(qs[-1], dtype=float)
    w.set_q(robot, b)
    goal = w.tool(robot)
    w.set_q(robot, a)
    c = (np.trace(goal[:3, :3].T @ w.tool(robot)[:3, :3]) - 1) / 2
    angle = math.acos(min(1.0, max(-1.0, c)))
    cut, where = 0.0, ""
    for u in np.linspace(0.0, 1.0, 201):
        w.set_q(robot, a + u * (b - a))
        for link in r.fingers:
            hit = w.closest(robot, obj, link, None, 0.0)
            if hit is not None and -hit[0] > cut:
                cut, where = -hit[0], hit[1]
    w.set_fingers(robot, None)
    return Doctored(
        plan,
        f"step {step}: {robot}'s {phase} configurations 2-4 with joint 7 turned {turn:+.4f} rad: the tool is "
        f"{angle:.3f} rad off the grasp's orientation at configuration 4; {where} cuts {cut * 1000:.1f} mm "
        f"into {obj} in the contact segment",
        (robot, obj, where),
        cut,
        {"turn_at_4": angle},
    )


# ------------------------------------------------------------------------------------- class 4: into the taker
def giver_into_taker(plan: dict[str, Any], step: int, push: float = 0.06) -> Doctored:
    """Class 4 (``--motions full``, a handover): the giver's ``giver-home`` path first pushes its open hand
    ``push`` m further along its approach axis, into the object its taker holds, and back: configurations 2
    and 3 of the path become the pushed configuration (IK) and the exchange configuration again.  In the
    giver-home phase the taker stands at its exchange configuration holding the object (validator/replay.py's
    execution model; before it, the validator ran giver-home beside the taker's home path, the object
    already placed, and found nothing there)."""
    plan = copy.deepcopy(plan)
    w = world_of(plan)
    act = action(plan, step)
    assert act["kind"] == "handover"
    giver, taker, obj = act["pick_robot"], act["place_robot"], act["object"]
    ex_giver, ex_taker = act["configs"]["handover"]
    tool_obj, opening = held_transform(w, act, taker)
    w.set_q(taker, ex_taker)
    w.set_fingers(taker, opening)
    place_objects(w, poses_before(w, plan, step), obj)
    w.set_pose(obj, w.tool(taker) @ tool_obj)
    w.set_q(giver, ex_giver)
    w.set_fingers(giver, held_transform(w, act, giver)[1])
    tool = w.tool(giver)
    pushed = tf.translation(*(push * tool[:3, 2])) @ tool  # further in along its approach
    (q_in,) = ik(w, giver, pushed[None], np.asarray(ex_giver, dtype=float))
    assert q_in is not None, "no IK for the pushed configuration"
    w.set_q(giver, q_in)
    box = w.closest(obj, giver, reach=0.0)
    arm = w.closest(giver, taker, reach=0.0)
    w.reset()
    assert box is not None
    path = act["paths"]["giver-home"]
    path[1:1] = [[float(v) for v in q_in], list(path[0])]
    return Doctored(
        plan,
        f"step {step}: {giver}'s 'giver-home' path pushes its hand {push * 1000:.0f} mm on along its approach: "
        f"{box[2]} of {giver} {-box[0] * 1000:.1f} mm inside {obj}, held by {taker} at its exchange"
        + (f"; {arm[1]} of {giver} {-arm[0] * 1000:.1f} mm inside {arm[2]} of {taker}" if arm else ""),
        (giver, obj, box[2], taker),
        -box[0],
        {"q": q_in, "arm": arm},
    )


# ------------------------------------------------------------------------------------- class 5: between samples
#: the doctored cart path's step (x, y, yaw; the largest coordinate change between waypoints), just under the
#: validator's resolution so that a sampler stepping evenly along the path's length at that resolution
#: checks exactly the waypoints (N steps of STEP make ceil(N * STEP / 0.01) = N samples steps, N < 1000)
STEP = 0.00999
#: how far the two waypoints beside the corner stand off the divider
STANDOFF = 0.00025


def _cheb(a: np.ndarray, b: np.ndarray) -> float:
    """The largest coordinate change from SE(2) pose ``a`` to ``b`` (yaw the shortest way round)."""
    d = b - a
    return float(max(abs(d[0]), abs(d[1]), abs(wrap_angle(float(d[2])))))


def _walk(guide: np.ndarray, step: float) -> list[np.ndarray]:
    """Poses from ``guide[0]`` to ``guide[-1]``, each exactly ``step`` from the last (:func:`_cheb`): on the
    guide polyline while two steps or more remain, then one pose off it (a yaw or y change of at most
    ``step``) so that the last step too is exactly ``step`` long and ends at ``guide[-1]``."""
    out, p, seg, u = [guide[0]], guide[0], 0, 0.0  # p lies at fraction u of guide segment seg
    end = guide[-1]
    while _cheb(p, end) >= 2 * step:
        while _cheb(p, guide[seg + 1]) < step:  # the segment's end is nearer than a step: go on
            seg, u = seg + 1, 0.0
        a, b = guide[seg], guide[seg + 1]
        lo, hi = u, 1.0  # the first point of the segment after p that is ``step`` from p (distances along a
        for _ in range(60):  # segment are convex, so everything before it is nearer)
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if _cheb(p, a + mid * (b - a)) < step else (lo, mid)
        p, u = a + hi * (b - a), hi
        out.append(p)
    d = end - p
    d[2] = wrap_angle(float(d[2]))
    i = int(np.argmax(np.abs(d)))
    j = 2 if i != 2 else 1
    e = d / 2
    e[i] = math.copysign(step, d[i])
    e[j] = d[j] - math.copysign(step, d[j] if d[j] else 1.0)
    out += [p + e, end]
    return out


def between_samples(plan: dict[str, Any], step: int, wall: str = "divider-s") -> Doctored:
    """Class 5: the cart of ``step``'s action drives its ``to-place`` path (backing east at yaw pi along
    y = 0 through the doorway, the held box trailing west) with a detour past ``wall``'s upper west corner W:
    waypoint A has the cart's south-east corner :data:`STANDOFF` west of the wall and STEP - STANDOFF
    below its top, the next waypoint B = A + (STEP, STEP, 0) has it STANDOFF above the top and STEP -
    STANDOFF east of its west face.  Both are clear; the straight motion between them cuts the corner
    (deepest at the middle: (STEP - 2 STANDOFF) / 2).  The whole path is rebuilt in steps of exactly STEP
    (:func:`_walk`) along a guide: the original path to x = A.x - 0.3, a straight leg to A; from B a
    straight leg to the original path at x = B.x + 0.3, then the original path."""
    plan = copy.deepcopy(plan)
    w = world_of(plan)
    act = action(plan, step)
    robot, obj = act["place_robot"], act["object"]
    path = np.asarray(act["paths"]["to-place"], dtype=float)
    assert np.all(np.abs(wrap_angle(path[:, 2] - math.pi)) < 1e-6) and np.all(np.abs(path[:, 1]) < 1e-6)
    body = w.scene.body(wall)
    hw = half_extents(body.shape)
    corner = body.pose[:2, 3] + np.array([-hw[0], hw[1]])  # the wall's upper west corner (it is not turned)
    hx, hy = (float(v) for v in half_extents(w.scene.robot(robot).kind.footprint)[:2])
    h = STEP - STANDOFF
    yaw = float(path[0, 2])
    a = np.array([corner[0] - STANDOFF - hx, corner[1] - h + hy, yaw])
    b = a + np.array([STEP, STEP, 0.0])
    before = path[path[:, 0] <= a[0] - 0.3]
    after = path[path[:, 0] >= b[0] + 0.3]
    back = _walk(np.vstack([a, before[::-1]]), STEP)[::-1]
    ahead = _walk(np.vstack([b, after]), STEP)
    new = np.vstack([back, ahead])
    act["paths"]["to-place"] = [[float(v) for v in q] for q in new]
    k = len(back) - 1  # A's index; B follows
    # measured: the cart (and the box it carries) against the wall at A, B and between them
    from mrgc.geometry.planar_grasps import carry_transform

    carry = carry_transform(w.scene.robot(robot).kind, w.scene.body(obj).shape, act["place_grasp"])
    place_objects(w, poses_before(w, plan, step), obj)

    def at(q: np.ndarray) -> float:
        w.set_q(robot, q)
        t = tf.rot_z(float(q[2]))
        t[0, 3], t[1, 3] = q[0], q[1]
        w.set_pose(obj, t @ carry)
        c = w.closest(robot, wall, reach=0.05)
        return c[0] if c is not None else math.inf

    ends = (at(new[k]), at(new[k + 1]))
    inside = min(at(new[k] + u * (new[k + 1] - new[k])) for u in np.linspace(0.0, 1.0, 101))
    # everywhere else: the cart and its box against everything fixed and movable, at quarter steps
    obstacles = [b.name for b in (*w.scene.fixed, *w.scene.movable) if b.name != obj]
    elsewhere = math.inf
    for i in range(len(new) - 1):
        for u in (0.0, 0.25, 0.5, 0.75, 1.0):
            if i == k and 0 < u < 1:
                continue
            at(new[i] + u * (new[i + 1] - new[i]))
            for o in obstacles:
                for body in (robot, obj):
                    c = w.closest(body, o, reach=0.005)
                    elsewhere = min(elsewhere, c[0] if c is not None and o != body else math.inf)
    w.reset()
    return Doctored(
        plan,
        f"step {step}: {robot}'s 'to-place' path rebuilt in {len(new) - 1} steps of {STEP} with configurations "
        f"{k + 1} and {k + 2} of {len(new)} {ends[0] * 1000:.2f} and {ends[1] * 1000:.2f} mm clear of {wall}; "
        f"the straight motion between them {-inside * 1000:.2f} mm into it",
        (robot, wall),
        -inside,
        {"index": k, "ends": ends, "path": new, "elsewhere": elsewhere},
    )


# ------------------------------------------------------------------------------------- class 8
def digest_changed(plan: dict[str, Any]) -> Doctored:
    """Class 8: only ``problem_digest`` changed (its first hex digit), the file's SHA-256 left as it was."""
    plan = copy.deepcopy(plan)
    old = plan["problem_digest"]
    plan["problem_digest"] = ("1" if old[0] != "1" else "2") + old[1:]
    return Doctored(plan, f"problem_digest {old[:8]}... -> {plan['problem_digest'][:8]}...", (), 0.0)


def huge_joint_value(plan: dict[str, Any], step: int = 2, value: float = 1e308) -> Doctored:
    """Class 8: joint 1 of pick configuration 3 of ``step`` set to ``value``."""
    plan = copy.deepcopy(plan)
    act = action(plan, step)
    act["configs"]["pick"][2][0] = value
    return Doctored(plan, f"step {step}: {act['pick_robot']}'s pick configuration 3, joint 1 = {value:g}", (), 0.0)
