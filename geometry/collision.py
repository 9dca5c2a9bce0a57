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
