"""Planar mobile manipulators (the box-moving domain): a footprint driven over the floor in SE(2).

The model (docs/geometry.md, "Planar robots"):

- **Base frame.**  A planar robot's base pose is ``(x, y, yaw)`` on the floor (z = 0, yaw about +z,
  radians in code, degrees in ``.mrg``); +x of the base frame is the robot's *front*.  The ``:base`` pose
  of a robot in a problem is its start (home) pose; its z is ignored.
- **Footprint.**  The robot's body is its kind's ``:footprint`` shape (usually a box), centred over the base
  origin and standing on the floor: its frame is the base frame lifted by the shape's half height plus
  :data:`~mrgc.geometry.conventions.PLANAR_LIFT` (so a footprint never touches a floor slab; touching counts
  as colliding).
- **Grasps.**  A planar robot grasps an object from one of its *side* faces: grasp ``side-x+`` means the
  robot stands on the object's +x side facing it (facing the object's -x direction), and so on for
  ``side-x-``, ``side-y+``, ``side-y-``.  ``top`` (and any grasp name this layer does not know) is not
  available to planar robots: it yields no fact.
- **Pick base pose.**  To pick object M with grasp g the robot stands facing M's g face with its front at
  :data:`~mrgc.geometry.planar_grasps.CLEARANCE` from that face: the base origin is at distance
  ``d = footprint half length (x) + CLEARANCE + M's half extent along the face normal`` from M's centre,
  along the face normal, yawed to face M.  The footprint at the pick pose therefore never touches M.
- **Carrying.**  After the pick, M rides at the kind's ``:carry`` pose relative to the base frame (the pose
  of M's own frame, i.e. its centre), turned so that the grasped face still faces the robot:
  ``carry @ Rz(face yaw of g)`` (``side-x-``: 0°, ``side-y-``: -90°, ``side-x+``: 180°, ``side-y+``: 90°).
  Without ``:carry`` the object rides on top of the footprint (centred, ``PLANAR_LIFT`` above it).  The
  change from "M on the floor in front of the robot" to "M at the carry pose" is instantaneous (not swept),
  but M at the carry pose must be free of fixed objects at the pick base pose, and must fit: above the floor
  and out of the robot's own footprint, 1 mm of depth allowed (:meth:`PlanarRobot.load_fits`; the
  validator's ``carry``).
- **Place base pose.**  Placing M at a pose P with grasp g is the pick geometry in reverse: the robot stands
  at the pick base pose it would use to pick M from P.  Candidate placements inside a region are a lattice
  (centre first) × four yaws (M's current yaw + 0°, 90°, 180°, 270°); a placement rests on the region's
  floor, ``PLANAR_LIFT`` above it.
- **Bounds.**  Base paths stay within the axis-aligned bounding box of every fixed object, movable object,
  region and robot start, grown by the footprint's circumradius plus 0.1 m.

Other robots are not obstacles here (they are at home between steps; simultaneous motions are the
grounding's business).  Nothing in this module plans: :mod:`mrgc.geometry.path_predicates` does.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Mapping

import numpy as np

from mrgc.geometry.collision import CollisionShape, CollisionWorld, ConvexHull, collision_shape
from mrgc.geometry.conventions import PLANAR_LIFT, lattice_offsets, se2, to_se2, yaw_of
from mrgc.geometry.lattice import box_corners
from mrgc.geometry.planar_grasps import carry_transform, grasp_base
from mrgc.geometry.robot import Held, Rest, Volume
from mrgc.geometry.scene import Body, RobotSpec, SceneSpec, half_extents, inside, outline
from mrgc.geometry.transforms import rot_z, translation
from mrgc.language.model import Box, Cylinder, GraspSpec, Shape

#: placements tried per region: a GRID × GRID lattice, centre first (each at four yaws)
PLACEMENT_GRID = 5
#: placement yaws tried, relative to the object's current yaw (degrees)
PLACEMENT_YAWS = (0.0, 90.0, 180.0, 270.0)


#: m: how deep a carried object may reach into the floor or its cart's footprint (the validator's contact
#: tolerance: touching is not overlapping)
LOAD_TOL = 1e-3


class PlanarRobot:
    """A planar mobile robot of a scene: footprint, grasp geometry and carried-object poses; the ``planar``
    kind of :class:`~mrgc.geometry.robot.Robot`.  Its configurations are base poses ``(x, y, yaw)``; it
    carries an object at its carry pose in its base frame; it picks and places from the base pose the grasp
    geometry gives, drives every motion as a path and waits parked at its start pose between them."""

    #: it picks and places from the one base pose the grasp gives (:attr:`Robot.approaches
    #: <mrgc.geometry.robot.Robot.approaches>`)
    approaches = False
    #: parked at its start pose between its drives (:attr:`Robot.parks <mrgc.geometry.robot.Robot.parks>`)
    parks = True

    def __init__(self, spec: RobotSpec) -> None:
        if spec.kind.footprint is None:
            raise ValueError(f"robot '{spec.name}' has a planar base but no footprint")
        self.spec = spec
        self.name = spec.name
        self.footprint: Shape = spec.kind.footprint
        self.half = half_extents(self.footprint)
        self.shape: CollisionShape = collision_shape(self.footprint)
        #: the footprint's frame relative to the base frame
        self.lift = translation(0.0, 0.0, float(self.half[2]) + PLANAR_LIFT)
        self.start = to_se2(spec.base)
        self._loads: dict[tuple[Shape, str], bool] = {}  # load_fits' answers

    @property
    def home(self) -> np.ndarray:
        """Its start pose ``(x, y, yaw)``: where every action drives from and back to."""
        return self.start

    @cached_property
    def radius(self) -> float:
        """Circumradius of the footprint in the floor plane (m)."""
        return float(np.hypot(self.half[0], self.half[1]))

    # ------------------------------------------------------------------------------------ geometry
    def body_transform(self, q: np.ndarray) -> np.ndarray:
        """World transform of the footprint at base pose ``q`` = (x, y, yaw)."""
        body: np.ndarray = se2(q[0], q[1], q[2]) @ self.lift
        return body

    def carry_transform(self, shape: Shape, grasp: str) -> np.ndarray:
        """Pose of a carried object (of ``shape``, held with ``grasp``) relative to the base frame."""
        return carry_transform(self.spec.kind, shape, grasp)

    def load_fits(self, shape: Shape, grasp: str) -> bool:
        """Whether an object of ``shape`` held with ``grasp`` can ride at its carry pose: above the floor the
        robot drives on (its lowest point no lower than 1 mm below z = 0) and clear of the robot's own
        footprint (:func:`~mrgc.geometry.collision.posed_collide`).  A box taller than twice the ``:carry``
        height would drag through the floor, a deep one ride inside the cart; the validator rejects both
        (``carry``), so such a pick is no fact.  As there, touching is not overlapping: 1 mm of depth is
        allowed (a 0.4 m deep box at ``:carry (0.45 0 0.2 0)`` touches the front of a 0.5 m footprint)."""
        key = (shape, grasp)
        if key not in self._loads:
            carried = self.carry_transform(shape, grasp)
            low = float((outline(shape) @ carried[:3, :3].T + carried[:3, 3])[:, 2].min())
            world = CollisionWorld()
            world.add("footprint", self.shape, self.lift)
            world.add("load", shape, carried)
            self._loads[key] = low >= -LOAD_TOL and world.distance("footprint", "load") >= -LOAD_TOL
        return self._loads[key]

    def probe(
        self, q: np.ndarray, carried: tuple[CollisionShape, np.ndarray] | None = None, margin: float = 0.0
    ) -> list[tuple[CollisionShape, np.ndarray]]:
        """Collision probe of the robot at ``q`` (and of the object it carries, given its carry transform);
        with a ``margin``, each part grown horizontally by it (:func:`grown`)."""
        base = se2(q[0], q[1], q[2])
        out = [(grown(self.shape, margin), base @ self.lift)]
        if carried is not None:
            out.append((grown(carried[0], margin), base @ carried[1]))
        return out

    def reach(self, carried: tuple[CollisionShape, np.ndarray] | None = None) -> float:
        """How far (m) from the base origin, in the floor plane, the robot (and what it carries) extends: the
        farthest corner of each part's bounding box."""
        parts = [(self.shape, self.lift)] + ([carried] if carried is not None else [])
        return max(_reach(shape, t) for shape, t in parts)

    def grasp_base(self, pose: np.ndarray, shape: Shape, grasp: str) -> np.ndarray:
        """The base pose ``(x, y, yaw)`` from which the robot picks (or places) an object at ``pose``."""
        return grasp_base(self.spec.kind, pose, shape, grasp)

    # ------------------------------------------------------------------ the Robot protocol
    def hold(self, shape: Shape, grasp: str, grasps: Mapping[str, GraspSpec]) -> tuple[float | None, np.ndarray]:
        """No fingers, and the carried object's pose in the base frame (:meth:`carry_transform`)."""
        return None, self.carry_transform(shape, grasp)

    def volumes(self, configs: np.ndarray, held: Held | None = None, opening: float | None = None) -> list[Volume]:
        """The footprint (and the carried object) at each base pose of ``configs`` (:meth:`probe`)."""
        return [self.probe(q, held) for q in np.atleast_2d(configs)]

    def rest(self) -> Rest:
        """The footprint at its start pose (nothing of a cart is bolted in place)."""
        return Rest(self.probe(self.start)[:1])

    def in_reach(self, point: np.ndarray, margin: float = 0.0) -> bool:
        """Always: a cart drives to what it handles (whether it gets there is its path's question)."""
        return True

    def comfort(self, tools: np.ndarray, share: float) -> np.ndarray:
        """0 for each pose of ``tools`` (..., 4, 4): no reach bound ranks a cart's placements."""
        return np.zeros(np.shape(tools)[:-2])


def _reach(shape: CollisionShape, t: np.ndarray) -> float:
    xy = box_corners(shape) @ t[:2, :3].T + t[:2, 3]
    return float(np.hypot(xy[:, 0], xy[:, 1]).max())


_GROWN: dict[tuple[object, ...], CollisionShape] = {}


def grown(shape: CollisionShape, margin: float) -> CollisionShape:
    """``shape`` grown horizontally by ``margin`` (m) in its own frame: a box or a vertical cylinder by its
    sides, anything else to its bounding box so grown.  A part of a planar robot is only ever turned about
    the vertical, so the grown shape holds every point within ``margin`` of the shape in the floor plane."""
    if margin <= 0.0:
        return shape
    geometry = shape.geometry
    key: tuple[object, ...]
    if isinstance(geometry, (Box, Cylinder)):
        key = (geometry, margin)
    else:
        key = (tuple(np.round(shape.center, 9)), tuple(np.round(shape.half, 9)), margin)
    out = _GROWN.get(key)
    if out is None:
        if isinstance(geometry, Box):
            out = collision_shape(Box(geometry.sx + 2 * margin, geometry.sy + 2 * margin, geometry.sz))
        elif isinstance(geometry, Cylinder):
            out = collision_shape(Cylinder(geometry.radius + margin, geometry.height))
        else:
            out = collision_shape(ConvexHull(box_corners(shape, (margin, margin, 0.0))))
        _GROWN[key] = out
    return out


def scene_bounds(scene: SceneSpec, margin: float) -> tuple[float, float, float, float]:
    """``(xmin, xmax, ymin, ymax)`` of everything in the scene (and the robots' starts), grown by ``margin``."""
    pts = [b.pose[:3, 3] for b in (*scene.fixed, *scene.movable, *scene.regions)]
    for b in (*scene.fixed, *scene.movable, *scene.regions):
        pts.extend(outline(b.shape) @ b.pose[:3, :3].T + b.pose[:3, 3])
    pts.extend(r.base[:3, 3] for r in scene.robots)
    xy = np.array(pts)[:, :2]
    lo, hi = xy.min(axis=0) - margin, xy.max(axis=0) + margin
    return float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])


def placements(obj: Body, region: Body, grid: int = PLACEMENT_GRID) -> list[np.ndarray]:
    """Candidate poses of ``obj`` resting inside box ``region``: a lattice (centre first) × four yaws.

    The object's yaw is its current yaw plus each of :data:`PLACEMENT_YAWS`, then (after every one of those,
    so they come first as before), when that is not a multiple of 90° in the region's frame, the region's own
    yaw plus each of them (a box turned 45° to a
    tight region fits it only aligned with it: "no robot can reach goal region" before); the lattice spans
    the room the object's (rotated) bounding box leaves in the region; every returned pose passes
    :func:`inside`.
    """
    if not isinstance(region.shape, Box):
        return []
    h_o, h_r = half_extents(obj.shape), half_extents(region.shape)
    if h_o[2] * 2 + PLANAR_LIFT > h_r[2] * 2:
        return []
    obj_yaw, reg_yaw = yaw_of(obj.pose), yaw_of(region.pose)
    groups = [[obj_yaw - reg_yaw + math.radians(d) for d in PLACEMENT_YAWS]]  # the object's yaws, region frame
    if abs(math.remainder(obj_yaw - reg_yaw, math.pi / 2)) > 1e-6:
        groups.append([math.radians(d) for d in PLACEMENT_YAWS])  # aligned with the region, after all of those
    out = []
    for turns, (a, b) in ((t, ab) for t in groups for ab in lattice_offsets(grid)):
        for rel in turns:
            c, s = abs(math.cos(rel)), abs(math.sin(rel))
            ex, ey = c * h_o[0] + s * h_o[1], s * h_o[0] + c * h_o[1]  # its bounding box in the region frame
            room = (h_r[0] - ex, h_r[1] - ey)
            if room[0] < 0 or room[1] < 0:
                continue
            local = translation(a * room[0] * 0.95, b * room[1] * 0.95, -h_r[2] + h_o[2] + PLANAR_LIFT) @ rot_z(rel)
            pose = region.pose @ local
            if inside(region, obj.shape, pose):
                out.append(pose)
    return out


class DiscGrid:
    """A necessary condition for base paths, on a grid: can the footprint's *inscribed disc* get through?

    Every valid base pose keeps the disc (radius ``r``, the footprint's inscribed radius, extruded over the
    footprint's height) clear of every obstacle, so a base path exists only if the disc's centre can move
    from start to goal among the obstacles grown by ``r``.  Cells of side ``cell`` are free when their
    centre has clearance ``≥ r - cell·√2/2 - slack``, ``slack`` being half the path's checking resolution
    (the planner checks states, not the segments between them); free cells are 8-connected.  So a start
    and goal in different components of the free cells have no path the planner could return, and the
    planner need not be run.  Obstacles counted are the vertical prisms (boxes turned about z only,
    cylinders along z) whose height range overlaps the footprint's; other shapes are left out, which
    keeps the test conservative.  Without a box or vertical-cylinder footprint the grid says "maybe" always.
    """

    def __init__(
        self,
        robot: PlanarRobot,
        scene: SceneSpec,
        bounds: tuple[float, float, float, float],
        cell: float = 0.05,
        slack: float = 0.025,
    ) -> None:
        self.bounds = bounds
        self.cell = cell
        xmin, xmax, ymin, ymax = bounds
        self.nx = max(1, int(math.ceil((xmax - xmin) / cell)))
        self.ny = max(1, int(math.ceil((ymax - ymin) / cell)))
        xs = xmin + (np.arange(self.nx) + 0.5) * cell
        ys = ymin + (np.arange(self.ny) + 0.5) * cell
        self.centres = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1)  # (nx, ny, 2)
        fp = robot.footprint
        self.enabled = isinstance(fp, (Box, Cylinder))
        self.threshold = float(min(robot.half[0], robot.half[1])) - cell * math.sqrt(2) / 2 - slack
        self.z_range = (PLANAR_LIFT, PLANAR_LIFT + 2 * float(robot.half[2]))
        self.bodies = {b.name: b for b in (*scene.fixed, *scene.movable)}
        self._masks: dict[str, np.ndarray | None] = {}
        self._reached: dict[frozenset[str], list[np.ndarray]] = {}

    def _mask(self, name: str) -> np.ndarray | None:
        """Cells whose centre is too close to object ``name`` (None: the object is not counted)."""
        if name in self._masks:
            return self._masks[name]
        body = self.bodies[name]
        t, shape, mask = body.pose, body.shape, None
        h = half_extents(shape)
        lo, hi = t[2, 3] - h[2], t[2, 3] + h[2]
        vertical = abs(t[2, 2] - 1.0) < 1e-9
        overlaps = lo < self.z_range[1] - 1e-9 and hi > self.z_range[0] + 1e-9
        if vertical and overlaps and isinstance(shape, (Box, Cylinder)):
            d = self.centres - t[:2, 3]
            if isinstance(shape, Box):
                local = d @ t[:2, :2]  # into the box frame (rows of R^T)
                out = np.maximum(np.abs(local) - h[:2], 0.0)
                dist = np.hypot(out[..., 0], out[..., 1])
            else:
                dist = np.maximum(np.hypot(d[..., 0], d[..., 1]) - shape.radius, 0.0)
            mask = dist < self.threshold
        self._masks[name] = mask
        return mask

    def _cell(self, q: np.ndarray) -> tuple[int, int]:
        i = int((q[0] - self.bounds[0]) / self.cell)
        j = int((q[1] - self.bounds[2]) / self.cell)
        return min(max(i, 0), self.nx - 1), min(max(j, 0), self.ny - 1)

    def connected(self, start: np.ndarray, goal: np.ndarray, obstacles: frozenset[str]) -> bool:
        """False only if no base path from ``start`` to ``goal`` avoids ``obstacles`` (object names)."""
        if not self.enabled or self.threshold <= 0:
            return True
        s, g = self._cell(start), self._cell(goal)
        for reached in self._reached.get(obstacles, ()):
            if reached[s]:
                return bool(reached[g])
        blocked = np.zeros((self.nx, self.ny), dtype=bool)
        for name in obstacles:
            m = self._mask(name)
            if m is not None:
                blocked |= m
        if blocked[s]:
            return False
        reached = self._flood(~blocked, s)
        self._reached.setdefault(obstacles, []).append(reached)
        return bool(reached[g])

    @staticmethod
    def _flood(free: np.ndarray, start: tuple[int, int]) -> np.ndarray:
        """The 8-connected component of ``free`` holding ``start``."""
        reached = np.zeros_like(free)
        reached[start] = True
        while True:
            grown = reached.copy()
            grown[1:, :] |= reached[:-1, :]
            grown[:-1, :] |= reached[1:, :]
            grown[:, 1:] |= grown[:, :-1].copy()
            grown[:, :-1] |= grown[:, 1:].copy()
            grown &= free
            if np.array_equal(grown, reached):
                return reached
            reached = grown
