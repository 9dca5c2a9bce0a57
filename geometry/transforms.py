"""Rigid transforms as 4×4 numpy arrays (metres, radians), and the conversions the geometry layer needs.

A transform ``T`` maps points from a child frame to its parent: ``p_parent = T @ [p_child, 1]``.  Batched
transforms are arrays of shape ``(..., 4, 4)``.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from mrgc.language.model import Pose


def translation(x: float, y: float, z: float) -> np.ndarray:
    """The translation by ``(x, y, z)``."""
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def rot_z(yaw: float) -> np.ndarray:
    """Rotation about +z by ``yaw`` radians."""
    c, s = math.cos(yaw), math.sin(yaw)
    t = np.eye(4)
    t[:2, :2] = [[c, -s], [s, c]]
    return t


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) @ Ry(pitch) @ Rx(roll), as a 3×3 matrix."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def from_xyz_rpy(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """The transform of a URDF origin: position ``xyz`` and fixed-axis roll-pitch-yaw ``rpy``."""
    t = np.eye(4)
    t[:3, :3] = rpy_matrix(*rpy)
    t[:3, 3] = xyz
    return t


def from_pose(pose: Pose) -> np.ndarray:
    """The transform of a ``.mrg`` pose (x y z, yaw in degrees about +z)."""
    t = rot_z(pose.yaw_rad)
    t[:3, 3] = pose.position
    return t


def from_quaternion(position: Sequence[float], quat_xyzw: Sequence[float]) -> np.ndarray:
    """The transform of a position and a unit quaternion ``(x, y, z, w)``."""
    x, y, z, w = quat_xyzw
    t = np.eye(4)
    t[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    t[:3, 3] = position
    return t


def to_quaternion(t: np.ndarray) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """(position, quaternion x y z w) of a transform (the form pybullet takes)."""
    m = t[:3, :3]
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    return (float(t[0, 3]), float(t[1, 3]), float(t[2, 3])), (float(x), float(y), float(z), float(w))


def inverse(t: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform (or a batch of them)."""
    out = np.zeros_like(t)
    r = t[..., :3, :3]
    rt = np.swapaxes(r, -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rt, t[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out
