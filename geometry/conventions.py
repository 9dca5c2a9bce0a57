"""The geometry layer's conventions, one home each: frames on the floor, lifts, the placement lattice, angle
wrapping, pose error, interpolation resolution and per-query seeds.

Everything here is plain numpy on 4×4 transforms (:mod:`mrgc.geometry.transforms`) and imports nothing else
of mrgc, so phase 1, the planner's grounding, the validator's replay and the pictures can all share it
without depending on each other.  The validator stays independent of the planner by using another engine
(pybullet instead of coal and the numpy kinematics), not by retyping these formulas.

- **Angles** are radians; a wrapped angle lies in [-π, π) (:func:`wrap_angle`).
- **Floor frames.**  A planar base pose is ``(x, y, yaw)``; :func:`se2` is its 4×4 transform and
  :func:`to_se2` projects a transform back onto the floor; :func:`yaw_of` is a transform's yaw about +z.
- **Lifts.**  Touching counts as colliding, so bodies resting on a surface float a little above it:
  :data:`ARM_PLACE_LIFT` for objects an arm puts down (6 mm: the object in hand dips a few mm below the
  straight line while the arm interpolates its approach in joint space), :data:`PLANAR_LIFT` for a planar
  robot's footprint, and for the objects such a robot puts down (1 mm).
- **Placements** inside a region are tried on a lattice, centre first (:func:`lattice_offsets`).
- **Pose error** between two poses is a position distance and a rotation angle (:func:`pose_error`).
- **Resolution.**  Motions are checked at :func:`refine`'s resolution (the validator's), paths are written
  :data:`PATH_RESOLUTION` apart, and an approach is :data:`APPROACH_SAMPLES` configurations from the
  pre-grasp to the grasp.
- **Seeds** derive from the query (:func:`seed_for`): the same queries give the same answers in any
  process.
"""

from __future__ import annotations

import math
import zlib
from typing import overload

import numpy as np
from numpy.typing import NDArray

from mrgc.geometry.transforms import rot_z

Array = NDArray[np.float64]

#: objects an arm puts down float this much above the region floor (m)
ARM_PLACE_LIFT = 6e-3
#: a planar robot's footprint, and the objects it puts down, float this much above the floor (m)
PLANAR_LIFT = 1e-3
#: configurations sampled from the pre-grasp to the grasp (an approach's swept volume)
APPROACH_SAMPLES = 5
#: largest step (m of translation, rad of turn) between checked states of a planar path, and largest joint
#: motion (rad) between the configurations of an arm's transfer: the validator's (plans say it in their
#: motion model, :func:`mrgc.planner.plan.planner_motion_model`)
PATH_RESOLUTION = 0.01


# ----------------------------------------------------------------------------------------- angles, frames


@overload
def wrap_angle(angle: float) -> float: ...
@overload
def wrap_angle(angle: Array) -> Array: ...
def wrap_angle(angle: float | Array) -> float | Array:
    """``angle`` (radians, or an array of them) wrapped into [-π, π)."""
    if isinstance(angle, np.ndarray):
        return (angle + math.pi) % (2 * math.pi) - math.pi
    return (float(angle) + math.pi) % (2 * math.pi) - math.pi


def yaw_of(t: Array) -> float:
    """The yaw (radians, about +z) of a 4×4 transform's rotation."""
    return math.atan2(float(t[1, 0]), float(t[0, 0]))


def se2(x: float, y: float, yaw: float) -> Array:
    """The 4×4 transform of a base pose on the floor (yaw in radians)."""
    t = rot_z(yaw)
    t[0, 3], t[1, 3] = x, y
    return t


def to_se2(t: Array) -> Array:
    """``(x, y, yaw)`` of a 4×4 transform projected onto the floor (yaw in [-π, π))."""
    return np.array([t[0, 3], t[1, 3], wrap_angle(yaw_of(t))])


# ------------------------------------------------------------------------------------------ pose error

_I1 = np.array([2, 0, 1])
_I2 = np.array([1, 2, 0])


def rotation_log(r: Array) -> Array:
    """Axis-angle vectors (..., 3) of rotation matrices (..., 3, 3), robust at 0 and at π."""
    v = 0.5 * (r[..., _I1, _I2] - r[..., _I2, _I1])  # sin θ · axis
    s = np.sqrt(np.einsum("...i,...i->...", v, v))
    c = 0.5 * (r[..., 0, 0] + r[..., 1, 1] + r[..., 2, 2] - 1.0)
    angle = np.arctan2(s, c)
    out: Array = v * (angle / np.maximum(s, 1e-300))[..., None]
    small = s < 1e-6
    if small.any():  # θ ≈ 0: the vector is v itself; θ ≈ π: the axis is the dominant column of (R + I)/2
        out[small & (c > 0)] = v[small & (c > 0)]
        near_pi = small & (c <= 0)
        if near_pi.any():
            b = 0.5 * (r[near_pi] + np.eye(3))
            col = np.argmax(np.diagonal(b, axis1=-2, axis2=-1), axis=-1)
            a = b[np.arange(len(b)), :, col]
            out[near_pi] = np.pi * a / np.linalg.norm(a, axis=-1, keepdims=True)
    return out


def pose_errors(pose: Array, target: Array) -> tuple[Array, Array]:
    """Position error vectors and rotation error vectors (axis-angle) from ``pose`` to ``target``, in the
    frame both are given in (broadcasting over leading axes)."""
    e_pos: Array = target[..., :3, 3] - pose[..., :3, 3]
    e_rot = rotation_log(target[..., :3, :3] @ np.swapaxes(pose[..., :3, :3], -1, -2))
    return e_pos, e_rot


def pose_error(pose: Array, target: Array) -> tuple[Array, Array]:
    """Position distance (m) and rotation angle (rad) between poses (broadcasting over leading axes; for
    two single poses, 0-d arrays: ``float()`` them)."""
    e_pos, e_rot = pose_errors(np.asarray(pose, dtype=float), np.asarray(target, dtype=float))
    return np.linalg.norm(e_pos, axis=-1), np.linalg.norm(e_rot, axis=-1)


# ------------------------------------------------------------------------------ placements, resolution


def lattice_offsets(grid: int) -> list[tuple[float, float]]:
    """The ``grid × grid`` placement lattice as offsets ``(a, b)`` in [-1, 1]² (a fraction of the room an
    object has in a region along its x and y), centre first, then by distance from it (ties by value)."""
    ticks = np.linspace(-1, 1, grid) if grid > 1 else np.zeros(1)
    return sorted(((float(a), float(b)) for a in ticks for b in ticks), key=lambda ab: (ab[0] ** 2 + ab[1] ** 2, ab))


#: configurations :func:`refine` puts per step of a path (the validator's resolution): row ``REFINE * k`` of a
#: refined path is its configuration ``k``
REFINE = 4


def refine(configs: Array, sub: int = REFINE) -> Array:
    """Configurations (..., C, dof) with ``sub - 1`` more interpolated between consecutive ones (the
    validator's resolution), so facts and grounding agree with what the validator checks; leading axes are
    paths refined alike.  Row ``sub * k`` is configuration ``k`` itself."""
    n = configs.shape[-2]
    if n < 2:
        return configs
    s = np.linspace(0.0, 1.0, sub + 1)[:-1, None]
    a, b = configs[..., :-1, None, :], configs[..., 1:, None, :]
    between = (a * (1 - s) + b * s).reshape(configs.shape[:-2] + ((n - 1) * sub, configs.shape[-1]))
    return np.concatenate([between, configs[..., -1:, :]], axis=-2)


def seed_for(*parts: str, seed: int = 0) -> int:
    """A stable per-query seed (Python's hash() is salted per process)."""
    return (zlib.crc32("|".join(parts).encode()) + seed) % (2**31)
