"""The validator's pybullet world: a plan replayed with another engine than the planner's.

A :class:`ReplayScene` is a private pybullet client (:func:`mrgc.geometry.bullet.private_client`) holding
every robot loaded from its URDF at its base pose and every fixed and movable object as a pybullet collision
body; its signed distances come from pybullet's own collision engine (``getClosestPoints``) and its forward
kinematics from pybullet, so that a bug in the planner's engines (coal, the numpy kinematics) cannot hide
in the validator too.  Nothing of the planner runs in it.

Frames: a link's frame is its URDF link frame (pybullet's ``worldLinkFrame``, not its centre of mass).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from mrgc.geometry import transforms as tf
from mrgc.geometry.bullet import pose_of, private_client, quiet_output
from mrgc.geometry.conventions import PLANAR_LIFT, yaw_of
from mrgc.geometry.kinematics import RobotModel, model_for_kind
from mrgc.geometry.scene import SceneSpec, half_extents
from mrgc.language.model import Box, Cylinder, Mesh, Shape, Sphere

#: where bodies wait while they are out of the scene (a parked body is never queried)
PARKED = (0.0, 0.0, -1.0e3)
#: the collision margin pybullet puts around every convex mesh shape (URDF meshes and ``GEOM_MESH``), which
#: its distances include: measured 1.000 mm per mesh (a mesh cube 30 mm from a box: 29 mm; two: 28 mm;
#: Panda link hulls vs coal's hulls of the same vertices: 1.99-2.00 mm link-link, up to 1.00 mm link-box).
#: Primitive shapes have none.  :meth:`ReplayScene.closest` adds it back.
MESH_MARGIN = 1e-3


def rotations(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of quaternions (N, 4; x, y, z, w), normalised first (pybullet's are single
    precision)."""
    q = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    out = np.empty((len(q), 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    return out


@dataclass(frozen=True)
class Closest:
    """The deepest pair of points between two bodies: ``distance`` (signed, negative when they overlap)
    and the links involved (link names for robots, None for rigid objects)."""

    distance: float
    link_a: str | None
    link_b: str | None


@dataclass(frozen=True)
class ReplayRobot:
    """A robot of a :class:`ReplayScene`.

    Arms: ``joints`` are the pybullet joint indices of the configuration vector's joints (the chain from
    the base link to the end-effector link, in order), ``lower``/``upper`` their limits as pybullet reads
    them from the URDF (an unlimited joint: -inf/+inf), ``ee`` the end-effector link index.  Planar robots
    (``planar``) are one rigid body, their footprint, at the base pose lifted by ``lift``; their
    configuration is ``(x, y, yaw)``, yaw in radians, limits infinite.  ``fingers``: an arm's finger joints
    (pybullet index, lower, upper, frozen value) and ``finger_value`` the model's opening -> joint value.
    """

    name: str
    body: int
    planar: bool
    joints: tuple[int, ...]
    lower: np.ndarray
    upper: np.ndarray
    ee: int
    links: dict[int, str]
    base: np.ndarray
    lift: np.ndarray
    joint_names: tuple[str, ...] = ("x", "y", "yaw")
    fingers: tuple[tuple[int, float, float, float], ...] = ()
    finger_value: Callable[[float], float] | None = None
    #: the links standing on the mount: pybullet's base link -1 and every link fixed to it through fixed
    #: joints (an xArm's ``link_base`` below its dummy root ``world``), exempt from contact with fixed objects
    mount: frozenset[int] = frozenset({-1})
    #: gripper joint values (pybullet index -> value) as functions of the drive value, their URDF mimic rules
    finger_joint: Callable[[int, float], float] | None = None

    @property
    def dof(self) -> int:
        """The length of the robot's configuration."""
        return len(self.joints) if not self.planar else 3


class ReplayScene:
    """A private pybullet world for replaying a plan (the validator's; no planner code runs in it).

    Built from a :class:`~mrgc.geometry.scene.SceneSpec`: each fixed-base robot is its URDF loaded with a
    fixed base at its base pose, its off-chain joints (a Panda's fingers) frozen as the kinematic model
    says (gripper open); each planar robot is a rigid body of its footprint shape; fixed and movable
    objects are static collision bodies (boxes as the convex hull of their 8 corners, because ``GEOM_BOX``'s
    margin rounds edges and corners by up to about 1 mm; ``GEOM_CYLINDER``, ``GEOM_SPHERE``; meshes are
    ``GEOM_MESH``, which pybullet reduces to the convex hull of the file's vertices).  Robot meshes are the
    URDF's collision meshes as pybullet loads them (convex hulls too).  Distances are corrected for
    pybullet's margin around mesh shapes (:data:`MESH_MARGIN`; a link with any mesh shape counts as a mesh).

    **The base-link rule.**  A fixed-base arm is bolted to the surface it stands on, so contacts between an
    arm's *mount* (its base link and every link fixed to it through fixed joints, as pybullet's joint info
    reads them: an xArm's ``link_base`` below its dummy root ``world``) and any *fixed* object are ignored
    (its base standing on the table is not a collision; a base inside a wall would be a fault of the problem
    file, not of a plan).  The mount still counts against movable objects and other robots.

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, scene: SceneSpec, models: Mapping[str, RobotModel] | None = None) -> None:
        self.pb: Any
        self.cid: int
        self.pb, self.cid = private_client()
        self.bodies: dict[str, int] = {}
        self.fixed: set[str] = set()
        self.robots: dict[str, ReplayRobot] = {}
        #: each arm's kinematic model as read from its URDF (link names, collision vertices, finger values)
        self.models: dict[str, RobotModel] = {}
        self._owner: dict[int, str] = {}
        self._margin: dict[tuple[int, int], float] = {}  # (body, link) -> MESH_MARGIN for mesh shapes
        self._margins: dict[int, dict[int, float]] = {}  # body -> link -> its margin (from _margin, on first ask)
        self._shaped: dict[int, tuple[int, ...]] = {}  # body -> its links with collision shapes
        #: getClosestPoints calls made so far
        self.queries = 0
        try:
            for b in scene.fixed:
                self.add_object(b.name, b.shape, b.pose, fixed=True)
            for b in scene.movable:
                self.add_object(b.name, b.shape, b.pose)
            for r in scene.robots:
                if r.kind.driven:
                    self._add_planar(r.name, r.kind.footprint, r.base)
                else:
                    model = (models or {}).get(r.name)
                    if model is None:
                        model = model_for_kind(r.kind, r.base_dir)  # InputError E400/E401 for a bad URDF
                    self._add_arm(r.name, model, r.base)
                    self.models[r.name] = model
        except BaseException:
            self.close()
            raise

    # ------------------------------------------------------------------ building
    def _shape(self, shape: Shape) -> int:
        pb, cid = self.pb, self.cid
        if isinstance(shape, Box):  # an 8-vertex hull: exact once MESH_MARGIN is added back (GEOM_BOX rounds)
            h = (shape.sx / 2, shape.sy / 2, shape.sz / 2)
            corners = [[x * h[0], y * h[1], z * h[2]] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
            return int(pb.createCollisionShape(pb.GEOM_MESH, vertices=corners, physicsClientId=cid))
        if isinstance(shape, Cylinder):
            return int(
                pb.createCollisionShape(pb.GEOM_CYLINDER, radius=shape.radius, height=shape.height, physicsClientId=cid)
            )
        if isinstance(shape, Sphere):
            return int(pb.createCollisionShape(pb.GEOM_SPHERE, radius=shape.radius, physicsClientId=cid))
        if isinstance(shape, Mesh):
            with quiet_output():
                return int(
                    pb.createCollisionShape(
                        pb.GEOM_MESH, fileName=shape.path, meshScale=[shape.scale] * 3, physicsClientId=cid
                    )
                )
        raise TypeError(f"no pybullet shape for {shape!r}")

    def add_object(self, name: str, shape: Shape, pose: np.ndarray | None, fixed: bool = False) -> None:
        """A rigid static body called ``name`` at ``pose`` (parked when None); ``fixed`` objects are what
        robots' base links may touch."""
        body = int(
            self.pb.createMultiBody(baseMass=0, baseCollisionShapeIndex=self._shape(shape), physicsClientId=self.cid)
        )
        self.bodies[name] = body
        self._owner[body] = name
        if isinstance(shape, (Mesh, Box)):
            self._margin[(body, -1)] = MESH_MARGIN
        if fixed:
            self.fixed.add(name)
        self.set_pose(name, pose)

    def _add_arm(self, name: str, model: RobotModel, base: np.ndarray) -> None:
        pb, cid = self.pb, self.cid
        pos, orn = tf.to_quaternion(np.asarray(base, dtype=float))
        with quiet_output():  # collision geometry only: the Panda's visual meshes are 90 % of its loading time
            body = int(
                pb.loadURDF(
                    model.urdf,
                    basePosition=pos,
                    baseOrientation=orn,
                    useFixedBase=True,
                    flags=pb.URDF_IGNORE_VISUAL_SHAPES,
                    physicsClientId=cid,
                )
            )
        by_link: dict[str, int] = {pb.getBodyInfo(body, physicsClientId=cid)[0].decode(): -1}
        info = {}
        mount = {-1}
        for j in range(pb.getNumJoints(body, physicsClientId=cid)):
            ji = pb.getJointInfo(body, j, physicsClientId=cid)
            by_link[ji[12].decode()] = j
            info[ji[1].decode()] = ji
            if ji[2] == pb.JOINT_FIXED and int(ji[16]) in mount:  # parents come first in pybullet's order
                mount.add(j)
        for index in by_link.values():
            if any(d[2] == pb.GEOM_MESH for d in pb.getCollisionShapeData(body, index, physicsClientId=cid)):
                self._margin[(body, index)] = MESH_MARGIN
        joints, lower, upper = [], [], []
        for joint in model.joints:
            ji = info[joint.name]
            joints.append(int(ji[0]))
            lo, hi = float(ji[8]), float(ji[9])
            lower.append(lo if lo <= hi else -math.inf)  # pybullet reports an unlimited joint as lower > upper
            upper.append(hi if lo <= hi else math.inf)
        fingers = []
        gripper = {}  # pybullet joint -> the model's link, for the mimic rules
        for link in model.links:  # off-chain movable joints stay at their frozen values (fingers open)
            j = by_link.get(link.name, -1)
            if link.chain_index < 0 and link.joint_kind in ("revolute", "prismatic") and j >= 0:
                pb.resetJointState(body, j, float(link.frozen_value), physicsClientId=cid)
                if link.finger:
                    fingers.append((j, link.lower, link.upper, float(link.frozen_value)))
                    gripper[j] = link.index
        self.robots[name] = ReplayRobot(
            name=name,
            body=body,
            planar=False,
            joints=tuple(joints),
            lower=np.array(lower),
            upper=np.array(upper),
            ee=by_link[model.end_effector],
            links={i: n for n, i in by_link.items()},
            base=np.asarray(base, dtype=float),
            lift=np.eye(4),
            joint_names=tuple(jt.name for jt in model.joints),
            fingers=tuple(fingers),
            finger_value=model.finger_value,
            mount=frozenset(mount),
            finger_joint=lambda j, drive: model.gripper_value(gripper[j], drive),
        )
        self._owner[body] = name

    def _add_planar(self, name: str, footprint: Shape | None, base: np.ndarray) -> None:
        if footprint is None:
            raise ValueError(f"planar robot {name!r} has no footprint")
        body = int(
            self.pb.createMultiBody(
                baseMass=0, baseCollisionShapeIndex=self._shape(footprint), physicsClientId=self.cid
            )
        )
        if isinstance(footprint, (Mesh, Box)):
            self._margin[(body, -1)] = MESH_MARGIN
        lift = tf.translation(0.0, 0.0, float(half_extents(footprint)[2]) + PLANAR_LIFT)
        self.robots[name] = ReplayRobot(
            name=name,
            body=body,
            planar=True,
            joints=(),
            lower=np.full(3, -math.inf),
            upper=np.full(3, math.inf),
            ee=-1,
            links={-1: "footprint"},
            base=np.asarray(base, dtype=float),
            lift=lift,
        )
        self.bodies[name] = body
        self._owner[body] = name
        yaw = yaw_of(base)
        self.set_config(name, [float(base[0, 3]), float(base[1, 3]), yaw])

    # ------------------------------------------------------------------ state
    def set_pose(self, name: str, pose: np.ndarray | None) -> None:
        """Put object ``name`` at ``pose`` (world, 4×4); None parks it out of the scene."""
        if pose is None:
            pos, orn = PARKED, (0.0, 0.0, 0.0, 1.0)
        else:
            pos, orn = tf.to_quaternion(np.asarray(pose, dtype=float))
        self.pb.resetBasePositionAndOrientation(self.bodies[name], pos, orn, physicsClientId=self.cid)

    def set_config(self, robot: str, q: Sequence[float] | np.ndarray) -> None:
        """Put ``robot`` at configuration ``q`` (joint values of the chain; planar: x, y, yaw in radians)."""
        r = self.robots[robot]
        if r.planar:
            x, y, yaw = (float(v) for v in q[:3])
            base = tf.rot_z(yaw)
            base[0, 3], base[1, 3] = x, y
            pos, orn = tf.to_quaternion(base @ r.lift)
            self.pb.resetBasePositionAndOrientation(r.body, pos, orn, physicsClientId=self.cid)
            return
        values = np.asarray(q[: len(r.joints)], dtype=float).reshape(-1, 1).tolist()
        self.pb.resetJointStatesMultiDof(r.body, r.joints, values, physicsClientId=self.cid)

    def set_fingers(self, robot: str, opening: float | None) -> None:
        """Open an arm's fingers ``opening`` metres apart (None: back to their frozen, fully open values)."""
        r = self.robots[robot]
        drive = None if opening is None or r.finger_value is None else r.finger_value(opening)
        for j, lo, hi, frozen in r.fingers:
            if drive is None:
                v = frozen
            else:
                v = r.finger_joint(j, drive) if r.finger_joint is not None else min(max(drive, lo), hi)
            self.pb.resetJointState(r.body, j, float(v), physicsClientId=self.cid)

    def ee_pose(self, robot: str) -> np.ndarray:
        """The robot's end-effector link frame in the world at its current configuration (pybullet's forward
        kinematics, single precision: errors up to about 1e-7 m); a planar robot's base frame."""
        r = self.robots[robot]
        if r.planar:
            pos, orn = self.pb.getBasePositionAndOrientation(r.body, physicsClientId=self.cid)
            base: np.ndarray = pose_of(pos, orn) @ tf.inverse(r.lift)
            return base
        st = self.pb.getLinkState(r.body, r.ee, computeForwardKinematics=True, physicsClientId=self.cid)
        return pose_of(st[4], st[5])

    def link_centres(self, robot: str, links: Sequence[int]) -> np.ndarray:
        """The world positions (L, 3) of the centres of mass of links ``links`` of arm ``robot`` (-1: its
        base) at its current configuration, as pybullet places them (one call for the links)."""
        r = self.robots[robot]
        states = self.pb.getLinkStates(
            r.body, [max(link, 0) for link in links], computeForwardKinematics=True, physicsClientId=self.cid
        )
        pos = np.array([st[0] for st in states], dtype=float).reshape(len(links), 3)
        for k, link in enumerate(links):
            if link == -1:  # pybullet's base position is the base link's centre of mass
                pos[k] = self.pb.getBasePositionAndOrientation(r.body, physicsClientId=self.cid)[0]
        return pos

    def position(self, name: str) -> np.ndarray:
        """The world position (3,) of rigid body ``name``'s frame (an object, a planar robot's footprint)."""
        r = self.robots.get(name)
        body = r.body if r is not None else self.bodies[name]
        return np.array(self.pb.getBasePositionAndOrientation(body, physicsClientId=self.cid)[0], dtype=float)

    def body_frame(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """The world frame of rigid body ``name`` (an object, or a planar robot's footprint body): position
        (3,) and rotation (3, 3)."""
        r = self.robots.get(name)
        pos, orn = self.pb.getBasePositionAndOrientation(
            r.body if r is not None else self.bodies[name], physicsClientId=self.cid
        )
        return np.array(pos, dtype=float), rotations(np.array([orn], dtype=float))[0]

    def all_meshes(self, robot: str, link: int) -> bool:
        """Whether every collision shape of link ``link`` of ``robot`` is a mesh (pybullet's hull of its
        vertices)."""
        data = self.pb.getCollisionShapeData(self.robots[robot].body, link, physicsClientId=self.cid)
        return bool(data) and all(d[2] == self.pb.GEOM_MESH for d in data)

    # ------------------------------------------------------------------ distances
    def aabb(self, name: str) -> tuple[float, float, float, float, float, float]:
        """The axis-aligned bounding box (min x, y, z, max x, y, z) of body ``name``'s collision shapes as
        they stand now, all links of a robot together (pybullet's, margins included)."""
        r = self.robots.get(name)
        body = r.body if r is not None else self.bodies[name]
        links = self._shaped.get(body)
        if links is None:  # the links that have collision shapes (a link without one has no box)
            links = self._shaped[body] = tuple(
                link
                for link in (tuple(r.links) if r is not None else (-1,))
                if self.pb.getCollisionShapeData(body, link, physicsClientId=self.cid)
            ) or (-1,)
        boxes = [self.pb.getAABB(body, link, physicsClientId=self.cid) for link in links]
        lo = [min(b[0][k] for b in boxes) for k in range(3)]
        hi = [max(b[1][k] for b in boxes) for k in range(3)]
        return (lo[0], lo[1], lo[2], hi[0], hi[1], hi[2])

    def closest(self, a: str, b: str, max_distance: float = 0.0) -> Closest | None:
        """The deepest pair of points of bodies ``a`` and ``b`` (robots or objects) closer than
        ``max_distance`` (None when there is none), after the base-link rule of the class docstring."""
        ba = self.robots[a].body if a in self.robots else self.bodies[a]
        bb = self.robots[b].body if b in self.robots else self.bodies[b]
        # ask for 2 margins more: a mesh pair reported up to 2 mm short may still be within max_distance
        pts = self.pb.getClosestPoints(ba, bb, float(max_distance) + 2 * MESH_MARGIN, physicsClientId=self.cid)
        self.queries += 1
        skip_a = self._mount(a, b)
        skip_b = self._mount(b, a)
        best: Closest | None = None
        margin = self._margin
        for p in pts:
            if p[3] in skip_a or p[4] in skip_b:
                continue
            d = float(p[8]) + margin.get((ba, p[3]), 0.0) + margin.get((bb, p[4]), 0.0)
            if d < max_distance and (best is None or d < best.distance):
                best = Closest(d, self._link(a, int(p[3])), self._link(b, int(p[4])))
        return best

    def link_distances(
        self, a: str, b: str, max_distance: float, links_a: tuple[int, ...] | None = None
    ) -> dict[tuple[int, int], float]:
        """Signed distances (margin-corrected) between the links of bodies ``a`` and ``b`` closer than
        ``max_distance``: (link of a, link of b) -> the least distance (-1 for a rigid object), after the
        base-link rule; with ``a == b`` (a robot against itself) ``links_a`` names the two links to ask."""
        return self.prober(a, b, max_distance, links_a)()

    def prober(
        self, a: str, b: str, max_distance: float, links_a: tuple[int, ...] | None = None
    ) -> Callable[[], dict[tuple[int, int], float]]:
        """:meth:`link_distances` of ``a`` and ``b`` as a function of no arguments, everything it needs to
        look up done once (the sweep asks one pair many times)."""
        pb, cid = self.pb, self.cid
        ba = self.robots[a].body if a in self.robots else self.bodies[a]
        bb = self.robots[b].body if b in self.robots else self.bodies[b]
        extra = float(max_distance) + 2 * MESH_MARGIN
        links = {} if links_a is None else {"linkIndexA": links_a[0], "linkIndexB": links_a[1]}
        skip_a, skip_b = self._mount(a, b), self._mount(b, a)
        margin_a, margin_b = self._body_margins(ba), self._body_margins(bb)

        def probe() -> dict[tuple[int, int], float]:
            pts = pb.getClosestPoints(ba, bb, extra, physicsClientId=cid, **links)
            self.queries += 1
            out: dict[tuple[int, int], float] = {}
            for p in pts:
                la, lb = p[3], p[4]
                if la in skip_a or lb in skip_b:  # the base-link rule
                    continue
                d = p[8] + margin_a.get(la, 0.0) + margin_b.get(lb, 0.0)
                if d < max_distance and d < out.get((la, lb), math.inf):
                    out[(la, lb)] = d
            return out

        return probe

    def _body_margins(self, body: int) -> dict[int, float]:
        """The margins of ``body``'s mesh links (link -> MESH_MARGIN), gathered once per body."""
        out = self._margins.get(body)
        if out is None:
            out = self._margins[body] = {link: m for (b, link), m in self._margin.items() if b == body}
        return out

    def _mount(self, a: str, b: str) -> frozenset[int]:
        """The links of ``a`` exempt from contact with ``b``: an arm's mount when ``b`` is a fixed object."""
        r = self.robots.get(a)
        return r.mount if r is not None and not r.planar and b in self.fixed else frozenset()

    def carrier(self, robot: str, obj: str, offset: np.ndarray) -> Callable[[], None]:
        """A function of no arguments that puts object ``obj`` where arm ``robot``, at its current
        configuration, holds it: at ``offset`` (4×4, the object's frame in the end-effector link's frame)
        from its end-effector link frame (pybullet's forward kinematics, the quaternion normalised, the
        product in double precision: what ``set_pose(obj, ee_pose(robot) @ offset)`` does, without the
        matrices)."""
        pb, cid = self.pb, self.cid
        body, ee, target = self.robots[robot].body, self.robots[robot].ee, self.bodies[obj]
        (ox, oy, oz), (bx, by, bz, bw) = tf.to_quaternion(np.asarray(offset, dtype=float))

        def put() -> None:
            st = pb.getLinkState(body, ee, computeForwardKinematics=True, physicsClientId=cid)
            (px, py, pz), (x, y, z, w) = st[4], st[5]
            n = math.sqrt(x * x + y * y + z * z + w * w)
            x, y, z, w = x / n, y / n, z / n, w / n
            tx, ty, tz = 2 * (y * oz - z * oy), 2 * (z * ox - x * oz), 2 * (x * oy - y * ox)  # q v q*
            pos = (
                px + ox + w * tx + (y * tz - z * ty),
                py + oy + w * ty + (z * tx - x * tz),
                pz + oz + w * tz + (x * ty - y * tx),
            )
            orn = (
                w * bx + x * bw + y * bz - z * by,
                w * by - x * bz + y * bw + z * bx,
                w * bz + x * by - y * bx + z * bw,
                w * bw - x * bx - y * by - z * bz,
            )
            pb.resetBasePositionAndOrientation(target, pos, orn, physicsClientId=cid)

        return put

    def link_name(self, name: str, index: int) -> str | None:
        """The name of link ``index`` of robot ``name`` (None for a rigid object)."""
        return self._link(name, index)

    def _link(self, name: str, index: int) -> str | None:
        r = self.robots.get(name)
        return None if r is None else r.links.get(index, str(index))

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Disconnect the private pybullet client (again: nothing)."""
        if self.cid >= 0:
            try:
                self.pb.disconnect(physicsClientId=self.cid)
            except self.pb.error:  # pragma: no cover - already gone
                pass
            self.cid = -1

    def __enter__(self) -> "ReplayScene":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
