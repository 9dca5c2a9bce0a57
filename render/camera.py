"""Cameras: named viewing directions (presets) fitted to what must be seen, as matrices and as rays.

A camera looks from ``eye`` at ``target`` with ``up`` (z, or y for the top view) and a vertical field of
view.  :func:`fit` keeps the target at the centre of the points to show and moves the eye back along the
preset's direction until every point lies inside the picture.  The matrices follow OpenGL's conventions
(column-major, as pybullet's TinyRenderer takes them); :meth:`Camera.rays` gives the per-pixel view rays the
translucent-region overlay uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: preset -> (azimuth of the eye around the target from +x, elevation above the horizon), degrees
PRESETS: dict[str, tuple[float, float]] = {
    "iso": (-55.0, 38.0),
    "front": (-90.0, 22.0),
    "back": (90.0, 22.0),
    "side": (0.0, 22.0),
    "top": (-90.0, 89.0),
}
DEFAULT_PRESET = "iso"
FOV = 40.0  # vertical field of view, degrees
MARGIN = 1.06  # room around the fitted points


@dataclass(frozen=True, eq=False)
class Camera:
    """A pinhole camera: eye, target and up (world), vertical field of view (degrees), clipping planes."""

    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray
    fov: float = FOV
    near: float = 0.02
    far: float = 100.0

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit right, up and forward vectors of the image."""
        f = self.target - self.eye
        f = f / np.linalg.norm(f)
        r = np.cross(f, self.up)
        r = r / np.linalg.norm(r)
        return r, np.cross(r, f), f

    def view_matrix(self) -> list[float]:
        """The 4×4 world → eye matrix, column-major (OpenGL's lookAt)."""
        r, u, f = self.axes()
        m = np.eye(4)
        m[0, :3], m[1, :3], m[2, :3] = r, u, -f
        m[:3, 3] = -m[:3, :3] @ self.eye
        return [float(v) for v in m.T.reshape(-1)]

    def projection_matrix(self, aspect: float) -> list[float]:
        """The perspective projection for width/height ``aspect``, column-major (OpenGL's gluPerspective)."""
        t = 1.0 / math.tan(math.radians(self.fov) / 2)
        n, f = self.near, self.far
        m = np.zeros((4, 4))
        m[0, 0], m[1, 1] = t / aspect, t
        m[2, 2], m[2, 3] = (f + n) / (n - f), 2 * f * n / (n - f)
        m[3, 2] = -1.0
        return [float(v) for v in m.T.reshape(-1)]

    def rays(self, width: int, height: int) -> np.ndarray:
        """Per-pixel ray directions (height, width, 3) through pixel centres, scaled so that their component
        along the viewing direction is 1 (a ray parameter is then the eye-space depth)."""
        r, u, f = self.axes()
        ty = math.tan(math.radians(self.fov) / 2)
        tx = ty * width / height
        xs = ((np.arange(width) + 0.5) / width * 2 - 1) * tx
        ys = (1 - (np.arange(height) + 0.5) / height * 2) * ty
        return f + xs[None, :, None] * r + ys[:, None, None] * u  # type: ignore[no-any-return]

    def project(self, points: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pixel columns, rows (from the top-left corner, as floats) and eye-space depths of world points
        (N, 3) in a ``width`` × ``height`` picture; a point behind the eye has depth <= 0."""
        r, u, f = self.axes()
        rel = np.asarray(points, dtype=float).reshape(-1, 3) - self.eye
        z = rel @ f
        safe = np.where(z > 1e-9, z, 1e-9)
        ty = math.tan(math.radians(self.fov) / 2)
        tx = ty * width / height
        cols = ((rel @ r) / safe / tx + 1) / 2 * width
        rows = (1 - (rel @ u) / safe / ty) / 2 * height
        return cols, rows, z

    def linear_depth(self, zbuffer: np.ndarray) -> np.ndarray:
        """Eye-space depth from an OpenGL depth buffer in [0, 1]."""
        n, f = self.near, self.far
        return f * n / (f - (f - n) * zbuffer)


def fit(points: np.ndarray, preset: str = DEFAULT_PRESET, aspect: float = 4 / 3, fov: float = FOV) -> Camera:
    """A camera of ``preset`` whose picture (width/height ``aspect``) shows every point, centred on them."""
    az, el = (math.radians(v) for v in PRESETS[preset])
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    target = (lo + hi) / 2
    back = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    up = np.array([0.0, 0.0, 1.0]) if PRESETS[preset][1] < 80 else np.array([0.0, 1.0, 0.0])
    r, u, f = Camera(target + back, target, up, fov).axes()
    ty = math.tan(math.radians(fov) / 2) / MARGIN
    tx = ty * aspect
    dist = 1.0
    for _ in range(4):  # fit the distance, then centre the picture on the points' projection, again
        rel = pts - target
        dist = max(float((np.maximum(np.abs(rel @ r) / tx, np.abs(rel @ u) / ty) - rel @ f).max()), 1e-3)
        depth = dist + rel @ f
        x, y = (rel @ r) / depth, (rel @ u) / depth
        target = target + dist * ((x.max() + x.min()) / 2 * r + (y.max() + y.min()) / 2 * u)
    rel = pts - target
    dist = max(float((np.maximum(np.abs(rel @ r) / tx, np.abs(rel @ u) / ty) - rel @ f).max()), 1e-3) + 1e-3
    span = float(np.linalg.norm(hi - lo)) + dist
    return Camera(target - dist * f, target, up, fov, near=max(1e-3, dist / 100), far=10 * span)
