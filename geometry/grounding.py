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

Every answer carries a :class:`Status`; failures are values, never exceptions.  Seeds derive from the
query, so the same queries in the same order give the same answers.
"""

from __future__ import annotations

import enum
import hashlib
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from mrgc.geometry.arm import Arm
from mrgc.geometry.collision import CollisionShape, CollisionWorld, collision_shape
from mrgc.geometry.grasps import finger_opening, fits, grasp_transform, pregrasp_transform
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.lattice import LatticePlanner, box_corners
from mrgc.geometry.motion import MAX_CHECKS, plan_joint_path
from mrgc.geometry.planar import DiscGrid, PlanarRobot, is_planar, scene_bounds, se2, to_se2
from mrgc.geometry.predicates import APPROACH_SAMPLES, LIFT, refine, scene_world, seed_for
from mrgc.geometry.scene import SceneSpec, half_extents, inside
from mrgc.geometry.transforms import rot_z, translation
from mrgc.language.model import Box, Shape

Volume = list[tuple[CollisionShape, np.ndarray]]  # shapes at world transforms

#: largest step (m of translation, rad of turn) between checked states of a planar path: the validator's
PATH_RESOLUTION = 0.01


class Status(str, enum.Enum):
    OK = "ok"
    NO_PLACEMENT = "no placement"
    NO_IK = "no inverse kinematics"
    COLLISION = "collision"
    NO_PATH = "no path"
    UNKNOWN = "unknown"


@dataclass
class Answer:
    """A status and, when OK, the values found (``pose``, ``configs``, ``path``), plus what blocked."""

    status: Status
    pose: np.ndarray | None = None
    configs: np.ndarray | None = None  # (C, dof): approach configurations, pre-grasp first
    path: list[np.ndarray] = field(default_factory=list)
    blockers: set[str] = field(default_factory=set)

    @property
    def ok(self) -> bool:
        return self.status is Status.OK


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
        # planar robots wait at their start pose (as the validator assumes): obstacles for the others
        self.parked: dict[str, str] = {}
        for spec in scene.robots:
            if is_planar(spec):
                pr = self.planar(spec.name)
                shape, pose = pr.probe(to_se2(spec.base))[0]
                self.parked[spec.name] = f"@{spec.name}"
                self.world.add(f"@{spec.name}", shape, pose, "robots")
        self.queries = 0

    # ------------------------------------------------------------ state
    def arm(self, robot: str) -> Arm:
        if robot not in self._arms:
            self._arms[robot] = Arm(self.scene.robot(robot))
        return self._arms[robot]

    def planar(self, robot: str) -> PlanarRobot:
        if robot not in self._planar:
            self._planar[robot] = PlanarRobot(self.scene.robot(robot))
        return self._planar[robot]

    def is_planar(self, robot: str) -> bool:
        return is_planar(self.scene.robot(robot))

    def move(self, obj: str, pose: np.ndarray) -> None:
        """Put ``obj`` at ``pose`` (world) for all later queries."""
        self.poses[obj] = pose.copy()
        self.world.set_transform(obj, pose)

    def shape(self, obj: str) -> CollisionShape:
        return collision_shape(self.scene.body(obj).shape)

    # ------------------------------------------------------------ volumes
    def arm_volume(self, robot: str, configs: np.ndarray, holding: tuple[str, str] | None = None,
                   grasp: tuple[str, str] | None = None) -> Volume:
        """Link hulls (and the held object) at each of ``configs`` (C, dof); the fingers stand at the opening
        of the (object, grasp) held, or of ``grasp`` (approaching it), else fully open."""
        arm = self.arm(robot)
        shapes, _ = arm.probes
        out: Volume = []
        fingers = holding or grasp
        opening = None if fingers is None else \
            finger_opening(self.scene.grasp(fingers[1]), self.scene.body(fingers[0]).shape)
        transforms = arm.link_transforms(np.atleast_2d(configs), opening)
        for t in transforms:
            out.extend(zip(shapes, t))
        if holding is not None:
            obj, held_grasp = holding
            g_inv = np.linalg.inv(grasp_transform(self.scene.grasp(held_grasp), self.scene.body(obj).shape))
            for tool in arm.tool_world(np.atleast_2d(configs)):
                out.append((self.shape(obj), tool @ g_inv))
        return out

    def base_volume(self, robot: str, path: Sequence[np.ndarray], holding: tuple[str, str] | None = None) -> Volume:
        """Footprint (and the carried object) at every state of an SE(2) path."""
        pr = self.planar(robot)
        carried = None
        if holding is not None:
            obj, grasp = holding
            carried = (self.shape(obj), pr.carry_transform(self.scene.body(obj).shape, grasp))
        out: Volume = []
        for q in path:
            out.extend(pr.probe(np.asarray(q), carried))
        return out

    def hits(self, volume: Volume, among: Iterable[str] | str = "movable", ignore: Iterable[str] = ()) -> set[str]:
        """The objects of ``among`` (names or a group) that ``volume`` overlaps."""
        self.queries += 1
        return self.world.probe_hits(volume, against=_against(among), ignore=tuple(ignore))

    # ------------------------------------------------------------ placements
    def placement(self, obj: str, region: str, avoid: Iterable[str] = (), volume: Volume | None = None,
                  samples: int = 200, key: str = "", skip: int = 0) -> Answer:
        """A pose of ``obj`` entirely inside ``region`` that hits no fixed object, none of ``avoid`` (at their
        current poses) and nothing of ``volume``: phase 1's lattice first, then random positions and the four
        yaws; ``skip`` passes over that many valid candidates (to get another one on a retry)."""
        body, reg = self.scene.body(obj), self.scene.body(region)
        if not isinstance(reg.shape, Box):
            return Answer(Status.NO_PLACEMENT)
        rng = np.random.default_rng(seed_for("placement", obj, region, key, seed=self.seed))
        h_o, h_r = half_extents(body.shape), half_extents(reg.shape)
        vol_world = None
        if volume:
            vol_world = CollisionWorld()
            for i, (shape, t) in enumerate(volume):
                vol_world.add(f"v{i}", shape, t, "volume")
        avoid = tuple(a for a in avoid if a != obj)
        shape = self.shape(obj)
        # first the 3 × 3 lattice phase 1 uses (so a placement the facts relied on is tried first), then
        # random positions and the four yaws
        room = np.maximum(h_r[:2] - h_o[:2], 0) * 0.9
        lattice = sorted(((a, b) for a in (-1.0, 0.0, 1.0) for b in (-1.0, 0.0, 1.0)),
                         key=lambda ab: (ab[0] ** 2 + ab[1] ** 2, ab))
        for k in range(len(lattice) + samples):
            if k < len(lattice):
                yaw, (x, y) = 0.0, (lattice[k][0] * room[0], lattice[k][1] * room[1])
            else:
                yaw = (np.pi / 2) * (k % 4)
                x, y = rng.uniform(-1, 1, 2) * np.maximum(h_r[:2] - min(h_o[0], h_o[1]), 0)
            pose = reg.pose @ translation(x, y, -h_r[2] + h_o[2] + LIFT) @ rot_z(yaw)
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
            if vol_world is not None and vol_world.probe_collides(probe, against="volume"):
                continue
            if skip > 0:  # the caller wants a different placement than the ones it already tried
                skip -= 1
                continue
            return Answer(Status.OK, pose=pose)
        return Answer(Status.NO_PLACEMENT)

    # ------------------------------------------------------------ arm configurations
    def _approach(self, robot: str, obj: str, grasp: str, pose: np.ndarray, key: str,
                  avoid: Iterable[str], attempts: int = 8, approach: bool = True, held: bool = False) -> Answer:
        spec = self.scene.grasp_specs.get(grasp)
        arm = self.arm(robot)
        if spec is None or not fits(spec, self.scene.body(obj).shape, arm.spec.kind):
            return Answer(Status.NO_IK)  # no geometry, or the gripper does not open wide enough
        g_t = grasp_transform(spec, self.scene.body(obj).shape)
        avoid = tuple(a for a in avoid if a != obj)
        blockers: set[str] = set()
        status = Status.NO_IK
        for attempt in range(attempts):
            seed = seed_for(robot, obj, grasp, key, str(attempt), seed=self.seed)
            q = solve_ik_many(arm.model, arm.ee_target(pose @ g_t)[None], seed, q_init=arm.home)[0]
            if not q.solved:
                if q.status.value == "unreachable":
                    return Answer(Status.NO_IK)  # provably out of reach: no other seed helps
                continue
            if approach:
                pre = solve_ik_many(arm.model, arm.ee_target(pose @ pregrasp_transform(g_t))[None], seed,
                                    q_init=q.q[None], restarts=2)[0]
                if not pre.solved:
                    continue
                s = np.linspace(0.0, 1.0, APPROACH_SAMPLES)[:, None]
                configs = pre.q[None] * (1 - s) + q.q[None] * s
            else:
                configs = np.asarray(q.q)[None]
            # checked on a 4× finer interpolation than the configurations kept (the validator's resolution),
            # with the object in hand when placing
            volume = self.arm_volume(robot, refine(configs), holding=(obj, grasp) if held else None,
                                     grasp=(obj, grasp))
            self.queries += 1
            if self.world.probe_collides(volume, against="fixed", ignore=() if held else (obj,)):
                status = Status.COLLISION
                continue
            hit = self.world.probe_hits(volume, against=avoid) if avoid else set()
            if hit:
                blockers |= hit
                status = Status.COLLISION
                continue
            return Answer(Status.OK, pose=pose, configs=configs)
        return Answer(status, blockers=blockers)

    def pick(self, robot: str, obj: str, grasp: str, avoid: Iterable[str] = ()) -> Answer:
        """Approach configurations for ``robot`` to grasp ``obj`` (at its current pose) with ``grasp``,
        free of fixed objects and of ``avoid``; ``blockers`` names the avoided objects that were in the way."""
        return self._approach(robot, obj, grasp, self.poses[obj], "pick", avoid)

    def place(self, robot: str, obj: str, grasp: str, pose: np.ndarray, avoid: Iterable[str] = ()) -> Answer:
        """Approach configurations for ``robot`` holding ``obj`` with ``grasp`` to put it at ``pose``."""
        return self._approach(robot, obj, grasp, pose, "place", avoid, held=True)

    def handover(self, obj: str, point: str, giver: str, g1: str, taker: str, g2: str,
                 avoid: Iterable[str] = ()) -> Answer:
        """Both arms' configurations holding ``obj`` at handover point ``point`` (configs: giver, taker)."""
        pose = translation(*self.scene.handover_points[point])
        # as in phase 1, a handover is checked at the exchange configurations (no approach)
        a = self._approach(giver, obj, g1, pose, f"handover:{point}", avoid, approach=False)
        b = self._approach(taker, obj, g2, pose, f"handover:{point}", avoid, approach=False)
        if not (a.ok and b.ok):
            return Answer(a.status if not a.ok else b.status, blockers=a.blockers | b.blockers)
        assert a.configs is not None and b.configs is not None
        world = CollisionWorld()
        for i, (shape, t) in enumerate(self.arm_volume(taker, b.configs[-1:], grasp=(obj, g2))):
            world.add(f"t{i}", shape, t, "taker")
        if world.probe_collides(self.arm_volume(giver, a.configs[-1:], grasp=(obj, g1)), against="taker"):
            return Answer(Status.COLLISION)
        return Answer(Status.OK, pose=pose, configs=np.stack([a.configs[-1], b.configs[-1]]))

    # ------------------------------------------------------------ paths
    def arm_path(self, robot: str, start: np.ndarray, goal: np.ndarray, holding: tuple[str, str] | None = None,
                 avoid: Iterable[str] = (), max_checks: int = MAX_CHECKS) -> Answer:
        """A joint-space path (RRTConnect, at most ``max_checks`` validity checks: no clock decides) free of
        fixed objects and ``avoid`` (and of the held object's collisions with them)."""
        arm = self.arm(robot)
        against = ("fixed", *[a for a in avoid if not holding or a != holding[0]])
        ignore = (holding[0],) if holding else ()

        def valid(q: np.ndarray) -> bool:
            self.queries += 1
            return not self.world.probe_collides(self.arm_volume(robot, q[None], holding), against=against,
                                                 ignore=ignore)

        res = plan_joint_path(arm.model.lower, arm.model.upper, start, goal, valid, max_checks=max_checks,
                              seed=seed_for(robot, "arm-path", seed=self.seed))
        return Answer(Status.OK if res.solved else Status.NO_PATH, path=list(res.path))

    def base_path(self, robot: str, start: np.ndarray, goal: np.ndarray, holding: tuple[str, str] | None = None,
                  avoid: Iterable[str] = (), busy: Sequence[tuple[CollisionShape, np.ndarray]] = ()) -> Answer:
        """An SE(2) path for a planar robot, free of fixed objects, of the other robots parked at their
        starts, of ``avoid`` (objects at their current poses) and of the volume ``busy`` (what robots moving
        at the same time sweep), searched on the robot's lattice
        (:mod:`mrgc.geometry.lattice`: deterministic, complete at the lattice's resolution) and checked
        state by state at the validator's resolution; hopeless queries are refused at once by an
        inscribed-disc grid test.  Answers are cached: the same query (same obstacles at the same poses)
        gets the same answer, and the search never asks twice."""
        movers = sorted({a for a in avoid if not holding or a != holding[0]})
        digest = hashlib.sha1()
        for part in (np.asarray(start, dtype=float), np.asarray(goal, dtype=float),
                     *(self.poses[a] for a in movers), *(t for _, t in busy)):
            digest.update(np.ascontiguousarray(part).tobytes())
        key = (robot, holding, tuple(movers), tuple(id(shape) for shape, _ in busy), digest.digest())
        if key not in self._paths:
            self._paths[key] = self._base_path(robot, start, goal, holding, movers, busy)
        return self._paths[key]

    def _base_path(self, robot: str, start: np.ndarray, goal: np.ndarray, holding: tuple[str, str] | None,
                   movers: list[str], busy: Sequence[tuple[CollisionShape, np.ndarray]]) -> Answer:
        others = [name for r, name in self.parked.items() if r != robot]
        against = ("fixed", *others, *movers)
        ignore = (holding[0],) if holding else ()
        if robot not in self._grids:
            self._grids[robot] = DiscGrid(self.planar(robot), self.scene, scene_bounds(self.scene, 0.5))
            self._lattices[robot] = LatticePlanner(scene_bounds(self.scene, 0.5))
        # the disc grid knows objects at their initial poses only: objects moved since are left to the lattice
        obstacles = frozenset([b.name for b in self.scene.fixed]
                              + [a for a in movers if np.array_equal(self.poses[a], self.scene.body(a).pose)])
        if not self._grids[robot].connected(np.asarray(start), np.asarray(goal), obstacles):
            return Answer(Status.NO_PATH)  # not even the footprint's inscribed disc gets through

        sweep = None
        if busy:
            sweep = CollisionWorld()
            for i, (shape, t) in enumerate(busy):
                sweep.add(f"busy{i}", shape, t, "busy")

        def valid(q: np.ndarray) -> bool:
            self.queries += 1
            probe = self.base_volume(robot, [q], holding)
            if sweep is not None and sweep.probe_collides(probe, against="busy"):
                return False
            return not self.world.probe_collides(probe, against=against, ignore=ignore)

        pr = self.planar(robot)
        parts: list[tuple[Shape, np.ndarray]] = [(pr.footprint, pr.lift)]
        if holding is not None:
            body = self.scene.body(holding[0])
            parts.append((body.shape, pr.carry_transform(body.shape, holding[1])))
        bodies = [(b.name, b.shape, b.pose) for b in self.scene.fixed]
        bodies += [((a, self.poses[a].tobytes()), self.scene.body(a).shape, self.poses[a]) for a in movers]
        for r in others:
            other = self.planar(r.lstrip("@"))
            bodies.append((r, other.footprint, se2(*other.start) @ other.lift))
        bodies += [(("busy", pts.tobytes()), pts, np.eye(4)) for pts in _swept_hulls(busy)]
        lattice = self._lattices[robot]
        occupied = lattice.occupancy(parts, bodies)
        res = lattice.plan(occupied, np.asarray(start, dtype=float), np.asarray(goal, dtype=float), valid,
                           PATH_RESOLUTION, PATH_RESOLUTION)
        return Answer(Status.OK if res.solved else Status.NO_PATH, path=list(res.path))


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


def _against(among: Iterable[str] | str) -> str | tuple[str, ...]:
    return among if isinstance(among, str) else tuple(among)
