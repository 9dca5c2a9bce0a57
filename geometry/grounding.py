"""The geometric queries the planner's grounding (reverse search) makes, as one stateful service.

A :class:`Grounder` holds the scene with the *current* object poses (the planner moves objects as it
grounds steps) and answers:

- :meth:`placement`: a collision-free pose of an object inside a region, avoiding given objects and a swept
  volume (the future volume V_fut of the paper's reverse search);
- :meth:`pick` / :meth:`place`: an arm's approach configurations for a grasp of an object at a pose;
- :meth:`handover`: both arms' configurations holding an object at a handover point, not colliding;
- :meth:`arm_path`: a joint-space RRTConnect path, optionally holding an object;
- :meth:`base_path`: an SE(2) path for a planar robot, optionally carrying an object;
- :meth:`arm_volume` / :meth:`base_volume`: the swept volume of configurations or a path, and
  :meth:`hits`: which objects a volume overlaps.

Every answer carries a :class:`GroundStatus`; failures are values, never exceptions.  Seeds derive from the
query, so the same queries in the same order give the same answers.

**The run's deadline** (:attr:`Grounder.deadline`, a ``time.perf_counter()`` value; ``benchmarks/cpu_plan.py``
swaps that clock for CPU time): every long loop reads it (placements, IK attempts, handover pairs, lifts,
transfers, transits, RRT solves, lattice searches), and past it the query stops at once with what it has
(status ``TIME_LIMIT`` where a status is the answer) and :attr:`Grounder.cut` turns True.  An answer made
after the cut may be wrong, so the caller discards everything grounded since (the planner ends its search
with ``time limit``); no clock decides an answer otherwise.
"""

from __future__ import annotations

import enum
import hashlib
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Hashable, Iterable, Iterator, Mapping, Sequence

import numpy as np

from mrgc.geometry.arm import Arm
from mrgc.geometry.collision import CollisionShape, Posed, collision_shape, posed_collide, scene_world
from mrgc.geometry.conventions import (
    APPROACH_SAMPLES,
    ARM_PLACE_LIFT,
    PATH_RESOLUTION,
    lattice_offsets,
    se2,
    seed_for,
    to_se2,
)
from mrgc.geometry.grasps import APPROACH, finger_opening, fits, grasp_transform, pregrasp_transform
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.lattice import Body, LatticePlanner, box_corners
from mrgc.geometry.motion import MAX_CHECKS, MotionStatus, plan_joint_path
from mrgc.geometry.planar import DiscGrid, PlanarRobot, is_planar, scene_bounds
from mrgc.geometry.scene import Body as SceneBody
from mrgc.geometry.scene import SceneSpec, half_extents, inside
from mrgc.geometry.transforms import rot_z, translation
from mrgc.language.model import Box, Shape

Volume = list[tuple[CollisionShape, np.ndarray]]  # shapes at world transforms
#: a volume as the queries read it (what other robots sweep meanwhile, ``busy``): any sequence of pieces
Pieces = Sequence[tuple[CollisionShape, np.ndarray]]

#: how far a transfer raises the tool straight up before it moves off (m): the approach's back-off, or more
#: when taller objects stand around the one picked (see :meth:`Grounder.lift_height`), up to MAX_LIFT
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
#: joint-space distance (rad) between the states an arm's path search checks when a finer path is asked
#: for (:meth:`Grounder.arm_path`): the path found is checked again, densely, before it is used
COARSE_RESOLUTION = 0.04
#: the share of the budget of checks the coarse search may spend (each of its checks covers 4x the motion)
COARSE_BUDGET = 0.5
#: the share of an arm's reach bound that :meth:`Grounder.comfortable` placements keep within
COMFORT = 0.85
#: path answers (transfers, base paths) remembered per grounder
REMEMBERED = 4096
#: largest joint motion (rad) between the configurations of an approach that are checked: half the
#: validator's resolution, so that the validator, sampling at other times, does not find the fingers deeper
#: in a neighbour than the 1 mm it tolerates where the planner found them clear (a 5-sample approach checked
#: at 4 times its samples let the validator reject whole plans for 1.1 mm finger overlaps)
APPROACH_CHECK = PATH_RESOLUTION / 2
#: IK attempts (each with its restarts) after which a pose none of them solved is called out of reach, as
#: phase 1 does (predicates.IK_SEEDS); attempts that solve it but collide go on to other branches
IK_GIVE_UP = 3
#: pairs of exchange configurations tried for a handover before the two arms are said to collide
HANDOVER_PAIRS = 6
#: an approach's last segment starts at most this many equal shares of the back-off from the grasp (the
#: validator allows 2)
CONTACT_START = 1.5


#: the detail of a failed query whose motion collided with what another robot of the step sweeps in the same
#: phase (the skeleton step may be split: planner/ground.py)
BUSY = "another robot of the step moves there in the same phase"
#: the detail of a failed query whose every answer put the arm in collision with itself (two links that
#: :attr:`~mrgc.geometry.kinematics.RobotModel.self_collision_pairs` keeps apart closer than
#: :data:`~mrgc.geometry.arm.SELF_CLEARANCE`)
SELF = "the arm collides with itself"

#: the phases of a step, in the order they run (docs/validator.md, "What a plan means")
PHASES = ("to-pick", "pick", "to-handover", "handover", "giver-home", "to-place", "place", "home")


class Stance(str, enum.Enum):
    """Where an arm of the step is during one of its :data:`PHASES` (:data:`STANCES`); the value names it in
    a failure line (``hits r2 at its exchange, holding``)."""

    HOME = "at home"
    #: its own motion of the phase: a path, an approach, its exchange configuration in the handover phase
    MOVES = "moving"
    #: standing at its last pick configuration, holding its object (fingers at the grasp's opening)
    PICKED = "at its grasp"
    #: a giver standing at its exchange configuration, the object let go (fingers at the grasp's opening)
    EXCHANGE = "at its exchange"
    #: a taker standing at its exchange configuration, holding the object
    RECEIVED = "at its exchange, holding"
    #: standing at its last place configuration, the object released (fingers at the grasp's opening)
    PLACED = "at its release"


#: **The execution model a plan means** (docs/validator.md; planner/replay.py replays it), the one place
#: the grounding reads it from: an arm's stance in each phase of :data:`PHASES`, by its role in its action,
#: under the ``configurations`` motion model.  Every arm starts the step at home; between its own motions it
#: stands where its last motion left it, its fingers as that motion left them; an arm in no action of the
#: step stays at home.
STANCES: dict[str, tuple[Stance, ...]] = {
    # to-pick, pick, to-handover, handover, giver-home, to-place, place, home
    "pick-place": (
        Stance.HOME,  # no to-pick path: it is at its pre-grasp when the pick phase starts
        Stance.MOVES,
        Stance.PICKED,  # while the handovers of the step run
        Stance.PICKED,
        Stance.PICKED,
        Stance.MOVES,
        Stance.MOVES,
        Stance.PLACED,  # no home path: at home when the next step starts
    ),
    "giver": (
        Stance.HOME,
        Stance.MOVES,
        Stance.MOVES,  # its to-handover transfer
        Stance.MOVES,  # at its exchange, holding
        Stance.EXCHANGE,  # no giver-home path: it lets go, and is at home when the phase ends
        Stance.HOME,
        Stance.HOME,
        Stance.HOME,
    ),
    "taker": (
        Stance.HOME,
        Stance.HOME,
        Stance.HOME,  # no taker-to-handover path: at its exchange when the handover phase starts
        Stance.MOVES,  # at its exchange, holding
        Stance.RECEIVED,  # while the giver withdraws
        Stance.MOVES,
        Stance.MOVES,
        Stance.PLACED,
    ),
}
#: each role's empty-handed transits: without a path (``configurations``) the arm jumps at the end of the
#: phase, so it stands where it was until then (:data:`STANCES`); with ``--motions full`` they are paths,
#: and the arm moves then
TRANSITS: dict[str, tuple[str, ...]] = {
    "pick-place": ("to-pick", "home"),
    "giver": ("to-pick", "giver-home"),
    "taker": ("to-handover", "home"),
}


def stance(role: str, phase: str, full: bool = False) -> Stance:
    """Where an arm of ``role`` (``pick-place``, ``giver``, ``taker``) is in ``phase``: :data:`STANCES`, or
    moving on its :data:`TRANSITS` when they are paths (``full``)."""
    if full and phase in TRANSITS[role]:
        return Stance.MOVES
    return STANCES[role][PHASES.index(phase)]


class GroundStatus(str, enum.Enum):
    """How a geometric query of the grounding ended (its value is what a failure line says)."""

    OK = "ok"
    NO_PLACEMENT = "no placement"
    NO_IK = "no inverse kinematics"
    COLLISION = "collision"
    NO_PATH = "no path"
    UNKNOWN = "unknown"
    TIME_LIMIT = "time limit"


@dataclass
class Answer:
    """A status and, when OK, the values found (``pose``, ``configs``, ``path``), plus what blocked."""

    status: GroundStatus
    pose: np.ndarray | None = None
    configs: np.ndarray | None = None  # (C, dof): approach configurations, pre-grasp first
    path: list[np.ndarray] = field(default_factory=list)
    blockers: set[str] = field(default_factory=set)
    #: what else was in the way when the status is COLLISION: fixed bodies, another arm at home, or what
    #: another robot of the step sweeps meanwhile (a line for the failure report)
    detail: str = ""
    #: a failure that only what never moves explains (no IK, fixed bodies, other arms' base links): the same
    #: query fails again in any state of the movable objects and the other robots
    static: bool = False

    @property
    def ok(self) -> bool:
        """The query succeeded."""
        return self.status is GroundStatus.OK


class Grounder:
    """Geometric queries over a scene whose movable objects can be moved (see the module docstring)."""

    def __init__(self, scene: SceneSpec, seed: int = 0) -> None:
        self.scene = scene
        self.seed = seed
        self.world = scene_world(scene)
        self.poses = {b.name: b.pose.copy() for b in scene.movable}
        self._arms: dict[str, Arm] = {}
        self._planar: dict[str, PlanarRobot] = {}
        self._grids: dict[str, DiscGrid] = {}
        self._lattices: dict[str, LatticePlanner] = {}
        self._paths: dict[tuple[object, ...], Answer] = {}
        self._grips: dict[tuple[str, str], tuple[float, np.ndarray]] = {}
        #: volumes (V_fut, what the step's other robots sweep, ``after``) as the collision kernel reads them
        self._volumes = _VolumeCache()
        # planar robots wait at their start pose (as the validator assumes): obstacles for the others
        self.parked: dict[str, str] = {}
        for spec in scene.robots:
            if is_planar(spec):
                pr = self.planar(spec.name)
                shape, pose = pr.probe(to_se2(spec.base))[0]
                self.parked[spec.name] = f"@{spec.name}"
                self.world.add(f"@{spec.name}", shape, pose, "robots")
        self.queries = 0
        #: the run's deadline (``time.perf_counter()``; None: none), and whether it has cut a query short
        self.deadline: float | None = None
        self.cut = False
        self.coarse_misses = 0  # coarse arm paths that collided between their states (searched again, finely)
        #: arms wait at home while others move (the validator's rule): each arm's links at home, group
        #: ``home:<arm>``, an obstacle to the other arms' motions
        self.homes: tuple[str, ...] = ()
        #: each arm's mount links (its base), group ``base:<arm>``: an obstacle to the other arms, home or not
        self._bases: tuple[str, ...] = ()
        #: the step being grounded (see :meth:`step`): each of its robots' role, and the arms' motion model
        self._roles: dict[str, str] = {}
        self._full = False
        #: arms of the step standing still away from home where they are known (:meth:`standing`): robot ->
        #: stance -> (world group, digest of its transforms)
        self._stands: dict[str, dict[Stance, tuple[str, bytes]]] = {}

    def late(self) -> bool:
        """Whether the run's :attr:`deadline` has passed (then :attr:`cut` is True: queries stop at once)."""
        if not self.cut and self.deadline is not None and time.perf_counter() > self.deadline:
            self.cut = True
        return self.cut

    def _arm_homes(self) -> tuple[str, ...]:
        """Put every arm's links at home into the world (once) and name their groups."""
        if not self.homes:
            for spec in self.scene.robots:
                if not is_planar(spec):
                    arm = self.arm(spec.name)
                    for i, (shape, t) in enumerate(self.arm_volume(spec.name, arm.home[None])):
                        self.world.add(f"@{spec.name}:{i}", shape, t, f"home:{spec.name}")
                    for j, (_, shape, t) in enumerate(arm.base_hulls):  # bolted in place: there, home or not
                        self.world.add(f"@{spec.name}:base" + (f":{j}" if j else ""), shape, t, f"base:{spec.name}")
                    if arm.base_hulls:
                        self._bases += (f"base:{spec.name}",)
            self.homes = tuple(f"home:{s.name}" for s in self.scene.robots if not is_planar(s))
        return self.homes

    def step(self, roles: Mapping[str, str], full: bool = False) -> None:
        """Declare the step whose actions are grounded next: each of its robots' role in its action
        (``pick-place``, ``giver`` or ``taker``) and whether arms' empty-handed transits are paths (``full``,
        ``mrgc plan --motions full``).  The grounder then knows, per phase, where every arm is (the execution
        model a plan means, :data:`STANCES`; docs/validator.md, docs/planner.md):

        - every arm starts the step at home; an arm in no action of the step stays there;
        - between its own motions an arm stands where its last motion left it, its fingers as that motion
          left them: a pick-and-place arm at its last pick configuration holding its object while the step's
          handovers run (to-handover, handover, giver-home), a taker at its exchange holding the object while
          the giver withdraws (giver-home), an arm without a home path at its last place configuration in
          the home phase;
        - a missing transit (no path under ``configurations``) is a jump at the end of its phase: a taker is
          at home until the handover phase (unless it has a ``taker-to-handover`` path), a giver at its
          exchange until the end of the giver-home phase, then at home (to-place, place, home);
        - planar robots always drive their paths (as ``full``).

        Each query of a phase keeps clear of the other arms at home then and of those standing still where
        :meth:`standing` has put them (:meth:`_others`); what the step's other robots do meanwhile, moving or
        standing, comes as the query's ``busy``.  ``step({})`` forgets the step."""
        self._roles, self._full = dict(roles), full

    def stance(self, robot: str, phase: str) -> Stance:
        """Where ``robot`` is during ``phase`` of the declared step (:meth:`step`); at home when it has no
        action in it."""
        role = self._roles.get(robot)
        if role is None:
            return Stance.HOME
        return stance(role, phase, self._full or self.is_planar(robot))

    @contextmanager
    def standing(self, robot: str, where: Mapping[Stance, Volume]) -> Iterator[None]:
        """``robot`` standing still at ``where`` (a volume per stance: its links, and the object it holds
        there) for the queries inside the ``with`` block: an obstacle to the other arms in the phases the
        execution model puts it there (:meth:`stance`); taken out again after the block."""
        before = self._stands.get(robot, {})
        added: list[str] = []
        mine = dict(before)
        try:
            for where_, volume in where.items():
                if where_ in before:
                    continue
                group = f"stand:{robot}:{where_.name}"
                for i, (shape, t) in enumerate(volume):
                    added.append(f"~{robot}:{where_.name}:{i}")
                    self.world.add(added[-1], shape, t, group)
                mine[where_] = (group, _fingerprint((), volume)[1])
            self._stands[robot] = mine
            yield
        finally:
            for name in added:
                self.world.remove(name)
            if before:
                self._stands[robot] = before
            else:
                self._stands.pop(robot, None)

    def _presence(self) -> tuple[object, ...]:
        """What :meth:`_others` answers depend on (a path cache's key): the step's roles, its motion model
        and where its arms stand."""
        stands = sorted((r, s.name, d) for r, m in self._stands.items() for s, (_, d) in m.items())
        return (tuple(sorted(self._roles.items())), self._full, tuple(stands))

    def _others(self, robot: str, phase: str) -> tuple[str, ...]:
        """The world groups of the other arms standing still in ``phase`` of the current step (:meth:`step`):
        at home, or where :meth:`standing` put them (an arm that moves then is in the query's ``busy``; one
        whose place is not known yet is left out), and every other arm's base link."""
        out = []
        for home in self._arm_homes():
            other = home[5:]
            if other == robot:
                continue
            where = self.stance(other, phase)
            if where is Stance.HOME:
                out.append(home)
            elif where in self._stands.get(other, {}):
                out.append(self._stands[other][where][0])
        return tuple(out) + tuple(b for b in self._bases if b != f"base:{robot}")

    # ------------------------------------------------------------ state
    def arm(self, robot: str) -> Arm:
        """The arm ``robot`` (its model, home and probes), made once."""
        if robot not in self._arms:
            self._arms[robot] = Arm(self.scene.robot(robot))
        return self._arms[robot]

    def planar(self, robot: str) -> PlanarRobot:
        """The planar robot ``robot``, made once."""
        if robot not in self._planar:
            self._planar[robot] = PlanarRobot(self.scene.robot(robot))
        return self._planar[robot]

    def is_planar(self, robot: str) -> bool:
        """Whether ``robot`` is a planar (mobile) robot rather than an arm."""
        return is_planar(self.scene.robot(robot))

    def move(self, obj: str, pose: np.ndarray) -> None:
        """Put ``obj`` at ``pose`` (world) for all later queries."""
        self.poses[obj] = pose.copy()
        self.world.set_transform(obj, pose)

    @contextmanager
    def moved(self, poses: Mapping[str, np.ndarray]) -> Iterator[None]:
        """The objects at ``poses`` for the queries inside the ``with`` block, back where they were after it
        (also when it raises)."""
        before = {o: self.poses[o] for o in poses}
        try:
            for o, pose in poses.items():
                self.move(o, pose)
            yield
        finally:
            for o, pose in before.items():
                self.move(o, pose)

    def shape(self, obj: str) -> CollisionShape:
        """The collision shape of body ``obj``."""
        return collision_shape(self.scene.body(obj).shape)

    # ------------------------------------------------------------ volumes
    def arm_volume(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> Volume:
        """Link hulls (and the held object) at each of ``configs`` (C, dof); the fingers stand at the opening
        of the (object, grasp) held, or of ``grasp`` (approaching it), else fully open."""
        return self._arm_volume(robot, configs, holding, grasp)[0]

    def arm_volumes(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> list[Volume]:
        """:meth:`arm_volume` at each of ``configs`` separately (one volume per configuration: a motion's
        samples), from one batched forward kinematics."""
        configs = np.atleast_2d(configs)
        volume = self._arm_volume(robot, configs, holding, grasp)[0]
        links = len(self.arm(robot).probes[0])
        out = [volume[k * links : (k + 1) * links] for k in range(len(configs))]
        if holding is not None:  # the held object's pieces follow the links' (one per configuration)
            for k, piece in enumerate(volume[links * len(configs) :]):
                out[k].append(piece)
        return out

    def free_volume(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> Volume | None:
        """:meth:`arm_volume`, or None when the arm collides with itself at one of ``configs``
        (:meth:`~mrgc.geometry.arm.Arm.self_collides`, on the same link transforms): every configuration the
        grounding answers with (approaches, exchanges, transfers, transits, paths) is checked through here.
        Past the run's deadline, None at once (:meth:`late`: every motion fails, the caller stops)."""
        if self.late():
            return None
        volume, transforms = self._arm_volume(robot, configs, holding, grasp)
        return None if self.arm(robot).self_collides_at(transforms) else volume

    def _arm_volume(
        self, robot: str, configs: np.ndarray, holding: tuple[str, str] | None, grasp: tuple[str, str] | None
    ) -> tuple[Volume, np.ndarray]:
        """:meth:`arm_volume` and the probed links' transforms it was made of."""
        arm = self.arm(robot)
        shapes, _ = arm.probes
        out: Volume = []
        fingers = holding or grasp
        opening = None if fingers is None else self._grip(*fingers)[0]
        transforms = arm.link_transforms(np.atleast_2d(configs), opening)
        for t in transforms:
            out.extend(zip(shapes, t))
        if holding is not None:
            obj, held_grasp = holding
            g_inv = self._grip(obj, held_grasp)[1]
            for tool in arm.tool_world(np.atleast_2d(configs)):
                out.append((self.shape(obj), tool @ g_inv))
        return out, transforms

    def _grip(self, obj: str, grasp: str) -> tuple[float, np.ndarray]:
        """The finger opening holding ``obj`` with ``grasp`` and the object's pose in the tool frame (the
        inverse grasp transform), computed once per pair: volumes ask for them at every configuration."""
        key = (obj, grasp)
        if key not in self._grips:
            spec, shape = self.scene.grasp(grasp), self.scene.body(obj).shape
            self._grips[key] = (finger_opening(spec, shape), np.linalg.inv(grasp_transform(spec, shape)))
        return self._grips[key]

    def base_volume(self, robot: str, path: Sequence[np.ndarray], holding: tuple[str, str] | None = None) -> Volume:
        """Footprint (and the carried object) at every state of an SE(2) path."""
        pr = self.planar(robot)
        carried = self._carried(robot, holding)
        out: Volume = []
        for q in path:
            out.extend(pr.probe(np.asarray(q), carried))
        return out

    def hits(self, volume: Volume, among: Iterable[str] | str = "movable", ignore: Iterable[str] = ()) -> set[str]:
        """The objects of ``among`` (names or a group) that ``volume`` overlaps."""
        self.queries += 1
        return self.world.probe_hits(volume, against=_against(among), ignore=tuple(ignore))

    # ------------------------------------------------------------ placements
    def placement(
        self,
        obj: str,
        region: str | SceneBody,
        avoid: Iterable[str] = (),
        volume: Volume | None = None,
        samples: int = 200,
        key: str = "",
        skip: int = 0,
        packed: bool = False,
    ) -> Answer:
        """A pose of ``obj`` entirely inside ``region`` that hits no fixed object, none of ``avoid`` (at their
        current poses) and nothing of ``volume``: phase 1's lattice first, then random positions and the four
        yaws; ``skip`` passes over that many valid candidates (to get another one on a retry).

        ``packed`` (a bin that several objects share): first a grid over the region at the four yaws,
        corners and walls first, so that each object leaves the largest free space in the middle for the
        ones placed before it (the reverse search places the last object first); the middle-first lattice
        scatters them and leaves no room for a third or fourth."""
        for pose in self.placements(obj, region, avoid, volume, samples, key, packed):
            if skip == 0:
                return Answer(GroundStatus.OK, pose=pose)
            skip -= 1  # the caller wants a different placement than the ones it already tried
        return Answer(GroundStatus.NO_PLACEMENT)

    def placements(
        self,
        obj: str,
        region: str | SceneBody,
        avoid: Iterable[str] = (),
        volume: Volume | None = None,
        samples: int = 200,
        key: str = "",
        packed: bool = False,
        prefer: Callable[[np.ndarray], float] | None = None,
    ) -> Iterator[np.ndarray]:
        """The poses :meth:`placement` would return with ``skip`` 0, 1, 2 ..., in that order, each checked
        once (asking :meth:`placement` for the k-th checks the first k again).  ``prefer`` (a rank of a pose,
        e.g. :meth:`comfortable`'s) orders the grid and lattice candidates by rank, keeping their order
        among equal ranks.  ``region`` is a region's name or a region body (a relay's spot on a fixed object's
        top: :func:`mrgc.geometry.relays.spot_region`)."""
        body = self.scene.body(obj)
        reg = region if isinstance(region, SceneBody) else self.scene.body(region)
        if not isinstance(reg.shape, Box):
            return
        rng = np.random.default_rng(seed_for("placement", obj, reg.name, key, seed=self.seed))
        h_o, h_r = half_extents(body.shape), half_extents(reg.shape)
        vol = self._volumes.posed(volume) if volume else None
        avoid = tuple(a for a in avoid if a != obj)
        shape = self.shape(obj)
        # first the 3 × 3 lattice phase 1 uses (so a placement the facts relied on is tried first), then
        # random positions and the four yaws
        room = np.maximum(h_r[:2] - h_o[:2], 0) * 0.9
        fixed: list[tuple[float, float, float]] = [(0.0, a * room[0], b * room[1]) for a, b in lattice_offsets(3)]
        if packed:
            fixed = _packing_grid(h_r[:2] - min(h_o[0], h_o[1])) + fixed
        if prefer is not None:  # accepted ones first in their order, then the others by the preference's rank
            rank = {
                c: prefer(reg.pose @ translation(c[1], c[2], -h_r[2] + h_o[2] + ARM_PLACE_LIFT) @ rot_z(c[0]))
                for c in fixed
            }
            fixed = sorted(fixed, key=lambda c: rank[c])  # stable
        for k in range(len(fixed) + samples):
            if self.late():
                return
            if k < len(fixed):
                yaw, x, y = fixed[k]
            else:
                yaw = (np.pi / 2) * (k % 4)
                x, y = rng.uniform(-1, 1, 2) * np.maximum(h_r[:2] - min(h_o[0], h_o[1]), 0)
            pose = reg.pose @ translation(x, y, -h_r[2] + h_o[2] + ARM_PLACE_LIFT) @ rot_z(yaw)
            if not inside(reg, body.shape, pose):
                continue
            probe = [(shape, pose)]
            self.queries += 1
            if self.world.probe_collides(probe, against="fixed"):
                continue
            if self.parked and self.world.probe_collides(probe, against="robots"):
                continue
            if avoid and self.world.probe_collides(probe, against=avoid):
                continue
            if vol is not None and posed_collide(Posed.of(probe), vol):
                continue
            yield pose

    def crowded_out(
        self, objs: Iterable[str], region: str, avoid: Iterable[str] = (), volume: Volume | None = None, key: str = ""
    ) -> str | None:
        """The first of ``objs`` that has no free pose left in ``region`` (the candidates and checks of a
        packed :meth:`placements`: fixed objects, ``avoid``, ``volume``), or None when each has one; objects
        already inside the region are not asked.  The reverse search asks it after grounding a placement
        into a bin that objects placed *earlier* still have to reach: a placement whose approach and carry
        sweep the whole bin leaves them none, and every grounding of an earlier step would then fail on it."""
        avoid, reg = tuple(avoid), self.scene.body(region)
        for obj in objs:
            if self.late():
                return None
            if inside(reg, self.scene.body(obj).shape, self.poses[obj]):
                continue
            if next(self.placements(obj, region, avoid, volume, key=f"room:{key}", packed=True), None) is None:
                return obj
        return None

    def comfortable(self, robot: str, obj: str, grasp: str, share: float = COMFORT) -> Callable[[np.ndarray], float]:
        """A rank of placements of ``obj`` for ``robot`` holding it with ``grasp``: 0 where the end effector
        lies within ``share`` of the arm's reach bound from the shoulder, else its distance from the shoulder
        (nearer first).  A bin at the edge of an arm's reach is reachable in its near part only, and IK at
        its far corners fails after every restart."""
        arm = self.arm(robot) if not self.is_planar(robot) else None
        spec = self.scene.grasp_specs.get(grasp)
        if arm is None or spec is None:
            return lambda pose: 0.0
        g_t = grasp_transform(spec, self.scene.body(obj).shape)

        def rank(pose: np.ndarray) -> float:
            far = float(np.linalg.norm(arm.ee_target(pose @ g_t)[:3, 3] - arm.model.shoulder))
            return 0.0 if far <= share * arm.model.reach else far

        return rank

    def _busy(self, volume: Pieces) -> Posed | None:
        """What other robots of a step sweep meanwhile (``busy``) as the kernel reads it (None: nothing)."""
        return self._volumes.posed(volume) if volume else None

    # ------------------------------------------------------------ arm configurations
    def _approach(
        self,
        robot: str,
        obj: str,
        grasp: str,
        pose: np.ndarray,
        key: str,
        avoid: Iterable[str],
        attempts: int = 8,
        approach: bool = True,
        held: bool = False,
        busy: Pieces = (),
        from_home: bool = True,
        after: Pieces = (),
    ) -> Answer:
        spec = self.scene.grasp_specs.get(grasp)
        arm = self.arm(robot)
        if spec is None or not fits(spec, self.scene.body(obj).shape, arm.spec.kind):
            return Answer(GroundStatus.NO_IK)  # no geometry, or the gripper does not open wide enough
        g_t = grasp_transform(spec, self.scene.body(obj).shape)
        avoid = tuple(a for a in avoid if a != obj)
        blockers: set[str] = set()
        status = GroundStatus.NO_IK
        moving = self._busy(busy)
        clash: tuple[str, Volume] | None = None  # the last attempt's collision not with ``avoid``: told at the end
        phase = key.split(":")[0]  # "pick", "place" or "handover"
        static = True  # every attempt so far failed on what never moves (IK, fixed bodies, bases)
        for attempt in range(attempts):
            seed = seed_for(robot, obj, grasp, key, str(attempt), seed=self.seed)
            # the first attempt starts from home (the solution nearest it); the others from a start drawn from
            # their seed, or every attempt would converge to that same solution again
            start = (
                arm.home
                if attempt == 0 and from_home
                else np.random.default_rng(seed).uniform(arm.model.lower, arm.model.upper)
            )
            q = solve_ik_many(arm.model, arm.ee_target(pose @ g_t)[None], seed, q_init=start)[0]
            if not q.solved or q.q is None:  # (q is None exactly when the solve failed)
                if q.status.value == "unreachable":
                    return Answer(GroundStatus.NO_IK, static=True)  # provably out of reach: no other seed helps
                if attempt + 1 >= IK_GIVE_UP and status is GroundStatus.NO_IK:
                    return Answer(GroundStatus.NO_IK, static=True)  # no start converged (phase 1 gives up too)
                continue
            configs = self._approach_configs(arm, pose @ g_t, q.q, seed) if approach else np.asarray(q.q)[None]
            if configs is None:
                continue
            # checked at every APPROACH_CHECK of joint motion (finer than the validator samples), with the
            # object in hand when placing
            dense = joint_line(configs, APPROACH_CHECK)
            volume = self.free_volume(robot, dense, holding=(obj, grasp) if held else None, grasp=(obj, grasp))
            if volume is None:  # the arm collides with itself: another branch may not (what never moves)
                status, clash = GroundStatus.COLLISION, ("self", [])
                continue
            self.queries += 1
            posed = Posed.of(volume)
            if self._fixed_clash(robot, obj, grasp, configs, posed, held, self._others(robot, phase)):
                status, clash = GroundStatus.COLLISION, ("fixed", volume)
                static = static and self._static_clash(robot, obj, posed, held)
                continue
            static = False  # this attempt failed (if it did) on what moves
            hit = self.world.probe_hits(posed, against=avoid) if avoid else set()
            if hit:
                blockers |= hit
                status = GroundStatus.COLLISION
                continue
            if (moving is not None and posed_collide(posed, moving)) or (
                after and self._standing_clash(robot, obj, grasp, configs[-1], after)
            ):
                # another robot of the step moves there meanwhile, or moves (or stands) where the arm stands
                # afterwards: another IK seed
                status, clash = GroundStatus.COLLISION, ("moving", volume)
                continue
            return Answer(GroundStatus.OK, pose=pose, configs=configs)
        detail = ""
        if clash is not None and not blockers:
            detail = self._clash_detail(robot, phase, clash, ignore=() if held else (obj,))
        return Answer(status, blockers=blockers, detail=detail, static=static)

    def _standing_clash(self, robot: str, obj: str, grasp: str, q: np.ndarray, after: Pieces) -> bool:
        """Whether ``robot`` standing at ``q`` holding ``obj`` hits ``after``: what the step's other robots do
        in the later phases it stands there (:meth:`step`).  Held: where it has let the object go, the object
        is there too then (placed, or held by the taker)."""
        volume = self.arm_volume(robot, q[None], holding=(obj, grasp))
        return posed_collide(Posed.of(volume), self._volumes.posed(after))

    def _static_clash(self, robot: str, obj: str, volume: Posed, held: bool) -> bool:
        """Whether an approach volume hits what never moves: a fixed body or another arm's base link."""
        bases = tuple(b for b in self._bases if b != f"base:{robot}")
        return self.world.probe_collides(volume, against=("fixed", *bases), ignore=() if held else (obj,))

    def _fixed_clash(
        self, robot: str, obj: str, grasp: str, configs: np.ndarray, volume: Posed, held: bool, homes: tuple[str, ...]
    ) -> bool:
        """Whether an approach (``configs``, swept as ``volume``) hits a fixed object or an arm at home
        (``homes``), or, picking, the object it picks before its contact segment (the last one: the validator
        exempts the picked object there only)."""
        if self.world.probe_collides(volume, against=("fixed", *homes), ignore=() if held else (obj,)):
            return True
        if held or len(configs) < 3:
            return False
        early = self.arm_volume(robot, joint_line(configs[:-1], APPROACH_CHECK), grasp=(obj, grasp))
        return self.world.probe_collides(early, against=(obj,))

    @staticmethod
    def _approach_configs(arm: Arm, tool: np.ndarray, q: np.ndarray, seed: int) -> np.ndarray | None:
        """The approach to grasp configuration ``q`` (tool at ``tool``): the pre-grasp by IK from ``q``, then
        :data:`APPROACH_SAMPLES` configurations to ``q``; None when the pre-grasp has no solution, or when
        pre-grasp and grasp come from different IK branches and swing the tool off the approach line (the
        contact segment must start near the grasp: the validator's rule, with a margin)."""
        pre = solve_ik_many(
            arm.model, arm.ee_target(tool @ pregrasp_transform(np.eye(4)))[None], seed, q_init=q[None], restarts=2
        )[0]
        if not pre.solved or pre.q is None:
            return None
        s = np.linspace(0.0, 1.0, APPROACH_SAMPLES)[:, None]
        configs: np.ndarray = pre.q[None] * (1 - s) + q[None] * s
        near = arm.tool_world(configs[-2][None])[0][:3, 3]
        if np.linalg.norm(near - tool[:3, 3]) > CONTACT_START * APPROACH / (APPROACH_SAMPLES - 1):
            return None
        return configs

    def _clash_detail(self, robot: str, phase: str, clash: tuple[str, Volume], ignore: tuple[str, ...]) -> str:
        """Name what a volume collided with besides the avoided objects: fixed bodies, other arms at home
        (their links are named ``@<arm>:<i>``) or standing still (``~<arm>:<stance>:<i>``), or the other robots
        of the step."""
        kind, volume = clash
        if kind == "moving":
            return BUSY
        if kind == "self":
            return SELF
        hit = self.world.probe_hits(volume, against=("fixed", *self._others(robot, phase)), ignore=ignore)
        named = sorted({_named(h) for h in hit})
        return "hits " + ", ".join(named) if named else ""

    def pick(
        self, robot: str, obj: str, grasp: str, avoid: Iterable[str] = (), busy: Pieces = (), after: Pieces = ()
    ) -> Answer:
        """Approach configurations for ``robot`` to grasp ``obj`` (at its current pose) with ``grasp``,
        free of fixed objects, of ``avoid`` and of ``busy`` (what other robots sweep meanwhile), the last one
        holding the object also free of ``after`` (what they do in the later phases the arm stands there,
        :meth:`step`); ``blockers`` names the avoided objects that were in the way."""
        return self._approach(robot, obj, grasp, self.poses[obj], "pick", avoid, busy=busy, after=after)

    def place(
        self,
        robot: str,
        obj: str,
        grasp: str,
        pose: np.ndarray,
        avoid: Iterable[str] = (),
        busy: Pieces = (),
        after: Pieces = (),
    ) -> Answer:
        """Approach configurations for ``robot`` holding ``obj`` with ``grasp`` to put it at ``pose`` (``busy``
        and ``after`` as for :meth:`pick`)."""
        return self._approach(robot, obj, grasp, pose, "place", avoid, held=True, busy=busy, after=after)

    def handover(
        self,
        obj: str,
        point: str,
        giver: str,
        g1: str,
        taker: str,
        g2: str,
        avoid: Iterable[str] = (),
        busy: Pieces = (),
        after: Mapping[str, Pieces] | None = None,
    ) -> Answer:
        """Both arms' configurations holding ``obj`` at handover point ``point`` (configs: giver, taker), free
        of ``busy`` (what the step's other robots do in the handover phase), each arm's also of ``after[arm]``
        (what they do in the later phases it stands at its exchange: :meth:`step`)."""
        pose = translation(*self.scene.handover_points[point])
        # as in phase 1, a handover is checked at the exchange configurations (no approach).  Each round draws
        # one more free exchange configuration of each arm (the first from home, the others from seeded
        # random starts: from home IK finds the same solution every time) and tries it against every
        # configuration of the other arm drawn so far, until a pair does not collide
        found: dict[str, list[np.ndarray]] = {giver: [], taker: []}
        failed = Answer(GroundStatus.COLLISION)
        worlds: list[Posed] = []  # the taker's configurations, as the kernel reads them
        later = after or {}

        def exchange(arm: str, grasp: str, attempt: int) -> Answer:
            key = f"handover:{point}" + (f":{attempt}" if attempt else "")
            first = attempt == 0
            return self._approach(
                arm, obj, grasp, pose, key, avoid, approach=False, busy=busy, from_home=first, after=later.get(arm, ())
            )

        for attempt in range(HANDOVER_PAIRS):
            if self.late():
                return Answer(GroundStatus.TIME_LIMIT)
            a, b = exchange(giver, g1, attempt), exchange(taker, g2, attempt)
            if not b.ok:
                failed = b
            else:
                assert b.configs is not None
                found[taker].append(b.configs[-1])
                world = Posed.of(self.arm_volume(taker, b.configs[-1:], grasp=(obj, g2)))
                worlds.append(world)
                for q in found[giver]:  # the new taker configuration against the giver's earlier ones
                    if not posed_collide(Posed.of(self.arm_volume(giver, q[None], grasp=(obj, g1))), world):
                        return Answer(GroundStatus.OK, pose=pose, configs=np.stack([q, b.configs[-1]]))
            if not a.ok:
                failed = a
            else:
                assert a.configs is not None
                found[giver].append(a.configs[-1])
                volume = Posed.of(self.arm_volume(giver, a.configs[-1:], grasp=(obj, g1)))
                for q, world in zip(found[taker], worlds):  # the new giver configuration against every taker's
                    if not posed_collide(volume, world):
                        return Answer(GroundStatus.OK, pose=pose, configs=np.stack([a.configs[-1], q]))
        if not (found[giver] and found[taker]):  # one arm never got there: why (its last attempt)
            return Answer(failed.status, blockers=failed.blockers, detail=failed.detail)
        return Answer(GroundStatus.COLLISION, detail="the two arms collide at every exchange drawn")

    # ------------------------------------------------------------ paths
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

        def free(configs: np.ndarray) -> bool:
            self.queries += 1
            volume = self.free_volume(robot, configs, holding, fingers)
            if volume is None:
                return False
            posed = Posed.of(volume)
            if moving is not None and posed_collide(posed, moving):
                return False
            return not self.world.probe_collides(posed, against=against, ignore=ignore)

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
        ) + _fingerprint([start, goal, *poses], busy)
        if key not in self._paths:
            answer = self._transfer(robot, obj, grasp, start, goal, avoid, lift, busy, lower, phase)
            self._remember(key, answer)
            return answer
        return self._paths[key]

    def _remember(self, key: tuple[object, ...], answer: Answer) -> None:
        """Keep a path answer, forgetting the oldest beyond :data:`REMEMBERED` (insertion order: the same
        run forgets the same ones)."""
        if self.cut:
            return  # made after the deadline: not an answer to keep (the caller discards it too)
        if len(self._paths) >= REMEMBERED:
            del self._paths[next(iter(self._paths))]
        self._paths[key] = answer

    def _transfer(
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
        """How ``robot`` carries ``obj`` (held with ``grasp``) from configuration ``start`` to ``goal``: when
        ``lift`` (``start`` grasps the object where it rests), first straight up by :meth:`lift_height`
        (tool poses every centimetre, each by IK from the one before; as far as the way up is free); then the
        straight joint-space line (the validator's reading of a plan that gives no transfer) or, when that line
        collides, an RRTConnect path (a budget of checks, seeded from the query); with ``lower``, that
        motion ends as high above ``goal`` and the carry comes straight down onto it (so the arm crosses
        a bin above what will stand in it, not through it).  Free of fixed objects, of the other arms
        where they stand in ``phase`` (:meth:`step`), of ``avoid`` and of ``busy`` (what the step's other
        robots do meanwhile).
        ``path`` is every configuration, ``start`` first, no joint moving more than
        :data:`PATH_RESOLUTION` between two; ``blockers`` the avoided objects in the way."""
        held = (obj, grasp)
        others = tuple(a for a in avoid if a != obj)
        against = ("fixed", *self._others(robot, phase), *others)
        moving = self._busy(busy)

        crossed = [False]  # did the last blocked motion cross what another robot of the step sweeps?

        def hits(configs: np.ndarray, holding: tuple[str, str] | None = held) -> set[str] | None:
            """None when free, else the avoided objects hit (empty: a fixed one, a moving robot or the arm
            itself)."""
            self.queries += 1
            volume = self.free_volume(robot, configs, holding=holding, grasp=held)
            posed = None if volume is None else Posed.of(volume)
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
            top = 1
            while top + 1 < len(up) and hits(joint_line(up[top : top + 2], PATH_RESOLUTION)) is None:
                top += 1
            back = joint_line(up[: top + 1], PATH_RESOLUTION)
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
        line = joint_line(np.stack([back[-1], tail[0]]), PATH_RESOLUTION)
        blocked = hits(line)
        if blocked is None:
            return Answer(GroundStatus.OK, path=[*back, *line[1:], *tail[1:]])
        planned = self.arm_path(
            robot,
            back[-1],
            tail[0],
            holding=held,
            avoid=others,
            resolution=PATH_RESOLUTION,
            busy=busy,
            phase=phase,
            max_checks=TRANSFER_CHECKS,
        )
        if not planned.ok:
            return Answer(GroundStatus.NO_PATH, blockers=blocked, detail=BUSY if crossed[0] else "")
        return Answer(GroundStatus.OK, path=[*back, *planned.path[1:], *tail[1:]])

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
        top = 0
        while top + 1 < len(up) and hits(joint_line(up[top : top + 2], PATH_RESOLUTION)) is None:
            top += 1
        return up[: top + 1]

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

        if retreat is not None:
            start = np.asarray(start, dtype=float)
            via = self._straight(robot, start, APPROACH, lambda c: None if free(c) else set(), retreat)
        back = joint_line(np.asarray(via if via is not None else [start], dtype=float), PATH_RESOLUTION)
        if not free(back):
            return Answer(GroundStatus.COLLISION)
        line = joint_line(np.stack([back[-1], np.asarray(goal, dtype=float)]), PATH_RESOLUTION)
        if free(line):
            return Answer(GroundStatus.OK, path=[*back, *line[1:]])
        planned = self.arm_path(
            robot,
            back[-1],
            np.asarray(goal, dtype=float),
            avoid=tuple(avoid),
            resolution=PATH_RESOLUTION,
            busy=busy,
            max_checks=TRANSFER_CHECKS,
            phase=phase,
            fingers=fingers,
        )
        if not planned.ok:
            return Answer(GroundStatus.NO_PATH)
        return Answer(GroundStatus.OK, path=[*back, *planned.path[1:]])

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
        poses = self.arm(robot).tool_world(configs) @ self._grip(obj, grasp)[1]
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
        its pose at ``q`` by up to ``height`` (one per centimetre, each solved from the one before, as far as
        none fails or jumps; None when not even the first centimetre can be solved)."""
        arm = self.arm(robot)
        tool = arm.tool_world(q[None])[0]
        way = (0.0, 0.0, 1.0) if direction is None else tuple(float(v) for v in direction)
        out = [q]
        for dz in np.arange(1, round(height / 0.01) + 1) * 0.01:
            if self.late():
                break
            target = arm.ee_target(translation(way[0] * dz, way[1] * dz, way[2] * dz) @ tool)
            ik = solve_ik_many(arm.model, target[None], 0, q_init=out[-1], restarts=0)[0]
            if not ik.solved or ik.q is None or float(np.abs(ik.q - out[-1]).max()) > 0.2:
                break  # as high as the arm goes straight up (at the edge of its reach: less)
            out.append(ik.q)
        return np.array(out) if len(out) > 1 else None

    def base_path(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        holding: tuple[str, str] | None = None,
        avoid: Iterable[str] = (),
        busy: Sequence[tuple[CollisionShape, np.ndarray]] = (),
    ) -> Answer:
        """An SE(2) path for a planar robot, free of fixed objects, of the other robots parked at their
        starts, of ``avoid`` (objects at their current poses) and of the volume ``busy`` (what robots moving
        at the same time sweep), searched on the robot's lattice
        (:mod:`mrgc.geometry.lattice`: deterministic, complete at the lattice's resolution), its states at
        the validator's resolution and every motion between two of them checked (the lattice's segment test,
        against ``busy`` too: the states of what the other robots sweep, not the motions between them);
        hopeless queries are refused at once by an inscribed-disc grid test.  Answers are cached: the same
        query (same obstacles at the same poses) gets the same answer, and the search never asks twice."""
        movers = sorted({a for a in avoid if not holding or a != holding[0]})
        key = (robot, holding, tuple(movers), *_fingerprint([start, goal, *(self.poses[a] for a in movers)], busy))
        if key not in self._paths:
            answer = self._base_path(robot, start, goal, holding, movers, busy)
            if answer.status is GroundStatus.NO_PATH and busy and not self.cut:
                # no path: is it the step's other robots (a path exists without them) or the scene?
                alone = self.base_path(robot, start, goal, holding, avoid, ())
                if alone.ok:
                    answer = Answer(GroundStatus.NO_PATH, detail=BUSY)
            self._remember(key, answer)
            return answer
        return self._paths[key]

    def _base_path(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        holding: tuple[str, str] | None,
        movers: list[str],
        busy: Sequence[tuple[CollisionShape, np.ndarray]],
    ) -> Answer:
        others = [name for r, name in self.parked.items() if r != robot]
        against = ("fixed", *others, *movers)
        ignore = (holding[0],) if holding else ()
        if robot not in self._grids:
            self._grids[robot] = DiscGrid(self.planar(robot), self.scene, scene_bounds(self.scene, 0.5))
            self._lattices[robot] = LatticePlanner(scene_bounds(self.scene, 0.5))
        # the disc grid knows objects at their initial poses only: objects moved since are left to the lattice
        obstacles = frozenset(
            [b.name for b in self.scene.fixed]
            + [a for a in movers if np.array_equal(self.poses[a], self.scene.body(a).pose)]
        )
        if not self._grids[robot].connected(np.asarray(start), np.asarray(goal), obstacles):
            return Answer(GroundStatus.NO_PATH)  # not even the footprint's inscribed disc gets through

        sweep = self._busy(busy)

        pr = self.planar(robot)
        carried = self._carried(robot, holding)

        def clear(q: np.ndarray, margin: float) -> bool:
            self.queries += 1
            if self.late():
                return False
            probe = pr.probe(q, carried, margin)
            if sweep is not None and posed_collide(Posed.of(probe), sweep):
                return False
            return not self.world.probe_collides(probe, against=against, ignore=ignore)

        def valid(q: np.ndarray) -> bool:
            return clear(q, 0.0)

        parts: list[tuple[Shape, np.ndarray]] = [(pr.footprint, pr.lift)]
        if holding is not None:
            body = self.scene.body(holding[0])
            parts.append((body.shape, pr.carry_transform(body.shape, holding[1])))
        bodies: list[tuple[Hashable, Body, np.ndarray]] = [(b.name, b.shape, b.pose) for b in self.scene.fixed]
        bodies += [((a, self.poses[a].tobytes()), self.scene.body(a).shape, self.poses[a]) for a in movers]
        for r in others:
            other = self.planar(r.lstrip("@"))
            bodies.append((r, other.footprint, se2(*other.start) @ other.lift))
        bodies += [(("busy", pts.tobytes()), pts, np.eye(4)) for pts in _swept_hulls(busy)]
        lattice = self._lattices[robot]
        occupied = lattice.occupancy(parts, bodies)
        res = lattice.plan(
            occupied,
            np.asarray(start, dtype=float),
            np.asarray(goal, dtype=float),
            valid,
            PATH_RESOLUTION,
            PATH_RESOLUTION,
            clear=clear,
            reach=pr.reach(carried),
            deadline=self.deadline,
        )
        if self.late() or res.status is MotionStatus.TIME_LIMIT:
            self.cut = True
            return Answer(GroundStatus.TIME_LIMIT)
        return Answer(GroundStatus.OK if res.solved else GroundStatus.NO_PATH, path=list(res.path))

    def _carried(self, robot: str, holding: tuple[str, str] | None) -> tuple[CollisionShape, np.ndarray] | None:
        """What planar ``robot`` carries holding ``holding`` (object, grasp): its shape and carry transform."""
        if holding is None:
            return None
        obj, grasp = holding
        return self.shape(obj), self.planar(robot).carry_transform(self.scene.body(obj).shape, grasp)


class _VolumeCache:
    """Volumes as the collision kernel reads them (:class:`~mrgc.geometry.collision.Posed`), converted once
    per list: the last few lists asked for (the same list object, unchanged: the reverse search's volumes
    grow by concatenation into new lists) are kept with their conversion.  Nothing is copied into coal."""

    SIZE = 8

    def __init__(self) -> None:
        self.kept: list[tuple[Pieces, int, Posed]] = []

    def posed(self, volume: Pieces) -> Posed:
        for k, (held, n, posed) in enumerate(self.kept):
            if held is volume and n == len(volume):
                if k:
                    self.kept.insert(0, self.kept.pop(k))
                return posed
        posed = Posed.of(volume)
        self.kept.insert(0, (volume, len(volume), posed))  # held, so that its id is not reused meanwhile
        del self.kept[self.SIZE :]
        return posed


def _packing_grid(room: np.ndarray, cells: int = 15) -> list[tuple[float, float, float]]:
    """(yaw, x, y) over ``[-room, room]`` (region frame) on a grid of at most ``cells`` per side (at least 1 cm
    apart), the four yaws at each point, points nearest a corner first."""
    room = np.maximum(room, 0.0)
    axes = [np.linspace(-r, r, max(1, min(cells, int(2 * r / 0.01) + 1))) for r in room]
    scale = np.maximum(room, 1e-9)

    def level(x: float, y: float) -> float:
        return float(-round(abs(x) / scale[0] + abs(y) / scale[1], 9))  # numpy's round, as before

    # the points of one level (the four corners, ...) at one yaw before the next yaw: a place that fails
    # at one corner (out of reach) is tried at the others before another yaw
    cands = [(level(float(x), float(y)), k, float(x), float(y)) for x in axes[0] for y in axes[1] for k in range(4)]
    return [(k * np.pi / 2, x, y) for _, k, x, y in sorted(cands)]


def _fingerprint(arrays: Iterable[np.ndarray], busy: Pieces) -> tuple[tuple[int, ...], bytes]:
    """What a path query's answer depends on besides its names: the shapes of ``busy`` and a digest of
    ``arrays`` (configurations, object poses) and of ``busy``'s transforms (the path caches' keys)."""
    digest = hashlib.sha1()
    for part in (*arrays, *(t for _, t in busy)):
        digest.update(np.ascontiguousarray(np.asarray(part, dtype=float)).tobytes())
    return tuple(id(shape) for shape, _ in busy), digest.digest()


def joint_line(configs: np.ndarray, step: float) -> np.ndarray:
    """The configurations of the straight joint-space motion through ``configs`` (C, dof), first and last
    included, no joint moving more than ``step`` between two."""
    out = [configs[:1]]
    for a, b in zip(configs[:-1], configs[1:]):
        n = max(1, int(np.ceil(float(np.abs(b - a).max()) / step - 1e-9)))
        s = np.arange(1, n + 1)[:, None] / n
        out.append(a[None] * (1 - s) + b[None] * s)
    return np.concatenate(out)


def _swept_hulls(volume: Sequence[tuple[CollisionShape, np.ndarray]], chunk: int = 8) -> list[np.ndarray]:
    """World points whose hulls cover ``volume``: the bounding-box corners of runs of ``chunk`` consecutive
    pieces of one shape (a path's states sweep little between them), for the lattice's occupancy."""
    runs: dict[int, list[np.ndarray]] = {}
    flushed: set[int] = set()
    out = []
    for shape, t in volume:
        run = runs.setdefault(id(shape), [])
        run.append(box_corners(shape) @ t[:3, :3].T + t[:3, 3])
        if len(run) == chunk:
            out.append(np.concatenate(run))
            runs[id(shape)] = [run[-1]]  # the next run starts where this one ended
            flushed.add(id(shape))
    out += [np.concatenate(run) for key, run in runs.items() if len(run) > 1 or key not in flushed]
    return out


def _named(hit: str) -> str:
    """A body of the grounder's world as a failure line names it: ``r2 at home`` for an arm's link at home
    (``@r2:<i>``, its base link ``@r2:base``), ``r1 at its exchange`` for one standing still
    (``~r1:EXCHANGE:<i>``, :meth:`Grounder.standing`), else its name."""
    if hit.startswith("@"):
        return f"{hit[1:].split(':')[0]} at home"
    if hit.startswith("~"):
        robot, where = hit[1:].split(":")[:2]
        return f"{robot} {Stance[where].value}"
    return hit


def _against(among: Iterable[str] | str) -> str | tuple[str, ...]:
    return among if isinstance(among, str) else tuple(among)
