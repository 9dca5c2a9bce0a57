"""The validator's own forward kinematics: an arm's link frames for many configurations at once, in numpy.

Derived from the arm's body as pybullet loaded it (:class:`~mrgc.validator.world.ReplayScene`), not
from the planner's kinematics (:mod:`mrgc.geometry.fk`): at the configuration the body stands in, each
link's frame (pybullet's ``worldLinkFrame``), its parent's and its joint's axis and value give the joint's
constant origin ``O_j = T_parent^-1 T_j J(v_j)^-1``, and then ``T_j(q) = T_parent(q) O_j J(q_j)`` for every
configuration (``J``: the turn about, or the slide along, the joint's axis; a joint off the configuration's
chain, a finger, keeps the value it has when the chain is derived).  A test checks the frames against
pybullet's at random configurations.

What the sweep asks of it (:mod:`mrgc.validator.certify`): where each link's centre of mass is (the centres
of the spheres that hold the links, :attr:`~mrgc.validator.bounds.ArmBounds.spheres`), and how far
each link's points are from each chain joint's axis, bounded by *motion spheres*: a few spheres per link,
fixed in the link's frame, that hold every collision vertex of the link (a point's distance from an axis is
convex, so its largest over the link's convex hull is at a vertex) or, for a link without its vertices, the
sphere about its centre of mass.  The distance of a sphere's centre from the axis plus its radius bounds
the distance of every point it holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from mrgc.geometry.bullet import pose_of

if TYPE_CHECKING:
    from mrgc.validator.bounds import ArmBounds
    from mrgc.validator.world import ReplayScene

#: motion spheres per link at most (the vertices split in slices along their longest spread)
MOTION_SPHERES = 4
SPHERE_PAD = 1e-3  # m added to a motion sphere's radius (pybullet's hull of the vertices, numerical noise)


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


@dataclass(frozen=True)
class _Joint:
    """One pybullet joint (link ``j`` hangs on it from ``parent``): its origin (R, p), for a joint of the
    chain its column of the configuration and kind, and the turn's ``A = R K``, ``B = R K^2`` (K: the skew
    matrix of the axis) so that ``R J(q) = R + sin(q) A + (1 - cos(q)) B``."""

    parent: int
    rot: np.ndarray
    pos: np.ndarray
    column: int
    revolute: bool
    axis: np.ndarray
    a: np.ndarray
    b: np.ndarray


class ArmChain:
    """Forward kinematics of arm ``robot`` of ``rs`` (module docstring), derived at the state its body
    stands in now (its fingers as they are: derive again after :meth:`ReplayScene.set_fingers`).

    :meth:`frames` gives every link's world frame for many configurations; links are indexed by pybullet
    link index + 1 (0: the base link)."""

    def __init__(self, rs: ReplayScene, robot: str) -> None:
        pb, cid = rs.pb, rs.cid
        r = rs.robots[robot]
        self.n = n = int(pb.getNumJoints(r.body, physicsClientId=cid))
        self.base = np.asarray(r.base, dtype=float)
        frames = [self.base]
        com = np.zeros((n + 1, 3))
        base_com = np.array(pb.getBasePositionAndOrientation(r.body, physicsClientId=cid)[0], dtype=float)
        com[0] = self.base[:3, :3].T @ (base_com - self.base[:3, 3])
        columns = {j: c for c, j in enumerate(r.joints)}
        self.joints: list[_Joint] = []
        for j in range(n):
            ji = pb.getJointInfo(r.body, j, physicsClientId=cid)
            st = pb.getLinkState(r.body, j, computeForwardKinematics=True, physicsClientId=cid)
            frame = pose_of(st[4], st[5])
            frames.append(frame)
            com[j + 1] = np.asarray(st[2], dtype=float)
            parent, kind = int(ji[16]), int(ji[2])
            axis = np.asarray(ji[13], dtype=float)
            axis = axis / max(float(np.linalg.norm(axis)), 1e-12)
            value = float(pb.getJointState(r.body, j, physicsClientId=cid)[0])
            move = np.eye(4)
            if kind == pb.JOINT_REVOLUTE:
                k = _skew(axis)
                move[:3, :3] = np.eye(3) + np.sin(value) * k + (1 - np.cos(value)) * (k @ k)
            elif kind == pb.JOINT_PRISMATIC:
                move[:3, 3] = axis * value
            origin = np.linalg.inv(frames[parent + 1]) @ frame @ np.linalg.inv(move)
            column = columns.get(j, -1)
            if column < 0:  # off the chain: the value it has now, folded into its origin
                origin = origin @ move
            k = _skew(axis)
            rot = origin[:3, :3]
            self.joints.append(
                _Joint(
                    parent + 1,
                    rot,
                    origin[:3, 3].copy(),
                    column,
                    kind == pb.JOINT_REVOLUTE,
                    axis,
                    rot @ k,
                    rot @ k @ k,
                )
            )
        self.com = com
        #: the link (index + 1) each column's joint moves, whose frame origin lies on the joint's axis
        self.child = np.array([j + 1 for j in r.joints], dtype=int)
        self.axis_local = np.array([self.joints[j].axis for j in r.joints]).reshape(-1, 3)

    def frames(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World rotations (N, n + 1, 3, 3) and positions (N, n + 1, 3) of every link at configurations
        ``qs`` (N, dof)."""
        qs = np.asarray(qs, dtype=float).reshape(len(qs), -1)
        m = len(qs)
        rot = np.empty((m, self.n + 1, 3, 3))
        pos = np.empty((m, self.n + 1, 3))
        rot[:, 0] = self.base[:3, :3]
        pos[:, 0] = self.base[:3, 3]
        for j, jt in enumerate(self.joints):
            rp, pp = rot[:, jt.parent], pos[:, jt.parent]
            pos[:, j + 1] = pp + rp @ jt.pos
            if jt.column < 0:
                rot[:, j + 1] = rp @ jt.rot
                continue
            q = qs[:, jt.column]
            if jt.revolute:
                rel = jt.rot + np.sin(q)[:, None, None] * jt.a + (1 - np.cos(q))[:, None, None] * jt.b
                rot[:, j + 1] = rp @ rel
            else:
                rot[:, j + 1] = rp @ jt.rot
                pos[:, j + 1] += np.einsum("nij,j,n->ni", rp, jt.rot @ jt.axis, q)
        return rot, pos

    def axes(self, rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each chain joint's axis in the world at :meth:`frames`' output: a point on it (N, dof, 3) and
        its unit direction (N, dof, 3)."""
        child = self.child
        direction = np.einsum("ncij,cj->nci", rot[:, child], self.axis_local)
        return pos[:, child], direction


def motion_spheres(
    rs: ReplayScene, robot: str, bounds: ArmBounds, chain: ArmChain | None = None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """For each link of ``bounds.links`` (in that order): centres (k, 3) in the link's frame and radii (k,)
    of the spheres that hold its points (module docstring): the collision vertices of a link whose shapes are
    all meshes, in up to :data:`MOTION_SPHERES` slices along their longest spread; otherwise the sphere about
    its centre of mass (:attr:`~mrgc.validator.bounds.ArmBounds.spheres`; ``chain``: the arm's
    :class:`ArmChain`, derived when not given)."""
    r = rs.robots[robot]
    model = rs.models.get(robot)
    points = {link.name: np.asarray(link.points, dtype=float) for link in model.links} if model else {}
    chain = chain or ArmChain(rs, robot)
    out = []
    for k, link in enumerate(bounds.links):
        v = points.get(r.links.get(link, ""), np.zeros((0, 3)))
        if link in bounds.fingers or len(v) < 4 or not rs.all_meshes(robot, link):
            out.append((chain.com[link + 1][None].copy(), np.array([float(bounds.spheres[k])])))
            continue
        centred = v - v.mean(axis=0)
        spread = np.linalg.svd(centred, full_matrices=False)[2][0]
        along = centred @ spread
        cuts = np.quantile(along, np.linspace(0.0, 1.0, MOTION_SPHERES + 1))
        centres, radii = [], []
        for i in range(MOTION_SPHERES):
            part = v[(along >= cuts[i]) & (along <= cuts[i + 1])]
            if not len(part):
                continue
            c = 0.5 * (part.min(axis=0) + part.max(axis=0))
            centres.append(c)
            radii.append(float(np.linalg.norm(part - c, axis=1).max()) + SPHERE_PAD)
        out.append((np.array(centres), np.array(radii)))
    return out


def pack(spheres: list[tuple[np.ndarray, np.ndarray]], links: list[int]) -> tuple[np.ndarray, ...]:
    """The motion spheres of pybullet links ``links`` (``spheres[i]`` those of ``links[i]``) in flat arrays
    for :func:`axis_reach`: each sphere's link (index + 1), centre in the link frame, radius, and where each
    link's spheres start."""
    index: list[int] = []
    local: list[np.ndarray] = []
    radius: list[float] = []
    first: list[int] = []
    for link, (c, r) in zip(links, spheres):
        first.append(len(radius))
        index += [link + 1] * len(r)
        local += list(c)
        radius += list(r)
    return np.array(index, dtype=int), np.array(local).reshape(-1, 3), np.array(radius), np.array(first, dtype=int)


def centres(rot: np.ndarray, pos: np.ndarray, packed: tuple[np.ndarray, ...]) -> np.ndarray:
    """The world centres (T, spheres, 3) of packed motion spheres (:func:`pack`) at :meth:`ArmChain.frames`'
    output."""
    links, local = packed[0], packed[1]
    out: np.ndarray = pos[:, links] + np.einsum("tkij,kj->tki", rot[:, links], local)
    return out


def axis_reach(
    chain: ArmChain, rot: np.ndarray, pos: np.ndarray, packed: tuple[np.ndarray, ...], world: np.ndarray | None = None
) -> np.ndarray:
    """The largest distance (T, links, dof) of each packed link's motion spheres (:func:`pack`) from each
    chain joint's axis, at :meth:`ArmChain.frames`' output (``world``: their :func:`centres`, when known): an
    upper bound of the distance of every point of the link from the axis."""
    radius, first = packed[2], packed[3]
    point, direction = chain.axes(rot, pos)  # (T, dof, 3)
    world = centres(rot, pos, packed) if world is None else world  # (T, spheres, 3)
    rel = world[:, :, None, :] - point[:, None, :, :]  # (T, spheres, dof, 3)
    u = direction[:, None, :, :]
    cx = rel[..., 1] * u[..., 2] - rel[..., 2] * u[..., 1]
    cy = rel[..., 2] * u[..., 0] - rel[..., 0] * u[..., 2]
    cz = rel[..., 0] * u[..., 1] - rel[..., 1] * u[..., 0]
    off_axis = np.sqrt(cx * cx + cy * cy + cz * cz) + radius[None, :, None]
    out: np.ndarray = np.maximum.reduceat(off_axis, first, axis=1)
    return out
