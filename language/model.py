"""The checked problem: what a ``.mrg`` file *means*, in typed frozen dataclasses.

Every later layer (geometry, compiler, planner) reads these objects and nothing of the syntax tree.  Units
are SI (metres); ``Pose.yaw`` is in degrees as written, ``Pose.yaw_rad`` in radians.  A problem is either
*symbolic* (no geometry; its facts are stated in ``:init``) or *geometric* (shapes and poses; facts are
computed by the geometry layer, or read from a completed ``:init`` written by ``mrgc facts``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Union

from mrgc.errors import Span
from mrgc.language.ast import NOWHERE

# The predicates: name -> sorts of the arguments, in order.  The paper's six, ``enable-relay`` (beyond
# the paper: a goal object set down on its way and picked up again, in a region or on the top of a fixed
# object, a "surface"; docs/language.md), ``occludes-handover`` (beyond the paper: an object in the way
# of the two arms at the exchange of a handover) and ``occludes-relay`` (beyond the paper: an object in the
# way at a relay's spot).
PREDICATES: dict[str, tuple[str, ...]] = {
    "in-region": ("movable", "region"),
    "reachable-pick": ("movable", "grasp", "robot"),
    "reachable-place": ("movable", "region", "grasp", "robot"),
    "occludes-pick": ("movable", "movable", "grasp", "robot"),
    "occludes-goal-place": ("movable", "movable", "region", "grasp", "robot"),
    "enable-goal-handover": ("movable", "grasp", "grasp", "robot", "robot"),
    "enable-relay": ("movable", "surface", "grasp", "grasp", "robot", "robot"),
    "occludes-handover": ("movable", "movable", "grasp", "grasp", "robot", "robot"),
    "occludes-relay": ("movable", "movable", "surface", "grasp", "grasp", "robot", "robot"),
}

#: words users write for a predicate -> the predicates they mean (E220's "did you mean"; a word that is a
#: part of predicate names, like ``reachable``, needs no entry: every predicate holding it is suggested)
PREDICATE_WORDS: dict[str, tuple[str, ...]] = {
    "handover": ("enable-goal-handover",),
    "hand-over": ("enable-goal-handover",),
    "handoff": ("enable-goal-handover",),
    "can-handover": ("enable-goal-handover",),
    "in": ("in-region",),
    "at": ("in-region",),
    "on": ("in-region",),
    "inside": ("in-region",),
    "pick": ("reachable-pick",),
    "can-pick": ("reachable-pick",),
    "graspable": ("reachable-pick",),
    "place": ("reachable-place",),
    "can-place": ("reachable-place",),
    "placeable": ("reachable-place",),
    "blocks": ("occludes-pick", "occludes-goal-place"),
    "obstructs": ("occludes-pick", "occludes-goal-place"),
    "blocks-handover": ("occludes-handover",),
    "occludes-exchange": ("occludes-handover",),
    "blocks-relay": ("occludes-relay",),
    "occludes-spot": ("occludes-relay",),
    "blocks-pick": ("occludes-pick",),
    "blocks-place": ("occludes-goal-place",),
    "occludes-place": ("occludes-goal-place",),
    "relay": ("enable-relay",),
    "regrasp": ("enable-relay",),
    "re-grasp": ("enable-relay",),
    "set-down": ("enable-relay",),
    "setdown": ("enable-relay",),
    "put-down": ("enable-relay",),
    "can-relay": ("enable-relay",),
}

#: requirement flags a domain may declare (informational; see docs/language.md)
REQUIREMENTS: tuple[str, ...] = ("handover", "planar-base", "symbolic")

BASE_TYPES: tuple[str, ...] = ("fixed", "planar")

Axis = tuple[float, float, float]

#: axis word -> unit vector in the object frame (``x`` is ``+x``)
AXES: dict[str, Axis] = {
    f"{sign}{name}": tuple(float(s * (i == k)) for i in range(3))  # type: ignore[misc]
    for k, name in enumerate("xyz")
    for sign, s in (("+", 1), ("-", -1), ("", 1))
}

DEFAULT_GRASP_DEPTH = 0.02  # m the tool centre point sits inside the face it approaches
DEFAULT_GRIPPER_OPENING = 0.08  # m: a Franka Panda's fingers open 2 × 4 cm


def _span() -> Span:
    return field(default=NOWHERE, compare=False, repr=False)


@dataclass(frozen=True)
class Pose:
    """A planar-yaw pose: position (x, y, z) in metres and rotation ``yaw`` about +z in degrees."""

    x: float
    y: float
    z: float
    yaw: float = 0.0

    @property
    def yaw_rad(self) -> float:
        """The yaw in radians."""
        return math.radians(self.yaw)

    @property
    def position(self) -> tuple[float, float, float]:
        """``(x, y, z)``."""
        return (self.x, self.y, self.z)


@dataclass(frozen=True)
class Box:
    """An axis-aligned box (in its own frame) with full side lengths, centred on its pose."""

    sx: float
    sy: float
    sz: float


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along its local z axis, centred on its pose."""

    radius: float
    height: float


@dataclass(frozen=True)
class Sphere:
    """A sphere centred on its pose."""

    radius: float


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh file (OBJ/STL), ``path`` resolved relative to the declaring file, scaled uniformly."""

    path: str
    scale: float = 1.0


Shape = Union[Box, Cylinder, Sphere, Mesh]


@dataclass(frozen=True)
class GraspSpec:
    """What a grasp means geometrically, in the frame of the object grasped (docs/geometry.md, "Grasps").

    ``approach`` is the direction the tool moves into the object, ``fingers`` the axis the fingers close
    along (unit axis vectors, perpendicular); the tool centre point sits ``depth`` metres inside the face
    the tool approaches, moved by ``offset`` (object frame).  How a spec becomes a tool pose and a finger
    opening is :mod:`mrgc.geometry.grasps`.  ``builtin`` marks the specs of :data:`BUILTIN_GRASPS`.
    """

    name: str
    approach: Axis
    fingers: Axis
    depth: float = DEFAULT_GRASP_DEPTH
    offset: Axis = (0.0, 0.0, 0.0)
    builtin: bool = False
    span: Span = _span()

    def describe(self) -> str:
        """``approach -z, fingers +y, depth 0.02`` (and the offset when there is one)."""
        words = {v: w for w, v in AXES.items() if w[0] in "+-"}
        text = f"approach {words[self.approach]}, fingers {words[self.fingers]}, depth {self.depth:g}"
        return text + (f", offset ({' '.join(f'{x:g}' for x in self.offset)})" if any(self.offset) else "")


def _builtin(name: str, approach: str, fingers: str) -> GraspSpec:
    return GraspSpec(name, AXES[approach], AXES[fingers], builtin=True)


#: the built-in grasps: what a bare name in ``(:grasps ...)`` means
BUILTIN_GRASPS: dict[str, GraspSpec] = {
    g.name: g
    for g in (
        _builtin("top", "-z", "+y"),  # from above, fingers closing along y
        _builtin("top-x", "-z", "+x"),  # from above, the wrist turned 90 degrees: fingers closing along x
        _builtin("side-x+", "-x", "+y"),  # from the +x side
        _builtin("side-x-", "+x", "+y"),
        _builtin("side-y+", "-y", "+x"),
        _builtin("side-y-", "+y", "+x"),
    )
}


@dataclass(frozen=True)
class RobotKind:
    """A kind of robot: its URDF, base type, end-effector link and home configuration.

    ``base`` is ``fixed`` (arm bolted to its base pose) or ``planar`` (x, y, yaw driven base).  A planar
    kind may give a ``footprint`` shape and the ``carry`` pose of a held object relative to its base.
    ``tcp`` is the tool centre point (between the fingertips) relative to the end-effector link, ``reach``
    an upper bound on the distance from the base at which the arm can place its tool centre point,
    ``gripper_opening`` the widest the fingers open (metres between them).
    """

    name: str
    urdf: str | None = None
    base: str = "fixed"
    end_effector: str | None = None
    home: tuple[float, ...] = ()
    footprint: Shape | None = None
    carry: Pose | None = None
    reach: float | None = None
    tcp: Pose | None = None
    gripper_opening: float = DEFAULT_GRIPPER_OPENING
    source: str = field(default="", compare=False)
    span: Span = _span()
    #: folder trees the URDF's mesh files may come from besides pybullet_data (empty: anywhere); the
    #: loader sets the problem file's tree and the ``--allow-outside`` folders
    roots: tuple[str, ...] = field(default=(), compare=False)
    #: where ``:home`` is written (the layout checks point there)
    home_span: Span = _span()

    @property
    def driven(self) -> bool:
        """Whether its robots are driven over the floor (``:base planar``: a cart with a footprint, carrying
        what it holds on its base, every motion a drive) rather than an arm bolted in place (``fixed``: a URDF,
        picks and places by IK).  The one reading of :data:`BASE_TYPES` for the layers that may not reach the
        geometry's robots (the compiler's drivers, the validator's replay world); the geometry asks its robot
        classes (``geometry/kinds.py``: :func:`~mrgc.geometry.kinds.approaches`)."""
        return self.base == "planar"


@dataclass(frozen=True)
class Domain:
    """A domain: requirement flags, robot kinds and the grasp vocabulary shared by its problems.

    ``grasp_specs`` holds the geometry of the vocabulary's grasps that have one (built-in or declared);
    in a domain without robot kinds a grasp may be a bare name with no geometry.
    """

    name: str
    requirements: tuple[str, ...] = ()
    robot_kinds: tuple[RobotKind, ...] = ()
    grasps: tuple[str, ...] = ()
    source: str = field(default="", compare=False)
    span: Span = _span()
    grasp_specs: tuple[GraspSpec, ...] = ()

    def kind(self, name: str) -> RobotKind:
        """The robot kind called ``name``."""
        return next(k for k in self.robot_kinds if k.name == name)

    def grasp_spec(self, name: str) -> GraspSpec | None:
        """The geometry of grasp ``name``: the domain's own declaration, else the built-in one, else None."""
        own = next((g for g in self.grasp_specs if g.name == name), None)
        return own if own is not None else BUILTIN_GRASPS.get(name)


@dataclass(frozen=True)
class Robot:
    """A robot of a problem; ``kind`` and ``base`` are None in symbolic problems."""

    name: str
    kind: str | None = None
    base: Pose | None = None
    span: Span = _span()


@dataclass(frozen=True)
class FixedObject:
    """An obstacle that never moves (a table, a wall)."""

    name: str
    shape: Shape | None = None
    pose: Pose | None = None
    span: Span = _span()


@dataclass(frozen=True)
class Region:
    """A region objects can be placed in; an object is in it iff the object lies entirely inside."""

    name: str
    shape: Shape | None = None
    pose: Pose | None = None
    span: Span = _span()


@dataclass(frozen=True)
class MovableObject:
    """A movable object; ``grasps`` are the grasps robots may use on it (the whole vocabulary unless its
    ``:grasps`` narrows it); ``handover_points`` the handover points it may be passed at (all of the
    problem's unless its ``:handover`` narrows them).
    """

    name: str
    shape: Shape | None = None
    pose: Pose | None = None
    grasps: tuple[str, ...] = ()
    handover_points: tuple[str, ...] = ()
    span: Span = _span()


@dataclass(frozen=True)
class HandoverPoint:
    """A predefined point in space where two robots may pass an object (``position`` None if symbolic)."""

    name: str
    position: tuple[float, float, float] | None = None
    span: Span = _span()


@dataclass(frozen=True, order=True)
class Fact:
    """A ground predicate instance, e.g. ``Fact("reachable-pick", ("o1", "top", "r1"))``."""

    predicate: str
    args: tuple[str, ...]

    def __str__(self) -> str:
        return f"({self.predicate} {' '.join(self.args)})"


@dataclass(frozen=True)
class Problem:
    """A checked problem, with its domain resolved.

    ``init`` holds the facts stated in the file (all of them for a symbolic problem; for a geometric one,
    the facts cached by ``mrgc facts``, or none).  ``goal`` is the conjunction of ``in-region`` facts.
    """

    name: str
    domain: Domain
    robots: tuple[Robot, ...]
    fixed: tuple[FixedObject, ...]
    regions: tuple[Region, ...]
    movable: tuple[MovableObject, ...]
    handover_points: tuple[HandoverPoint, ...]
    init: tuple[Fact, ...]
    goal: tuple[Fact, ...]
    symbolic: bool
    source: str = field(default="", compare=False)
    span: Span = _span()

    @property
    def goal_regions(self) -> dict[str, str]:
        """Goal object name → its goal region."""
        return {f.args[0]: f.args[1] for f in self.goal}

    @property
    def initial_regions(self) -> dict[str, str]:
        """Object name → the region ``(in-region o r)`` in ``:init`` puts it in (where stated)."""
        return {f.args[0]: f.args[1] for f in self.init if f.predicate == "in-region"}

    @property
    def bodies(self) -> tuple[MovableObject | FixedObject | Region, ...]:
        """Every movable object, fixed object and region, in that order."""
        return (*self.movable, *self.fixed, *self.regions)

    def object(self, name: str) -> MovableObject:
        """The movable object called ``name``."""
        return next(m for m in self.movable if m.name == name)

    def grasps_of(self, name: str) -> tuple[str, ...]:
        """The grasps robots may use on movable object ``name``."""
        return self.object(name).grasps or self.domain.grasps

    @property
    def grasp_specs(self) -> dict[str, GraspSpec]:
        """Grasp name -> its geometry, for every grasp an object of this problem may use that has one
        (all of them in a geometric problem: the checks guarantee it)."""
        out: dict[str, GraspSpec] = {}
        for m in self.movable:
            for g in self.grasps_of(m.name):
                spec = self.domain.grasp_spec(g)
                if spec is not None:
                    out[g] = spec
        return out
