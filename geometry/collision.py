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
result) at the start of every ``collide`` call, so results are read after each call.

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
from typing import TYPE_CHECKING, Any, Iterable, Sequence, Union

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
    """A geometry built for coal once: its coal geometry, a coal object that probes move, and its local AABB.

    Make one with :func:`collision_shape`; hand it to probes as often as needed.  Not thread-safe (a probe
    moves the shape's own coal object), which is fine with one world per process.
    """

    __slots__ = ("geometry", "coal_geometry", "coal_object", "center", "half")

    def __init__(self, geometry: Geometry, coal_geometry: Any) -> None:
        import coal

        self.geometry = geometry
        self.coal_geometry = coal_geometry
        self.coal_object = coal.CollisionObject(coal_geometry, coal.Transform3s())
        coal_geometry.computeLocalAABB()
        box = coal_geometry.aabb_local
        lo, hi = np.array(box.min_, dtype=float), np.array(box.max_, dtype=float)
        #: centre and half extents of the axis-aligned bounding box in the shape's own frame
        self.center: np.ndarray = (lo + hi) / 2
        self.half: np.ndarray = (hi - lo) / 2

    def __repr__(self) -> str:
        return f"CollisionShape({self.geometry!r})"


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


class _Entry:
    __slots__ = ("name", "group", "shape", "obj", "gid", "transform")

    def __init__(self, name: str, group: str, shape: CollisionShape, obj: Any, gid: int, transform: np.ndarray) -> None:
        self.name, self.group, self.shape, self.obj, self.gid, self.transform = (
            name,
            group,
            shape,
            obj,
            gid,
            transform,
        )


class _Selection:
    """A coal broadphase manager over one selection of world objects, refit when objects have moved."""

    __slots__ = ("manager", "version", "size")

    def __init__(self, manager: Any, version: int, size: int) -> None:
        self.manager, self.version, self.size = manager, version, size


class CollisionWorld:
    """Named collision objects at world transforms, with groups, and collision queries against them.

    ``against`` (which world objects a query tests) and ``ignore`` (which to leave out) take a group tag,
    an object name, or an iterable of them; ``against=None`` means every object.  Tokens that name no
    group and no object select nothing.  A query's own objects are never tested against each other or
    themselves: several names in one query act as one body (a robot's links and the object it holds).
    """

    #: how many selections (against × ignore × query objects) keep a broadphase manager
    MAX_SELECTIONS = 256

    def __init__(self, tolerance: float = TOLERANCE) -> None:
        import coal

        if tolerance < TOLERANCE:
            raise ValueError(f"tolerance must be >= {TOLERANCE:g} (coal reports overlaps as free below it)")
        self.tolerance = float(tolerance)
        self._entries: dict[str, _Entry] = {}
        self._groups: dict[str, set[str]] = {}
        self._by_gid: dict[int, str] = {}
        self._selections: dict[Any, _Selection] = {}
        self._version = 0  # bumped by every move; a selection refits its manager when it lags
        self._coal = coal
        # one callback stops at the first collision, the other collects every colliding pair
        self._first = self._callback(coal, 1)
        self._every = self._callback(coal, 1 << 30)

    def _callback(self, coal: Any, max_contacts: int) -> Any:
        request = coal.CollisionRequest()
        request.enable_contact = False
        request.security_margin = self.tolerance
        request.gjk_tolerance = GJK_TOLERANCE
        request.num_max_contacts = max_contacts
        callback = coal.CollisionCallBackDefault()
        callback.data.request = request
        return callback

    # ----------------------------------------------------------------------------------------- contents

    def add(self, name: str, geometry: ShapeLike, transform: np.ndarray, group: str = "fixed") -> None:
        """Add object ``name`` of ``geometry`` at ``transform`` (4×4, world frame) to ``group``."""
        if name in self._entries:
            raise ValueError(f"object '{name}' is already in the collision world")
        if name in self._groups or group in self._entries:
            raise ValueError(f"'{name if name in self._groups else group}' is both an object and a group")
        shape = collision_shape(geometry)
        geom = shape.coal_geometry.clone()  # its own geometry, so a contact's geometry id names the object
        geom.computeLocalAABB()
        t = np.array(transform, dtype=float)
        obj = self._coal.CollisionObject(geom, self._coal.Transform3s())
        _place(obj, t)
        self._entries[name] = _Entry(name, group, shape, obj, geom.id(), t)
        self._by_gid[geom.id()] = name
        self._groups.setdefault(group, set()).add(name)
        self._selections.clear()

    def remove(self, name: str) -> None:
        """Take object ``name`` out of the world."""
        self._selections.clear()  # first: managers hold raw pointers to the objects
        entry = self._entries.pop(name)
        del self._by_gid[entry.gid]
        members = self._groups[entry.group]
        members.discard(name)
        if not members:
            del self._groups[entry.group]

    def set_transform(self, name: str, transform: np.ndarray) -> None:
        """Move object ``name`` to ``transform`` (4×4, world frame)."""
        entry = self._entries[name]
        t = np.array(transform, dtype=float)
        entry.transform = t
        _place(entry.obj, t)
        self._version += 1

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
        entries = self._query_entries(names)
        manager = self._manager(against, ignore, tuple(e.name for e in entries))
        if manager is None:
            return False
        cb = self._first
        result = cb.data.result
        for e in entries:
            manager.collide(e.obj, cb)
            if result.isCollision():
                return True
        return False

    def colliding_with(self, names: str | Iterable[str], against: Against = None, ignore: Against = ()) -> set[str]:
        """The selected objects that any of the named world objects collides with."""
        entries = self._query_entries(names)
        manager = self._manager(against, ignore, tuple(e.name for e in entries))
        hits: set[str] = set()
        if manager is None:
            return hits
        own = {e.name for e in entries}
        result = self._every.data.result
        for e in entries:
            manager.collide(e.obj, self._every)
            if result.numContacts():
                self._collect(result, hits, own)
        return hits

    def distance(self, a: str, b: str) -> float:
        """Distance between two world objects; negative is a penetration depth (convex shapes)."""
        coal = self._coal
        result = coal.DistanceResult()
        return float(coal.distance(self._entries[a].obj, self._entries[b].obj, coal.DistanceRequest(), result))

    # ---------------------------------------------------------------------------------------- probes

    def probe_collides(self, shapes: Probe, against: Against = None, ignore: Against = ()) -> bool:
        """Does any shape of the probe ((shape, 4×4 transform) pairs, not in the world) hit a selected object?"""
        return self._probe_collides(shapes, against, ignore)

    def probe_hits(self, shapes: Probe, against: Against = None, ignore: Against = ()) -> set[str]:
        """The selected objects that some shape of the probe hits."""
        return self._probe_hits(shapes, against, ignore)

    def sweep_hits(self, probes: Iterable[Probe], against: Against = None, ignore: Against = ()) -> set[str]:
        """The union of the objects the probes hit (a swept volume given as configurations along a path)."""
        return self._probe_hits([pair for probe in probes for pair in probe], against, ignore)

    def batch_collides(
        self, shapes: Sequence[ShapeLike], transforms: np.ndarray, against: Against = None, ignore: Against = ()
    ) -> bool:
        """:meth:`probe_collides` for shapes ``L`` at ``transforms`` of shape (L, 4, 4) or (C, L, 4, 4)
        (C configurations of the same L links, as batched forward kinematics returns them)."""
        return self._probe_collides(_batch(shapes, transforms), against, ignore)

    def batch_hits(
        self, shapes: Sequence[ShapeLike], transforms: np.ndarray, against: Against = None, ignore: Against = ()
    ) -> set[str]:
        """:meth:`probe_hits` (or :meth:`sweep_hits` for C configurations) in the batched form."""
        return self._probe_hits(_batch(shapes, transforms), against, ignore)

    # -------------------------------------------------------------------------------------- internals

    def _probe_collides(
        self, shapes: Iterable[tuple[ShapeLike, np.ndarray]], against: Against, ignore: Against
    ) -> bool:
        manager = self._manager(against, ignore, ())
        if manager is None:
            return False
        cb = self._first
        result, collide = cb.data.result, manager.collide
        for shape, t in shapes:
            collide(_posed(shape, t), cb)  # the manager re-initialises the callback (clears its result) first
            if result.isCollision():
                return True
        return False

    def _probe_hits(
        self, shapes: Iterable[tuple[ShapeLike, np.ndarray]], against: Against, ignore: Against
    ) -> set[str]:
        manager = self._manager(against, ignore, ())
        hits: set[str] = set()
        if manager is None:
            return hits
        cb = self._every
        result, collide = cb.data.result, manager.collide
        for shape, t in shapes:
            collide(_posed(shape, t), cb)
            if result.numContacts():
                self._collect(result, hits)
        return hits

    def _collect(self, result: Any, hits: set[str], own: set[str] | None = None) -> None:
        """Add the world objects the contacts in ``result`` name (other than ``own``) to ``hits``."""
        by_gid = self._by_gid
        for contact in result.getContacts():
            for geometry in (contact.o1, contact.o2):
                name = by_gid.get(geometry.id())
                if name is not None and (own is None or name not in own):
                    hits.add(name)

    def _query_entries(self, names: str | Iterable[str]) -> list[_Entry]:
        if isinstance(names, str):
            names = (names,)
        return [self._entries[n] for n in names]

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

    def _manager(self, against: Against, ignore: Against, exclude: tuple[str, ...]) -> Any:
        """The broadphase manager of the selected objects (None when nothing is selected), refit if stale."""
        key = (
            against if against is None or isinstance(against, str) else frozenset(against),
            ignore if isinstance(ignore, str) else frozenset(ignore or ()),
            exclude,
        )
        sel = self._selections.get(key)
        if sel is None:
            chosen = self._tokens(against) - self._tokens(ignore) - set(exclude)
            manager = self._coal.DynamicAABBTreeCollisionManager()
            for name, entry in self._entries.items():  # insertion order: deterministic trees
                if name in chosen:
                    manager.registerObject(entry.obj)
            manager.setup()
            if len(self._selections) >= self.MAX_SELECTIONS:
                del self._selections[next(iter(self._selections))]
            sel = self._selections[key] = _Selection(manager, self._version, len(chosen))
        elif sel.version != self._version:
            sel.manager.update()
            sel.version = self._version
        return sel.manager if sel.size else None


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


def _batch(shapes: Sequence[ShapeLike], transforms: np.ndarray) -> list[tuple[CollisionShape, np.ndarray]]:
    t = np.asarray(transforms, dtype=float)
    links = [collision_shape(s) for s in shapes]
    if t.shape[-3:] != (len(links), 4, 4):
        raise ValueError(f"transforms of shape {t.shape} do not match {len(links)} shapes")
    flat = t.reshape(-1, 4, 4)
    return list(zip(links * (len(flat) // max(1, len(links))), flat))


def _posed(shape: ShapeLike, t: np.ndarray) -> Any:
    """The shape's probe object moved to ``t`` (4×4), its bounding box refreshed (coal trap: without
    ``computeAABB`` after a move the broadphase silently works on the old box)."""
    obj = (shape if type(shape) is CollisionShape else collision_shape(shape)).coal_object
    t = np.asarray(t, dtype=float)
    obj.setRotation(t[:3, :3])
    obj.setTranslation(t[:3, 3])
    obj.computeAABB()
    return obj
