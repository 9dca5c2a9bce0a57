"""Batched forward kinematics in numpy on a :class:`~mrgc.geometry.kinematics.RobotModel`.

Configurations are arrays ``q`` of shape ``(..., dof)`` (any leading batch shape, also none); results keep
that batch shape.  Transforms are in the robot's base-link frame unless a ``base`` pose is given, in which
case ``world = base_T @ link_T``.  Agrees with pybullet to float precision (tests/test_kinematics.py).

Each joint's local transform is affine in (sin q, cos q) for a revolute joint and in q for a prismatic one
(Rodrigues), so all joints of a batch are evaluated in a few array operations; links are then chained with
one batched matmul each.  Helpers for inverse kinematics (:func:`chain_frames`, :func:`jacobian_t`) work on
the chain alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

import numpy as np

from mrgc.geometry import transforms as tf
from mrgc.geometry.kinematics import RobotModel
from mrgc.language.model import Pose

BasePose = Union[Pose, np.ndarray, None]


@dataclass(frozen=True)
class _Plan:
    """Precomputed constants of a model: joint local transform = O + a·A + b·B."""

    rev: np.ndarray  # (dof,) bool: revolute (else prismatic)
    o: np.ndarray  # (dof, 4, 4) parent link → joint frame at 0
    a: np.ndarray  # (dof, 4, 4)
    b: np.ndarray  # (dof, 4, 4)
    ob: np.ndarray  # o + b: revolute local = ob + sin q · a − cos q · b
    pre_o: np.ndarray  # same three with ``pre`` (previous chain joint → joint) instead of ``origin``
    pre_a: np.ndarray
    pre_b: np.ndarray
    pre_ob: np.ndarray  # pre_o + pre_b: revolute local = pre_ob + sin q · pre_a − cos q · pre_b
    axes: np.ndarray  # (dof, 3)
    all_rev: bool  # every chain joint revolute
    z_axes: bool  # every chain joint axis is +z (joint axes in the base frame are then frame columns)
    steps: tuple[tuple[int, int, int, np.ndarray | None], ...]  # (link, parent, chain index or -1, const)


_PLANS: dict[str, _Plan] = {}


def _skew4(axis: np.ndarray) -> np.ndarray:
    x, y, z = axis
    k = np.zeros((4, 4))
    k[:3, :3] = [[0, -z, y], [z, 0, -x], [-y, x, 0]]
    return k


def _terms(origin: np.ndarray, kind: str, axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if kind == "revolute":
        k = _skew4(axis)
        return origin @ k, origin @ k @ k
    a = np.zeros((4, 4))
    a[:3, 3] = origin[:3, :3] @ axis
    return a, np.zeros((4, 4))


def _local(kind: str, origin: np.ndarray, axis: np.ndarray, value: float) -> np.ndarray:
    a, b = _terms(origin, kind, axis)
    if kind == "revolute":
        local: np.ndarray = origin + np.sin(value) * a + (1 - np.cos(value)) * b
        return local
    slid: np.ndarray = origin + value * a
    return slid


def plan(model: RobotModel) -> _Plan:
    """The precomputed constants of ``model`` (cached per :attr:`RobotModel.key`)."""
    p = _PLANS.get(model.key)
    if p is None:
        js = model.joints

        def stack(mats: list[np.ndarray]) -> np.ndarray:
            return np.array(mats).reshape(-1, 4, 4)

        ta = [_terms(j.origin, j.kind, j.axis) for j in js]
        tp = [_terms(j.pre, j.kind, j.axis) for j in js]
        steps: list[tuple[int, int, int, np.ndarray | None]] = []
        for link in model.links[1:]:
            if link.chain_index >= 0:
                steps.append((link.index, link.parent, link.chain_index, None))
            elif link.joint_kind in ("revolute", "prismatic"):
                steps.append(
                    (link.index, link.parent, -1, _local(link.joint_kind, link.origin, link.axis, link.frozen_value))
                )
            else:
                steps.append((link.index, link.parent, -1, np.array(link.origin)))
        o, pre = stack([j.origin for j in js]), stack([j.pre for j in js])
        b, pre_b = stack([t[1] for t in ta]), stack([t[1] for t in tp])
        p = _Plan(
            rev=np.array([j.kind == "revolute" for j in js], dtype=bool),
            o=o,
            a=stack([t[0] for t in ta]),
            b=b,
            ob=o + b,
            pre_o=pre,
            pre_a=stack([t[0] for t in tp]),
            pre_b=pre_b,
            pre_ob=pre + pre_b,
            axes=np.array([j.axis for j in js]).reshape(-1, 3),
            all_rev=all(j.kind == "revolute" for j in js),
            z_axes=all(np.array_equal(j.axis, [0.0, 0.0, 1.0]) for j in js),
            steps=tuple(steps),
        )
        _PLANS[model.key] = p
    return p


def _coeffs(p: _Plan, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.where(p.rev, np.sin(q), q)[..., None, None]
    b = np.where(p.rev, 1.0 - np.cos(q), 0.0)[..., None, None]
    return a, b


def _as_q(model: RobotModel, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (model.dof,):
        raise ValueError(f"configuration of shape {q.shape} for a robot with {model.dof} joints")
    return q


def base_transform(base: BasePose) -> np.ndarray | None:
    """The 4×4 of a base pose given as a :class:`Pose`, a 4×4 array or None (identity)."""
    if base is None:
        return None
    if isinstance(base, Pose):
        return tf.from_pose(base)
    return np.asarray(base, dtype=float)


_FINGER_STEPS: dict[tuple[str, float], tuple[tuple[int, int, int, np.ndarray | None], ...]] = {}


def _steps(model: RobotModel, p: _Plan, fingers: float | None) -> tuple[tuple[int, int, int, np.ndarray | None], ...]:
    """The chaining steps of ``p`` with the gripper's joints at drive value ``fingers``
    (:meth:`RobotModel.gripper_value`: mimic rules applied, clamped into their limits) instead of their
    frozen values; cached per (model, value)."""
    if fingers is None:
        return p.steps
    key = (model.key, round(float(fingers), 12))
    steps = _FINGER_STEPS.get(key)
    if steps is None:
        if len(_FINGER_STEPS) > 4096:  # openings come from object widths: few distinct values; stay bounded
            _FINGER_STEPS.clear()
        links = model.links
        steps = tuple(
            (
                k,
                parent,
                ci,
                _local(links[k].joint_kind, links[k].origin, links[k].axis, model.gripper_value(k, float(fingers)))
                if links[k].finger
                else const,
            )
            for k, parent, ci, const in p.steps
        )
        _FINGER_STEPS[key] = steps
    return steps


def fk(model: RobotModel, q: np.ndarray, base: BasePose = None, fingers: float | None = None) -> np.ndarray:
    """Frames of every link (in ``model.links`` order): shape ``q.shape[:-1] + (L, 4, 4)``.

    In the base-link frame, or in the world when ``base`` (the base link's pose) is given.  ``fingers``
    is the gripper's drive value (see :meth:`RobotModel.finger_value`); None leaves it frozen (open).
    """
    q = _as_q(model, q)
    p = plan(model)
    batch = q.shape[:-1]
    flat = q.reshape(math.prod(batch), model.dof)  # (a chain of 0 joints too)
    if p.all_rev:
        local = p.ob + np.sin(flat)[..., None, None] * p.a - np.cos(flat)[..., None, None] * p.b  # (N, dof, 4, 4)
    else:
        a, b = _coeffs(p, flat)
        local = p.o + a * p.a + b * p.b
    out = np.empty((flat.shape[0], len(model.links), 4, 4))
    bt = base_transform(base)
    out[:, 0] = np.eye(4) if bt is None else bt
    steps = _steps(model, p, fingers)
    if flat.shape[0] == 1:  # one configuration (a motion check's): 4x4 products, the same numbers, less indexing
        one, own = out[0], local[0]
        for k, parent, ci, const in steps:
            np.matmul(one[parent], own[ci] if const is None else const, out=one[k])
    else:
        for k, parent, ci, const in steps:
            np.matmul(out[:, parent], local[:, ci] if const is None else const, out=out[:, k])
    return out.reshape(batch + out.shape[1:])


def fk_world(model: RobotModel, q: np.ndarray, base: BasePose, fingers: float | None = None) -> np.ndarray:
    """:func:`fk` with the base link at ``base`` (a :class:`Pose` or a 4×4): ``world = base_T @ link_T``."""
    return fk(model, q, base, fingers)


def chain_frames(model: RobotModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frames of the chain joints (``q.shape[:-1] + (dof, 4, 4)``) and of the end effector, base frame."""
    q = _as_q(model, q)
    p = plan(model)
    if p.all_rev:
        local = p.pre_ob + np.sin(q)[..., None, None] * p.pre_a - np.cos(q)[..., None, None] * p.pre_b
    else:
        a, b = _coeffs(p, q)
        local = p.pre_o + a * p.pre_a + b * p.pre_b
    frames = np.empty(local.shape)
    if model.dof:
        frames[..., 0, :, :] = local[..., 0, :, :]
    for i in range(1, model.dof):
        np.matmul(frames[..., i - 1, :, :], local[..., i, :, :], out=frames[..., i, :, :])
    last = frames[..., -1, :, :] if model.dof else np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4))
    return frames, last @ model.ee_offset


def ee_pose(model: RobotModel, q: np.ndarray, base: BasePose = None) -> np.ndarray:
    """Frame(s) of the end-effector link, shape ``q.shape[:-1] + (4, 4)``."""
    t = chain_frames(model, q)[1]
    bt = base_transform(base)
    return t if bt is None else bt @ t


def jacobian_from_frames(model: RobotModel, frames: np.ndarray, ee: np.ndarray) -> np.ndarray:
    """Geometric Jacobian ``(..., 6, dof)`` of the end effector in the base frame: rows vx vy vz wx wy wz."""
    return np.swapaxes(jacobian_t(model, frames, ee), -1, -2)


def jacobian_t(model: RobotModel, frames: np.ndarray, ee: np.ndarray) -> np.ndarray:
    """The transposed Jacobian, ``(..., dof, 6)`` (what least squares uses; one transpose fewer)."""
    p = plan(model)
    if p.z_axes:
        z = frames[..., :3, 2]
    else:
        z = np.einsum("...ij,...j->...i", frames[..., :3, :3], p.axes)  # joint axes in the base frame
    d = ee[..., None, :3, 3] - frames[..., :3, 3]
    lin = z[..., _I1] * d[..., _I2] - z[..., _I2] * d[..., _I1]  # z × d, without np.cross's overhead
    if p.all_rev:
        return np.concatenate([lin, z], axis=-1)
    rev = p.rev[:, None]
    return np.concatenate([np.where(rev, lin, z), np.where(rev, z, 0.0)], axis=-1)


_I1 = np.array([1, 2, 0])
_I2 = np.array([2, 0, 1])


def jacobian(model: RobotModel, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian of the end effector at ``q``, ``q.shape[:-1] + (6, dof)``, base frame."""
    frames, ee = chain_frames(model, q)
    return jacobian_from_frames(model, frames, ee)


def collision_points(model: RobotModel, q: np.ndarray, base: BasePose = None) -> dict[str, np.ndarray]:
    """Link name → its collision vertices moved to configuration(s) ``q``: ``q.shape[:-1] + (P, 3)``.

    Links without collision geometry are left out.  In the base frame, or the world with ``base``.
    """
    t = fk(model, q, base)
    out = {}
    for link in model.links:
        if len(link.points):
            tk = t[..., link.index, :, :]
            out[link.name] = np.einsum("...ij,pj->...pi", tk[..., :3, :3], link.points) + tk[..., None, :3, 3]
    return out
