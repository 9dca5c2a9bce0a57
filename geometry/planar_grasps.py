"""The planar grasp convention (docs/geometry.md, "Planar robots"; :mod:`mrgc.geometry.planar`'s docstring):
which faces a planar robot grasps, where it stands to pick or place, and where the object rides while
carried.  Its one home, read by the planner's model (:mod:`mrgc.geometry.planar`) and by the validator's
replay (:mod:`mrgc.validator.actions`), which must not import the planner's collision kernel or lattice.
"""

from __future__ import annotations

import math

import numpy as np

from mrgc.geometry.conventions import PLANAR_LIFT, wrap_angle
from mrgc.geometry.scene import half_extents
from mrgc.geometry.transforms import from_pose, rot_z, translation
from mrgc.language.model import RobotKind, Shape

#: gap between the robot's front and the face of the object it picks or places (m)
CLEARANCE = 0.05

#: grasp -> (outward normal of the grasped face in the object frame, yaw of the object in the base frame
#: while carried, degrees): the grasped face always faces the robot (the base's -x)
PLANAR_GRASPS: dict[str, tuple[tuple[float, float], float]] = {
    "side-x+": ((1.0, 0.0), 180.0),
    "side-x-": ((-1.0, 0.0), 0.0),
    "side-y+": ((0.0, 1.0), 90.0),
    "side-y-": ((0.0, -1.0), -90.0),
}


def planar_grasp(grasp: str) -> bool:
    """Can a planar robot use ``grasp`` (a side grasp)?"""
    return grasp in PLANAR_GRASPS


def _footprint_half(kind: RobotKind) -> np.ndarray:
    return half_extents(kind.footprint) if kind.footprint is not None else np.zeros(3)


def carry_transform(kind: RobotKind, shape: Shape, grasp: str) -> np.ndarray:
    """Pose of an object (of ``shape``) that a planar robot of ``kind`` carries, held with ``grasp``,
    relative to its base frame: the kind's ``:carry`` pose, or on top of the footprint; the grasped face
    towards the robot."""
    face = rot_z(math.radians(PLANAR_GRASPS[grasp][1]))
    on: np.ndarray = (
        from_pose(kind.carry)
        if kind.carry is not None
        else translation(
            0.0, 0.0, 2 * float(_footprint_half(kind)[2]) + 2 * PLANAR_LIFT + float(half_extents(shape)[2])
        )
    )
    carried: np.ndarray = on @ face
    return carried


def grasp_base(kind: RobotKind, pose: np.ndarray, shape: Shape, grasp: str) -> np.ndarray:
    """The base pose ``(x, y, yaw)`` from which a planar robot of ``kind`` picks (or places) an object of
    ``shape`` at ``pose`` with ``grasp``: facing the grasped face, its front :data:`CLEARANCE` from it."""
    nx, ny = PLANAR_GRASPS[grasp][0]
    n = pose[:2, :2] @ np.array([nx, ny])
    n = n / max(float(np.linalg.norm(n)), 1e-12)
    d = float(_footprint_half(kind)[0]) + CLEARANCE + float(np.abs([nx, ny]) @ half_extents(shape)[:2])
    x, y = float(pose[0, 3] + d * n[0]), float(pose[1, 3] + d * n[1])
    return np.array([x, y, wrap_angle(math.atan2(-n[1], -n[0]))])
