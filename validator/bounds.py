"""What the validator derives from a robot's URDF, as pybullet loads it: self-collision pairs and motion bounds.

Both are computed once per robot of a :class:`~mrgc.validator.world.ReplayScene` from the loaded body
(its joint tree, joint types and link frames); nothing here comes from the planner's kinematics.

**Self-collision pairs.**  Two links of one arm that carry collision shapes are *exempt* from the
self-collision check when the tree path between them crosses at most one joint of the configuration chain
(the joints the plan's configurations drive).  Fixed joints and off-chain joints (a gripper's fingers) do not
count: links rigidly attached to each other (a Panda's link7, link8 and hand) and the gripper (hand and
fingers, finger and finger) never move against each other in a plan, and neighbours across one chain joint
(link6 and the hand) are built to touch at their joint.  Every other pair is checked like any two bodies.
No pair is dropped because it "cannot meet": that would be a sampled claim, and the sweep's bounds already
make far pairs cheap (a pair 30 cm apart is re-checked only after its links could have moved 30 cm).

**Motion bounds** (the continuous check of :mod:`mrgc.validator.sweep`).  When joint ``j`` turns by ``dq``,
no point of a link it moves travels farther than ``|dq|`` times the point's distance from the joint's axis;
along a straight joint-space motion every point of link ``k`` travels at most ``sum_j |dq_j| R[j, k]``
(Schwarzer, Saha and Latombe's bound for path segments).  ``R[j, k]`` is bounded here by the chain length
from joint ``j``'s frame origin (on its axis) to link ``k``'s frame origin, the sum of the constant distances
between consecutive link frames (a prismatic joint on the way adds its whole range), plus the link's radius
about its frame origin (the farthest corner of its axis-aligned bounding box, the smallest such bound over a
few configurations).  A prismatic chain joint moves every point it carries by ``|dq|`` exactly: ``R = 1``.
A held object is a rigid part of the end-effector link: its bound is the end effector's chain length plus
the object's radius about the end-effector frame.  A planar robot's point at horizontal distance ``rho``
from its base origin travels at most ``|d(x, y)| + rho |d yaw|``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from mrgc.geometry.bullet import pose_of

if TYPE_CHECKING:
    from mrgc.validator.world import ReplayScene

#: configurations (home and these many more, drawn with a fixed seed within the limits) whose bounding boxes
#: bound each link's radius: the smallest bound is kept (each is a true upper bound)
RADIUS_CONFIGS = 6
RADIUS_PAD = 1e-3  # m added to a bound from collision vertices (pybullet's hull of them, numerical noise)


@dataclass(frozen=True)
class ArmBounds:
    """What the validator knows of one arm's links.

    ``links``: the pybullet link indices that carry collision shapes (-1, the base link, included);
    ``reach`` (dof, len(links)): ``R[j, i]`` bounds how far a point of ``links[i]`` travels per unit turn of
    chain joint ``j`` (0 when ``j`` does not move it; see the module docstring); ``ee_chain`` (dof,): the
    same for the end-effector link's frame origin (a held object adds its radius about that origin);
    ``self_pairs``: the link pairs checked against each other; ``fingers``: the finger links (and what
    hangs on them), which touch a held object; ``gripper``: the end-effector link and every link attached
    below it across joints outside the chain (hand and fingers), which may touch the object it picks in the
    pick's contact segment; ``turns`` (dof,): 1 for a revolute chain joint, 0 for a prismatic one;
    ``spheres`` (len(links),): the radius of a sphere about each link's centre of mass holding its collision
    shapes (:func:`_spheres`)."""

    links: tuple[int, ...]
    reach: np.ndarray
    ee_chain: np.ndarray
    self_pairs: tuple[tuple[int, int], ...]
    fingers: frozenset[int]
    gripper: frozenset[int]
    turns: np.ndarray
    spheres: np.ndarray

    def column(self, link: int) -> int:
        """The column of ``reach`` that belongs to pybullet link ``link``."""
        return self.links.index(link)


class _Tree:
    """An arm's pybullet joint tree: link ``j`` hangs on joint ``j`` from link ``parent[j]`` (-1: the base
    link); ``chain``: the joints the configuration drives."""

    def __init__(self, rs: ReplayScene, robot: str) -> None:
        pb, cid = rs.pb, rs.cid
        self.r = r = rs.robots[robot]
        self.n = n = pb.getNumJoints(r.body, physicsClientId=cid)
        self.parent, self.kind, self.span, self.axis = {-1: -2}, {}, {}, {}
        self.names = {-1: pb.getBodyInfo(r.body, physicsClientId=cid)[0].decode()}
        for j in range(n):
            ji = pb.getJointInfo(r.body, j, physicsClientId=cid)
            self.parent[j], self.kind[j], self.names[j] = int(ji[16]), int(ji[2]), ji[12].decode()
            lo, hi = float(ji[8]), float(ji[9])
            self.span[j] = hi - lo if self.kind[j] == pb.JOINT_PRISMATIC and lo <= hi else 0.0
            axis = np.asarray(ji[13], dtype=float)
            self.axis[j] = axis / max(float(np.linalg.norm(axis)), 1e-12)
        self.prismatic = pb.JOINT_PRISMATIC
        self.movable = (pb.JOINT_PRISMATIC, pb.JOINT_REVOLUTE)
        self.chain = set(r.joints)
        self.shaped = tuple(
            link for link in range(-1, n) if pb.getCollisionShapeData(r.body, link, physicsClientId=cid)
        )

    def up(self, link: int) -> list[int]:
        """``link``, its parent, ... up to the base link -1."""
        out = [link]
        while out[-1] != -1:
            out.append(self.parent[out[-1]])
        return out

    def chain_joints_between(self, a: int, b: int) -> int:
        """How many chain joints the tree path between links ``a`` and ``b`` crosses."""
        up_a, up_b = self.up(a), self.up(b)
        common = next(x for x in up_a if x in set(up_b))
        path = up_a[: up_a.index(common)] + up_b[: up_b.index(common)]
        return sum(1 for link in path if link in self.chain)  # link j hangs on joint j

    def fingers(self) -> frozenset[int]:
        """The links below an off-chain movable joint (prismatic fingers, a revolute finger linkage) between
        them and the end effector."""
        return frozenset(
            link
            for link in range(self.n)
            if any(self.kind.get(x) in self.movable and x not in self.chain for x in _up_to(self.up(link), self.r.ee))
            and self.r.ee in self.up(link)
        )

    def gripper(self) -> frozenset[int]:
        """The end-effector link and the links below it across joints outside the chain."""
        ee = self.r.ee
        return frozenset(
            link
            for link in range(-1, self.n)
            if ee in self.up(link) and not (set(_up_to(self.up(link), ee)) - {ee}) & self.chain
        )

    def rigid_with(self, link: int, j: int) -> bool:
        """Whether ``link`` hangs below link ``j`` across no chain joint."""
        return j in self.up(link) and not set(_up_to(self.up(link), j)) & self.chain


def arm_bounds(rs: ReplayScene, robot: str, home: np.ndarray) -> ArmBounds:
    """The :class:`ArmBounds` of arm ``robot`` of ``rs`` (its configuration is changed and put back at
    ``home``)."""
    tree = _Tree(rs, robot)
    r, shaped = tree.r, tree.shaped
    pairs = tuple((a, b) for i, a in enumerate(shaped) for b in shaped[i + 1 :] if tree.chain_joints_between(a, b) > 1)
    fingers = tree.fingers()
    rs.set_config(robot, home)
    frames = {link: _frame(rs, r, link) for link in range(-1, tree.n)}
    edge = {  # constant distance between a link's frame origin and its parent's (plus a prismatic range)
        link: tree.span[link]
        + (
            float(np.linalg.norm(frames[link][:3, 3] - frames[tree.parent[link]][:3, 3]))
            if tree.parent[link] >= 0
            else 0
        )
        for link in range(tree.n)
    }
    model = rs.models.get(robot)
    points = {link.name: np.asarray(link.points, dtype=float) for link in model.links} if model else {}
    verts: dict[int, np.ndarray] = {
        link: points[tree.names[link]]
        for link in shaped
        if link not in fingers and len(points.get(tree.names[link], ()))
    }
    radius = _radii(rs, robot, shaped, home)
    for link, v in verts.items():  # the link's own collision vertices, where the model has them, bound it tighter
        radius[link] = min(radius[link], float(np.linalg.norm(v, axis=1).max()) + RADIUS_PAD)

    def chain_length(j: int, link: int) -> float:  # from joint j's axis (link j's origin) to link's origin
        return sum(edge[x] for x in _up_to(tree.up(link), j))

    def bound(j: int, link: int) -> float:
        if tree.kind[j] == tree.prismatic:
            return 1.0
        out = chain_length(j, link) + radius[link]
        if link in verts and tree.rigid_with(link, j):  # its points' distance from joint j's axis
            rel = np.linalg.inv(frames[j]) @ frames[link]
            local = verts[link] @ rel[:3, :3].T + rel[:3, 3]
            off_axis = local - np.outer(local @ tree.axis[j], tree.axis[j])
            out = min(out, float(np.linalg.norm(off_axis, axis=1).max()) + RADIUS_PAD)
        return out

    chain = list(r.joints)
    reach = np.array([[bound(j, link) if j in tree.up(link) else 0.0 for link in shaped] for j in chain])
    ee_chain = np.array(
        [
            (1.0 if tree.kind[j] == tree.prismatic else chain_length(j, r.ee)) if j in tree.up(r.ee) else 0.0
            for j in chain
        ]
    )
    turns = np.array([tree.kind[j] != tree.prismatic for j in chain], dtype=float)
    spheres = _spheres(rs, robot, shaped, verts, home)
    return ArmBounds(
        shaped, reach.reshape(len(chain), len(shaped)), ee_chain, pairs, fingers, tree.gripper(), turns, spheres
    )


def _up_to(path: list[int], stop: int) -> list[int]:
    """The links of ``path`` (a link and its ancestors) before ``stop`` (all of them when it is not on it)."""
    return path[: path.index(stop)] if stop in path else path


def _radii(rs: ReplayScene, robot: str, links: tuple[int, ...], home: np.ndarray) -> dict[int, float]:
    """Each link's radius about its frame origin: the farthest corner of its bounding box, the smallest such
    bound over :data:`RADIUS_CONFIGS` configurations and home."""
    pb, cid = rs.pb, rs.cid
    r = rs.robots[robot]
    rng = np.random.default_rng(0)
    lo = np.where(np.isfinite(r.lower), r.lower, -np.pi)
    hi = np.where(np.isfinite(r.upper), r.upper, np.pi)
    best = dict.fromkeys(links, np.inf)
    for k in range(RADIUS_CONFIGS + 1):
        rs.set_config(robot, home if k == 0 else rng.uniform(lo, hi))
        for link in links:
            box = np.array(pb.getAABB(r.body, link, physicsClientId=cid))
            corners = np.array([[box[i][0], box[j][1], box[m][2]] for i in (0, 1) for j in (0, 1) for m in (0, 1)])
            frame = _frame(rs, r, link)[:3, 3]
            best[link] = min(best[link], float(np.linalg.norm(corners - frame, axis=1).max()))
    rs.set_config(robot, home)
    return best


def _spheres(
    rs: ReplayScene, robot: str, links: tuple[int, ...], verts: dict[int, np.ndarray], home: np.ndarray
) -> np.ndarray:
    """The radius of a sphere about each link's centre of mass (as pybullet places it:
    :meth:`~mrgc.validator.world.ReplayScene.link_centres`) holding its collision shapes: the smallest
    of (a) the farthest of the link's collision vertices (+ :data:`RADIUS_PAD`), where every shape of the
    link is a mesh (pybullet's shape is the hull of those vertices), and (b) at home and
    :data:`RADIUS_CONFIGS` more configurations, the farthest corner of pybullet's bounding box of the link
    (which holds its shapes, margins included).  Each is a true bound: shapes and centre of mass are rigid in
    the link's frame."""
    r = rs.robots[robot]
    rng = np.random.default_rng(1)
    lo = np.where(np.isfinite(r.lower), r.lower, -np.pi)
    hi = np.where(np.isfinite(r.upper), r.upper, np.pi)
    best = dict.fromkeys(links, np.inf)
    rs.set_config(robot, home)
    centres = rs.link_centres(robot, list(links))
    for k, link in enumerate(links):
        v = verts.get(link)
        if v is not None and rs.all_meshes(robot, link):
            frame = _frame(rs, r, link)
            local = frame[:3, :3].T @ (centres[k] - frame[:3, 3])
            best[link] = float(np.linalg.norm(v - local, axis=1).max()) + RADIUS_PAD
    for k in range(RADIUS_CONFIGS + 1):
        rs.set_config(robot, home if k == 0 else rng.uniform(lo, hi))
        centres = rs.link_centres(robot, list(links))
        for i, link in enumerate(links):
            box = np.array(rs.pb.getAABB(r.body, link, physicsClientId=rs.cid))
            corners = np.array([[box[a][0], box[b][1], box[c][2]] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
            best[link] = min(best[link], float(np.linalg.norm(corners - centres[i], axis=1).max()) + RADIUS_PAD)
    rs.set_config(robot, home)
    return np.array([best[link] for link in links])


def _frame(rs: ReplayScene, r: Any, link: int) -> np.ndarray:
    """The world pose of a link's frame (the base link's: the robot's base pose)."""
    if link == -1:
        return np.asarray(r.base, dtype=float)
    st = rs.pb.getLinkState(r.body, link, physicsClientId=rs.cid)
    return pose_of(st[4], st[5])


def planar_radius(points: np.ndarray) -> float:
    """The largest horizontal distance of ``points`` (N, 3; in a frame whose z axis is the yaw axis) from
    the axis."""
    return float(np.hypot(points[:, 0], points[:, 1]).max()) if len(points) else 0.0
