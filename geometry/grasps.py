"""Grasps: each grasp name of the vocabulary becomes a tool pose relative to the object.

Tool frame (the tool centre point between the fingertips): +z is the approach direction (pointing into
the object), +y the axis the fingers close along.  ``top`` approaches along -z of the object; ``side-x+``
approaches from the +x side (moving along -x), and so on.  The tool centre point sits ``depth`` inside
the face it approaches (the fingers wrap that much of the object); the pre-grasp pose is the grasp pose
backed off by ``approach`` along -z of the tool.  See docs/geometry.md for a drawing of the frames.
"""

from __future__ import annotations

import numpy as np

from mrgc.geometry.scene import half_extents
from mrgc.language.model import Shape

#: grasp name -> (approach direction in the object frame, finger axis in the object frame)
GRASPS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "top": ((0, 0, -1), (0, 1, 0)),
    "side-x+": ((-1, 0, 0), (0, 1, 0)),
    "side-x-": ((1, 0, 0), (0, 1, 0)),
    "side-y+": ((0, -1, 0), (1, 0, 0)),
    "side-y-": ((0, 1, 0), (1, 0, 0)),
}

DEPTH = 0.02  # how far the fingers reach past the face (m)
APPROACH = 0.08  # pre-grasp back-off along the approach axis (m)


def known(grasp: str) -> bool:
    return grasp in GRASPS


def grasp_transform(grasp: str, shape: Shape, depth: float = DEPTH) -> np.ndarray:
    """Tool pose in the object frame for ``grasp`` (KeyError for a name this layer does not know)."""
    approach, fingers = (np.array(v, dtype=float) for v in GRASPS[grasp])
    z = approach
    y = fingers
    x = np.cross(y, z)
    half = half_extents(shape)
    reach = float(np.abs(approach) @ half)  # half extent along the approach axis
    t = np.eye(4)
    t[:3, 0], t[:3, 1], t[:3, 2] = x, y, z
    t[:3, 3] = -approach * max(reach - min(depth, reach), 0.0)
    return t


def pregrasp_transform(grasp_t: np.ndarray, approach: float = APPROACH) -> np.ndarray:
    """The grasp pose backed off by ``approach`` along the tool's -z."""
    back = np.eye(4)
    back[2, 3] = -approach
    return grasp_t @ back
