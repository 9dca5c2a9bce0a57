"""The scene of a geometric problem as plain, picklable data: what is where, in world coordinates.

A :class:`SceneSpec` is built once per checked geometric :class:`~mrgc.language.model.Problem`; worker
processes rebuild their own collision worlds and robot models from it (one pybullet client per process).
"""

from __future__ import annotations

import os
import weakref
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from mrgc.errors import Diagnostic, InputError
from mrgc.geometry.meshes import checked_vertices
from mrgc.geometry.transforms import from_pose
from mrgc.language.model import Box, Cylinder, GraspSpec, Mesh, Problem, RobotKind, Shape, Sphere


@dataclass(frozen=True)
class Body:
    """A rigid body or region: its shape and its pose (4×4, world frame)."""

    name: str
    shape: Shape
    pose: np.ndarray = field(compare=False)


@dataclass(frozen=True)
class RobotSpec:
    """A robot: its kind, its base pose (4×4, world frame) and the folder its kind's URDF is relative to."""

    name: str
    kind: RobotKind
    base: np.ndarray = field(compare=False)
    base_dir: str = ""


@dataclass(frozen=True)
class SceneSpec:
    """Everything geometric about a problem, in the order the problem declares it."""

    problem: str
    robots: tuple[RobotSpec, ...]
    fixed: tuple[Body, ...]
    movable: tuple[Body, ...]
    regions: tuple[Body, ...]
    handover_points: dict[str, np.ndarray]
    grasps: dict[str, tuple[str, ...]]
    handover_of: dict[str, tuple[str, ...]]
    goal: dict[str, str]
    grasp_specs: dict[str, GraspSpec] = field(default_factory=dict)  # grasp name -> its geometry

    def grasp(self, name: str) -> GraspSpec:
        """The geometry of grasp ``name`` (KeyError for a grasp with none: planar-only names)."""
        return self.grasp_specs[name]

    def body(self, name: str) -> Body:
        """The movable object, fixed object or region called ``name``."""
        for b in (*self.movable, *self.fixed, *self.regions):
            if b.name == name:
                return b
        raise KeyError(name)

    def region(self, name: str) -> Body:
        """The region called ``name``, or, for a fixed object, its :func:`surface` (where a relay may set an
        object down on it: ``enable-relay M table ...``)."""
        for b in self.regions:
            if b.name == name:
                return b
        for b in self.fixed:
            if b.name == name:
                return surface(b)
        raise KeyError(name)

    def robot(self, name: str) -> RobotSpec:
        """The robot called ``name``."""
        return next(r for r in self.robots if r.name == name)


#: the scene of each problem object alive (keyed by identity; an entry goes when its problem does)
_SCENES: dict[int, SceneSpec] = {}


def scene_from_problem(problem: Problem) -> SceneSpec:
    """The scene of a geometric problem (InputError E402 for a symbolic one).  A fixed-base robot kind
    without ``:tcp`` gets the one derived from its URDF (:mod:`mrgc.geometry.tcp`), so every user of the
    scene (phase 1, grounding, the validator, the pictures) grasps at the same point.

    Built once per problem object: the layout checks, phase 1, the planning method, the referee and the
    summary of one ``mrgc plan`` share it (the problem and the scene are immutable: the dataclasses are
    frozen and every pose array is read-only)."""
    hit = _SCENES.get(id(problem))
    if hit is not None:
        return hit
    scene = _build(problem)
    _SCENES[id(problem)] = scene
    weakref.finalize(problem, _SCENES.pop, id(problem), None)
    return scene


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def _build(problem: Problem) -> SceneSpec:
    if problem.symbolic:
        raise InputError(
            [Diagnostic("E402", f"problem '{problem.name}' is symbolic: it has no geometry", problem.span)]
        )
    for shape in _mesh_shapes(problem):  # bad mesh files fail here, located, before any worker starts
        mesh_vertices(shape)
    from mrgc.geometry.tcp import with_tcp

    kinds = {k.name: with_tcp(k) for k in problem.domain.robot_kinds}  # a :tcp derived when not given
    robots = []
    for r in problem.robots:
        assert r.kind is not None and r.base is not None  # guaranteed by the checks of a geometric problem
        kind = kinds[r.kind]
        base = _frozen(from_pose(r.base))
        robots.append(RobotSpec(r.name, kind, base, os.path.dirname(os.path.abspath(kind.source))))
    return SceneSpec(
        problem=problem.name,
        robots=tuple(robots),
        fixed=tuple(Body(o.name, o.shape, _frozen(from_pose(o.pose))) for o in problem.fixed if o.shape and o.pose),
        movable=tuple(Body(o.name, o.shape, _frozen(from_pose(o.pose))) for o in problem.movable if o.shape and o.pose),
        regions=tuple(Body(o.name, o.shape, _frozen(from_pose(o.pose))) for o in problem.regions if o.shape and o.pose),
        handover_points={h.name: _frozen(np.array(h.position)) for h in problem.handover_points if h.position},
        grasps={m.name: problem.grasps_of(m.name) for m in problem.movable},
        handover_of={m.name: m.handover_points for m in problem.movable},
        goal=problem.goal_regions,
        grasp_specs=problem.grasp_specs,
    )


#: how high the region standing on a fixed object's top reaches: anything a robot sets down there fits
SURFACE_HEIGHT = 1.0


def surface(body: Body) -> Body:
    """The top of a fixed object as a region (named as the object): a box of its footprint and
    SURFACE_HEIGHT standing on its top face, for a box (the language's poses turn bodies about z only); a
    body of no volume (nothing lies inside it) for any other fixed object."""
    if not isinstance(body.shape, Box):
        return Body(body.name, Box(0.0, 0.0, 0.0), body.pose)
    up = (body.shape.sz + SURFACE_HEIGHT) / 2
    pose = body.pose.copy()
    pose[:3, 3] = body.pose[:3, 3] + np.array([0.0, 0.0, up])
    return Body(body.name, Box(body.shape.sx, body.shape.sy, SURFACE_HEIGHT), pose)


#: m: how far a region's floor may lie above what holds it up (the ground, a fixed object's top) and below
#: it (then the object, set down 6 mm above the floor, would hit that top: its collision check refuses it):
#: an object set down ``ARM_PLACE_LIFT`` above the floor must stand within the validator's 10 mm support band
FLOOR_ABOVE = 3e-3
FLOOR_BELOW = 1e-2
#: m: how far inside a fixed object's top an object's centre stays when the region's floor is not on the
#: ground (the validator's largest required margin)
SUPPORT_MARGIN = 5e-3
#: m: a fixed object's top this close to z = 0 is a table's top, not the ground
GROUND_TOL = 1e-3


def ground_height(fixed: Sequence[Body]) -> float:
    """The ground: z = 0, unless a ``fixed`` object's top lies there (a table slab whose top is z = 0: then
    the ground is the lowest bottom of such slabs).  A wall or post reaching below z = 0 does not move it."""
    slabs = []
    for b in fixed:
        z = (outline(b.shape) @ b.pose[:3, :3].T + b.pose[:3, 3])[:, 2]
        if abs(float(z.max())) <= GROUND_TOL:
            slabs.append(float(z.min()))
    return min(slabs) if slabs else 0.0


def floor_support(fixed: Sequence[Body], region: Body) -> Callable[[np.ndarray], bool] | None:
    """What holds up an object set down on ``region``'s floor, as a test of the object's pose (its centre
    over the top of a ``fixed`` object that lies at the floor, :data:`FLOOR_ABOVE` below it to
    :data:`FLOOR_BELOW` above it, :data:`SUPPORT_MARGIN` inside that top), or None when the floor lies on the
    ground (:func:`ground_height`, within :data:`GROUND_TOL`) and holds up anything.  A region drawn over a
    table is held up by the table, where the table is; one drawn in the air by nothing (the validator rejects
    such placements as ``floating``, or ``unstable`` over a table's edge).  A box's top is its rectangle, a
    vertical cylinder's its disc, a mesh's the convex hull of its vertices within 1 mm of its highest one; a
    sphere or a lying cylinder holds nothing up."""
    floor = float((outline(region.shape) @ region.pose[:3, :3].T + region.pose[:3, 3])[:, 2].min())
    if abs(floor - ground_height(fixed)) <= GROUND_TOL:
        return None
    tests = [t for t in (_top_test(b, floor) for b in fixed) if t is not None]

    def held(pose: np.ndarray) -> bool:
        return any(test(pose[:3, 3]) for test in tests)

    return held


def _top_test(body: Body, floor: float) -> Callable[[np.ndarray], bool] | None:
    """Whether a point (x, y) lies :data:`SUPPORT_MARGIN` inside ``body``'s top, when that top lies at
    ``floor`` (:func:`floor_support`); None when it does not (or the top is too small)."""
    pts = outline(body.shape) @ body.pose[:3, :3].T + body.pose[:3, 3]
    top = float(pts[:, 2].max())
    if not -FLOOR_BELOW <= floor - top <= FLOOR_ABOVE:
        return None
    inv = np.linalg.inv(body.pose)
    if isinstance(body.shape, Box):
        half = np.array([body.shape.sx, body.shape.sy]) / 2 - SUPPORT_MARGIN
        if np.any(half <= 0):
            return None
        return lambda p: bool(np.all(np.abs((inv[:3, :3] @ p + inv[:3, 3])[:2]) <= half))
    if isinstance(body.shape, Cylinder) and abs(float(body.pose[2, 2])) > 1 - 1e-9:  # standing on a disc
        r = body.shape.radius - SUPPORT_MARGIN
        return None if r <= 0 else lambda p: bool(np.hypot(*(inv[:3, :3] @ p + inv[:3, 3])[:2]) <= r)
    if not isinstance(body.shape, Mesh):
        return None  # a sphere's top is a point, a lying cylinder's a line: nothing stands on them
    ring = pts[pts[:, 2] >= top - 1e-3][:, :2]  # a mesh's top, as the validator builds a face
    if len(ring) < 3:
        return None
    hull = hull2d(ring)
    if len(hull) < 3:
        return None
    edges = np.roll(hull, -1, axis=0) - hull
    normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)  # outward for a counter-clockwise hull
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    offsets = np.einsum("ij,ij->i", normals, hull)
    return lambda p: bool(np.all(normals @ p[:2] - offsets <= -SUPPORT_MARGIN))


def hull2d(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points, counter-clockwise, no repeated or collinear vertices."""
    pts = sorted({(round(float(x), 12), round(float(y), 12)) for x, y in points})
    if len(pts) <= 2:
        return np.array(pts, dtype=float)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    upper: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _mesh_shapes(problem: Problem) -> list[Mesh]:
    shapes = [o.shape for o in problem.bodies]
    shapes += [k.footprint for k in problem.domain.robot_kinds]
    return [s for s in shapes if isinstance(s, Mesh)]


def half_extents(shape: Shape) -> np.ndarray:
    """Half sizes of the shape's bounding box in its own frame."""
    if isinstance(shape, Box):
        return np.array([shape.sx, shape.sy, shape.sz]) / 2
    if isinstance(shape, Cylinder):
        return np.array([shape.radius, shape.radius, shape.height / 2])
    if isinstance(shape, Sphere):
        return np.full(3, shape.radius)
    return mesh_half_extents(shape)


def mesh_half_extents(mesh: Mesh) -> np.ndarray:
    """Half the extents of a mesh's axis-aligned bounding box about its origin."""
    extents: np.ndarray = np.abs(mesh_vertices(mesh)).max(axis=0)
    return extents


def mesh_vertices(mesh: Mesh) -> np.ndarray:
    """The vertices of a mesh shape's file (OBJ or STL, checked by :mod:`mrgc.geometry.meshes`), scaled."""
    pts = checked_vertices(mesh.path, mesh.scale)
    return pts if len(pts) else np.zeros((1, 3))


def outline(shape: Shape) -> np.ndarray:
    """Points whose convex hull contains the shape (its bounding-box corners; a mesh's own vertices)."""
    if isinstance(shape, Mesh):
        return mesh_vertices(shape)
    h = half_extents(shape)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    corners: np.ndarray = signs * h
    return corners


def inside(region: Body, shape: Shape, pose: np.ndarray, tol: float = 1e-6) -> bool:
    """``in-region``: the object (of ``shape`` at ``pose``) lies entirely inside the region's box.

    Cylinders and spheres are tested by their bounding boxes, which makes the test conservative (an
    object reported inside is inside).  A region must be a box.
    """
    return inside_test(region, shape, tol)(pose)


def inside_test(region: Body, shape: Shape, tol: float = 1e-6) -> Callable[[np.ndarray], bool]:
    """:func:`inside` of ``shape`` in ``region`` as a function of the pose, what does not depend on it (the
    shape's outline, the region's inverse pose) computed once: the same answers, for a caller that asks
    many poses (the placements of an object in a region)."""
    if not isinstance(region.shape, Box):
        return lambda pose: False
    pts = outline(shape)
    inv = np.linalg.inv(region.pose)
    half = half_extents(region.shape) + tol

    def test(pose: np.ndarray) -> bool:
        world = pts @ pose[:3, :3].T + pose[:3, 3]
        local = world @ inv[:3, :3].T + inv[:3, 3]
        return bool(np.all(np.abs(local) <= half))

    return test
