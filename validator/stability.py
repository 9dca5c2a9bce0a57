"""Whether a released object stands: the support polygon of its contacts and its centre of mass over it; and
how a planar robot (a cart) sets a box down.  The validator's own reading, in plain numpy.

This module is the validator's (it shares nothing with the planner's search or grounding, nor with coal or
pybullet): shapes are :mod:`mrgc.language.model`'s, poses 4×4 world transforms, mesh files read by
:mod:`mrgc.geometry.meshes`.

**Support polygon** (:func:`stability`).  The object's *lowest face* is the part of it within
:data:`FACE_TOL` of its lowest point, measured in its own frame when it stands upright (its z axis within
:data:`FLAT_TOL` of the vertical): a box's bottom rectangle, a cylinder's bottom disc (a regular
:data:`CIRCLE_POINTS`-gon inscribed in it: at most 0.12 % of the radius inside the circle, on the safe side),
a mesh's lowest vertices, a sphere's lowest point (a point contact).  A *supporter* is a fixed or movable
object whose *top face* (the same construction at its highest point), or a region whose *floor* (its
lowest face: a region's floor is a surface whatever lies under it, as for ``[floating]``), lies within
:data:`SUPPORT_TOL` of the object's lowest point, above or below (what lies within that distance under the
object counts as touching, as in :mod:`mrgc.validator.replay`; an object sunk into its supporter is still held
up by it, and the sinking is a collision reported on its own), and whose face overlaps the object's lowest
face in the horizontal plane.  Its *contact patch* is that overlap (two convex polygons clipped, or a point
or an edge where either is one), and the *support polygon* is the convex hull of every patch: a bridge
over two supports spans the gap between them.

**Stable** means: the object rests flat (an object tilted beyond :data:`FLAT_TOL` touches on an edge or a
corner: not flat, never stable), it has a supporter, and the horizontal projection of its centre of mass
(its shape's centroid, uniform density: a box's, cylinder's or sphere's centre, a mesh's volume centroid)
lies inside the support polygon at least the *required margin* from its edge.  The margin achieved is the
signed distance from that point to the polygon's boundary: positive inside, negative outside (minus the
distance to the polygon), minus infinity without a supporter.

**The required margin** is ``min(MARGIN, MARGIN_SHARE × the object's smaller footprint side)``: 5 mm, or 5 %
of the smaller side of a small object (a 4 cm cube needs 2 mm), and 0 for a sphere (a ball on a flat top
is in neutral equilibrium: its centre is always above its contact point; it must only touch a top face).
A margin within :data:`EPS` (1 nm) of the required one passes: for a ball it is 0 up to rounding.
Why 5 mm: a centre of mass on the polygon's edge is the tipping point itself, so some margin is needed
for a verdict that does not flip with noise, and 5 mm covers what the validator lets a release pose be off
by (1 mm in position; 0.01 rad of tilt moves the centre of mass of a 0.3 m box 1.5 mm sideways; the
cylinder's polygon 0.1 mm) with room to spare, while a 0.3 m box still needs to be pushed 1.9° over
before it falls (``atan(5 / 150)``).  The share keeps the test meaningful for small objects, for which
5 mm would be a large part of their width.

**A rounded bottom** (a mesh: :func:`_rolls`).  A mesh's lowest face is what lies within 1 mm of its lowest
point, which for a rounded bottom is a small disc that can hold the centre of mass (a test tube on its round
end: a 4.9 mm disc, the centre of mass 1.2 mm inside it).  So a mesh that stands by the polygon is also tilted
in 16 directions by 0.01 to 0.16 rad, about its centre of mass, and must right itself at one of those tilts
in every direction: a contact with a horizontal floor farther along the tilt than its centre of mass.  A flat
bottom tilts onto its edge; a rounded one of radius R rolls over when its centre of mass lies higher than R
above its lowest point (message: ``{obj} would roll over on {supporters}: tilted toward (x, y), its centre of
mass passes beyond its contact with them (a rounded bottom under a high centre of mass)``).  Boxes, cylinders
and spheres need no such test (a flat face, or neutral equilibrium).

**Messages** (:meth:`Stability.message`; the replay reports an unstable verdict as ``[unstable]`` with the
object as subject).  Distances in mm with one decimal, supporters sorted and joined by ", " (a region's
floor named ``floor of R``), the tilt in degrees with one decimal:

- centre of mass outside the polygon:
  ``{obj} would topple: its centre of mass lies {-margin} mm outside the support polygon of its contacts
  with {supporters} (it must lie at least {required} mm inside)``, e.g. ``o2 would topple: its centre of
  mass lies 63.6 mm outside the support polygon of its contacts with o1 (it must lie at least 5.0 mm
  inside)``;
- inside but too near the edge: the same with ``lies only {margin} mm inside the support polygon``, and
  exactly on its edge (a box balanced on a ball's top point) ``lies on the edge of the support polygon``;
- tilted: ``{obj} is set down tilted {degrees} degrees from upright on {supporters}: it touches them on an
  edge or a corner, not flat on its lowest face (tolerance 0.01 rad)``;
- nothing under it: ``{obj} rests on nothing: nothing lies within 10 mm under its lowest face``;
- stable: ``{obj} stands on {supporters}, its centre of mass {margin} mm inside the support polygon``.

**Carts** (:func:`cart_set_down`).  A planar robot carries its box upright (its ``:carry`` pose, or its
place on top of the footprint, turns about z only: :mod:`mrgc.geometry.planar`) and, placing it, lowers it
onto the floor it drives on, the plane of its base poses (z = 0: a base pose has no height), "the pick
geometry in reverse" of the planar model.  So the place pose has no roll or pitch (within the validator's
rotation tolerance), and the box's lowest point stands on that floor: no lower than the position tolerance
below it, no higher than :data:`SUPPORT_TOL` above it (the band in which the validator counts an object as
resting on a floor; the planar model's own placements float 1 mm up, ``PLANAR_LIFT``, the planner's 6 mm,
``ARM_PLACE_LIFT``, which its grounding uses for every placement).  A cart has no lift: it cannot set a box
down on another box or a table.  The messages (reported as ``[placement]`` with the robot as subject):
``{robot} sets {obj} down tilted {degrees} degrees ({rad} rad) from upright; it carries it upright and lowers
it so onto the floor (tolerance {rot_tol} rad)`` and ``{robot} sets {obj} down with its lowest point {d} mm
above (or below) the floor it drives on (z = 0); a cart lowers what it carries onto that floor: 0 to 10 mm
above it (tolerance {pos_tol} mm below)``.

**From the replay**: after a step, for each placed object ``o``, ``stability(o, shape of o, pose of o,
{every fixed and movable object: (shape, current pose)}, [(region name, shape, pose) for every region])``;
the supporter names are those of ``[floating]`` (objects, and ``floor of R``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from mrgc.geometry.meshes import read_mesh
from mrgc.geometry.scene import half_extents, outline
from mrgc.language.model import Box, Cylinder, Mesh, Shape, Sphere

Array = NDArray[np.float64]

#: m: what lies within this distance under (or over) a released object's lowest point counts as touching it
#: (the replay's SUPPORT_TOL)
SUPPORT_TOL = 0.01
#: m: a body's lowest (top) face is what lies within this of its lowest (highest) point
FACE_TOL = 1e-3
#: rad: an object whose z axis leans farther from the vertical than this is tilted (not resting flat)
FLAT_TOL = 0.01
#: m: the margin the centre of mass must keep inside the support polygon ...
MARGIN = 5e-3
#: ... or this share of the object's smaller footprint side, if that is less
MARGIN_SHARE = 0.05
#: vertices of the polygon inscribed in a cylinder's disc
CIRCLE_POINTS = 64
#: m: points this close count as one, a point this close to a polygon as on it
EPS = 1e-9
#: m²: three points spanning less than this (twice the triangle's area) are collinear
AREA_EPS = 1e-15
#: directions a mesh is tilted in to see whether it rolls over (:func:`_rolls`) ...
ROLL_DIRECTIONS = 16
#: ... and the tilts (rad), the first :data:`FLAT_TOL`
ROLL_TILTS = (FLAT_TOL, 0.02, 0.04, 0.08, 0.16)
#: m: a tilted mesh touches the floor at the points this close to its lowest one
CONTACT_EXACT = 1e-6


@dataclass(frozen=True)
class Stability:
    """Whether object ``obj`` stands where it was released.

    ``stable``: flat, supported, and its centre of mass at least ``required`` inside the support polygon;
    ``flat``: its z axis within :data:`FLAT_TOL` of the vertical (``tilt``, rad, is the angle between them;
    0 for a sphere); ``margin`` (m): the signed distance from the centre of mass's horizontal projection
    ``com`` to the support polygon's boundary, positive inside, negative outside, ``-inf`` with no
    supporter; ``required`` (m): the margin it needs; ``supporters``: the names of what it touches (region
    floors as ``floor of R``), sorted; ``polygon``: the support polygon's vertices (x, y), counter-clockwise
    (one point or two for a point or edge contact, none without a supporter)."""

    obj: str
    stable: bool
    flat: bool
    tilt: float
    margin: float
    required: float
    supporters: tuple[str, ...]
    polygon: tuple[tuple[float, float], ...]
    com: tuple[float, float]
    load: tuple[str, ...] = ()
    #: a mesh whose bottom is rounded: tilted in this direction (x, y), its centre of mass passes beyond its new
    #: contact with the floor, so the tilt grows (None: it rights itself every way; :func:`_rolls`)
    rolls: tuple[float, float] | None = None

    def message(self) -> str:
        """The verdict in one line (the formats of the module docstring)."""
        on = ", ".join(self.supporters)
        if not self.supporters:
            return f"{self.obj} rests on nothing: nothing lies within {SUPPORT_TOL * 1e3:g} mm under its lowest face"
        if self.rolls is not None:
            dx, dy = self.rolls
            return (
                f"{self.obj} would roll over on {on}: tilted toward ({dx:.2f}, {dy:.2f}), its centre of mass passes "
                f"beyond its contact with them (a rounded bottom under a high centre of mass)"
            )
        if not self.flat:
            return (
                f"{self.obj} is set down tilted {math.degrees(self.tilt):.1f} degrees from upright on {on}: it "
                f"touches them on an edge or a corner, not flat on its lowest face (tolerance {FLAT_TOL:g} rad)"
            )
        if self.stable:
            return (
                f"{self.obj} stands on {on}, its centre of mass {self.margin * 1e3:.1f} mm inside the support polygon"
            )
        if self.margin > 0:
            where = f"lies only {self.margin * 1e3:.1f} mm inside"
        elif self.margin < 0:
            where = f"lies {-self.margin * 1e3:.1f} mm outside"
        else:
            where = "lies on the edge of"
        whose = "its centre of mass" if not self.load else f"the centre of mass of it and {', '.join(self.load)} on it"
        return (
            f"{self.obj} would topple: {whose} {where} the support polygon of its contacts with "
            f"{on} (it must lie at least {self.required * 1e3:.1f} mm inside)"
        )


def stability(
    obj: str,
    shape: Shape,
    pose: Array,
    bodies: Mapping[str, tuple[Shape, Array]],
    floors: Sequence[tuple[str, Shape, Array]] = (),
    load: Mapping[str, tuple[Shape, Array]] | None = None,
) -> Stability:
    """Whether ``obj`` (of ``shape`` at world ``pose``, 4×4) stands on what is under it: ``bodies`` (name ->
    shape and world pose of every fixed and movable object it may rest on; ``obj`` itself and the ``load``
    are skipped) and the floors of ``floors`` (regions: name, shape, world pose).  ``load``: the objects
    that stand on ``obj`` alone (directly or through each other): their weight is its weight, so the centre
    of mass judged is that of ``obj`` and its load together (uniform density, each weighted by its volume).
    A value for every geometric outcome (tilted, unsupported, toppling); never raises for one."""
    pose = np.asarray(pose, dtype=float)
    tilt = 0.0 if isinstance(shape, Sphere) else _tilt(pose)
    flat = tilt <= FLAT_TOL
    bottom, low = _face(shape, pose, top=False)
    names: list[str] = []
    patches: list[Array] = []
    load = load or {}
    faces = [
        (name, *_face(s, np.asarray(p, dtype=float), top=True))
        for name, (s, p) in bodies.items()
        if name != obj and name not in load
    ]
    faces += [(f"floor of {name}", *_face(s, np.asarray(p, dtype=float), top=False)) for name, s, p in floors]
    for name, face, height in faces:
        if abs(low - height) > SUPPORT_TOL or not _boxes_meet(bottom, face):
            continue
        patch = _patch(bottom, face)
        if len(patch):
            names.append(name)
            patches.append(patch)
    polygon = _hull(np.vstack(patches)) if patches else np.zeros((0, 2))
    parts = [(shape, pose), *((s, np.asarray(p, dtype=float)) for s, p in load.values())]
    weights = np.array([_volume(s) for s, _ in parts])
    centres = np.array([(p @ np.append(_centroid(s), 1.0))[:2] for s, p in parts])
    com = weights @ centres / weights.sum() if weights.sum() > 0 else centres[0]
    margin = _signed_distance(com, polygon)
    required = _required(shape)
    standing = bool(flat and names and margin >= required - EPS)  # on the edge within EPS: a ball on its point
    rolls = None
    if standing and isinstance(shape, Mesh):
        centres3 = np.array([(p @ np.append(_centroid(s), 1.0))[:3] for s, p in parts])
        rolls = _rolls(shape, pose, weights @ centres3 / weights.sum() if weights.sum() > 0 else centres3[0])
    return Stability(
        obj=obj,
        stable=standing and rolls is None,
        rolls=rolls,
        flat=flat,
        tilt=tilt,
        margin=margin,
        required=required,
        supporters=tuple(sorted(names)),
        polygon=tuple((float(x), float(y)) for x, y in polygon),
        com=(float(com[0]), float(com[1])),
        load=tuple(sorted(load)),
    )


def cart_set_down(obj: str, shape: Shape, pose: Array, robot: str, rot_tol: float, pos_tol: float) -> list[str]:
    """What is wrong with planar ``robot`` releasing ``obj`` (of ``shape``) at world ``pose`` (module
    docstring, "Carts"), one message per fault (none: nothing): a tilt beyond ``rot_tol`` (rad), a lowest point
    more than ``pos_tol`` (m) below the floor the robot drives on or more than :data:`SUPPORT_TOL` above it."""
    pose = np.asarray(pose, dtype=float)
    out = []
    tilt = 0.0 if isinstance(shape, Sphere) else _tilt(pose)
    if tilt > rot_tol:
        out.append(
            f"{robot} sets {obj} down tilted {math.degrees(tilt):.1f} degrees ({tilt:.3f} rad) from upright; it "
            f"carries it upright and lowers it so onto the floor (tolerance {rot_tol:g} rad)"
        )
    low = lowest(shape, pose)
    if not -pos_tol <= low <= SUPPORT_TOL:
        where = f"{low * 1e3:.1f} mm above" if low >= 0 else f"{-low * 1e3:.1f} mm below"
        out.append(
            f"{robot} sets {obj} down with its lowest point {where} the floor it drives on (z = 0); a cart lowers "
            f"what it carries onto that floor: 0 to {SUPPORT_TOL * 1e3:g} mm above it (tolerance "
            f"{pos_tol * 1e3:g} mm below)"
        )
    return out


def lowest(shape: Shape, pose: Array) -> float:
    """The world height (m) of the lowest point of ``shape`` at ``pose``, at any orientation (a mesh: of its
    vertices)."""
    r, c = pose[:3, :3], pose[:3, 3]
    if isinstance(shape, Sphere):
        return float(c[2] - shape.radius)
    if isinstance(shape, Cylinder):  # the axis's lower end, then the rim's lowest point
        up = abs(float(r[2, 2]))
        return float(c[2] - shape.height / 2 * up - shape.radius * math.sqrt(max(0.0, 1.0 - up * up)))
    return float((_points(shape) @ r[2]).min() + c[2])


# ------------------------------------------------------------------------------------- shapes


def _tilt(pose: Array) -> float:
    """The angle (rad) between the body's z axis and the vertical."""
    return math.acos(min(1.0, max(-1.0, float(pose[2, 2]))))


def _points(shape: Shape) -> Array:
    """Points of ``shape`` (own frame) whose convex hull is it, or inscribed in it: a box's corners, a
    cylinder's rims as polygons, a mesh's vertices, a sphere's poles (its faces are taken apart)."""
    if isinstance(shape, Cylinder):
        a = np.linspace(0.0, 2 * math.pi, CIRCLE_POINTS, endpoint=False)
        ring = np.stack([shape.radius * np.cos(a), shape.radius * np.sin(a)], axis=1)
        half = shape.height / 2
        rims: Array = np.vstack(
            [np.column_stack([ring, np.full(len(a), -half)]), np.column_stack([ring, np.full(len(a), half)])]
        )
        return rims
    if isinstance(shape, Sphere):
        return np.array([[0.0, 0.0, -shape.radius], [0.0, 0.0, shape.radius]])
    points: Array = np.asarray(outline(shape), dtype=float)  # a box's corners, a mesh's vertices
    return points


def _face(shape: Shape, pose: Array, top: bool) -> tuple[Array, float]:
    """The top (or lowest) face of ``shape`` at ``pose``: its points' world (x, y) and its world height (the
    highest, or lowest, of them).  Chosen in the body's frame when it stands upright (a face of it), else
    in the world (a tilted body's edge or corner)."""
    if isinstance(shape, Sphere):
        c = pose[:3, 3]
        return c[None, :2].copy(), float(c[2] + (shape.radius if top else -shape.radius))
    local = _points(shape)
    world = local @ pose[:3, :3].T + pose[:3, 3]
    key = local[:, 2] if _tilt(pose) <= FLAT_TOL else world[:, 2]
    sign = 1.0 if top else -1.0
    chosen = world[sign * key >= float((sign * key).max()) - FACE_TOL]
    height = float(chosen[:, 2].max() if top else chosen[:, 2].min())
    return chosen[:, :2], height


def _rolls(shape: Mesh, pose: Array, com: Array) -> tuple[float, float] | None:
    """A direction (x, y) in which ``shape`` at ``pose``, standing with its centre of mass at ``com`` (world,
    3D), rolls over, or None when it rights itself every way (:data:`ROLL_DIRECTIONS` directions).  Tilted by
    an angle (about a horizontal axis through its centre of mass) it touches a horizontal floor at its lowest
    points (within :data:`CONTACT_EXACT`); gravity turns it back iff one of them lies farther in the direction
    of the tilt than the centre of mass.  It rolls over in a direction when that fails at every one of
    :data:`ROLL_TILTS`: a flat bottom tilts onto its edge on that side, well ahead of the centre of mass; a
    rounded one (radius R, centre of mass h above its lowest point) touches about R x tilt ahead of the old
    contact while the centre of mass moves h x tilt, so it rolls over when h > R, as a test tube standing on
    its round end does.  The larger tilts carry the contact across the facets of a tessellated curve (a mesh
    standing on one vertex tilts about it until the next ring of vertices touches)."""
    world = _points(shape) @ pose[:3, :3].T + pose[:3, 3] - com
    for k in range(ROLL_DIRECTIONS):
        a = 2 * math.pi * k / ROLL_DIRECTIONS
        d = np.array([math.cos(a), math.sin(a), 0.0])
        axis = np.array([-d[1], d[0], 0.0])  # z x d: the top moves toward d
        if not any(_rights_itself(world @ _rotation(axis, tilt).T, d) for tilt in ROLL_TILTS):
            return (float(d[0]), float(d[1]))
    return None


def _rights_itself(points: Array, d: Array) -> bool:
    """Whether a body whose points (relative to its centre of mass) are ``points`` rests on a floor with a
    contact farther along ``d`` than its centre of mass (gravity then turns it back against ``d``)."""
    low = points[:, 2] <= float(points[:, 2].min()) + CONTACT_EXACT
    return float((points[low] @ d).max()) > 0.0


def _rotation(axis: Array, angle: float) -> Array:
    """The rotation by ``angle`` about unit ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    out: Array = np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)
    return out


@functools.lru_cache(maxsize=256)
def _mesh_centroid(mesh: Mesh) -> tuple[float, float, float]:
    """The volume centroid of a closed triangle mesh (uniform density), by the divergence theorem over the
    tetrahedra its triangles span with the origin; the mean of its vertices when it encloses no volume."""
    v, f = read_mesh(mesh.path)
    v = np.asarray(v, dtype=float) * mesh.scale
    if not len(v):
        return (0.0, 0.0, 0.0)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    total = float(vol.sum())
    size = float(np.ptp(v, axis=0).max())
    if abs(total) <= 1e-9 * size**3:
        mean = v.mean(axis=0)
        return (float(mean[0]), float(mean[1]), float(mean[2]))
    centre = (vol[:, None] * (a + b + c)).sum(axis=0) / (4.0 * total)
    return (float(centre[0]), float(centre[1]), float(centre[2]))


def _volume(shape: Shape) -> float:
    """The shape's volume (a mesh: its bounding box's, a documented approximation of its weight)."""
    if isinstance(shape, Box):
        return float(shape.sx * shape.sy * shape.sz)
    if isinstance(shape, Cylinder):
        return float(math.pi * shape.radius**2 * shape.height)
    if isinstance(shape, Sphere):
        return float(4.0 / 3.0 * math.pi * shape.radius**3)
    return float(np.prod(2 * half_extents(shape)))


def _centroid(shape: Shape) -> Array:
    """The centre of mass of ``shape`` in its own frame (uniform density)."""
    if isinstance(shape, Mesh):
        return np.array(_mesh_centroid(shape))
    return np.zeros(3)


def _required(shape: Shape) -> float:
    """The margin (m) ``shape``'s centre of mass must keep inside its support polygon (module docstring)."""
    if isinstance(shape, Sphere):
        return 0.0
    if isinstance(shape, Box):
        side = min(shape.sx, shape.sy)
    elif isinstance(shape, Cylinder):
        side = 2 * shape.radius
    else:
        side = float(np.ptp(_points(shape)[:, :2], axis=0).min())
    return min(MARGIN, MARGIN_SHARE * side)


# ------------------------------------------------------------------------------------- plane geometry


def _cross(o: Array, a: Array, b: Array) -> float:
    """Twice the signed area of triangle o, a, b (positive: counter-clockwise)."""
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _distinct_rows(pts: Array) -> Array:
    """The distinct rows of (N, 2) ``pts``, sorted by x, then y (``np.unique(pts, axis=0)``, which loads
    numpy.ma: 7 ms of a small plan's validation)."""
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = (pts[1:] != pts[:-1]).any(axis=1)
    out: Array = pts[keep]
    return out


def _hull(points: Array) -> Array:
    """The convex hull of (x, y) ``points``, counter-clockwise without collinear vertices (Andrew's monotone
    chain): one row for a point, two for a segment, none for no points."""
    pts = _distinct_rows(np.round(np.asarray(points, dtype=float).reshape(-1, 2), 12))
    if len(pts) <= 2:
        return pts

    def chain(seq: Array) -> list[Array]:
        out: list[Array] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= AREA_EPS:
                out.pop()
            out.append(p)
        return out

    lower, upper = chain(pts), chain(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _boxes_meet(a: Array, b: Array) -> bool:
    """Whether the axis-aligned bounding boxes of point sets ``a`` and ``b`` overlap (within EPS)."""
    return bool(np.all(a.min(axis=0) <= b.max(axis=0) + EPS) and np.all(b.min(axis=0) <= a.max(axis=0) + EPS))


def _clip(subject: Array, clip: Array) -> Array:
    """The part of convex polygon (or point, or segment) ``subject`` inside convex polygon ``clip`` (at least
    three counter-clockwise vertices), by Sutherland and Hodgman's clipping."""
    out = list(subject)
    for i in range(len(clip)):
        a, b = clip[i], clip[(i + 1) % len(clip)]
        length = float(np.hypot(*(b - a)))
        src, out = out, []
        for j, cur in enumerate(src):
            prev = src[j - 1]
            dc, dp = _cross(a, b, cur) / length, _cross(a, b, prev) / length  # signed distances, + inside
            if dc >= -EPS:
                if dp < -EPS:
                    out.append(prev + (cur - prev) * (dp / (dp - dc)))
                out.append(cur)
            elif dp >= -EPS:
                out.append(prev + (cur - prev) * (dp / (dp - dc)))
        if not out:
            break
    return np.array(out).reshape(-1, 2)


def _patch(bottom: Array, top: Array) -> Array:
    """Where an object's lowest face (x, y points) and a supporter's face overlap: points whose hull is the
    contact patch (none when they do not meet)."""
    b, t = _hull(bottom), _hull(top)
    if len(t) >= 3:
        return _clip(b, t)
    if len(b) >= 3:
        return _clip(t, b)
    # both a point or a segment: the points of each on the other, and where two segments cross
    out = [p for p in b if _segment_distance(p, t) <= EPS] + [p for p in t if _segment_distance(p, b) <= EPS]
    if len(b) == 2 and len(t) == 2:
        d1, d2 = _cross(t[0], t[1], b[0]), _cross(t[0], t[1], b[1])
        d3, d4 = _cross(b[0], b[1], t[0]), _cross(b[0], b[1], t[1])
        if d1 * d2 < 0 and d3 * d4 < 0:
            out.append(b[0] + (b[1] - b[0]) * (d1 / (d1 - d2)))
    return np.array(out).reshape(-1, 2)


def _segment_distance(p: Array, seg: Array) -> float:
    """Distance from point ``p`` to a point or segment (one or two rows)."""
    if len(seg) == 1:
        return float(np.hypot(*(p - seg[0])))
    a, b = seg[0], seg[1]
    d = b - a
    s = min(1.0, max(0.0, float(np.dot(p - a, d) / max(float(np.dot(d, d)), EPS * EPS))))
    return float(np.hypot(*(p - (a + s * d))))


def _signed_distance(c: Array, polygon: Array) -> float:
    """Signed distance (m) from point ``c`` to the boundary of convex ``polygon`` (counter-clockwise): positive
    inside, negative outside; for a point or segment minus the distance to it; ``-inf`` for no polygon."""
    if not len(polygon):
        return -math.inf
    if len(polygon) <= 2:
        return 0.0 - _segment_distance(c, polygon)  # 0.0 -: no negative zero
    n = len(polygon)
    edges = [(polygon[i], polygon[(i + 1) % n]) for i in range(n)]
    inside = [_cross(a, b, c) / float(np.hypot(*(b - a))) for a, b in edges]
    if min(inside) >= 0.0:
        return min(inside)
    return 0.0 - min(_segment_distance(c, np.array([a, b])) for a, b in edges)
