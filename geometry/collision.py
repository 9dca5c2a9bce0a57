"""Collision checking on coal: a world of named rigid shapes, and fast yes/no and which-objects queries.

A :class:`CollisionWorld` holds named objects, each a shape (a :class:`~mrgc.language.model.Box`,
``Cylinder``, ``Sphere``, a triangle ``Mesh`` file, or a :class:`ConvexHull` of points) at a 4×4 world
transform, tagged with a group (``"fixed"``, ``"movable"``, ``"robot:r1"`` ...).  Queries name what they
test *against* by groups or object names, and what to *ignore* (also groups or names).

*Probes* test shapes that are not in the world (a robot's link hulls at one configuration, an object at a
candidate placement) without adding them; a *sweep* is many probes (configurations along a path) and
answers the union of the objects they hit, which is what ``occludes-pick`` / ``occludes-goal-place`` ask.
Build a :class:`CollisionShape` handle once per geometry (:func:`collision_shape`) and reuse it: a probe
then only moves prebuilt coal objects.

Semantics: two shapes collide when their distance is at most ``tolerance`` (default :data:`TOLERANCE`,
2 µm), so shapes that merely *touch* collide; a "free" answer means a distance above 1 µm, a "collides"
answer a distance of at most 2 µm (the coal traps below say why these bounds and not zero).  An object
resting on a table collides with the table: leave the supporting surface out of the query (``ignore=``),
or lift placements by a millimetre.

How the queries run: each selection of world objects (``against`` minus ``ignore`` minus the query's own
objects) gets a coal ``DynamicAABBTreeCollisionManager``, built on first use, cached, and refit when
objects have moved.  Each probe shape is moved and collided against it with ``CollisionCallBackDefault``:
stopping at the first contact for yes/no, collecting every contact for which-objects (a contact's
geometry id names the world object: each world object owns a clone of its geometry).  coal's
``CollisionCallBackCollect`` is no use here: it collects *AABB-overlap* pairs, not collisions, and its
pair list cannot be read from Python in coal 3.0.3.  A manager re-initialises the callback (clearing its
result) at the start of every ``collide`` call, so results are read after each call.  A large :class:`Posed`
set asked about again and again (another arm's sweep while an RRT searches a carry) gets such a tree of its
own after a few queries (:data:`TREE_AFTER`; its boxes grown by the tolerance, the same answers).

coal traps handled here (coal 3.0.3):

- *A yes/no collide is GJK's distance compared with the security margin, and GJK answers "in collision"
  with a positive distance.*  With ``enable_contact=False`` coal runs GJK without EPA and reports a
  collision iff the distance it returns is at most ``security_margin``.  When GJK finds the origin within
  its tolerance (``gjk_tolerance``, default and minimum 1e-6) of its simplex it stops with status
  ``Collision`` but returns the simplex's distance to the origin, a number in (0, 1e-6), even for shapes
  that overlap by centimetres (coal's narrowphase.h, ``GJKCollisionExtractWitnessPointsAndNormal``).  A
  margin below 1e-6 then turns that collision into "free".  Measured with the old margin of 1e-9: 6 of
  408 handover configurations of two facing Pandas (both hands at one object, yaws on a 5° grid) were
  "free" although the fingers overlap by 4.4 mm (coal's signed distance and pybullet agree), and 24 of
  3,672 gripper link pairs, overlapping by up to 62 mm, were "free"; of 6,000 random near-contact box
  and hull pairs, 1 was.  When GJK instead converges with distance ``d >= 1e-6`` (status ``NoCollision``)
  its stopping rule guarantees a true distance of at least ``d - 1e-6 (1 + d)``.  So with a margin of
  :data:`TOLERANCE` = 2 × 1e-6, "free" (``d > 2e-6``) proves a distance above 1e-6 and "collides" a
  distance of at most 2e-6: sound both ways whenever GJK converges (it stops after 128 iterations
  otherwise, which coal logs as a warning), at no cost (the margin is only compared after GJK has run).
  tests/test_collision.py checks it against coal's signed distance and pybullet on random near-contact
  box, hull and Panda gripper poses (0 misses outside 0.1 mm of contact).
- With ``security_margin=0`` coal also misses genuinely overlapping box/box and box/hull pairs whose faces
  line up (the same GJK stop, on grid-snapped boxes); the same margin fixes it.
- A ``CollisionResult`` passed to ``coal.collide`` must be cleared before reuse, or coal answers from the
  old contacts without looking.  qhull needs the ``Qt`` option to keep triangles.  ``computeAABB``
  follows every move.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Sequence, Union

import numpy as np

from mrgc.errors import Diagnostic, InputError
from mrgc.language.model import Box, Cylinder, Mesh, Sphere

if TYPE_CHECKING:
    from mrgc.geometry.scene import SceneSpec

#: coal's GJK tolerance (its default and its minimum): GJK's distances are exact to this (metres)
GJK_TOLERANCE = 1e-6
#: default distance at or below which two shapes count as colliding (metres): coal's security margin.  It
#: must be at least GJK_TOLERANCE, or GJK's "collision" verdicts come back as "free" (module docstring)
TOLERANCE = 2 * GJK_TOLERANCE
#: thickness given to flat or degenerate point clouds before taking their hull (metres)
DEGENERATE_THICKNESS = 1e-6


@dataclass(frozen=True, eq=False)
class ConvexHull:
    """The convex hull of ``vertices`` (a (K, 3) array of points in the object's own frame).

    A cloud with (almost) no volume (fewer than 4 points, or on a plane or a line) is thickened along its
    flat directions first to :data:`DEGENERATE_THICKNESS` (or 1e-5 of its size, if more), so its hull is a
    thin slab or needle.
    """

    vertices: np.ndarray

    def __repr__(self) -> str:
        return f"ConvexHull(<{len(np.asarray(self.vertices).reshape(-1, 3))} points>)"

    @classmethod
    def of_mesh(cls, mesh: Mesh) -> "ConvexHull":
        """The hull of a mesh file's (scaled) vertices."""
        geom = _load_mesh(mesh)
        return cls(np.array(geom.vertices(), dtype=float))


Geometry = Union[Box, Cylinder, Sphere, Mesh, ConvexHull]
Against = Union[str, Iterable[str], None]


class CollisionShape:
    """A geometry built for coal once: its coal geometry, its local AABB, and the prebuilt narrowphase calls
    against the other shapes it has been tested with.

    Make one with :func:`collision_shape`; hand it to probes and worlds as often as needed: it is shared,
    never copied (a world's objects and a probe's pieces only refer to it).
    """

    __slots__ = ("geometry", "coal_geometry", "coal_object", "center", "half", "box", "_calls")

    def __init__(self, geometry: Geometry, coal_geometry: Any) -> None:
        self.geometry = geometry
        self.coal_geometry = coal_geometry
        #: a coal object of the geometry that small probes move (:meth:`CollisionWorld.probe_collides`)
        self.coal_object = _kit().coal.CollisionObject(coal_geometry, _kit().coal.Transform3s())
        coal_geometry.computeLocalAABB()
        box = coal_geometry.aabb_local
        lo, hi = np.array(box.min_, dtype=float), np.array(box.max_, dtype=float)
        #: centre and half extents of the axis-aligned bounding box in the shape's own frame
        self.center: np.ndarray = (lo + hi) / 2
        self.half: np.ndarray = (hi - lo) / 2
        #: both, stacked (2, 3)
        self.box: np.ndarray = np.stack([self.center, self.half])
        self._calls: dict[int, tuple[Any, CollisionShape]] = {}

    def __repr__(self) -> str:
        return f"CollisionShape({self.geometry!r})"

    def call(self, other: "CollisionShape") -> Any:
        """coal's ``ComputeCollision`` of this shape (first) and ``other``, made once per pair (it holds
        ``other``, so the key, ``other``'s id, is never reused while it is cached)."""
        found = self._calls.get(id(other))
        if found is None:
            found = self._calls[id(other)] = (
                _kit().coal.ComputeCollision(self.coal_geometry, other.coal_geometry),
                other,
            )
        return found[0]


ShapeLike = Union[CollisionShape, Geometry]
Probe = Sequence[tuple[ShapeLike, np.ndarray]]

_SHAPES: dict[Any, CollisionShape] = {}


def collision_shape(geometry: ShapeLike) -> CollisionShape:
    """The coal shape of a geometry.  Primitives and meshes are cached by value; a hull is built each call."""
    if isinstance(geometry, CollisionShape):
        return geometry
    if isinstance(geometry, ConvexHull):
        return CollisionShape(geometry, _hull(geometry.vertices))
    cached = _SHAPES.get(geometry)
    if cached is None:
        cached = _SHAPES[geometry] = CollisionShape(geometry, _build(geometry))
    return cached


def _build(geometry: Geometry) -> Any:
    import coal

    if isinstance(geometry, Box):
        return coal.Box(float(geometry.sx), float(geometry.sy), float(geometry.sz))
    if isinstance(geometry, Cylinder):
        return coal.Cylinder(float(geometry.radius), float(geometry.height))
    if isinstance(geometry, Sphere):
        return coal.Sphere(float(geometry.radius))
    if isinstance(geometry, Mesh):
        return _load_mesh(geometry)
    raise TypeError(f"not a collision geometry: {geometry!r}")


def _load_mesh(mesh: Mesh) -> Any:
    import coal

    try:
        return coal.MeshLoader().load(mesh.path, np.full(3, float(mesh.scale)))
    except ValueError as exc:  # coal reports a missing or unreadable file as ValueError
        raise InputError([Diagnostic("E258", f"mesh file '{mesh.path}' cannot be loaded")]) from exc


def _hull(vertices: np.ndarray) -> Any:
    import coal

    pts = np.asarray(vertices, dtype=float).reshape(-1, 3)
    if len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise ValueError("a convex hull needs at least one point, all finite")
    pts = _thicken(pts)
    cloud = coal.StdVec_Vec3s()
    for p in pts:
        cloud.append(p)
    return coal.ConvexBase.convexHull(cloud, True, "Qt")  # keep triangles: a coal.Convex with faces


def _thicken(pts: np.ndarray) -> np.ndarray:
    """The cloud, with offset copies along its principal axes that are too thin for qhull.

    coal's qhull call *crashes the process* (segfault, coal 3.0.3) on clouds flatter than about 3e-8 of
    their coordinate size, and refuses fewer than 4 points; every principal extent is made at least
    ``max(DEGENERATE_THICKNESS, 1e-5 × size)`` here.
    """
    centred = pts - pts.mean(axis=0)
    axes = np.linalg.eigh(centred.T @ centred)[1].T  # rows: principal axes
    proj = centred @ axes.T
    extent = proj.max(axis=0) - proj.min(axis=0)
    least = max(DEGENERATE_THICKNESS, 1e-5 * max(float(np.abs(pts).max()), float(extent.max())))
    out = [pts]
    for axis, e in zip(axes, extent):
        if e < least:
            out += [pts + (least / 2) * axis, pts - (least / 2) * axis]
    return np.concatenate(out) if len(out) > 1 else pts


def _merged(shapes: list[CollisionShape], index: dict[int, int], more: Sequence[CollisionShape]) -> np.ndarray:
    """Where each of ``more`` is in ``shapes`` (the distinct shapes so far; ``index``: their ids -> position),
    the ones not there yet appended in order: the index of each of ``more`` (``shapes`` and ``index`` grow)."""
    remap = np.empty(len(more), dtype=np.intp)
    for j, shape in enumerate(more):
        k = index.get(id(shape))
        if k is None:
            k = index[id(shape)] = len(shapes)
            shapes.append(shape)
        remap[j] = k
    return remap


#: a kernel query tests every pair of pieces directly when there are at most this many; above it, the pieces
#: are first grouped (:data:`GROUP` consecutive ones) and only the pairs of groups whose boxes meet are opened
DIRECT_PAIRS = 1 << 14
#: consecutive pieces of a :class:`Posed` bounded together in the broadphase's coarse level (a path's
#: consecutive samples, an arm's links at one configuration: they lie close together)
GROUP = 16


class Posed:
    """Shapes at world transforms as arrays, the kernel's unit: a probe, a volume, a selection of a world.

    ``shapes`` are the distinct shapes, ``kind`` (N,) which of them each piece is, ``transforms`` (N, 4, 4)
    where; ``lo`` / ``hi`` (N, 3) the world axis-aligned bounding boxes, grown by ``pad`` (a query's
    tolerance: the boxes of two shapes within it of each other meet).  Built once, read by any number of
    queries; nothing is copied into coal (the exact test moves no coal object: :func:`_exact`) unless the set
    is asked often enough to get a broadphase tree of its own (:meth:`tree`, :data:`TREE_MIN`).
    """

    __slots__ = ("shapes", "kind", "transforms", "lo", "hi", "pad", "_coarse", "_tree", "_probed", "_parts")

    def __init__(
        self,
        shapes: Sequence[CollisionShape],
        kind: np.ndarray,
        transforms: np.ndarray,
        pad: float,
        boxes: np.ndarray | None = None,
    ) -> None:
        """``boxes``: the shapes' :attr:`CollisionShape.box` stacked ((S, 2, 3)), from a caller that keeps them
        (an arm's links: :meth:`Arm.posed <mrgc.geometry.arm.Arm.posed>`); None: stacked here."""
        self.shapes = list(shapes)
        self.pad = pad
        self.kind = np.asarray(kind, dtype=np.intp)
        self.transforms = np.asarray(transforms, dtype=float).reshape(-1, 4, 4)
        self._coarse: tuple[np.ndarray, np.ndarray] | None = None
        self._tree: tuple[float, Any, list[Any]] | None = None  # (pad, coal's tree, its objects): Posed.tree
        self._probed = 0  # large-set queries so far (posed_collide): a tree pays after enough of them
        self._parts: dict[bytes, Posed] = {}  # within()'s answers, by box
        if not len(self.kind):
            self.lo = self.hi = np.zeros((0, 3))
            return
        rot = self.transforms[:, :3, :3]
        if len(self.shapes) == 1:  # (N, 3, 3) @ (3,): one shape's box everywhere
            mid = rot @ self.shapes[0].center
            reach = np.abs(rot) @ (self.shapes[0].half + pad)
        else:
            table = (np.stack([s.box for s in self.shapes]) if boxes is None else boxes)[self.kind]  # (N, 2, 3)
            mid = (rot @ table[:, 0, :, None])[..., 0]
            reach = (np.abs(rot) @ (table[:, 1, :, None] + pad))[..., 0]
        mid += self.transforms[:, :3, 3]
        self.lo, self.hi = mid - reach, mid + reach

    def __len__(self) -> int:
        return len(self.kind)

    @classmethod
    def of(cls, pieces: Iterable[tuple[ShapeLike, np.ndarray]], pad: float = TOLERANCE) -> "Posed":
        """The pieces of a probe or a volume ((shape, 4×4 world transform) pairs)."""
        return cls(*_arrays(pieces), pad)

    def extended(self, pieces: Sequence[tuple[ShapeLike, np.ndarray]]) -> "Posed | None":
        """This set followed by ``pieces``, equal to the bit to :meth:`of` of this set's pieces and then
        ``pieces`` (same shapes in the same order, same rows, the new pieces' boxes made the way :meth:`of`
        makes them), without converting this set's pieces again; None where :meth:`of` would take its
        one-shape way (every piece one shape) or this set is empty."""
        more, kind_more, transforms = _arrays(pieces)
        shapes = list(self.shapes)
        remap = _merged(shapes, {id(s): k for k, s in enumerate(shapes)}, more)
        if len(shapes) == 1 or not len(self.kind):
            return None
        tail = Posed(shapes, remap[kind_more], transforms, self.pad)  # boxes by the shapes' table, as of() does
        out = Posed.__new__(Posed)
        out.shapes, out.pad = shapes, self.pad
        out.kind = np.concatenate([self.kind, tail.kind])
        out.transforms = np.concatenate([self.transforms, tail.transforms])
        out.lo, out.hi = np.concatenate([self.lo, tail.lo]), np.concatenate([self.hi, tail.hi])
        out._coarse, out._tree, out._probed, out._parts = None, None, 0, {}
        return out

    @classmethod
    def join(cls, given: Sequence["Posed | Packed"]) -> "Posed":
        """The pieces of ``given`` one after the other, as a new set (nothing cached yet, so that a query
        of the union grows no tree or part on the sets it was joined from): their boxes as they were made
        (a :class:`Packed` set's made again, the same), the distinct shapes in order of first appearance.
        The parts must share their pad (an empty union has :data:`TOLERANCE`).  A grounded step keeps its
        volume packed, and a suffix's volume is the join of its steps'."""
        parts = [p.posed() if isinstance(p, Packed) else p for p in given]
        pads = {p.pad for p in parts}
        if len(pads) > 1:
            raise ValueError(f"sets of different pads {sorted(pads)} cannot be joined")
        out = Posed.__new__(Posed)
        out.pad = pads.pop() if pads else TOLERANCE
        index: dict[int, int] = {}
        out.shapes = []
        kinds = [_merged(out.shapes, index, p.shapes)[p.kind] for p in parts]
        if len(parts) == 1:  # the arrays shared (never written to), the caches its own
            only = parts[0]
            out.kind, out.transforms, out.lo, out.hi = kinds[0], only.transforms, only.lo, only.hi
        elif parts:
            out.kind = np.concatenate(kinds)
            out.transforms = np.concatenate([p.transforms for p in parts])
            out.lo, out.hi = np.concatenate([p.lo for p in parts]), np.concatenate([p.hi for p in parts])
        else:
            out.kind, out.transforms = np.zeros(0, dtype=np.intp), np.zeros((0, 4, 4))
            out.lo = out.hi = np.zeros((0, 3))
        out._coarse, out._tree, out._probed, out._parts = None, None, 0, {}
        return out

    @classmethod
    def batch(cls, shapes: Sequence[ShapeLike], transforms: np.ndarray, pad: float = TOLERANCE) -> "Posed":
        """Shapes ``L`` at ``transforms`` (L, 4, 4) or (C, L, 4, 4): C configurations of the same L links."""
        links = [collision_shape(s) for s in shapes]
        t = np.asarray(transforms, dtype=float)
        if t.shape[-3:] != (len(links), 4, 4):
            raise ValueError(f"transforms of shape {t.shape} do not match {len(links)} shapes")
        flat = t.reshape(-1, 4, 4)
        return cls(links, np.tile(np.arange(len(links)), len(flat) // max(1, len(links))), flat, pad)

    def coarse(self) -> tuple[np.ndarray, np.ndarray]:
        """The boxes of runs of :data:`GROUP` consecutive pieces (the last run may be shorter)."""
        if self._coarse is None:
            self._coarse = _grouped(self.lo, self.hi)
        return self._coarse

    def shape(self, i: int) -> CollisionShape:
        """The shape of piece ``i``."""
        return self.shapes[int(self.kind[i])]

    def within(self, lo: np.ndarray, hi: np.ndarray) -> "Posed":
        """The pieces whose boxes meet the world box ``[lo, hi]``, in their order (the same shapes, no copy of
        them): every probe whose box lies in ``[lo, hi]`` gets the same answers from it as from all pieces,
        fewer of them to look through (placements inside a small region against a large swept volume).
        The same box asked again gets the same object (its query count and tree go on)."""
        box = np.concatenate([lo, hi]).tobytes()
        out = self._parts.get(box)
        if out is not None:
            return out
        keep = np.flatnonzero(_boxes_overlap(self.lo, self.hi, lo, hi))
        out = self if len(keep) == len(self.kind) else self.rows(keep)
        if len(self._parts) >= 16:
            del self._parts[next(iter(self._parts))]
        self._parts[box] = out
        return out

    def rows(self, index: np.ndarray) -> "Posed":
        """The pieces ``index`` (an index array), in that order: the same shapes, the rows copied, nothing
        cached yet."""
        out = Posed.__new__(Posed)
        out.shapes, out.kind, out.transforms, out.pad = self.shapes, self.kind[index], self.transforms[index], self.pad
        out.lo, out.hi, out._coarse, out._tree, out._probed, out._parts = (
            self.lo[index],
            self.hi[index],
            None,
            None,
            0,
            {},
        )
        return out

    def tree(self, pad: float) -> Any:
        """coal's broadphase tree over the pieces (one coal object each, sharing its shape's geometry, its box
        grown by ``pad``: two pieces within ``pad`` of each other meet), built on the first call (again if
        ``pad`` changes); the pieces must not move afterwards (a moved world row drops it)."""
        if self._tree is None or self._tree[0] != pad:
            coal = _kit().coal
            manager = coal.DynamicAABBTreeCollisionManager()
            grow = np.full(3, pad)
            objects = []  # the manager holds raw pointers: the objects live as long as the tree
            for k, t in zip(self.kind.tolist(), self.transforms):
                obj = coal.CollisionObject(self.shapes[k].coal_geometry, coal.Transform3s())
                _place(obj, t)
                obj.getAABB().expand(grow)
                manager.registerObject(obj)  # in piece order: the same tree every run
                objects.append(obj)
            manager.setup()
            self._tree = (pad, manager, objects)
        return self._tree[1]


@dataclass(frozen=True, eq=False)
class Packed:
    """A :class:`Posed` set kept for later in less memory: what a grounded step sweeps, which a search holds
    for every step its nodes grounded (the 6-arm, 40-object instance of seed 0: some 11,500 pieces a step,
    745,000 after 13 nodes, 426 steps after 62).  The shapes, which of them each piece is (``kind``, int32),
    where (``rows``: the top three rows of each 4×4 transform, whose last row is (0, 0, 0, 1); the whole
    transforms when one is not) and the pad: 100 bytes a piece where a :class:`Posed` holds 184 (its boxes
    and 4×4 transforms), the boxes made again when it is read (:meth:`posed`: bit for bit the ones
    :class:`Posed` made from the same rows)."""

    shapes: tuple[CollisionShape, ...]
    kind: np.ndarray
    rows: np.ndarray
    pad: float

    @classmethod
    def of(cls, posed: Posed) -> "Packed":
        """``posed``'s pieces, packed."""
        t = posed.transforms
        affine = bool(np.all(t[:, 3] == _BOTTOM))
        rows = np.ascontiguousarray(t[:, :3]) if affine else t.copy()
        return cls(tuple(posed.shapes), posed.kind.astype(np.int32), rows, posed.pad)

    def __len__(self) -> int:
        return len(self.kind)

    def posed(self) -> Posed:
        """The pieces as a :class:`Posed` set again (new arrays, nothing cached)."""
        if self.rows.shape[1] == 4:
            transforms = self.rows
        else:
            transforms = np.empty((len(self.rows), 4, 4))
            transforms[:, :3] = self.rows
            transforms[:, 3] = _BOTTOM
        return Posed(self.shapes, self.kind.astype(np.intp), transforms, self.pad)


#: the last row of an affine 4×4 transform
_BOTTOM = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True, eq=False)
class Probes:
    """Many probes as one set of pieces (:meth:`CollisionWorld.slot_collides`, :meth:`CollisionWorld.slot_hits`):
    ``pieces``, and ``slots`` (N,) the probe each piece belongs to, 0 ≤ slot < ``count``."""

    pieces: Posed
    slots: np.ndarray
    count: int

    @classmethod
    def of(cls, probes: Sequence[Probe], pad: float = TOLERANCE) -> "Probes":
        """The probes given as lists of (shape, 4×4 world transform) pieces, in order."""
        slots = np.repeat(np.arange(len(probes)), [len(p) for p in probes])
        return cls(Posed.of([piece for p in probes for piece in p], pad), slots, len(probes))

    @classmethod
    def batch(cls, shapes: Sequence[ShapeLike], transforms: np.ndarray, pad: float = TOLERANCE) -> "Probes":
        """One probe per leading row of ``transforms`` (K, ..., L, 4, 4): shapes ``L`` at each of its
        configurations (:meth:`Posed.batch`)."""
        t = np.asarray(transforms, dtype=float)
        per = int(np.prod(t.shape[1:-3], dtype=int)) * len(shapes)
        return cls(Posed.batch(shapes, t, pad), np.repeat(np.arange(len(t)), per), len(t))


#: each probe's own object of :meth:`CollisionWorld.slot_collides` (a name or None per probe), or None
Owners = Union[Sequence[Union[str, None]], None]
#: a yes/no answer per probe (a bool array)
Bools = np.ndarray
#: the names of the objects each probe hits, one set per probe
Names = list[set[str]]


def _grouped(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = len(lo)
    size = -(-n // GROUP) * GROUP
    plo, phi = np.full((size, 3), np.inf), np.full((size, 3), -np.inf)
    plo[:n], phi[:n] = lo, hi
    return plo.reshape(-1, GROUP, 3).min(axis=1), phi.reshape(-1, GROUP, 3).max(axis=1)


def _boxes_overlap(alo: np.ndarray, ahi: np.ndarray, blo: np.ndarray, bhi: np.ndarray) -> np.ndarray:
    """Whether boxes ``[alo, ahi]`` and ``[blo, bhi]`` (arrays (..., 3), broadcast together) meet: on every axis
    neither lies beyond the other (touching counts).  Axis by axis, not ``np.all(..., axis=-1)``: numpy's
    reduction over an axis of three costs more than the comparisons (a broadphase of 187 pieces against 30:
    441 -> 75 µs)."""
    out: np.ndarray = (alo[..., 0] <= bhi[..., 0]) & (blo[..., 0] <= ahi[..., 0])
    for k in (1, 2):
        out &= alo[..., k] <= bhi[..., k]
        out &= blo[..., k] <= ahi[..., k]
    return out


def _meet(alo: np.ndarray, ahi: np.ndarray, blo: np.ndarray, bhi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The index pairs (i, j) whose boxes meet, every pair tested (i major)."""
    i, j = np.nonzero(_boxes_overlap(alo[:, None], ahi[:, None], blo[None], bhi[None]))
    return i, j


def overlaps(a: Posed, b: Posed) -> tuple[np.ndarray, np.ndarray]:
    """The broadphase: the pairs (piece of ``a``, piece of ``b``) whose bounding boxes meet.  Small queries
    test every pair; large ones first the boxes of :data:`GROUP` consecutive pieces of each side, then the
    pieces of the groups that meet (numpy throughout).  Sound: two shapes within the pad of each other have
    boxes that meet."""
    na, nb = len(a), len(b)
    if not na or not nb:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    if na * nb <= DIRECT_PAIRS:
        return _meet(a.lo, a.hi, b.lo, b.hi)
    parts = list(_chunks(a, b))
    if not parts:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


#: group pairs opened at once by :func:`_chunks` (a yes/no query stops after the first chunk that collides)
CHUNK = 256


def _chunks(a: Posed, b: Posed) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """:func:`overlaps` of two large sets, :data:`CHUNK` pairs of groups at a time."""
    na, nb = len(a), len(b)
    glo_a, ghi_a = a.coarse() if na > GROUP else (a.lo, a.hi)
    glo_b, ghi_b = b.coarse() if nb > GROUP else (b.lo, b.hi)
    all_a, all_b = _meet(glo_a, ghi_a, glo_b, ghi_b)
    for start in range(0, len(all_a), CHUNK):
        i, j = _opened(a, b, all_a[start : start + CHUNK], all_b[start : start + CHUNK])
        if len(i):
            yield i, j


def _opened(a: Posed, b: Posed, ga: np.ndarray, gb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The piece pairs of the group pairs (ga, gb) whose boxes meet, in the order (group pair, piece of a,
    piece of b).  Each side's pieces are first tested against the other side's group box (2·GROUP box tests
    per group pair instead of GROUP²), then only the survivors are crossed."""
    ia, ok_a = _members(a, ga, b, gb)
    jb, ok_b = _members(b, gb, a, ga)
    g, p, q = np.nonzero(ok_a[:, :, None] & ok_b[:, None, :])
    i, j = ia[g, p], jb[g, q]
    keep = _boxes_overlap(a.lo[i], a.hi[i], b.lo[j], b.hi[j])
    return i[keep], j[keep]


def _members(a: Posed, ga: np.ndarray, b: Posed, gb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each group pair k, the pieces of ``a``'s group ``ga[k]`` (a (K, S) index array, S = GROUP, or 1
    when ``a`` is not grouped) and which of them (K, S) exist and meet ``b``'s group box ``gb[k]``."""
    na, nb = len(a), len(b)
    size = GROUP if na > GROUP else 1
    idx = ga[:, None] * size + np.arange(size)[None, :]
    exists = idx < na
    idx = np.minimum(idx, na - 1)
    blo, bhi = b.coarse() if nb > GROUP else (b.lo, b.hi)
    lo, hi = a.lo[idx], a.hi[idx]  # (K, S, 3)
    meet = _boxes_overlap(lo, hi, blo[gb][:, None, :], bhi[gb][:, None, :])
    return idx, exists & meet


class _Kit:
    """coal objects the exact test reuses (one per process): requests per tolerance, a result, two transforms."""

    def __init__(self) -> None:
        import coal

        self.coal = coal
        self.requests: dict[float, Any] = {}
        self.callbacks: dict[float, Any] = {}
        self.result = coal.CollisionResult()
        self.identity = coal.Transform3s()
        self.relative = coal.Transform3s()

    def callback(self, tolerance: float) -> Any:
        """A broadphase callback that stops at the first collision within ``tolerance``."""
        cb = self.callbacks.get(tolerance)
        if cb is None:
            cb = self.callbacks[tolerance] = self.coal.CollisionCallBackDefault()
            request = cb.data.request
            request.enable_contact = False
            request.security_margin = tolerance
            request.gjk_tolerance = GJK_TOLERANCE
            request.num_max_contacts = 1
        return cb

    def request(self, tolerance: float) -> Any:
        req = self.requests.get(tolerance)
        if req is None:
            req = self.requests[tolerance] = self.coal.CollisionRequest()
            req.enable_contact = False
            req.security_margin = tolerance
            req.gjk_tolerance = GJK_TOLERANCE
        return req


_KIT: list[_Kit] = []


def _kit() -> _Kit:
    if not _KIT:
        _KIT.append(_Kit())
    return _KIT[0]


#: candidate pairs of one query given to coal as they come; past them, blocks of :data:`EXACT_BLOCK` pairs
#: are first cut down to those whose oriented boxes meet (:func:`_oriented_meet`)
EXACT_PLAIN = 32
EXACT_BLOCK = 512


#: marks of :func:`_exact`: a bool array, and for each candidate pair the index of its mark (None: b's piece)
Marks = tuple[np.ndarray, Union[np.ndarray, None]]


def _exact(
    a: Posed, b: Posed, i: np.ndarray, j: np.ndarray, tolerance: float, stop: bool, marks: Marks | None = None
) -> list[int]:
    """coal's narrowphase on the candidate pairs (a's piece i[k], b's piece j[k]): the k of the pairs that
    collide (within ``tolerance``, coal's security margin: the module docstring's semantics), in order, the
    first one only with ``stop``.  ``marks`` (a bool array, and each pair's index into it, or None for b's
    piece): pairs whose mark is set are passed over, and a colliding one sets it
    (which-objects queries need one contact per object; many probes at once one per probe, or per probe and
    object).

    The first :data:`EXACT_PLAIN` pairs go to coal as they are (a yes/no query that collides mostly stops
    among them); the others, in blocks of :data:`EXACT_BLOCK`, only where the two pieces' oriented boxes
    (their shapes' local boxes, placed) come within twice the tolerance of each other: two arms working side
    by side have world-aligned boxes that meet far more often than their links (on the 6-arm, 40-object
    instance 89 % of the candidate pairs of free answers were so parted, at a quarter of coal's cost per
    pair).  The pairs passed over cannot collide, so the answers are the same."""
    out: list[int] = []
    start, n = 0, len(i)
    while start < n:
        end = min(n, start + EXACT_BLOCK if start else EXACT_PLAIN)
        k = np.arange(start, end)
        if start:
            k = k[_oriented_meet(a, b, i[k], j[k], 2 * tolerance)]
        chosen = marks if marks is None or marks[1] is None else (marks[0], marks[1][k])
        out.extend(int(k[x]) for x in _narrow(a, b, i[k], j[k], tolerance, stop, chosen))
        if stop and out:
            break
        start = end
    return out


def _oriented_meet(a: Posed, b: Posed, i: np.ndarray, j: np.ndarray, grow: float) -> np.ndarray:
    """Whether the oriented boxes of a's pieces ``i`` and b's pieces ``j`` (each shape's local box at the
    piece's transform, a's grown by ``grow``) meet, pair by pair (a bool array)."""
    ta, tb = a.transforms[i], b.transforms[j]
    box_a, box_b = np.stack([s.box for s in a.shapes])[a.kind[i]], np.stack([s.box for s in b.shapes])[b.kind[j]]
    centre_a = (ta[:, :3, :3] @ box_a[:, 0, :, None])[..., 0] + ta[:, :3, 3]
    centre_b = (tb[:, :3, :3] @ box_b[:, 0, :, None])[..., 0] + tb[:, :3, 3]
    meet: np.ndarray = _boxes_meet(ta[:, :3, :3], centre_a, box_a[:, 1] + grow, tb[:, :3, :3], centre_b, box_b[:, 1])
    return meet


def _narrow(
    a: Posed, b: Posed, i: np.ndarray, j: np.ndarray, tolerance: float, stop: bool, marks: Marks | None
) -> list[int]:
    """:func:`_exact` on pairs it has chosen: each call is a prebuilt ``ComputeCollision`` of the two
    geometries (cached on the first shape), b's shape placed in a's frame: no coal object is moved or
    copied."""
    if not len(i):
        return []
    kit = _kit()
    request, result, identity, relative = kit.request(tolerance), kit.result, kit.identity, kit.relative
    ta, tb = a.transforms[i], b.transforms[j]
    inv_rot = np.swapaxes(ta[:, :3, :3], -1, -2)
    rel_rot = inv_rot @ tb[:, :3, :3]
    rel_pos = (inv_rot @ (tb[:, :3, 3:] - ta[:, :3, 3:]))[..., 0]
    out: list[int] = []
    ka, kb = a.kind[i].tolist(), b.kind[j].tolist()
    skip, at = (None, []) if marks is None else (marks[0], (j if marks[1] is None else marks[1]).tolist())
    for k in range(len(ka)):
        if skip is not None and skip[at[k]]:
            continue
        result.clear()
        relative.setRotation(rel_rot[k])
        relative.setTranslation(rel_pos[k])
        if a.shapes[ka[k]].call(b.shapes[kb[k]])(identity, relative, request, result):
            out.append(k)
            if stop:
                break
            if skip is not None:
                skip[at[k]] = True
    return out


def posed_collide(a: Posed, b: Posed, tolerance: float = TOLERANCE) -> bool:
    """Whether some piece of ``a`` collides with some piece of ``b`` (within ``tolerance``): every pair of
    boxes tested directly up to :data:`DIRECT_YES_NO` pairs, larger sets opened a chunk of groups at a time,
    stopping at the first collision; a large ``b`` asked again and again answers through its tree
    (:data:`TREE_MIN`)."""
    if len(b) >= TREE_MIN and len(a) <= min(TREE_PIECES, len(b)):
        b._probed += 1
        if b._probed > max(TREE_AFTER, len(b) // TREE_AMORTISED):
            return _tree_probe(a, b, tolerance)
    if len(a) * len(b) <= DIRECT_PAIRS:
        i, j = overlaps(a, b)
        return bool(_exact(a, b, i, j, tolerance, stop=True))
    if len(a) <= GROUP:  # a probe against a large set (one configuration against a swept volume)
        i, j = _near(a, b)
        return bool(_exact(a, b, i, j, tolerance, stop=True))
    if len(b) <= GROUP:
        j, i = _near(b, a)
        return bool(_exact(a, b, i, j, tolerance, stop=True))
    if len(a) * len(b) <= DIRECT_YES_NO:
        i, j = _meet(a.lo, a.hi, b.lo, b.hi)
        return bool(_exact(a, b, i, j, tolerance, stop=True))
    return any(_exact(a, b, i, j, tolerance, stop=True) for i, j in _chunks(a, b))


#: a yes/no query (:func:`posed_collide`) of two sets of more than :data:`GROUP` pieces tests every pair of
#: boxes directly up to this many pairs (the grouped broadphase only above): an RRTConnect edge's states
#: against a world's objects (about 700 pieces against 75) are mostly answered "collides", and their pairs
#: in the probe's order find it sooner than the group pairs' chunks.  Measured on the 6-arm instance of seed
#: 2: 7,356 such queries, 6.7 -> 3.1 s of CPU (the same answers); its first 15 groundings 91.4 -> 79.4 s,
#: its 40th 283 -> 274 s; the other 6-arm seeds and the PA10/BO8 presets within noise (docs/benchmarks.md).
DIRECT_YES_NO = 1 << 17


#: a set of at least TREE_MIN pieces (another arm's sweep, a step's busy volume, a suffix's sweep around a
#: region) asked about by probes of at most TREE_PIECES pieces (and no more than its own) more than
#: max(TREE_AFTER, size / TREE_AMORTISED) times gets coal's broadphase tree (:meth:`Posed.tree`, built once,
#: about 10 µs a piece, so a numpy query of about 0.3 ms pays for some 30 pieces of it) and answers each later
#: probe by one tree query per probe piece (a few µs each) instead of the numpy broadphase and the pairs it
#: leaves: the RRT of a carry among another arm's sweep asks the same set hundreds of times (measured on a
#: PA5 instance: 1,164 one-configuration probes of 11 pieces against 2,706, 377 -> 60 µs each; 373 batches of
#: 591 pieces, 2,256 -> 344 µs); placements ask a suffix's sweep around a region (one piece against 3,500:
#: 431 -> 20 µs).  The answers are the same: the tree's boxes are grown by the tolerance and coal's
#: narrowphase runs with it as its security margin (tests/test_collision.py compares both paths).  A count,
#: not a clock, decides the path.
TREE_MIN = 256
TREE_AFTER = 4
TREE_AMORTISED = 32
TREE_PIECES = 4096


def _tree_probe(a: Posed, b: Posed, tolerance: float) -> bool:
    """:func:`posed_collide` of ``a``'s pieces against ``b``'s tree (:meth:`Posed.tree`), one piece at a time
    in their order (each shape's probe object moved to the piece), stopping at the first collision."""
    manager = b.tree(tolerance)
    callback = _kit().callback(tolerance)
    result = callback.data.result
    shapes, kind, transforms = a.shapes, a.kind, a.transforms
    if len(a) > GROUP:  # a batch: only its pieces whose boxes meet the box around all of b
        glo, ghi = b.coarse()
        near = np.flatnonzero(_boxes_overlap(a.lo, a.hi, glo.min(axis=0), ghi.max(axis=0)))
        kind, transforms = kind[near], transforms[near]
    for k, t in zip(kind.tolist(), transforms):
        obj = shapes[k].coal_object
        _place(obj, t)
        manager.collide(obj, callback)
        if result.isCollision():
            return True
    return False


def _near(small: Posed, large: Posed) -> tuple[np.ndarray, np.ndarray]:
    """:func:`overlaps` of a few pieces and a large set (more than :data:`GROUP` pieces): the large set's
    groups, then its pieces, that meet the box around all of ``small`` first; then the pairs."""
    lo, hi = small.lo.min(axis=0), small.hi.max(axis=0)
    glo, ghi = large.coarse()
    groups = np.flatnonzero(_boxes_overlap(glo, ghi, lo, hi))
    j = (groups[:, None] * GROUP + np.arange(GROUP)[None, :]).ravel()
    j = j[j < len(large)]
    j = j[_boxes_overlap(large.lo[j], large.hi[j], lo, hi)]
    i, k = _meet(small.lo, small.hi, large.lo[j], large.hi[j])
    return i, j[k]


def pieces_collide(a: Probe, b: Probe, tolerance: float = TOLERANCE) -> bool:
    """:func:`posed_collide` for two lists of (shape, 4×4 world transform) pieces."""
    if not a or not b:
        return False
    return posed_collide(Posed.of(a), Posed.of(b), tolerance)


def grouped_collide(
    a: Posed, a_start: np.ndarray, b: Posed, b_start: np.ndarray, pairs: np.ndarray, tolerance: float = TOLERANCE
) -> bool:
    """Whether a piece of group ``k`` of ``a`` collides with a piece of group ``m`` of ``b`` for some row
    ``(k, m)`` of ``pairs`` ((P, 2)).  A group is a run of consecutive pieces: group ``k`` of ``a`` is pieces
    ``a_start[k]:a_start[k + 1]`` (``a_start`` ascending from 0 to ``len(a)``, no group empty), and so for
    ``b``.  Two motions compared sample by sample: a group is one sample's volume, each sample once however
    often it meets the other's, ``pairs`` the samples that meet in time.  Pairs of groups whose boxes (the
    union of their pieces') do not meet are passed over before any pair of pieces is formed."""
    if not len(pairs):
        return False
    a_start, b_start = np.asarray(a_start, dtype=np.intp), np.asarray(b_start, dtype=np.intp)
    for start, posed in ((a_start, a), (b_start, b)):
        if len(start) < 2 or start[0] != 0 or start[-1] != len(posed) or (np.diff(start) <= 0).any():
            raise ValueError("grouped_collide: the groups must cover the pieces in order, every group a piece")
    k, m = np.asarray(pairs, dtype=np.intp).reshape(-1, 2).T
    a_lo, a_hi = np.minimum.reduceat(a.lo, a_start[:-1]), np.maximum.reduceat(a.hi, a_start[:-1])
    b_lo, b_hi = np.minimum.reduceat(b.lo, b_start[:-1]), np.maximum.reduceat(b.hi, b_start[:-1])
    meet = _boxes_overlap(a_lo[k], a_hi[k], b_lo[m], b_hi[m])
    k, m = k[meet], m[meet]
    if not len(k):
        return False
    # every piece of a's group against every piece of b's, pair by pair: a's pieces of the pairs first (rows),
    # then each row repeated once per piece of its pair's b group
    na, nb = np.diff(a_start)[k], np.diff(b_start)[m]
    pair = np.repeat(np.arange(len(k)), na)
    rows = a_start[k][pair] + np.arange(len(pair)) - np.repeat(np.cumsum(na) - na, na)
    per_row = nb[pair]
    i = np.repeat(rows, per_row)
    j = np.repeat(b_start[m][pair] - (np.cumsum(per_row) - per_row), per_row) + np.arange(int(per_row.sum()))
    keep = _boxes_overlap(a.lo[i], a.hi[i], b.lo[j], b.hi[j])
    return bool(_exact(a, b, i[keep], j[keep], tolerance, stop=True))


#: a yes/no probe of at most this many pieces goes through coal's broadphase tree of the selection (a few
#: µs a piece) rather than the numpy kernel (a few tens of µs a query, whatever its size)
SMALL_PROBE = 16


class _Entry:
    __slots__ = ("name", "group", "shape", "transform", "slot", "obj")

    def __init__(self, name: str, group: str, shape: CollisionShape, transform: np.ndarray, obj: Any) -> None:
        self.name, self.group, self.shape, self.transform, self.obj = name, group, shape, transform, obj
        self.slot = -1


class _Tree:
    """coal's broadphase tree over one selection of world objects (their coal objects share the shapes'
    geometry), refit when objects have moved."""

    __slots__ = ("manager", "version")

    def __init__(self, manager: Any, version: int) -> None:
        self.manager, self.version = manager, version


class CollisionWorld:
    """Named collision objects at world transforms, with groups, and collision queries against them.

    ``against`` (which world objects a query tests) and ``ignore`` (which to leave out) take a group tag,
    an object name, or an iterable of them; ``against=None`` means every object.  Tokens that name no
    group and no object select nothing.  A query's own objects are never tested against each other or
    themselves: several names in one query act as one body (a robot's links and the object it holds).

    The kernel (module docstring): the world's objects are one :class:`Posed` (their shapes shared, never
    copied), built on the first query after an object was added or removed; a move updates its row in
    place; each selection (``against`` minus ``ignore`` minus the query's own objects) is an index array,
    cached until objects are added or removed.  A probe is a :class:`Posed` too; the broadphase
    (:func:`overlaps`) and coal's narrowphase on its pairs (:func:`_exact`) answer.
    """

    #: how many selections (against × ignore × query objects) are remembered
    MAX_SELECTIONS = 256

    def __init__(self, tolerance: float = TOLERANCE) -> None:
        if tolerance < TOLERANCE:
            raise ValueError(f"tolerance must be >= {TOLERANCE:g} (coal reports overlaps as free below it)")
        self.tolerance = float(tolerance)
        self._entries: dict[str, _Entry] = {}
        self._groups: dict[str, set[str]] = {}
        self._selections: dict[Any, np.ndarray] = {}
        self._posed: Posed | None = None  # every object, in insertion order (None: rebuilt on the next query)
        self._order: list[_Entry] = []
        self._trees: dict[Any, _Tree] = {}
        self._version = 0  # bumped by every move; a tree refits when it lags
        coal = _kit().coal
        self._first = coal.CollisionCallBackDefault()  # stops at the first collision
        request = self._first.data.request
        request.enable_contact = False
        request.security_margin = self.tolerance
        request.gjk_tolerance = GJK_TOLERANCE
        request.num_max_contacts = 1

    # ----------------------------------------------------------------------------------------- contents

    def add(self, name: str, geometry: ShapeLike, transform: np.ndarray, group: str = "fixed") -> None:
        """Add object ``name`` of ``geometry`` at ``transform`` (4×4, world frame) to ``group``."""
        if name in self._entries:
            raise ValueError(f"object '{name}' is already in the collision world")
        if name in self._groups or group in self._entries:
            raise ValueError(f"'{name if name in self._groups else group}' is both an object and a group")
        shape = collision_shape(geometry)
        t = np.array(transform, dtype=float)
        obj = _kit().coal.CollisionObject(shape.coal_geometry, _kit().coal.Transform3s())  # shared, not cloned
        _place(obj, t)
        self._entries[name] = _Entry(name, group, shape, t, obj)
        self._groups.setdefault(group, set()).add(name)
        self._changed()

    def remove(self, name: str) -> None:
        """Take object ``name`` out of the world."""
        entry = self._entries.pop(name)
        members = self._groups[entry.group]
        members.discard(name)
        if not members:
            del self._groups[entry.group]
        self._changed()

    def _changed(self) -> None:
        self._posed = None
        self._selections.clear()
        self._trees.clear()  # trees hold raw pointers to the objects

    def set_transform(self, name: str, transform: np.ndarray) -> None:
        """Move object ``name`` to ``transform`` (4×4, world frame): its row of the kernel is updated in place."""
        entry = self._entries[name]
        t = np.array(transform, dtype=float)
        entry.transform = t
        _place(entry.obj, t)
        self._version += 1
        posed = self._posed
        if posed is not None:
            one = Posed([entry.shape], np.zeros(1, dtype=np.intp), t[None], 0.0)
            posed.transforms[entry.slot] = t
            posed.lo[entry.slot], posed.hi[entry.slot] = one.lo[0], one.hi[0]
            posed._coarse = posed._tree = None
            posed._parts = {}

    def transform(self, name: str) -> np.ndarray:
        """Object ``name``'s pose (a copy)."""
        return self._entries[name].transform.copy()

    def group_of(self, name: str) -> str:
        """The group object ``name`` belongs to."""
        return self._entries[name].group

    def names(self, group: str | None = None) -> list[str]:
        """Object names (of one group), in the order they were added."""
        return [n for n, e in self._entries.items() if group is None or e.group == group]

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __len__(self) -> int:
        return len(self._entries)

    # ------------------------------------------------------------------------------ queries on objects

    def collides(self, names: str | Iterable[str], against: Against = None, ignore: Against = ()) -> bool:
        """Does any of the named world objects collide with a selected object (other than themselves)?"""
        entries = [self._entries[n] for n in ((names,) if isinstance(names, str) else names)]
        tree = self._tree(against, ignore, tuple(e.name for e in entries))
        return tree is not None and self._tree_collides(tree, [e.obj for e in entries])

    def colliding_with(self, names: str | Iterable[str], against: Against = None, ignore: Against = ()) -> set[str]:
        """The selected objects that any of the named world objects collides with."""
        own = self._own(names)
        hits = self._query(own, self._select(against, ignore, tuple(e.name for e in own[1])), stop=False)
        assert isinstance(hits, set)
        return hits

    def distance(self, a: str, b: str) -> float:
        """Distance between two world objects; negative is a penetration depth (convex shapes)."""
        coal = _kit().coal
        result = coal.DistanceResult()
        return float(coal.distance(self._entries[a].obj, self._entries[b].obj, coal.DistanceRequest(), result))

    # ---------------------------------------------------------------------------------------- probes

    def probe_collides(self, shapes: Probe | Posed, against: Against = None, ignore: Against = ()) -> bool:
        """Does any shape of the probe ((shape, 4×4 transform) pairs, not in the world) hit a selected object?"""
        if len(shapes) <= SMALL_PROBE:
            tree = self._tree(against, ignore, ())
            if tree is None:
                return False
            pieces: Probe = (
                [(shapes.shapes[k], t) for k, t in zip(shapes.kind.tolist(), shapes.transforms)]
                if isinstance(shapes, Posed)
                else shapes
            )
            # one piece at a time: each is its shape's probe object moved there, and one shape may stand at
            # several pieces (an object along a path: moved there all at once, only its last pose was tested)
            return any(self._tree_collides(tree, [_posed(s, t)]) for s, t in pieces)
        return self._query(self._probe(shapes), self._select(against, ignore, ()), stop=True) is True

    def probe_hits(self, shapes: Probe | Posed, against: Against = None, ignore: Against = ()) -> set[str]:
        """The selected objects that some shape of the probe hits."""
        hits = self._query(self._probe(shapes), self._select(against, ignore, ()), stop=False)
        assert isinstance(hits, set)
        return hits

    def sweep_hits(self, probes: Iterable[Probe], against: Against = None, ignore: Against = ()) -> set[str]:
        """The union of the objects the probes hit (a swept volume given as configurations along a path)."""
        return self.probe_hits([pair for probe in probes for pair in probe], against, ignore)

    def batch_collides(
        self, shapes: Sequence[ShapeLike], transforms: np.ndarray, against: Against = None, ignore: Against = ()
    ) -> bool:
        """:meth:`probe_collides` for shapes ``L`` at ``transforms`` of shape (L, 4, 4) or (C, L, 4, 4)
        (C configurations of the same L links, as batched forward kinematics returns them)."""
        return self.probe_collides(Posed.batch(shapes, transforms, self.tolerance), against, ignore)

    def batch_hits(
        self, shapes: Sequence[ShapeLike], transforms: np.ndarray, against: Against = None, ignore: Against = ()
    ) -> set[str]:
        """:meth:`probe_hits` (or :meth:`sweep_hits` for C configurations) in the batched form."""
        return self.probe_hits(Posed.batch(shapes, transforms, self.tolerance), against, ignore)

    def slot_collides(self, probes: Probes, against: Against = None, ignore: Against = (), own: Owners = None) -> Bools:
        """Many probes asked at once (:class:`Probes`): for each, whether one of its pieces hits a selected
        object, the probe's ``own`` object excepted (``own[s]``: an object name or None, one per probe).  A
        (count,) bool array, the answers :meth:`probe_collides` gives each probe alone (with ``own[s]`` added to
        ``ignore``): the same candidate pairs (one broadphase for all), coal's narrowphase deciding each
        (:func:`_exact`: past its first pairs only those whose oriented boxes meet, the others cannot collide),
        a probe's pairs passed over once one of them collides.  Phase 1 checks the approaches of a round of
        queries this way."""
        return self._slotted(probes, against, ignore, own, hits=False)

    def slot_hits(self, probes: Probes, against: Against = None, ignore: Against = (), own: Owners = None) -> Names:
        """:meth:`slot_collides` answering :meth:`probe_hits` for each probe: the selected objects (but its
        ``own``) some piece of the probe hits."""
        done = self._slotted(probes, against, ignore, own, hits=True)
        names = [self._order[k].name for k in self._select(against, ignore, ()).tolist()]
        return [{names[c] for c in np.flatnonzero(row).tolist()} for row in done]

    # -------------------------------------------------------------------------------------- internals

    def _slotted(self, probes: Probes, against: Against, ignore: Against, own: Owners, hits: bool) -> np.ndarray:
        """:meth:`slot_collides` ((count,) bools) or, with ``hits``, which selected objects each probe hits
        ((count, selected) bools)."""
        sel = self._select(against, ignore, ())
        n = len(sel)
        probe, count = probes.pieces, probes.count
        done = np.zeros((count, n) if hits else count, dtype=bool)
        if not n or not len(probe):
            return done
        chosen = self._world().rows(sel)
        i, j = overlaps(probe, chosen)
        s = probes.slots[i]
        if own is not None:  # each probe's own object (its column among the selected; -1: not selected)
            column = {self._order[k].name: c for c, k in enumerate(sel.tolist())}
            mine = np.array([-1 if o is None else column.get(o, -1) for o in own], dtype=np.intp)
            keep = mine[s] != j
            i, j, s = i[keep], j[keep], s[keep]
        _exact(probe, chosen, i, j, self.tolerance, stop=False, marks=(done.reshape(-1), s * n + j if hits else s))
        return done

    def _probe(self, shapes: Probe | Posed) -> Posed:
        return shapes if isinstance(shapes, Posed) else Posed.of(shapes, self.tolerance)

    def _own(self, names: str | Iterable[str]) -> tuple[Posed, list[_Entry]]:
        entries = [self._entries[n] for n in ((names,) if isinstance(names, str) else names)]
        pieces = Posed.of([(e.shape, e.transform) for e in entries], self.tolerance)
        return pieces, entries

    def _world(self) -> Posed:
        """Every object of the world as one :class:`Posed` (insertion order), built when stale."""
        if self._posed is None:
            self._order = list(self._entries.values())
            for k, e in enumerate(self._order):
                e.slot = k
            self._posed = Posed.of([(e.shape, e.transform) for e in self._order], 0.0)
        return self._posed

    def _query(self, probe: Posed | tuple[Posed, list[_Entry]], sel: np.ndarray, stop: bool) -> bool | set[str]:
        """The probe against the selected objects: with ``stop``, whether something collides; else the names
        of the selected objects something collides with."""
        pieces = probe[0] if isinstance(probe, tuple) else probe
        if not len(sel) or not len(pieces):
            return False if stop else set()
        world = self._world()
        chosen = world.rows(sel)
        if stop:
            return posed_collide(pieces, chosen, self.tolerance)
        i, j = overlaps(pieces, chosen)
        skip = np.zeros(len(sel), dtype=bool)
        _exact(pieces, chosen, i, j, self.tolerance, stop=False, marks=(skip, None))
        return {self._order[int(k)].name for k in sel[skip]}

    def _tree_collides(self, tree: _Tree, objs: list[Any]) -> bool:
        if tree.version != self._version:
            tree.manager.update()
            tree.version = self._version
        cb, collide = self._first, tree.manager.collide
        result = cb.data.result
        for obj in objs:
            collide(obj, cb)  # the manager re-initialises the callback (clears its result) first
            if result.isCollision():
                return True
        return False

    def _tree(self, against: Against, ignore: Against, exclude: tuple[str, ...]) -> _Tree | None:
        """coal's broadphase tree of a selection (None when it is empty), built on first use."""
        sel = self._select(against, ignore, exclude)
        if not len(sel):
            return None
        key = (against if against is None or isinstance(against, str) else frozenset(against), ignore, exclude)
        key = (key[0], ignore if isinstance(ignore, str) else frozenset(ignore or ()), exclude)
        tree = self._trees.get(key)
        if tree is None:
            manager = _kit().coal.DynamicAABBTreeCollisionManager()
            for k in sel.tolist():  # insertion order: deterministic trees
                manager.registerObject(self._order[k].obj)
            manager.setup()
            if len(self._trees) >= self.MAX_SELECTIONS:
                del self._trees[next(iter(self._trees))]
            tree = self._trees[key] = _Tree(manager, self._version)
        return tree

    def _tokens(self, tokens: Against) -> set[str]:
        if tokens is None:
            return set(self._entries)
        if isinstance(tokens, str):
            tokens = (tokens,)
        out: set[str] = set()
        for tok in tokens:
            if tok in self._groups:
                out |= self._groups[tok]
            elif tok in self._entries:
                out.add(tok)
        return out

    def _select(self, against: Against, ignore: Against, exclude: tuple[str, ...]) -> np.ndarray:
        """The rows of the selected objects (insertion order), cached until objects are added or removed."""
        key = (
            against if against is None or isinstance(against, str) else frozenset(against),
            ignore if isinstance(ignore, str) else frozenset(ignore or ()),
            exclude,
        )
        sel = self._selections.get(key)
        if sel is None:
            self._world()
            chosen = self._tokens(against) - self._tokens(ignore) - set(exclude)
            sel = np.array([e.slot for e in self._order if e.name in chosen], dtype=np.intp)
            if len(self._selections) >= self.MAX_SELECTIONS:
                del self._selections[next(iter(self._selections))]
            self._selections[key] = sel
        return sel


#: slack added to the bounds of :class:`PairCheck`'s pre-filter (m): hulls of flat clouds are thickened by up to
#: a few µm (:func:`_thicken`) beyond the points the bounds are taken from
BOUND_SLACK = 1e-4
#: :class:`PairCheck` tests oriented boxes only when at least this many pairs pass the spheres: on fewer, its
#: ~60 numpy operations cost more than the coal calls they save (about 8 µs each, half of them saved)
BOX_STAGE_MIN = 32


class PairCheck:
    """Yes/no collisions between chosen pairs of the parts of one body: an arm's links against each other.

    ``shapes`` are the parts, ``pairs`` the index pairs (into ``shapes``) to test; a pair collides when its
    two shapes come within ``clearance`` of each other (coal's security margin: "free" proves a distance
    above ``clearance - 1e-6``, "collides" one of at most ``clearance``; see the module docstring).  A query
    takes the parts' transforms at C poses, ``(C, S, 4, 4)``, in any frame common to the parts.

    Three stages, each on what the one before leaves: bounding spheres (numpy, every pair at every pose);
    oriented bounding boxes grown by half the clearance (separating axes, numpy), when at least
    :data:`BOX_STAGE_MIN` pairs are left; then coal's GJK on each pair left, one call per pair and pose (a
    prebuilt ``ComputeCollision`` of the two geometries, the second shape placed in the first one's frame).
    Spheres and boxes bound the shapes' points (hulls) or their bounding boxes (primitives, meshes), so the
    pre-filter never drops a colliding pair.
    """

    def __init__(self, shapes: Sequence[CollisionShape], pairs: Sequence[tuple[int, int]], clearance: float) -> None:
        import coal

        if clearance < TOLERANCE:
            raise ValueError(f"clearance must be >= {TOLERANCE:g} (coal reports overlaps as free below it)")
        self.size = len(shapes)
        self.clearance = float(clearance)
        self.pairs = np.array(pairs, dtype=np.intp).reshape(-1, 2)
        bounds = [_bounds(_points(s)) for s in shapes]
        # bounding spheres in the shapes' frames: centres (homogeneous, (S, 4, 1)) and radii
        self._centre_h = _homogeneous([b[0] for b in bounds])
        radius = np.array([b[1] for b in bounds])
        #: (P,) squared distance between a pair's sphere centres below which the pair goes on
        self._reach2 = (radius[self.pairs[:, 0]] + radius[self.pairs[:, 1]] + self.clearance) ** 2
        #: (P, S): +1 at a pair's second shape, -1 at its first (its centres' difference is one matmul)
        self._difference = np.zeros((len(self.pairs), self.size))
        self._difference[np.arange(len(self.pairs)), self.pairs[:, 1]] = 1.0
        self._difference[np.arange(len(self.pairs)), self.pairs[:, 0]] -= 1.0
        # oriented bounding boxes in the shapes' frames: axes as columns, centres (homogeneous), half extents
        self._box_rot = np.array([b[2] for b in bounds]).reshape(-1, 3, 3)
        self._box_centre_h = _homogeneous([b[3] for b in bounds])
        self._box_half = np.array([b[4] for b in bounds]).reshape(-1, 3) + self.clearance / 2
        self._calls = [coal.ComputeCollision(shapes[a].coal_geometry, shapes[b].coal_geometry) for a, b in pairs]
        request = coal.CollisionRequest()
        request.enable_contact = False
        request.security_margin = self.clearance
        request.gjk_tolerance = GJK_TOLERANCE
        self._request = request
        self._result = coal.CollisionResult()
        self._identity = coal.Transform3s()
        self._relative = coal.Transform3s()  # set for each call (cheaper than making one)
        #: coal calls made (pairs the pre-filter left), for measurements
        self.exact_checks = 0

    def __repr__(self) -> str:
        return f"PairCheck(<{self.size} shapes, {len(self.pairs)} pairs, clearance {self.clearance:g}>)"

    def collides(self, transforms: np.ndarray) -> bool:
        """Whether some pair collides at some pose of ``transforms`` ((C, S, 4, 4) or (S, 4, 4))."""
        return bool(self._colliding(transforms, stop=True).any())

    def colliding(self, transforms: np.ndarray) -> np.ndarray:
        """Whether some pair collides, for each pose of ``transforms`` (C, S, 4, 4): a (C,) bool array."""
        return self._colliding(transforms, stop=False)

    def _colliding(self, transforms: np.ndarray, stop: bool) -> np.ndarray:
        t = np.asarray(transforms, dtype=float)
        if t.shape[-3:] != (self.size, 4, 4):
            raise ValueError(f"transforms of shape {t.shape} do not match {self.size} shapes")
        t = t.reshape(-1, self.size, 4, 4)
        out = np.zeros(len(t), dtype=bool)
        if not len(self.pairs) or not len(t):
            return out
        # spheres: every pair at every pose
        centres = (t @ self._centre_h)[..., :3, 0]  # (C, S, 3)
        gap = self._difference @ centres  # (C, P, 3): second shape's centre minus the first one's
        pose, pair = np.nonzero((gap * gap).sum(axis=-1) <= self._reach2)
        if not len(pose):
            return out
        ia, ib = self.pairs[pair, 0], self.pairs[pair, 1]
        ta, tb = t[pose, ia], t[pose, ib]
        if len(pose) >= BOX_STAGE_MIN:  # oriented boxes: the pairs whose spheres meet
            meet = _boxes_meet(
                ta[:, :3, :3] @ self._box_rot[ia],
                (ta @ self._box_centre_h[ia])[:, :3, 0],
                self._box_half[ia],
                tb[:, :3, :3] @ self._box_rot[ib],
                (tb @ self._box_centre_h[ib])[:, :3, 0],
                self._box_half[ib],
            )
            pose, pair, ta, tb = pose[meet], pair[meet], ta[meet], tb[meet]
            if not len(pose):
                return out
        # coal on what is left: the second shape in the first one's frame
        inv_rot = np.swapaxes(ta[:, :3, :3], -1, -2)
        rel_rot = inv_rot @ tb[:, :3, :3]
        rel_pos = (inv_rot @ (tb[:, :3, 3:] - ta[:, :3, 3:]))[..., 0]
        calls, request, result, identity, relative = (
            self._calls,
            self._request,
            self._result,
            self._identity,
            self._relative,
        )
        for k, (c, p) in enumerate(zip(pose.tolist(), pair.tolist())):
            if out[c]:
                continue
            self.exact_checks += 1
            result.clear()
            relative.setRotation(rel_rot[k])
            relative.setTranslation(rel_pos[k])
            if calls[p](identity, relative, request, result):
                out[c] = True
                if stop:
                    break
        return out


def _arrays(pieces: Iterable[tuple[ShapeLike, np.ndarray]]) -> tuple[list[CollisionShape], np.ndarray, np.ndarray]:
    """(shape, 4×4 transform) pieces as :class:`Posed` holds them: the distinct shapes in order of first
    appearance, each piece's index among them, the transforms (N, 4, 4)."""
    pieces = pieces if isinstance(pieces, (list, tuple)) else list(pieces)
    given = [collision_shape(p[0]) if type(p[0]) is not CollisionShape else p[0] for p in pieces]
    ids = list(map(id, given))
    first = dict(zip(ids, given))  # each distinct shape, in order of first appearance
    index = {i: k for k, i in enumerate(first)}
    kind = np.fromiter(map(index.__getitem__, ids), dtype=np.intp, count=len(ids))
    return list(first.values()), kind, np.array([p[1] for p in pieces], dtype=float).reshape(-1, 4, 4)


def _homogeneous(points: Sequence[np.ndarray]) -> np.ndarray:
    """Points as homogeneous column vectors, (N, 4, 1)."""
    out = np.ones((len(points), 4, 1))
    if len(points):
        out[:, :3, 0] = np.array(points).reshape(-1, 3)
    return out


def _points(shape: CollisionShape) -> np.ndarray:
    """Points whose convex hull holds ``shape``: a hull's own points, else its bounding box's corners."""
    if isinstance(shape.geometry, ConvexHull):
        return np.asarray(shape.geometry.vertices, dtype=float).reshape(-1, 3)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    corners: np.ndarray = shape.center + signs * shape.half
    return corners


def _bounds(pts: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray, np.ndarray]:
    """A bounding sphere (centre, radius) and an oriented bounding box (axes as the columns of a rotation,
    centre, half extents) of ``pts``, each grown by :data:`BOUND_SLACK`."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = (lo + hi) / 2
    radius = float(np.sqrt(((pts - centre) ** 2).sum(axis=1).max())) + BOUND_SLACK
    mean = pts.mean(axis=0)
    centred = pts - mean
    axes = np.linalg.eigh(centred.T @ centred)[1]  # principal axes as columns
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1
    local = centred @ axes
    box_lo, box_hi = local.min(axis=0), local.max(axis=0)
    return centre, radius, axes, mean + axes @ ((box_lo + box_hi) / 2), (box_hi - box_lo) / 2 + BOUND_SLACK


def _boxes_meet(
    rot_a: np.ndarray, pos_a: np.ndarray, half_a: np.ndarray, rot_b: np.ndarray, pos_b: np.ndarray, half_b: np.ndarray
) -> np.ndarray:
    """Whether each pair of oriented boxes (K of them: axes as the columns of ``rot`` (K, 3, 3), centres
    ``pos`` (K, 3), half extents ``half`` (K, 3)) overlaps: the separating axis test on the 15 axes (each
    box's 3 axes and their 9 cross products), vectorised; a small epsilon keeps near-parallel edges sound."""
    r = np.swapaxes(rot_a, -1, -2) @ rot_b  # b's axes in a's frame
    t = np.einsum("kji,kj->ki", rot_a, pos_b - pos_a)  # b's centre in a's frame
    abs_r = np.abs(r) + 1e-9
    apart = np.any(np.abs(t) > half_a + np.einsum("kij,kj->ki", abs_r, half_b), axis=1)
    apart |= np.any(np.abs(np.einsum("kij,ki->kj", r, t)) > half_b + np.einsum("kij,ki->kj", abs_r, half_a), axis=1)
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            reach = (
                half_a[:, i1] * abs_r[:, i2, j]
                + half_a[:, i2] * abs_r[:, i1, j]
                + half_b[:, j1] * abs_r[:, i, j2]
                + half_b[:, j2] * abs_r[:, i, j1]
            )
            apart |= np.abs(t[:, i2] * r[:, i1, j] - t[:, i1] * r[:, i2, j]) > reach
    meet: np.ndarray = ~apart
    return meet


def scene_world(scene: SceneSpec) -> CollisionWorld:
    """A scene's collision world: fixed objects in group ``fixed``, movable objects (at their initial
    poses) in group ``movable``."""
    world = CollisionWorld()
    for b in scene.fixed:
        world.add(b.name, b.shape, b.pose, "fixed")
    for b in scene.movable:
        world.add(b.name, b.shape, b.pose, "movable")
    return world


def _place(obj: Any, t: np.ndarray) -> None:
    """Move a coal object to a 4×4 transform and refresh its AABB (the broadphase reads the AABB)."""
    t = np.asarray(t, dtype=float)
    obj.setRotation(t[:3, :3])
    obj.setTranslation(t[:3, 3])
    obj.computeAABB()


def _posed(shape: ShapeLike, t: np.ndarray) -> Any:
    """The shape's probe object moved to ``t`` (4×4), its bounding box refreshed (coal trap: without
    ``computeAABB`` after a move the broadphase silently works on the old box)."""
    obj = (shape if type(shape) is CollisionShape else collision_shape(shape)).coal_object
    _place(obj, t)
    return obj
