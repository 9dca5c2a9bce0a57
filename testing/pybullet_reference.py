"""pybullet references for the numpy kinematics and coal: forward kinematics, inverse kinematics and
box distances computed by pybullet alone, for tests and benchmarks to compare against.

They run in this process's shared pybullet client (:func:`mrgc.geometry.bullet.shared_client`).  The
reference IK draws its own restarts and measures its error with pybullet's own forward kinematics: nothing
of :mod:`mrgc.geometry.fk` or :mod:`mrgc.geometry.ik`, which it checks, runs in it.  Only the robot model
(the URDF read into a :class:`~mrgc.geometry.kinematics.RobotModel`: joint order, limits, frozen joints)
is shared, to put both engines in the same configuration.
"""

from __future__ import annotations

import math
import os
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from mrgc.geometry import transforms as tf
from mrgc.geometry.bullet import pose_of, shared_body, shared_client
from mrgc.geometry.conventions import pose_error
from mrgc.geometry.ik import IKResult, IKStatus
from mrgc.geometry.kinematics import Link, RobotModel

__all__ = ["pybullet_box_distance", "pybullet_fk", "pybullet_ik"]

Array = NDArray[np.float64]

#: (pid, model key) -> (link name -> pybullet link index, movable joints in pybullet order with our link)
_LINKS: dict[tuple[int, object], tuple[dict[str, int], list[tuple[int, Link]]]] = {}


def _pb_links(model: RobotModel) -> tuple[int, dict[str, int], list[tuple[int, Link]]]:
    """The model's body, link name → pybullet link index (base -1), and its movable joints in pybullet
    order with our link (pybullet's IK takes and returns one value per movable joint, in that order)."""
    pb, cid = shared_client()
    body = shared_body(model.urdf)
    key = (os.getpid(), model.key)
    if key not in _LINKS:
        by_name = {pb.getBodyInfo(body, physicsClientId=cid)[0].decode(): -1}
        movable = []
        for j in range(pb.getNumJoints(body, physicsClientId=cid)):
            info = pb.getJointInfo(body, j, physicsClientId=cid)
            by_name[info[12].decode()] = j
            if info[2] != pb.JOINT_FIXED:
                movable.append((j, model.links[model.link_index(info[12].decode())]))
        _LINKS[key] = (by_name, movable)
    by_name, movable = _LINKS[key]
    return body, by_name, movable


def _set_state(model: RobotModel, q: Array, base: Array | None, fingers: float | None = None) -> tuple[Any, int, int]:
    pb, cid = shared_client()
    body, _, movable = _pb_links(model)
    base_t = np.eye(4) if base is None else np.asarray(base, dtype=float)
    # resetBasePositionAndOrientation places the base's centre of mass, not its URDF frame
    com = base_t @ pose_of(*pb.getDynamicsInfo(body, -1, physicsClientId=cid)[3:5])
    pos, orn = tf.to_quaternion(com)
    pb.resetBasePositionAndOrientation(body, pos, orn, physicsClientId=cid)
    for j, link in movable:
        v = q[link.chain_index] if link.chain_index >= 0 else link.frozen_value
        if link.finger and fingers is not None:
            v = model.gripper_value(link.index, fingers)
        pb.resetJointState(body, j, float(v), physicsClientId=cid)
    return pb, cid, body


def pybullet_fk(
    model: RobotModel, q: Sequence[float] | Array, base: Array | None = None, fingers: float | None = None
) -> dict[str, Array]:
    """pybullet's forward kinematics (reference): link name → 4×4 URDF link frame in the world, with the
    base link's frame at ``base`` (identity when None); off-chain joints at their frozen values, the finger
    joints at ``fingers`` when given (clamped into their limits).

    pybullet reports link frames in single precision (errors up to about 1e-7 m).
    """
    pb, cid, body = _set_state(model, np.asarray(q, dtype=float), base, fingers)
    _, by_name, _ = _pb_links(model)
    out = {}
    bpos, born = pb.getBasePositionAndOrientation(body, physicsClientId=cid)
    inertial = pose_of(*pb.getDynamicsInfo(body, -1, physicsClientId=cid)[3:5])
    names = [n for n in model.link_names if by_name[n] >= 0]
    states = pb.getLinkStates(body, [by_name[n] for n in names], computeForwardKinematics=True, physicsClientId=cid)
    out[model.links[0].name] = pose_of(bpos, born) @ tf.inverse(inertial)
    for name, st in zip(names, states):
        out[name] = pose_of(st[4], st[5])  # worldLinkFramePosition/Orientation, not the centre of mass
    return out


def pybullet_box_distance(
    model: RobotModel,
    q: Sequence[float] | Array,
    base: Array | None,
    size: Sequence[float],
    pose: Array,
    skip_links: Sequence[str] = (),
) -> float:
    """Reference signed distance (negative: penetration) between the robot's links at ``q`` and a box of full
    side lengths ``size`` at ``pose``, from pybullet's own collision engine (``getClosestPoints``), the
    second engine the tests compare coal against.  Links named in ``skip_links`` are left out."""
    pb, cid, body = _set_state(model, np.asarray(q, dtype=float), base)
    _, by_name, _ = _pb_links(model)
    shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[float(v) / 2 for v in size], physicsClientId=cid)
    pos, orn = tf.to_quaternion(np.asarray(pose, dtype=float))
    box = pb.createMultiBody(
        baseMass=0, baseCollisionShapeIndex=shape, basePosition=pos, baseOrientation=orn, physicsClientId=cid
    )
    # the box body stays (pybullet refuses to remove it in DIRECT mode); only the robot's distance to it is read
    best = float("inf")
    for name, index in by_name.items():
        if name in skip_links:
            continue
        for pt in pb.getClosestPoints(body, box, 1.0, linkIndexA=index, physicsClientId=cid):
            best = min(best, float(pt[8]))
    return best


def pybullet_ik(
    model: RobotModel,
    target: Array,
    seed: int,
    q_init: Sequence[float] | Array | None = None,
    restarts: int = 8,
    tol_pos: float = 1e-4,
    tol_rot: float = 1e-3,
    max_iters: int = 200,
    null_space: bool = False,
) -> IKResult:
    """pybullet's ``calculateInverseKinematics`` with random restarts, for comparison; ``target`` in the
    base frame.  The starts are ``q_init`` (the middle of the limits when None), then uniform draws within
    the limits from ``default_rng(seed)``; a restart counts when its result, measured with pybullet's own
    forward kinematics, meets the tolerances within the joint limits.

    ``null_space`` selects pybullet's variant that takes joint limits and rest poses; on the Panda it
    rarely gets within 1e-4 m (0 of 100 reachable poses here), so the plain damped least squares is the
    default.
    """
    target = np.asarray(target, dtype=float)
    pb, cid = shared_client()
    body, by_name, movable = _pb_links(model)
    ll = [lk.frozen_value if lk.chain_index < 0 else model.lower[lk.chain_index] for _, lk in movable]
    ul = [lk.frozen_value if lk.chain_index < 0 else model.upper[lk.chain_index] for _, lk in movable]
    jr = [max(u - lo, 1e-6) for lo, u in zip(ll, ul)]
    pos, orn = tf.to_quaternion(target)
    best = (math.inf, math.inf)
    first = (model.lower + model.upper) / 2 if q_init is None else np.clip(q_init, model.lower, model.upper)
    starts = [first, *np.random.default_rng(seed).uniform(model.lower, model.upper, (max(restarts, 1) - 1, model.dof))]
    for r, q0 in enumerate(starts):
        _set_state(model, q0, None)
        kw: dict[str, Any] = {}
        if null_space:
            rest = [float(q0[lk.chain_index]) if lk.chain_index >= 0 else lk.frozen_value for _, lk in movable]
            kw = {"lowerLimits": ll, "upperLimits": ul, "jointRanges": jr, "restPoses": rest}
        sol = pb.calculateInverseKinematics(
            body,
            by_name[model.end_effector],
            pos,
            orn,
            maxNumIterations=max_iters,
            residualThreshold=1e-8,
            physicsClientId=cid,
            **kw,
        )
        q = np.zeros(model.dof)
        for (_, lk), v in zip(movable, sol):
            if lk.chain_index >= 0:
                q[lk.chain_index] = v
        pe, re = (float(e) for e in pose_error(pybullet_fk(model, q)[model.end_effector], target))
        best = min(best, (pe, re), key=sum)
        if pe <= tol_pos and re <= tol_rot and bool(model.within_limits(q)):
            return IKResult(IKStatus.SOLVED, q, pe, re, r + 1)
    return IKResult(IKStatus.NO_CONVERGENCE, None, best[0], best[1], len(starts))
