"""Geometric plan replay for the validator: every step re-run in pybullet, checked continuously.

Nothing here comes from the planner's search or grounding: configurations are read from the plan, forward
kinematics and signed distances are pybullet's (:class:`mrgc.validator.world.ReplayScene`: the robots'
URDF collision meshes, the objects as pybullet shapes), motion bounds and self-collision pairs are derived
from the URDFs as pybullet loads them (:mod:`mrgc.validator.bounds`), grasp frames come from their
specification (:mod:`mrgc.geometry.grasps`), the planar-robot model from :mod:`mrgc.geometry.planar`'s
docstring.  Each action's geometry is read and checked by :mod:`mrgc.validator.actions`; this module
sweeps it (:mod:`mrgc.validator.sweep`).

**Execution model** (what a plan means; the checks follow it).  Every robot starts each step at home (its
kind's ``:home``; a planar robot at its ``:base`` pose).  Between its own motions a robot stands where its
last motion left it, holding what it holds, its fingers as they were: it is never "in transit".  A step
runs in synchronised phases:

1. *to-pick* (paths ``to-pick``): pick robots move from home to their first pick configuration;
2. *pick*: every pick robot follows its ``configs.pick`` (pre-grasp first, grasp last) and grasps its object
   at the last one; every object is where the earlier steps left it;
3. *to-handover* (holding: ``to-handover``; empty-handed: ``taker-to-handover``);
4. *handover*: each giver at ``configs.handover[0]``, each taker at ``configs.handover[1]``, both holding
   the object; then the taker holds it;
5. *giver-home* (paths ``giver-home``): each giver lets go (its fingers stay at the grasp's opening) and
   withdraws home while its taker stands at the exchange holding the object;
6. *to-place* (paths ``to-place``, holding): from the grasp (or a taker's exchange) to the pre-place;
7. *place*: every place robot follows its ``configs.place`` (pre-place first) holding its object and
   releases it at ``place_pose``;
8. *home* (paths ``home``): back home, every object at its new pose.

So a pick-and-place arm in a step with a handover stands at its last pick configuration, holding its
object, through phases 3-5; a taker stands at home until phase 3; robots that wait stand at home.

**The motion model** (the plan's ``motion_model``) says which motions the plan holds.  Planar robots
(``paths``): ``to-pick``, ``to-place`` and ``home`` are required of every action.  Arms, ``full``: every
path of the action's kind is required.  Arms, ``configurations`` (the paper's packaging model): no path is
required; a *holding* transfer without a path (``to-handover``, ``to-place``) is the straight joint-space
move between the configurations it connects, checked like a path; an empty-handed transit without a path is
not modelled: the robot stands where it was until the end of the transit's phase and is at its destination
from then on (a giver is home after phase 5, a placer after phase 8).  Motions of different robots in one
phase are paired by index: they share the phase's time ``s`` in [0, 1], each linear between its
configurations (:mod:`mrgc.validator.sampling`).

**Checks** (codes in brackets; tolerances as module constants here and in :mod:`~mrgc.validator.actions`):

- what :mod:`~mrgc.validator.actions` checks per action: ``[motion-model]``, ``[missing]``,
  ``[config]``, ``[joint-limits]``, ``[pose]``, ``[grasp]``, ``[approach]`` (including the tool's pose along
  the pick's and place's contact segment), ``[handover]``, ``[path]``;
- **continuously** through every phase (:mod:`mrgc.validator.sweep`: conservative advancement on bounds of
  how far any point of a link, footprint or held object can move; nothing passes between two checked
  samples), no overlap deeper than :data:`CONTACT_TOL` of: a moving robot with the fixed objects (except an
  arm's base link, see :class:`~mrgc.validator.world.ReplayScene`), the objects present, the other
  robots moving or standing and what they hold ``[collision-robot-fixed]``, ``[collision-robot-robot]``,
  ``[collision-robot-object]``; an arm with itself, every pair of links more than one chain joint apart
  (:mod:`mrgc.validator.bounds`) ``[collision-self]``; a held object with the fixed objects, the
  other objects and robots, and every link of the arm or arms holding it but their fingers
  ``[collision-object-fixed]``, ``[collision-object-object]``, ``[collision-self-held]``.  The object a robot
  picks may touch only its gripper (hand and fingers), only in the *contact segment* of its pick
  approach (between its last two configurations) and no deeper than the gripper stands in it at the grasp;
  its other links may not touch it.  A collision is
  reported once per step, phase and pair (link pair, for a self-collision), at its deepest;
- a motion longer than :data:`MAX_SAMPLES` samples at the resolution (:data:`RESOLUTION`), or a plan whose
  motions need more than :data:`MAX_PLAN_SAMPLES` robot samples at the resolution in all, or a phase that
  needs more than :data:`MAX_SAMPLES` checked times, is not checked and so not valid ``[too-long]``;
- every placement lies inside its action's region, or on the top of the fixed object its action names and resting
  on it ``[outside-region]``, is free of fixed objects, other
  objects and the robots at home, to :data:`CONTACT_TOL` ``[collision-...]``, and rests on something
  ``[floating]``: its lowest point at most :data:`SUPPORT_TOL` above the floor of a region under it whose
  floor lies on the ground (:func:`_grounded_regions`; a region drawn over a table is held up by the table,
  one drawn in the air by nothing), or lowered by :data:`SUPPORT_TOL` it would sink into a fixed or movable
  object (one beside it does not count); an object that rested on one a step moves away must still rest on
  something;
- at the end every goal object lies entirely inside its goal region ``[goal]``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from mrgc.geometry.scene import SceneSpec, inside, outline, scene_from_problem
from mrgc.geometry.transforms import translation
from mrgc.language.model import Problem
from mrgc.planfile.format import MotionModel, PlannedAction
from mrgc.validator.actions import PATH_PHASES, ActionGeometry, ActionReader
from mrgc.validator.bounds import ArmBounds, arm_bounds, planar_radius
from mrgc.validator.certify import Certifier, Phase
from mrgc.validator.fk import ArmChain, motion_spheres
from mrgc.validator.phase_bounds import PhaseBounds
from mrgc.validator.sampling import config_at, deltas, sample_count, where
from mrgc.validator.stability import stability
from mrgc.validator.sweep import CAP, Pair, Sweep
from mrgc.validator.violation import Violation
from mrgc.validator.world import ReplayScene

RESOLUTION = 0.01  # largest joint (rad) or planar base (m, rad) motion between samples
MIN_RESOLUTION = 1e-3  # a plan's finer resolution is followed down to this
CONTACT_TOL = 1e-3  # m of penetration tolerated (resting contact, numerical noise)
SUPPORT_TOL = 0.01  # m: a released object's lowest point may stand this far above what it rests on
MAX_SAMPLES = 100_000  # per motion: one needing more is too long to check (and reported)
MAX_PLAN_SAMPLES = 1_000_000  # robot samples of the whole plan (samples x robots moving)
BOX_PAD = 1e-3  # m: bounding boxes closer than this are handed to pybullet's distance query


@dataclass
class _Track:
    """A robot during a phase: moving through ``configs`` (one row: standing), maybe holding an object.
    ``carries``: the track puts the held object where its tool holds it (a taker at a handover does not:
    the giver does); ``exempt``: the object the robot picks, which its gripper links may touch from time
    ``exempt_from`` on (the pick's contact segment)."""

    robot: str
    configs: np.ndarray  # (m, dof)
    label: str
    holding: str | None = None
    grasp: str | None = None
    fingers: float | None = None  # finger opening (m) while approaching or holding; None: fully open
    carries: bool = True
    exempt: str | None = None
    exempt_from: float = 2.0


@dataclass(frozen=True)
class _Part:
    """One side of a checked pair: a robot (``link`` -1 .. its links) or an object, with the columns of the
    phase's speeds that move it and how (``rows``: link -> rate coefficients over all columns)."""

    name: str
    label: tuple[str, str]  # (what, where) for messages
    rows: dict[int, np.ndarray]
    track: int  # index of the track whose columns move it; -1: it stands
    robot: bool
    holder: str | None = None  # an object held: the robot that carries it


@dataclass
class _StepState:
    """Where each robot is during a step: its configuration (every robot starts the step at home), what it
    holds (object, grasp) and its finger opening since its last motion (absent: fully open)."""

    cur: dict[str, np.ndarray]
    hold: dict[str, tuple[str, str]] = field(default_factory=dict)
    opening: dict[str, float | None] = field(default_factory=dict)


class _PairList:
    """The pairs of a phase as they are added: :class:`~mrgc.validator.sweep.Pair` (sub-pairs and rates) and
    their sides (parts, the link indices of a self pair, the collision kind)."""

    def __init__(self) -> None:
        self.pairs: list[Pair] = []
        self.sides: list[tuple[_Part, _Part, tuple[int, int] | None, str]] = []

    def add(
        self,
        a: _Part,
        b: _Part,
        kind: str,
        links: tuple[int, int] | None = None,
        skip: frozenset[int] = frozenset(),
        until: dict[int, tuple[float, float]] | None = None,
    ) -> None:
        """Pair ``a`` with ``b`` (not when neither moves): every link of a robot side (only ``links`` for a
        self pair; robot links in ``skip`` left out), each sub-pair's rate the sum of its sides' rates, or for
        two parts moved by one track only what moves one and not the other; ``until``: link -> the time from
        which that link of the robot side is no longer checked."""
        if a.track < 0 and b.track < 0:
            return
        a_rows = {links[0]: a.rows[links[0]]} if links else a.rows
        b_rows = {links[1]: b.rows[links[1]]} if links else b.rows
        same = a.track >= 0 and a.track == b.track
        a_links = [la for la in a_rows if not (a.robot and la in skip)]
        b_links = [lb for lb in b_rows if not (b.robot and lb in skip)]
        if not a_links or not b_links:
            return
        ra = np.array([a_rows[la] for la in a_links])[:, None]  # (A, 1, C)
        rb = np.array([b_rows[lb] for lb in b_links])[None]  # (1, B, C)
        rows = ra * (rb == 0) + rb * (ra == 0) if same else ra + rb
        subs = [(la, lb) for la in a_links for lb in b_links]
        ends = [(until or {}).get(la if a.robot else lb, (np.inf, 0.0)) for la, lb in subs]
        self.pairs.append(
            Pair(subs, rows.reshape(len(subs), -1), np.array([e[0] for e in ends]), np.array([e[1] for e in ends]))
        )
        self.sides.append((a, b, links, kind))


class _PhaseWorld:
    """The pybullet world set up for one phase, and what the sweep needs of it: the moving ``tracks`` (each
    owns columns of the phase's speed vector: an arm's joints, a planar robot's (|d(x, y)|, |d yaw|)), the
    ``standing`` robots, the objects present (not held), and every robot and object as a :class:`_Part`."""

    def __init__(self, rp: _Replayer, tracks: list[_Track], standing: list[_Track]) -> None:
        self.rp, self.tracks, self.standing = rp, tracks, standing
        self.everyone = [*tracks, *standing]
        held = {tr.holding for tr in self.everyone if tr.holding}
        self.present = [o for o in rp.movable if o not in held]
        rs = rp.rs
        for tr in self.everyone:
            rs.set_fingers(tr.robot, tr.fingers)
            rs.set_config(tr.robot, tr.configs[0])
            if tr.holding and tr.grasp and tr.carries:
                rs.set_pose(tr.holding, rp.held_pose(tr.robot, tr.configs[0], tr.holding, tr.grasp))
        for o in rp.movable:
            if o not in held:
                rs.set_pose(o, rp.poses[o])
        self.offset: list[int] = []
        self.columns = 0
        for tr in tracks:
            self.offset.append(self.columns)
            self.columns += 2 if rp.planar[tr.robot] else len(tr.configs[0])
        self.parts = {tr.robot: self._robot(i, tr) for i, tr in enumerate(self.everyone)}
        carrier = {tr.holding: (i, tr) for i, tr in enumerate(self.everyone) if tr.holding and tr.carries}
        self.objects = {o: self._object(o, carrier.get(o)) for o in (*self.present, *carrier)}
        for f in rp.fixed:
            self.objects[f] = _Part(f, (f, ""), {-1: np.zeros(self.columns)}, -1, False)

    def _robot(self, i: int, tr: _Track) -> _Part:
        """Track ``i``'s robot: each link's rate coefficients (zero when it stands)."""
        rp, r = self.rp, tr.robot
        moving = i < len(self.tracks)
        rows: dict[int, np.ndarray] = {}
        if rp.planar[r]:
            rows[-1] = np.zeros(self.columns)
            if moving:
                rows[-1][self.offset[i] : self.offset[i] + 2] = (1.0, rp.footprint.get(r, 0.0))
        else:
            b = rp.bounds[r]
            for col, link in enumerate(b.links):
                rows[link] = np.zeros(self.columns)
                if moving:
                    rows[link][self.offset[i] : self.offset[i] + len(b.reach)] = b.reach[:, col]
        return _Part(r, (r, tr.label), rows, i if moving else -1, True)

    def _object(self, o: str, carried: tuple[int, _Track] | None) -> _Part:
        """Object ``o``: standing, or held by the track that carries it (its rate: the end effector's plus its
        radius about the end-effector frame per unit turn; planar: about the base's yaw axis)."""
        rp = self.rp
        row = np.zeros(self.columns)
        if carried is None:
            return _Part(o, (o, ""), {-1: row}, -1, False)
        i, tr = carried
        if i < len(self.tracks) and tr.grasp:
            at = self.offset[i]
            if rp.planar[tr.robot]:
                rel = rp.grasp_frame(tr.robot, o, tr.grasp)
                row[at : at + 2] = (1.0, float(np.hypot(rel[0, 3], rel[1, 3])) + rp.radius[o])
            else:
                b = rp.bounds[tr.robot]
                held = rp.held_pose(tr.robot, tr.configs[0], o, tr.grasp)
                rho = float(np.linalg.norm(held[:3, 3] - rp.rs.ee_pose(tr.robot)[:3, 3])) + rp.radius[o]
                row[at : at + len(b.ee_chain)] = b.ee_chain + rho * b.turns
        return _Part(o, (f"{o} held by {tr.robot}", ""), {-1: row}, i if i < len(self.tracks) else -1, False, tr.robot)

    def breakpoints(self) -> np.ndarray:
        """The times between which every motion's speed is constant: each track's configurations, and the
        start of each pick's contact segment."""
        times = [np.zeros(1), np.ones(1)]
        for tr in self.tracks:
            times.append(np.linspace(0.0, 1.0, len(tr.configs)) if len(tr.configs) > 1 else np.zeros(1))
            if tr.exempt and 0.0 < tr.exempt_from < 1.0:
                times.append(np.array([tr.exempt_from]))
        self._bp: np.ndarray = np.unique(np.concatenate(times))
        return self._bp

    def speeds(self, k: int) -> np.ndarray:
        """The absolute speeds (per unit of phase time) on ``[breakpoints[k], breakpoints[k + 1]]``."""
        out: np.ndarray = self.all_speeds()[k]
        return out

    def all_speeds(self) -> np.ndarray:
        """:meth:`speeds` of every stretch between breakpoints (K, columns), computed once."""
        kept: np.ndarray | None = getattr(self, "_speeds", None)
        if kept is not None:
            return kept
        bp = self._bp
        mid = 0.5 * (bp[:-1] + bp[1:])
        w = np.zeros((len(mid), self.columns))
        for i, tr in enumerate(self.tracks):
            m = len(tr.configs)
            if m < 2:
                continue
            j = np.minimum((mid * (m - 1)).astype(int), m - 2)
            planar = self.rp.planar[tr.robot]
            d = deltas(tr.configs, planar)[j] * (m - 1)
            at = self.offset[i]
            if planar:
                w[:, at] = np.hypot(d[:, 0], d[:, 1])
                w[:, at + 1] = np.abs(d[:, 2])
            else:
                w[:, at : at + d.shape[1]] = np.abs(d)
        self._speeds = w
        return w


class _Stop(Exception):
    """The first violation is known and no more are wanted."""


def replay(
    problem: Problem,
    model: MotionModel,
    steps: Sequence[Sequence[PlannedAction]],
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
    stats["resolution_samples"] = r.plan_samples
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


def _arm_bounds(rs: ReplayScene, homes: dict[str, np.ndarray]) -> dict[str, ArmBounds]:
    """Each arm's :class:`~mrgc.validator.bounds.ArmBounds`, derived once per world (they depend on
    the URDF as loaded and on the arm's home only) and kept with it."""
    kept: dict[tuple[int, str], tuple[np.ndarray, ArmBounds]] = _WORLD.setdefault("bounds", {})
    out = {}
    for robot, home in homes.items():
        key = (id(rs), robot)
        if key not in kept or not np.array_equal(kept[key][0], home):
            kept[key] = (np.array(home), arm_bounds(rs, robot, home))
        out[robot] = kept[key][1]
    return out


def _grounded_regions(scene: SceneSpec) -> frozenset[str]:
    """The regions whose floor lies on the ground, within :data:`CONTACT_TOL`: z = 0, unless a fixed object's
    top lies there (a table slab whose top is z = 0 stands on a ground at its bottom: then the lowest bottom of
    such slabs; a wall reaching below z = 0 does not move the ground).  Only their floors hold objects up;
    any other region's floor is drawn over something (a table, a shelf) that must hold the object up itself,
    or over nothing."""
    slabs = []
    for b in scene.fixed:
        z = (outline(b.shape) @ b.pose[:3, :3].T + b.pose[:3, 3])[:, 2]
        if abs(float(z.max())) <= CONTACT_TOL:
            slabs.append(float(z.min()))
    ground = min(slabs) if slabs else 0.0
    out = set()
    for r in scene.regions:
        floor = float((outline(r.shape) @ r.pose[:3, :3].T + r.pose[:3, 3])[:, 2].min())
        if abs(floor - ground) <= CONTACT_TOL:
            out.add(r.name)
    return frozenset(out)


class _Replayer(ActionReader):
    def __init__(self, scene: SceneSpec, rs: ReplayScene, model: MotionModel) -> None:
        super().__init__(scene, rs, model)
        self.fixed = [b.name for b in scene.fixed]
        self.movable = [b.name for b in scene.movable]
        self.resolution = max(MIN_RESOLUTION, min(RESOLUTION, model.resolution))
        self.samples = 0
        self.plan_samples = 0  # robot samples at the resolution of the motions checked so far (the cap's measure)
        self.budget_spent = False
        self._worst: dict[tuple[Any, ...], tuple[float, str, str]] = {}
        self.first_only = False
        self.bounds = _arm_bounds(rs, {r: self.home[r] for r, planar in self.planar.items() if not planar})
        self.footprint_shape = {r.name: r.kind.footprint for r in scene.robots if r.kind.footprint is not None}
        self.footprint = {
            r.name: planar_radius(outline(r.kind.footprint))
            for r in scene.robots
            if self.planar[r.name] and r.kind.footprint
        }
        self.radius = {b.name: float(np.linalg.norm(outline(b.shape), axis=1).max()) for b in scene.movable}
        self.grounded = _grounded_regions(scene)
        self._placements_state()
        self.support = {o: self._supports(o) for o in self.movable}  # what each object rests on

    # ------------------------------------------------------------------ one step
    def run_step(self, t: int, acts: list[ActionGeometry]) -> None:
        """Replay step ``t``: the phases of the module docstring, every robot at its true configuration."""
        geo = [a for a in acts if a.geometry]
        st = _StepState(dict(self.home))
        self._phase(t, "to-pick", st, [self._path(a, "to-pick") for a in geo])
        self._phase(t, "pick", st, [self._pick(a, st) for a in geo])
        self._picked_from_under(t, [a.obj for a in geo])
        for a in geo:
            if self.planar[a.action.pick_robot]:
                self._cart_load(t, a)
        for a in geo:
            st.hold[a.action.pick_robot] = (a.obj, a.action.pick_grasp)
        self._phase(t, "to-handover", st, [self._path(a, n) for a in geo for n in ("to-handover", "taker-to-handover")])
        self._phase(t, "handover", st, [tr for a in geo if a.handover for tr in self._exchange(a, st)])
        for a in geo:
            if a.handover:
                del st.hold[a.action.pick_robot]
                st.hold[a.action.place_robot] = (a.obj, a.action.place_grasp)
        self._phase(t, "giver-home", st, [self._withdraw(a) for a in geo if a.handover])
        for a in geo:
            if a.handover:  # without a giver-home path (configurations model) the giver is home now
                st.cur[a.action.pick_robot] = self.home[a.action.pick_robot]
                st.opening.pop(a.action.pick_robot, None)
        self._phase(t, "to-place", st, [self._path(a, "to-place") for a in geo])
        self._phase(t, "place", st, [self._place(a, st) for a in geo])
        for a in geo:
            st.hold.pop(a.action.place_robot, None)
        self._release(t, acts)
        self._phase(t, "home", st, [self._path(a, "home") for a in geo])
        placed = [a for a in acts if a.place_pose is not None]
        self._placements(t, placed)
        self._rests(t, placed)
        self._on_tops(t, placed)
        self.flush()

    def _path(self, a: ActionGeometry, name: str) -> _Track | None:
        """The track of ``a``'s path ``name`` (given, or the model's straight transfer); None without one."""
        if name not in a.paths:
            return None
        role, grasp_role = PATH_PHASES[name][:2]
        robot, grasp = a.robot(role), a.grasp(grasp_role)
        label = f"straight {name} transfer" if name in a.straight else f"{name} path"
        return _Track(robot, a.paths[name], label, a.obj if grasp else None, grasp, self.fingers(robot, a.obj, grasp))

    def _pick(self, a: ActionGeometry, st: _StepState) -> _Track:
        """The pick approach of ``a``; its arm may touch the object with its gripper in the contact segment (a
        planar robot stops in front of what it picks).  Without a to-pick path the robot is at its first
        pick configuration now."""
        qs, robot = a.configs["pick"], a.action.pick_robot
        st.cur[robot] = qs[0]
        contact = max(0.0, (len(qs) - 2) / (len(qs) - 1)) if len(qs) > 1 else 0.0
        fingers = self.fingers(robot, a.obj, a.action.pick_grasp)
        exempt = None if self.planar[robot] else a.obj
        return _Track(robot, qs, "pick", fingers=fingers, exempt=exempt, exempt_from=contact)

    def _cart_load(self, t: int, a: ActionGeometry) -> None:
        """A planar robot carries its box where its kind's ``:carry`` puts it, the same all along the carry: that
        pose must keep the box above the floor the robot drives on (z = 0) and out of the robot's own footprint,
        to :data:`CONTACT_TOL` ``[carry]`` (a 0.6 m box at a carry height of 0.2 m was dragged 10 cm through the
        floor, a 0.6 m deep one rode 10 cm inside its cart, and no other check saw either: the footprint is
        not an obstacle to what it carries, and the floor is no body)."""
        robot, obj, grasp = a.action.pick_robot, a.obj, a.action.pick_grasp
        rs = self.rs
        rs.set_config(robot, a.configs["pick"][-1])
        pose = self.held_pose_now(robot, obj, grasp)
        low = float((outline(self.shapes[obj]) @ pose[:3, :3].T + pose[:3, 3])[:, 2].min())
        if low < -CONTACT_TOL:
            below = f"with its lowest point {-low * 1e3:.1f} mm below the floor it drives on"
            self._v(t, obj, "carry", f"{robot} carries {obj} {below}")
        rs.set_pose(obj, pose)
        hit = rs.closest(obj, robot, 0.0)
        rs.set_pose(obj, self.poses[obj])
        if hit is not None and -hit.distance > CONTACT_TOL:
            self._v(t, obj, "carry", f"{robot} carries {obj} {-hit.distance * 1e3:.1f} mm into its own footprint")

    def _exchange(self, a: ActionGeometry, st: _StepState) -> list[_Track]:
        """A handover's giver and taker at their exchange configurations, both holding the object (where
        the giver holds it); without paths to it the robots are there now."""
        h, (giver, taker) = a.configs["handover"], a.action.robots()
        g1, g2 = a.action.pick_grasp, a.action.place_grasp
        st.cur[giver], st.cur[taker] = h[0], h[1]
        return [
            _Track(giver, h[:1], "handover (giver)", a.obj, g1, self.fingers(giver, a.obj, g1)),
            _Track(taker, h[1:], "handover (taker)", a.obj, g2, self.fingers(taker, a.obj, g2), carries=False),
        ]

    def _withdraw(self, a: ActionGeometry) -> _Track | None:
        """The giver's way home from the exchange, its fingers as they let the object go (the grasp's
        opening); None without a giver-home path."""
        tr = self._path(a, "giver-home")
        if tr is not None:
            tr.fingers = self.fingers(a.action.pick_robot, a.obj, a.action.pick_grasp)
        return tr

    def _place(self, a: ActionGeometry, st: _StepState) -> _Track:
        """The place approach of ``a``, holding the object; without a path to it the robot is there now."""
        robot, grasp = a.action.place_robot, a.action.place_grasp
        st.cur[robot] = a.configs["place"][0]
        return _Track(robot, a.configs["place"], "place", a.obj, grasp, self.fingers(robot, a.obj, grasp))

    def _release(self, t: int, acts: list[ActionGeometry]) -> None:
        """The step's objects at their placements, each inside its action's region ``[outside-region]``."""
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
                    + (
                        f"is not entirely on the top of {a.action.region}"
                        if a.action.region in self.fixed
                        else f"is not entirely inside region {a.action.region}"
                    ),
                )

    def _phase(self, t: int, phase: str, st: _StepState, tracks: list[_Track | None]) -> None:
        """Sweep phase ``phase`` with the ``tracks`` that move in it; then each robot that moved stands at
        its last configuration with its fingers as they were."""
        moving = [tr for tr in tracks if tr is not None]
        if moving and not self.budget_spent and self._within_budget(t, phase, moving):
            self._sweep(t, phase, moving, self._standing(moving, st))
        for tr in moving:
            st.cur[tr.robot], st.opening[tr.robot] = tr.configs[-1], tr.fingers

    def _standing(self, tracks: list[_Track], st: _StepState) -> list[_Track]:
        """Every robot without a track in a phase, standing where ``st`` says, holding what it holds."""
        moving = {tr.robot for tr in tracks}
        out = []
        for r in self.planar:
            if r in moving:
                continue
            home = np.array_equal(st.cur[r], self.home[r])
            obj, grasp = st.hold.get(r, (None, None))
            out.append(_Track(r, np.asarray(st.cur[r])[None], "home" if home else "standing", obj, grasp))
            out[-1].fingers = st.opening.get(r)
        return out

    # ------------------------------------------------------------------ sweeping a phase
    def _sweep(self, t: int, phase: str, tracks: list[_Track], standing: list[_Track]) -> None:
        """Check phase ``phase`` of step ``t`` continuously (:mod:`mrgc.validator.sweep`): the ``tracks`` move,
        the ``standing`` robots stand (with what they hold)."""
        ph = _PhaseWorld(self, tracks, standing)
        pairs, sides = self._pairs(ph)
        rs = self.rs

        carry = [self._carrier(tr) for tr in tracks]

        def set_state(s: float) -> None:
            for tr, put in zip(tracks, carry):
                rs.set_config(tr.robot, config_at(tr.configs, s, self.planar[tr.robot]))
                if put is not None:
                    put()
            self.samples += len(tracks)

        probes = [rs.prober(a.name, b.name, CAP, links) for a, b, links, _ in sides]

        def query(p: int, s: float) -> dict[tuple[int, int], float]:
            return probes[p]()

        def report(p: int, sub: tuple[int, int], d: float, s: float) -> None:
            a, b, _, kind = sides[p]
            self._hit_at(t, phase, kind, (a, sub[0]), (b, sub[1]), d, ph.everyone, s)

        bp = ph.breakpoints()
        bounds = PhaseBounds(ph, pairs, sides, self._offsets(tracks), self._chain) if pairs else None
        if bounds is not None and self._certified(ph, pairs, sides, bounds, set_state, probes):
            self.stop_if_found()  # as after a sweep: with first_only, what earlier checks found ends the replay
            return
        sweep = Sweep(bp, ph.speeds, pairs, set_state, query, report, CONTACT_TOL, MAX_SAMPLES)
        sweep.bound = bounds
        if self.first_only:
            sweep.stop = lambda: bool(self._worst)
        sweep.run()
        if sweep.exhausted:
            self._v(
                t, None, "too-long", f"{phase}: the motions need more than {MAX_SAMPLES} checked samples; not checked"
            )
        self.stop_if_found()

    def _chain(self, robot: str) -> tuple[ArmChain, list[tuple[np.ndarray, np.ndarray]]]:
        """Arm ``robot``'s numpy kinematics with its fingers as they stand now, and its links' motion spheres
        (kept with the world, per finger values)."""
        r = self.rs.robots[robot]
        fingers = tuple(
            float(self.rs.pb.getJointState(r.body, j, physicsClientId=self.rs.cid)[0]) for j, *_ in r.fingers
        )
        kept: dict[tuple[int, str, tuple[float, ...]], Any] = _WORLD.setdefault("chains", {})
        key = (id(self.rs), robot, fingers)
        if key not in kept:
            chain = ArmChain(self.rs, robot)
            motion = _WORLD.setdefault("motion", {})
            if (id(self.rs), robot) not in motion:
                motion[(id(self.rs), robot)] = motion_spheres(self.rs, robot, self.bounds[robot], chain)
            kept[key] = (chain, motion[(id(self.rs), robot)])
        out: tuple[ArmChain, list[tuple[np.ndarray, np.ndarray]]] = kept[key]
        return out

    def _offsets(self, tracks: list[_Track]) -> dict[int, np.ndarray]:
        """For each track that carries an object: the object's frame in its robot's end-effector frame (a
        planar robot's: its base frame)."""
        out = {}
        for i, tr in enumerate(tracks):
            if tr.holding and tr.grasp and tr.carries:
                key = (tr.robot, tr.holding, tr.grasp)
                if key not in self._held:
                    self.held_pose_now(*key)
                out[i] = self.tcp[tr.robot] @ self._held[key]
        return out

    def _certified(
        self,
        ph: _PhaseWorld,
        pairs: list[Pair],
        sides: list[tuple[_Part, _Part, tuple[int, int] | None, str]],
        bounds: PhaseBounds,
        set_state: Callable[[float], None],
        probes: list[Callable[[], dict[tuple[int, int], float]]],
    ) -> bool:
        """Whether the certifier (:mod:`mrgc.validator.certify`) proves the phase free of overlaps beyond the
        tolerance; when it cannot, the sweep checks the phase and reports."""
        rows = bounds.rows
        same = np.concatenate(
            [np.full(len(p.subs), a.track >= 0 and a.track == b.track) for p, (a, b, _, _) in zip(pairs, sides)]
        )
        ga, gb = rows[bounds.ends[:, 0]] > 0, rows[bounds.ends[:, 1]] > 0
        side_a = np.where(same[:, None], ga & ~gb, True)
        side_b = np.where(same[:, None], gb & ~ga, True)
        bp = ph._bp
        speeds = ph.all_speeds()
        first = np.full(len(same), -1)
        first_rate = np.full(len(same), np.inf)
        for j in np.flatnonzero(same & (side_a.any(axis=1) != side_b.any(axis=1))).tolist():
            down = 1 if side_b[j].any() else 0  # the side the joints between them move
            col = int(np.flatnonzero((side_b if down else side_a)[j])[0])
            rate = bounds.first_joint(int(bounds.ends[j, 1 - down]), col)
            if np.isfinite(rate):
                first[j], first_rate[j] = col, rate
        phase = Phase(
            bp,
            speeds,
            pairs,
            bounds.ends,
            np.stack([side_a, side_b], axis=1).astype(float),
            rows,
            bounds.at,
            set_state,
            lambda p: probes[p](),
            first,
            first_rate,
        )
        return Certifier(phase, CONTACT_TOL, MAX_SAMPLES).run()

    def _carrier(self, tr: _Track) -> Callable[[], None] | None:
        """What puts the object track ``tr`` carries where its robot holds it now (None: it carries none)."""
        if not (tr.holding and tr.grasp and tr.carries):
            return None
        robot, obj, grasp = tr.robot, tr.holding, tr.grasp
        if self.planar[robot]:
            return lambda: self.rs.set_pose(obj, self.held_pose_now(robot, obj, grasp))
        self.held_pose_now(robot, obj, grasp)  # the grasp's offset, computed once
        return self.rs.carrier(robot, obj, self.tcp[robot] @ self._held[(robot, obj, grasp)])

    def _pairs(self, ph: _PhaseWorld) -> tuple[list[Pair], list[tuple[_Part, _Part, tuple[int, int] | None, str]]]:
        """The pairs a phase checks, with their two sides, link indices (self pairs) and collision kind:
        each moving robot and what it carries against the fixed objects, the objects present, itself, the
        other moving robots and the standing ones with what they hold."""
        out = _PairList()
        for i, tr in enumerate(ph.tracks):
            me, b, h = ph.parts[tr.robot], self.bounds.get(tr.robot), tr.holding
            for f in self.fixed:
                out.add(me, ph.objects[f], "robot-fixed")
            for o in ph.present:
                exempt = self._grasp_depths(tr) if o == tr.exempt else None
                out.add(me, ph.objects[o], "robot-object", until=exempt)
            for la, lb in b.self_pairs if b is not None else ():
                out.add(me, me, "self", (la, lb))
            if h and h in ph.objects:
                for o in (*self.fixed, *ph.present):
                    out.add(ph.objects[h], ph.objects[o], "object-fixed" if o in self.fixed else "object-object")
                if b is not None:  # the held object against its own arm, the fingers (which hold it) excepted
                    out.add(ph.objects[h], me, "self-held", skip=b.fingers)
            for other in [*ph.tracks[i + 1 :], *ph.standing]:
                self._between(ph, out, tr, other)
        return out.pairs, out.sides

    def _grasp_depths(self, tr: _Track) -> dict[int, tuple[float, float]]:
        """A pick track's gripper links against the object it picks: from the contact segment on, each may
        reach as deep into the object as it stands at the grasp (its last configuration), no deeper."""
        b, obj = self.bounds[tr.robot], tr.exempt or ""
        self.rs.set_config(tr.robot, tr.configs[-1])
        depth = self.rs.link_distances(tr.robot, obj, 0.0)
        self.rs.set_config(tr.robot, tr.configs[0])
        return {link: (tr.exempt_from, max(0.0, -depth.get((link, -1), 0.0))) for link in b.gripper}

    def _between(self, ph: _PhaseWorld, out: _PairList, tr: _Track, other: _Track) -> None:
        """The pairs of two robots of a phase (``tr`` moves) and what they hold: robot-robot, each robot
        against the other's object, object-object; the object two robots hold at a handover is checked
        against both arms but their fingers."""
        me, them, h, oh = ph.parts[tr.robot], ph.parts[other.robot], tr.holding, other.holding
        out.add(me, them, "robot-robot")
        if oh and oh != h and oh in ph.objects:
            out.add(me, ph.objects[oh], "robot-object")
        if not (h and h in ph.objects):
            return
        if oh == h:
            ob = self.bounds.get(other.robot)
            out.add(ph.objects[h], them, "self-held", skip=ob.fingers if ob else frozenset())
            return
        out.add(ph.objects[h], them, "robot-object")
        if oh and oh in ph.objects:
            out.add(ph.objects[h], ph.objects[oh], "object-object")

    def _within_budget(self, t: int, phase: str, tracks: list[_Track]) -> bool:
        """Whether the phase's motions can be checked: no motion longer than :data:`MAX_SAMPLES` samples at
        the resolution, the plan's samples in all at most :data:`MAX_PLAN_SAMPLES` ``[too-long]`` (then the
        rest of the plan's motions are not checked)."""
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
        self.plan_samples += sum(counts) * len(tracks)
        if self.plan_samples > MAX_PLAN_SAMPLES:
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

    def stop_if_found(self) -> None:
        """With ``first_only``, end the replay once a violation is known."""
        if self.first_only and (self.out or self._worst):
            raise _Stop

    def _hit_at(
        self,
        t: int,
        phase: str,
        kind: str,
        a: tuple[_Part, int],
        b: tuple[_Part, int],
        d: float,
        everyone: list[_Track],
        s: float,
    ) -> None:
        """Record an overlap of ``d`` (< -CONTACT_TOL) between (part, link) ``a`` and ``b`` at time ``s`` of
        the phase, keeping the deepest per (step, phase, pair; link pair of a self-collision)."""
        (pa, la), (pb, lb) = a, b
        links = (la, lb) if kind == "self" else None
        key = (t, phase, f"collision-{kind}", pa.name, pb.name, links)
        if key in self._worst and self._worst[key][0] <= d:
            return
        by = {tr.robot: tr for tr in everyone}

        def at(robot: str) -> str:
            tr = by[robot]
            return {"home": "at home", "standing": "standing still"}.get(tr.label) or where(
                tr.label, len(tr.configs), s
            )

        def side(p: _Part, link: int) -> str:
            if not p.robot:
                return p.label[0] + (f" ({at(p.holder)})" if p.holder else "")
            return f"{self.rs.link_name(p.name, link)} of {p.name} ({at(p.name)})"

        msg = f"{phase}: {side(pa, la)} and {side(pb, lb)} overlap by {-d * 1e3:.1f} mm"
        self._worst[key] = (d, pa.name, msg)

    def flush(self) -> None:
        for (t, _, code, *_), (_, subject, msg) in self._worst.items():
            self._v(t, subject, code, msg)
        self._worst.clear()

    def _hit(
        self, t: int, phase: str, a: str, b: str, c: Any, da: tuple[str, str], db: tuple[str, str], kind: str
    ) -> None:
        """Record a penetration deeper than CONTACT_TOL between ``a`` and ``b`` (described by (label, when)),
        keeping the deepest per (step, phase, pair): the placement checks."""
        if c is None or c.distance >= -CONTACT_TOL:
            return
        key = (t, phase, f"collision-{kind}", a, b)
        if key in self._worst and self._worst[key][0] <= c.distance:
            return

        def side(d: tuple[str, str], link: str | None) -> str:
            return (f"{link} of {d[0]}" if link else d[0]) + (f" ({d[1]})" if d[1] else "")

        msg = f"{phase}: {side(da, c.link_a)} and {side(db, c.link_b)} overlap by {-c.distance * 1e3:.1f} mm"
        self._worst[key] = (c.distance, a, msg)

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

    def _floor_gap(self, obj: str, grounded: bool = True) -> tuple[float, str] | None:
        """How far the object's lowest point stands above the floor of the nearest region under its centre
        (negative: below it), and that region; None when no region lies under it.  ``grounded``: only the
        regions whose floor lies on the ground (:func:`_grounded_regions`), the floors that hold objects up."""
        pose = self.poses[obj]
        pts = outline(self.shapes[obj]) @ pose[:3, :3].T + pose[:3, 3]
        low = float(pts[:, 2].min())
        best: tuple[float, str] | None = None
        for region in self.scene.regions:
            if grounded and region.name not in self.grounded:
                continue
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
        """A move onto a fixed object's top (a relay's spot, an obstacle set aside on a table) sets its object
        down resting on that object ``[outside-region]`` (inside its :func:`~mrgc.geometry.scene.surface` box
        is not enough: a slab under the table has one too)."""
        fixed = set(self.fixed)
        for a in acts:
            top = a.action.region
            if top in fixed and top not in self._supports(a.obj):
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
                floor = self._floor_gap(o, grounded=False)
                p = self.poses[o][:3, 3]
                above = (
                    "no region lies under it"
                    if floor is None
                    else f"it stands on the floor of {floor[1]}, which holds nothing up there: that floor lies "
                    "neither on the ground nor on a fixed object"
                    if floor[1] not in self.grounded and floor[0] <= SUPPORT_TOL
                    else f"its lowest point is {floor[0] * 1e3:.1f} mm above the floor of {floor[1]}"
                )
                self._v(
                    t,
                    o,
                    "floating",
                    f"{o} is released at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) resting on "
                    f"nothing: {above}, and nothing is within {SUPPORT_TOL * 1e3:g} mm under it",
                )
            else:
                self._stable(t, o)
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
            else:
                self._stable(t, o)

    def _stable(self, t: int, o: str, gone: frozenset[str] = frozenset()) -> None:
        """An object that rests on something rests stably, with the objects that stand on it alone (their
        weight is its weight), and so does every object under it that holds it up alone, down to what
        stands on several supports or on something fixed: the centre of mass over the support polygon of the
        contacts, with a margin, flat on its lowest face (:mod:`mrgc.validator.stability`) ``[unstable]``;
        ``gone``: objects not in the scene now (picked up)."""
        floors = [(r.name, r.shape, r.pose) for r in self.scene.regions if r.name in self.grounded]
        bodies = {
            b: (s, self.poses[b] if b in self.poses else self.scene.body(b).pose)
            for b, s in self.shapes.items()
            if b not in gone
        }
        seen: set[str] = set()
        while o not in seen:
            seen.add(o)
            load = {x: bodies[x] for x in self._load(o, gone)}
            verdict = stability(o, self.shapes[o], self.poses[o], bodies, floors, load)
            if not verdict.stable:
                self._v(t, o, "unstable", verdict.message())
                return
            under = [s for s in self.support.get(o, set()) if s in self.poses and s not in gone]
            if len(self.support.get(o, set())) != 1 or len(under) != 1:
                return
            o = under[0]

    def _load(self, o: str, gone: frozenset[str]) -> set[str]:
        """The objects that stand on ``o`` alone, directly or through each other."""
        out: set[str] = set()
        todo = [o]
        while todo:
            x = todo.pop()
            for y, under in self.support.items():
                if y not in out and y != o and y not in gone and under == {x}:
                    out.add(y)
                    todo.append(y)
        return out

    def _picked_from_under(self, t: int, picked: list[str]) -> None:
        """When a step picks objects up, what rested on them must rest on something else at once, and
        stand (``[floating]``, ``[unstable]``): a support is not there while it is held, even if it is put
        back by the end of the step."""
        gone = frozenset(picked)
        hit = [o for o in self.movable if o not in gone and self.support.get(o, set()) & gone]
        if not hit:
            return
        for p in picked:
            self.rs.set_pose(p, None)
        for o in hit:
            self.rs.set_pose(o, self.poses[o])
            left = self._supports(o) - gone
            if not left:
                lost = ", ".join(sorted(self.support[o] & gone))
                self._v(t, o, "floating", f"{o} rested on {lost}, which step {t} picks up: nothing holds it up then")
            else:
                self._stable(t, o, gone)
        for p in picked:
            self.rs.set_pose(p, self.poses[p])

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
