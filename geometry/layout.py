"""Layout checks of a geometric problem: start states that cannot be, and parts that will never be used.

Each finding is a located :class:`~mrgc.errors.Diagnostic` (docs/errors.md).  Two tiers:

**Without robot models** (``mrgc check``, and every command before it works on a problem):

- ``E263`` a robot kind's ``:home`` does not have one value per joint of its arm (the URDF's revolute,
  continuous and prismatic joints from the base to the end-effector link: 7 for the Panda).  The URDF is
  read (its XML only, no meshes); a URDF that cannot be found or read is left to ``mrgc facts`` (E400/E401);
- ``E264`` two movable objects overlap at their start poses;
- ``E265`` a movable object overlaps a fixed object at its start pose;
- ``E266`` a planar robot's footprint at its start pose overlaps a movable object, a fixed object or
  another robot's footprint;
- ``E269`` a region whose shape is not a box (:func:`region_shape_diagnostics`); ``W277`` a region's floor that
  holds nothing up (:func:`floor_diagnostics`); ``W278`` an object no cart can carry (:func:`load_diagnostics`);
  ``W279`` a goal object too tall for its goal region (:func:`fit_diagnostics`);
- ``E267`` a ``(mesh ...)`` shape's file holds no triangle, ``E268`` the mesh of a movable object or a
  footprint is not centred on its origin, ``E403`` a mesh file cannot be used (:func:`mesh_diagnostics`:
  every mesh file is read here; a declaration whose mesh is refused gets no other complaint);
- ``W270`` (:func:`mrgc.geometry.grasps.grasp_warnings`) a grasp no gripper opens wide enough for;
- ``W271`` a movable object lies in no region at its start pose (``in-region`` holds for none): unless it
  is a goal object it can never move, so an obstacle in no region makes its goals unreachable;
- ``W273`` an arm kind has no ``:tcp`` and none can be derived from its URDF (:mod:`mrgc.geometry.tcp`);
- ``W274``-``W276`` an arm that can reach nothing, and why (:mod:`mrgc.geometry.arm_diagnosis`; these load
  the arms' models, and are reported by ``facts`` and ``plan`` too): every configuration collides, its home
  configuration collides, or IK never converges.

**With robot models** (``mrgc facts`` and the commands that run phase 1, ``plan``):

- ``E266`` an arm at its home configuration overlaps a movable object or a fixed object (the mount, the base
  link and the links fixed to it, bolted in place, is checked against movable objects only), or an
  arm's mount overlaps another arm's (two arms bolted at one base).  Arms whose moving links overlap at home
  are not checked: the grounding keeps every motion clear of the other arms at home, so such arms only
  narrow what can be planned;
- ``W272`` a region lies outside the workspace of every robot: farther from each arm's shoulder than its
  reach bound (:attr:`~mrgc.geometry.kinematics.RobotModel.reach`).  Planar robots drive, so a problem with
  one has no such warning.

Overlap means a penetration deeper than :data:`TOLERANCE` (signed distance, coal): shapes that touch, as
an object standing on a table or two boxes side by side, do not overlap.  The overlaps are errors because
no plan can start from them (the validator would reject every plan at its first step); objects in no
region and unreachable regions are warnings because the problem may still be solvable without them.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Iterable

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.geometry.collision import CollisionWorld, scene_world
from mrgc.geometry.transforms import from_pose
from mrgc.language.model import FixedObject, Mesh, MovableObject, Problem, RobotKind

if TYPE_CHECKING:
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.scene import SceneSpec
    from mrgc.geometry.urdf import UrdfJoint

#: penetration depth (m) above which two shapes overlap
TOLERANCE = 1e-3


def layout_diagnostics(problem: Problem, arms: bool = True) -> list[Diagnostic]:
    """The layout diagnostics of ``problem`` that need no robot model (none for a symbolic one), in
    declaration order within each check; :func:`robot_diagnostics` has the others.  ``arms`` False leaves
    out W274-W276 (they load the arms' models; ``plan`` asks for them only when it finds no plan)."""
    if problem.symbolic:
        return []
    from mrgc.geometry.grasps import grasp_warnings

    meshes = mesh_diagnostics(problem)
    unusable = {d.span for d in meshes}  # a declaration whose mesh is refused gets no other complaint
    out = home_diagnostics(problem) + meshes
    out += [
        d
        for d in (
            overlap_diagnostics(problem)
            + grasp_warnings(problem)
            + region_shape_diagnostics(problem)
            + floor_diagnostics(problem)
            + region_diagnostics(problem)
            + fit_diagnostics(problem)
            + load_diagnostics(problem)
        )
        if d.span not in unusable
    ]
    out += tcp_diagnostics(problem)
    if arms and not any(d.severity != "warning" for d in out):  # an arm that can reach nothing, and why
        from mrgc.geometry.arm_diagnosis import arm_diagnostics

        out += arm_diagnostics(problem)
    return out


# ---------------------------------------------------------------------------------------------- :tcp
def tcp_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W273 for each arm kind used by the problem that has no ``:tcp`` and none can be derived from its URDF
    (:mod:`mrgc.geometry.tcp`); a URDF that cannot be found or read, or lacks the end-effector link, is left
    to ``mrgc facts`` (E400/E401)."""
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.tcp import derive_tcp

    used = {r.kind for r in problem.robots}
    out = []
    for kind in problem.domain.robot_kinds:
        if kind.name not in used or not approaches(kind) or kind.tcp is not None or arm_joints(kind) is None:
            continue
        if derive_tcp(kind) is None:
            out.append(
                Diagnostic(
                    "W273",
                    f"robot kind '{kind.name}' has no :tcp and none can be derived from '{kind.urdf}' (no "
                    f"grasp-target link, no fingers along the z axis of '{kind.end_effector}'): grasps put "
                    f"the origin of '{kind.end_effector}' on the object; give :tcp (x y z yaw)",
                    kind.span,
                    severity="warning",
                )
            )
    return out


# ---------------------------------------------------------------------------------------------- :home
def arm_joints(kind: RobotKind) -> tuple[str, ...] | None:
    """The joints of ``kind``'s arm from its base to its end-effector link, read from the URDF; None when
    the kind has no URDF or it cannot be found or read (``mrgc facts`` reports that)."""
    chain = _arm_chain(kind)
    return None if chain is None else tuple(j.name for j in chain)


def _arm_chain(kind: RobotKind) -> "tuple[UrdfJoint, ...] | None":
    """:func:`arm_joints` as the URDF's joints (with their limits)."""
    if kind.urdf is None or kind.end_effector is None:
        return None
    from mrgc.geometry.kinematics import resolve_urdf
    from mrgc.geometry.urdf import parse_urdf

    base = os.path.dirname(os.path.abspath(kind.source)) if kind.source else os.getcwd()
    try:
        urdf = parse_urdf(resolve_urdf(kind.urdf, base, kind.span, kind.roots))
    except InputError:
        return None
    if kind.end_effector not in urdf.order:
        return None
    chain = []
    link = kind.end_effector
    while link in urdf.joint_of:
        joint = urdf.joint_of[link]
        if joint.kind in ("revolute", "continuous", "prismatic"):
            chain.append(joint)
        link = joint.parent
    return tuple(reversed(chain))


def home_diagnostics(problem: Problem) -> list[Diagnostic]:
    """E263 for each robot kind used by the problem whose ``:home`` does not fit its arm: a length that
    differs from its arm's joints, or a value outside its joint's limits (the planner and the validator
    clamp it, so every motion started and ended elsewhere than declared, silently)."""
    from mrgc.geometry.kinds import approaches

    used = {r.kind for r in problem.robots}
    out = []
    for kind in problem.domain.robot_kinds:
        if kind.name not in used or not approaches(kind) or not kind.home:
            continue
        chain = _arm_chain(kind)
        if chain is None:
            continue
        joints = tuple(j.name for j in chain)
        if len(joints) == len(kind.home):
            outside = [
                (j, v)
                for j, v in zip(chain, kind.home)
                if not j.lower - 1e-9 <= v <= j.upper + 1e-9  # a continuous joint's: [-pi, pi], clamped alike
            ]
            if outside:
                j, v = outside[0]
                out.append(
                    Diagnostic(
                        "E263",
                        f"robot kind '{kind.name}': :home gives joint '{j.name}' {v:g}, outside its limits "
                        f"[{j.lower:g}, {j.upper:g}] in '{kind.urdf}' (the arm would be homed at the nearest limit)"
                        + (f"; {len(outside) - 1} more joint(s) outside theirs" if len(outside) > 1 else ""),
                        kind.home_span,
                    )
                )
            continue
        shown = ", ".join(joints) if len(joints) <= 4 else f"{joints[0]}, ..., {joints[-1]}"
        out.append(
            Diagnostic(
                "E263",
                f"robot kind '{kind.name}': :home has {len(kind.home)} value{'s' * (len(kind.home) != 1)}, but "
                f"the arm of '{kind.urdf}' has {len(joints)} joint{'s' * (len(joints) != 1)} from its base to "
                f"'{kind.end_effector}' ({shown}): give one value per joint",
                kind.home_span,
            )
        )
    return out


# ---------------------------------------------------------------------------------------------- meshes
#: m: how far a movable object's (or a footprint's) mesh may have its bounding box's centre off its origin
MESH_CENTRE_TOL = 1e-3


def mesh_diagnostics(problem: Problem) -> list[Diagnostic]:
    """The mesh files of ``(mesh ...)`` shapes, read now (each once): E403 for a file that cannot be used
    (located in that file), E267 for one with no triangle (nothing to collide with, grasp or set down), and
    E268 for the mesh of a movable object or a robot's footprint whose bounding box is not centred on its
    origin (:data:`MESH_CENTRE_TOL`): grasps, placements and a cart's load take such a shape's origin as its
    centre, so an off-centre one would be set down in the air or gripped beside itself.  A fixed object's
    mesh may lie anywhere about its origin (a region's shape is a box: E269)."""
    import numpy as np

    from mrgc.geometry.meshes import read_mesh

    uses: list[tuple[str, str, Mesh, Span, bool]] = []
    for what, decls in (("movable object", problem.movable), ("fixed object", problem.fixed)):
        for d in decls:
            if isinstance(d.shape, Mesh):
                uses.append((what, d.name, d.shape, d.span, what == "movable object"))
    uses += [("region", r.name, r.shape, r.span, False) for r in problem.regions if isinstance(r.shape, Mesh)]
    uses += [
        ("the footprint of robot kind", k.name, k.footprint, k.span, True)
        for k in problem.domain.robot_kinds
        if isinstance(k.footprint, Mesh)
    ]
    out: list[Diagnostic] = []
    unusable: set[str] = set()
    for what, name, mesh, span, centred in uses:
        try:
            vertices, faces = read_mesh(mesh.path)
        except InputError as exc:
            if mesh.path not in unusable:  # the file's own complaint, once
                out += exc.diagnostics
            unusable.add(mesh.path)
            continue
        if not len(faces) or not len(vertices):
            out.append(
                Diagnostic(
                    "E267",
                    f"mesh file '{mesh.path}' of {what} '{name}' holds no triangle ({len(vertices)} vertices, "
                    f"{len(faces)} faces): "
                    + ("it holds nothing to set down in" if what == "region" else "it has no volume to collide with"),
                    span,
                )
            )
            continue
        scaled = np.asarray(vertices, dtype=float) * mesh.scale
        centre = (scaled.min(axis=0) + scaled.max(axis=0)) / 2
        if centred and float(np.abs(centre).max()) > MESH_CENTRE_TOL:
            x, y, z = (float(c) + 0.0 for c in centre)  # + 0.0: no "-0.0000"
            out.append(
                Diagnostic(
                    "E268",
                    f"the mesh of {what} '{name}' is not centred on its origin: its bounding box's centre lies at "
                    f"({x:.4f}, {y:.4f}, {z:.4f}) m in the mesh's frame; grasps and placements take the origin "
                    f"as the centre, so move the file's vertices by ({0.0 - x:.4f}, {0.0 - y:.4f}, {0.0 - z:.4f}) m",
                    span,
                )
            )
    return out


# ---------------------------------------------------------------------------------------------- overlaps
def overlap_diagnostics(problem: Problem) -> list[Diagnostic]:
    """E264 (object-object), E265 (object-fixed) and E266 (planar footprint) overlaps at the start.  Mesh
    shapes are left out: a mesh may be concave (a bin that holds objects), and its file is read by
    ``mrgc facts``."""
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.planar import PlanarRobot
    from mrgc.geometry.scene import RobotSpec

    world = CollisionWorld()
    spans = _spans(problem)
    fixed = [o.name for o in _solids(problem.fixed)]
    movable = [o.name for o in _solids(problem.movable)]
    for group, decls in (("fixed", problem.fixed), ("movable", problem.movable)):
        for o in _solids(decls):
            assert o.shape is not None and o.pose is not None
            world.add(o.name, o.shape, from_pose(o.pose), group)
    kinds = {k.name: k for k in problem.domain.robot_kinds}
    footprints = []
    for r in problem.robots:
        kind = kinds.get(r.kind or "")
        if (
            kind is None
            or approaches(kind)
            or kind.footprint is None
            or isinstance(kind.footprint, Mesh)
            or r.base is None
        ):
            continue
        robot = PlanarRobot(RobotSpec(r.name, kind, from_pose(r.base)))
        world.add(r.name, robot.footprint, robot.body_transform(robot.start), "robot")
        footprints.append(r.name)
    out: list[Diagnostic] = []
    for i, name in enumerate(movable):
        for other, depth in _overlaps(world, name, movable[:i]):
            out.append(
                _overlap(
                    "E264", f"movable object '{name}' overlaps movable object '{other}'", depth, spans, name, other
                )
            )
        for other, depth in _overlaps(world, name, fixed):
            out.append(
                _overlap("E265", f"movable object '{name}' overlaps fixed object '{other}'", depth, spans, name, other)
            )
    for i, name in enumerate(footprints):
        for other, depth in _overlaps(world, name, [*movable, *fixed, *footprints[:i]]):
            what = "robot" if other in footprints else "fixed object" if other in fixed else "movable object"
            out.append(
                _overlap(
                    "E266", f"the footprint of robot '{name}' overlaps {what} '{other}'", depth, spans, name, other
                )
            )
    return out


def _spans(problem: Problem) -> dict[str, Span]:
    """Where each fixed object, movable object and robot is declared."""
    out: dict[str, Span] = {f.name: f.span for f in problem.fixed}
    out.update({m.name: m.span for m in problem.movable})
    out.update({r.name: r.span for r in problem.robots})
    return out


def _solids(decls: Iterable[FixedObject | MovableObject]) -> list[FixedObject | MovableObject]:
    """The declarations with a primitive shape and a pose (meshes are left out)."""
    return [d for d in decls if d.shape is not None and d.pose is not None and not isinstance(d.shape, Mesh)]


def _overlaps(world: CollisionWorld, name: str, against: Iterable[str]) -> list[tuple[str, float]]:
    """(other, penetration depth) for each world object of ``against`` that ``name`` overlaps, in order."""
    candidates = [a for a in against if a != name]
    if not candidates:
        return []
    hits = world.colliding_with(name, against=candidates)
    out = []
    for other in candidates:
        if other in hits:
            depth = -world.distance(name, other)
            if depth > TOLERANCE:
                out.append((other, depth))
    return out


def _overlap(code: str, what: str, depth: float, spans: dict[str, Span], name: str, other: str) -> Diagnostic:
    note = (f"'{other}' is declared at {spans[other]}",) if other in spans and spans[other].line else ()
    return Diagnostic(
        code, f"{what} by {depth * 1000:.1f} mm at the start: no plan can start from here", spans.get(name), notes=note
    )


# ---------------------------------------------------------------------------------------------- regions
def region_shape_diagnostics(problem: Problem) -> list[Diagnostic]:
    """E269 for each region whose shape is not a box: ``in-region``, phase 1's placements and the grounding's
    are tests against a region's box, so nothing could ever be put in (or found in) a cylinder, a sphere or a
    mesh; planning said "no robot can reach goal region" for one within every arm's reach."""
    from mrgc.language.model import Box

    kinds = {"Cylinder": "a cylinder", "Sphere": "a sphere", "Mesh": "a mesh"}
    return [
        Diagnostic(
            "E269",
            f"region '{r.name}' is {kinds.get(type(r.shape).__name__, 'not a box')}: a region is a box "
            "(in-region and placements test against it); give the box objects are to stand in",
            r.span,
        )
        for r in problem.regions
        if r.shape is not None and not isinstance(r.shape, Box)
    ]


def floor_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W277 for each region whose floor holds nothing up: it lies neither on the ground nor under a fixed
    box's top at its height anywhere (:func:`mrgc.geometry.scene.floor_support`, the rule the planner's
    placements follow and the validator's ``floating``), so nothing set down in it can stand (a region drawn
    a few cm above its table).  Left out while a region is not a box (E269)."""
    import numpy as np

    from mrgc.geometry.scene import Body, floor_support
    from mrgc.geometry.transforms import translation
    from mrgc.language.model import Box

    if region_shape_diagnostics(problem):
        return []
    fixed = [Body(f.name, f.shape, from_pose(f.pose)) for f in problem.fixed if f.shape and f.pose]
    out = []
    for r in problem.regions:
        if not isinstance(r.shape, Box) or r.pose is None:
            continue
        region = Body(r.name, r.shape, from_pose(r.pose))
        try:
            held = floor_support(fixed, region)
        except InputError:  # a fixed mesh that cannot be read: E403 says so
            continue
        if held is None:
            continue
        grid = np.linspace(-0.5, 0.5, 21)  # the floor's points on a 21 x 21 grid
        spots = [(x * r.shape.sx, y * r.shape.sy) for x in grid for y in grid]
        if not any(held(region.pose @ translation(x, y, 0.0)) for x, y in spots):
            z = float(region.pose[2, 3] - r.shape.sz / 2)
            out.append(
                Diagnostic(
                    "W277",
                    f"the floor of region '{r.name}' (z = {z:.3f}) holds nothing up: it lies neither on the "
                    "ground nor on a fixed object's top (at most 3 mm above it), so nothing set down in it can stand",
                    r.span,
                    severity="warning",
                )
            )
    return out


def fit_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W279 for each goal object taller than its goal region leaves room for: the grounding's placements rest
    :data:`~mrgc.geometry.conventions.ARM_PLACE_LIFT` above the floor (a cart's too),
    and the object must lie entirely inside the region (``in-region``), so a 0.100 m object in a 0.105 m bin
    has no placement at all (planning said "no robot can reach goal region bin").  Left out while a region is
    not a box (E269) or a mesh cannot be used."""
    from mrgc.geometry.conventions import ARM_PLACE_LIFT
    from mrgc.geometry.scene import half_extents
    from mrgc.language.model import Box

    if region_shape_diagnostics(problem):
        return []
    lift = ARM_PLACE_LIFT  # the grounding sets every object down this high, a cart's too (phase 1: PLANAR_LIFT)
    regions = {r.name: r for r in problem.regions}
    out = []
    for m in problem.movable:
        region = regions.get(problem.goal_regions.get(m.name, ""))
        if m.shape is None or region is None or not isinstance(region.shape, Box):
            continue
        try:
            tall = 2 * float(half_extents(m.shape)[2])
        except InputError:
            continue
        if tall + lift > region.shape.sz:
            out.append(
                Diagnostic(
                    "W279",
                    f"movable object '{m.name}' ({tall:.3f} m tall) does not fit in its goal region "
                    f"'{region.name}' ({region.shape.sz:.3f} m tall): it is set down {lift * 1e3:g} mm above the "
                    f"floor and must lie entirely inside, so the region needs {tall + lift:.3f} m",
                    m.span,
                    severity="warning",
                )
            )
    return out


def load_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W278 for each movable object that no planar robot of the problem can carry with any of its side grasps:
    at its kind's ``:carry`` pose it would reach below the floor or into the cart's own footprint
    (:meth:`~mrgc.geometry.planar.PlanarRobot.load_fits`; the validator's ``carry``).  None without planar
    robots, or when an arm could move the object."""
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.planar import PlanarRobot
    from mrgc.geometry.planar_grasps import PLANAR_GRASPS
    from mrgc.geometry.scene import RobotSpec

    kinds = {k.name: k for k in problem.domain.robot_kinds}
    carts = []
    for r in problem.robots:
        kind = kinds.get(r.kind or "")
        if kind is None or r.base is None:
            continue
        if approaches(kind):
            return []  # an arm may move what no cart carries
        if kind.footprint is not None and not isinstance(kind.footprint, Mesh):
            carts.append(PlanarRobot(RobotSpec(r.name, kind, from_pose(r.base))))
    out = []
    for m in problem.movable:
        if not carts or m.shape is None or isinstance(m.shape, Mesh):
            continue
        grasps = [g for g in problem.grasps_of(m.name) if g in PLANAR_GRASPS]
        if grasps and not any(c.load_fits(m.shape, g) for c in carts for g in grasps):
            out.append(
                Diagnostic(
                    "W278",
                    f"no robot can carry movable object '{m.name}': at the :carry pose of its kind it would reach "
                    "below the floor or into the robot's own footprint with every grasp, so it can never move",
                    m.span,
                    severity="warning",
                )
            )
    return out


def region_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W271 for each movable object in no region at its start pose (as ``in-region`` of phase 1 reads
    it; a mesh whose file cannot be read is left to ``mrgc facts``)."""
    from mrgc.geometry.scene import Body, inside

    if region_shape_diagnostics(problem):
        return []  # a region that is not a box is E269: "in no region" would only repeat it
    regions = [Body(r.name, r.shape, from_pose(r.pose)) for r in problem.regions if r.shape and r.pose]
    goal = problem.goal_regions
    out = []
    for m in problem.movable:
        if m.shape is None or m.pose is None:
            continue
        try:
            if any(inside(region, m.shape, from_pose(m.pose)) for region in regions):
                continue
        except InputError:
            continue
        use = (
            "it is a goal object, so it can still be moved into its goal region"
            if m.name in goal
            else "it can never move, so if it is in the way its goals cannot be reached"
        )
        out.append(
            Diagnostic(
                "W271",
                f"movable object '{m.name}' lies in no region at its start pose (a region "
                f"must hold it entirely): {use}",
                m.span,
                severity="warning",
            )
        )
    return out


# ---------------------------------------------------------------------------------------------- robots
def robot_diagnostics(problem: Problem, arms: bool = True) -> list[Diagnostic]:
    """E266 for arms at home that overlap something, W272 for regions no robot reaches (none for a
    symbolic problem), and (``arms``) W274-W276."""
    if problem.symbolic:
        return []
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.scene import scene_from_problem

    scene = scene_from_problem(problem)
    models = [Arm(spec) for spec in scene.robots if approaches(spec.kind)]
    out = _arms_at_home(problem, scene, models)
    if models and len(models) == len(scene.robots):
        out += _regions_out_of_reach(problem, scene, models)
    if not arms:
        return out
    from mrgc.geometry.arm_diagnosis import arm_diagnostics

    return out + arm_diagnostics(problem)


def _arms_at_home(problem: Problem, scene: SceneSpec, arms: list[Arm]) -> list[Diagnostic]:
    """E266 for each arm whose mount overlaps another arm's (two arms bolted at one base: :func:`_arm_on_arm`),
    and for each arm at its home configuration overlapping an object (the deepest link per object; the mount
    stands on what the arm is bolted to, and is checked against movable objects only)."""
    spans = _spans(problem)
    world = scene_world(scene)
    links: dict[str, list[str]] = {}  # each arm's moving links, then its mount's
    for arm in arms:
        shapes, index = arm.probes
        transforms = arm.link_transforms(arm.home[None])[0]
        parts = [(arm.model.links[k].name, shape, t) for shape, k, t in zip(shapes, index, transforms)]
        links[arm.name] = []
        for name, shape, t in [*parts, *arm.base_hulls]:
            world.add(f"{arm.name}/{name}", shape, t, f"robot:{arm.name}")
            links[arm.name].append(f"{arm.name}/{name}")
    out = _arm_on_arm(world, arms, links, spans)
    movable, objects = world.names("movable"), [*world.names("movable"), *world.names("fixed")]
    for arm in arms:
        found: dict[str, tuple[float, str]] = {}
        moving = len(arm.probes[0])
        for n, key in enumerate(links[arm.name]):  # the mount against movable objects only
            for other, depth in _overlaps(world, key, objects if n < moving else movable):
                if depth > found.get(other, (0.0, ""))[0]:
                    found[other] = (depth, key.split("/")[1])
        for target, (depth, link) in found.items():
            what = "movable object" if target in world.names("movable") else "fixed object"
            message = f"robot '{arm.name}' ({link}) at its home configuration overlaps {what} '{target}'"
            out.append(_overlap("E266", message, depth, spans, arm.name, target))
    return out


def _arm_on_arm(
    world: CollisionWorld, arms: list[Arm], links: dict[str, list[str]], spans: dict[str, Span]
) -> list[Diagnostic]:
    """E266 for each pair of arms whose mounts (the last of ``links``: world keys ``arm/link``) overlap: arms
    bolted into each other (two at one base), named by the later arm, with the deepest pair of links.  Arms
    whose moving links overlap at home are not reported: the paper's motion model does not check the way
    home (docs/geometry.md, "Layout checks")."""
    mounts = {arm.name: links[arm.name][len(arm.probes[0]) :] for arm in arms}
    out: list[Diagnostic] = []
    for i, arm in enumerate(arms):
        met: dict[str, tuple[float, str, str]] = {}
        for key in mounts[arm.name]:
            for other in arms[:i]:
                for hit, depth in _overlaps(world, key, mounts[other.name]):
                    if depth > met.get(other.name, (0.0, "", ""))[0]:
                        met[other.name] = (depth, key.split("/")[1], hit.split("/")[1])
        for name, (depth, link, other_link) in met.items():
            message = f"the mount of robot '{arm.name}' ({link}) overlaps the mount of robot '{name}' ({other_link})"
            out.append(_overlap("E266", message, depth, spans, arm.name, name))
    return out


def _regions_out_of_reach(problem: Problem, scene: SceneSpec, arms: list[Arm]) -> list[Diagnostic]:
    """W272 for each region farther from every arm's shoulder than its reach."""
    import numpy as np

    from mrgc.geometry.scene import half_extents

    shoulders = [(arm.base @ np.append(arm.model.shoulder, 1.0))[:3] for arm in arms]
    region_spans = {r.name: r.span for r in problem.regions}
    out: list[Diagnostic] = []
    for region in scene.regions:
        inv = np.linalg.inv(region.pose)
        half = half_extents(region.shape)
        gaps = [
            float(np.linalg.norm(np.maximum(np.abs(inv[:3, :3] @ shoulder + inv[:3, 3]) - half, 0.0)))
            for shoulder in shoulders
        ]
        if all(gap > arm.model.reach for arm, gap in zip(arms, gaps)):
            out.append(
                Diagnostic(
                    "W272",
                    f"region '{region.name}' lies outside the workspace of every robot (farther from each "
                    f"arm's shoulder than its reach): nothing can be placed in it or picked from it",
                    region_spans.get(region.name),
                    severity="warning",
                )
            )
    return out
