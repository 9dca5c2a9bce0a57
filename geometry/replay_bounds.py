"""What the validator derives from a robot's URDF, as pybullet loads it: self-collision pairs and motion bounds.

Both are computed once per robot of a :class:`~mrgc.geometry.replay_world.ReplayScene` from the loaded body
(its joint tree, joint types and link frames); nothing here comes from the planner's kinematics.

**Self-collision pairs.**  Two links of one arm that carry collision shapes are *exempt* from the
self-collision check when the tree path between them crosses at most one joint of the configuration chain
(the joints the plan's configurations drive).  Fixed joints and off-chain joints (a gripper's fingers) do not
count: links rigidly attached to each other (a Panda's link7, link8 and hand) and the gripper (hand and
fingers, finger and finger) never move against each other in a plan, and neighbours across one chain joint
(link6 and the hand) are built to touch at their joint.  Every other pair is checked like any two bodies.
No pair is dropped because it "cannot meet": that would be a sampled claim, and the sweep's bounds already
make far pairs cheap (a pair 30 cm apart is re-checked only after its links could have moved 30 cm).

**Motion bounds** (the continuous check of :mod:`mrgc.planner.sweep`).  When joint ``j`` turns by ``dq``,
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

if TYPE_CHECKING:
    from mrgc.geometry.replay_world import ReplayScene

#: configurations (home and these many more, drawn with a fixed seed within the limits) whose bounding boxes
#: bound each link's radius: the smallest bound is kept (each is a true upper bound)
RADIUS_CONFIGS = 6


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
    pick's contact segment; ``turns`` (dof,): 1 for a revolute chain joint, 0 for a prismatic one."""

    links: tuple[int, ...]
    reach: np.ndarray
    ee_chain: np.ndarray
    self_pairs: tuple[tuple[int, int], ...]
    fingers: frozenset[int]
    gripper: frozenset[int]
    turns: np.ndarray

    def column(self, link: int) -> int:
        """The column of ``reach`` that belongs to pybullet link ``link``."""
        return self.links.index(link)


def arm_bounds(rs: ReplayScene, robot: str, home: np.ndarray) -> ArmBounds:
    """The :class:`ArmBounds` of arm ``robot`` of ``rs`` (its configuration is changed and put back at
    ``home``)."""
    pb, cid = rs.pb, rs.cid
    r = rs.robots[robot]
    body = r.body
    n = pb.getNumJoints(body, physicsClientId=cid)
    parent = {-1: -2}
    kind: dict[int, int] = {}
    span: dict[int, float] = {}
    for j in range(n):
        ji = pb.getJointInfo(body, j, physicsClientId=cid)
        parent[j], kind[j] = int(ji[16]), int(ji[2])
        lo, hi = float(ji[8]), float(ji[9])
        span[j] = hi - lo if kind[j] == pb.JOINT_PRISMATIC and lo <= hi else 0.0
    chain = list(r.joints)
    chain_set = set(chain)
    shaped = tuple(link for link in range(-1, n) if pb.getCollisionShapeData(body, link, physicsClientId=cid))

    def ancestors(link: int) -> list[int]:  # link, its parent, ... up to -1
        out = [link]
        while out[-1] != -1:
            out.append(parent[out[-1]])
        return out

    def chain_joints_between(a: int, b: int) -> int:
        up_a, up_b = ancestors(a), ancestors(b)
        common = next(x for x in up_a if x in set(up_b))
        path = up_a[: up_a.index(common)] + up_b[: up_b.index(common)]
        return sum(1 for link in path if link in chain_set)  # link j hangs on joint j

    pairs = tuple((a, b) for i, a in enumerate(shaped) for b in shaped[i + 1 :] if chain_joints_between(a, b) > 1)
    fingers = frozenset(
        link
        for link in range(n)
        if any(kind.get(x) == pb.JOINT_PRISMATIC and x not in chain_set for x in _up_to(ancestors(link), r.ee))
    )
    gripper = frozenset(
        link
        for link in range(-1, n)
        if r.ee in ancestors(link) and not (set(_up_to(ancestors(link), r.ee)) - {r.ee}) & chain_set
    )

    rs.set_config(robot, home)
    origin = {link: np.array(pb.getLinkState(body, link, physicsClientId=cid)[4]) for link in range(n)}
    edge = {
        link: float(np.linalg.norm(origin[link] - origin[parent[link]])) + span[link]
        if parent[link] >= 0
        else span[link]
        for link in range(n)
    }
    radius = _radii(rs, robot, shaped, home)

    def chain_length(j: int, link: int) -> float:  # from joint j's axis (link j's origin) to link's origin
        total, x = 0.0, link
        while x != j:
            total += edge[x]
            x = parent[x]
        return total

    reach = np.zeros((len(chain), len(shaped)))
    ee_chain = np.zeros(len(chain))
    for row, j in enumerate(chain):
        for col, link in enumerate(shaped):
            if j in ancestors(link):
                reach[row, col] = 1.0 if kind[j] == pb.JOINT_PRISMATIC else chain_length(j, link) + radius[link]
        if j in ancestors(r.ee):
            ee_chain[row] = 1.0 if kind[j] == pb.JOINT_PRISMATIC else chain_length(j, r.ee)
    turns = np.array([kind[j] != pb.JOINT_PRISMATIC for j in chain], dtype=float)
    return ArmBounds(shaped, reach, ee_chain, pairs, fingers, gripper, turns)


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
            frame = _link_frame(rs, r, link)
            best[link] = min(best[link], float(np.linalg.norm(corners - frame, axis=1).max()))
    rs.set_config(robot, home)
    return best


def _link_frame(rs: ReplayScene, r: Any, link: int) -> np.ndarray:
    """The world position of a link's frame origin (the base link's: the robot's base pose)."""
    if link == -1:
        return np.asarray(r.base[:3, 3], dtype=float)
    return np.array(rs.pb.getLinkState(r.body, link, physicsClientId=rs.cid)[4])


def planar_radius(points: np.ndarray) -> float:
    """The largest horizontal distance of ``points`` (N, 3; in a frame whose z axis is the yaw axis) from
    the axis."""
    return float(np.hypot(points[:, 0], points[:, 1]).max()) if len(points) else 0.0
