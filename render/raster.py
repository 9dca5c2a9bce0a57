"""Images of a :class:`~mrgc.render.world.World` with pybullet's TinyRenderer (CPU, headless, no display).

The one render module that imports pybullet.  A :class:`Rasterizer` owns a private DIRECT client holding a
visual body per drawable (fixed objects, movable objects, each robot part); :meth:`Rasterizer.draw` moves
them to a frame's poses and renders.  Robots are their collision shapes (see :mod:`mrgc.render.world`):
pybullet's Panda visual meshes hold about 30 times more triangles and cost about 0.08 s per image whatever
its size, four times the collision meshes' cost at 320×240.

The TinyRenderer ignores alpha, so regions are not bodies: they are drawn afterwards, translucent, by
casting each pixel's view ray against the region boxes and blending the region colour wherever the box's
near face lies in front of the rendered depth (:func:`tint_regions`).  A region that is not a box is drawn
as its bounding box.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mrgc.geometry.scene import half_extents
from mrgc.geometry.transforms import to_quaternion
from mrgc.render.camera import Camera
from mrgc.render.frames import Frame
from mrgc.render.palette import REGION_ALPHA, RGB
from mrgc.render.world import Drawable, World

#: light: direction towards the light (world), ambient and diffuse shares
LIGHT = (0.4, -0.6, 1.0)
AMBIENT, DIFFUSE, SPECULAR = 0.55, 0.45, 0.05


class Rasterizer:
    """Renders frames of ``world``; use as a context manager (or call :meth:`close`)."""

    def __init__(self, world: World) -> None:
        from mrgc.geometry.bullet import quiet_output

        with quiet_output():
            import pybullet

            self.pb: Any = pybullet
            self.cid: int = pybullet.connect(pybullet.DIRECT)
        self.world = world
        self._shapes: dict[tuple[Any, ...], int] = {}
        self.bodies: dict[str, int] = {}
        self._patches: tuple[Any, list[RegionPatch]] = (None, [])
        try:
            for part, pose in world.fixed:
                self._place(self._body(part), pose)
            for name, part in world.objects.items():
                self._place(self._body(part), world.start[name])
            for view in world.robots.values():
                for part, pose in view.part_poses(view.home):
                    self._place(self._body(part), pose)
        except BaseException:
            self.close()
            raise

    def _body(self, d: Drawable) -> int:
        pb, cid = self.pb, self.cid
        key = (d.kind, d.size, d.mesh_path, d.colour)
        if key not in self._shapes:
            rgba = [*d.colour, 1.0]
            if d.kind == "box":
                vs = pb.createVisualShape(
                    pb.GEOM_BOX, halfExtents=[s / 2 for s in d.size], rgbaColor=rgba, physicsClientId=cid
                )
            elif d.kind == "sphere":
                vs = pb.createVisualShape(pb.GEOM_SPHERE, radius=d.size[0], rgbaColor=rgba, physicsClientId=cid)
            elif d.kind in ("cylinder", "capsule"):
                geom = pb.GEOM_CYLINDER if d.kind == "cylinder" else pb.GEOM_CAPSULE
                vs = pb.createVisualShape(geom, radius=d.size[0], length=d.size[1], rgbaColor=rgba, physicsClientId=cid)
            elif d.mesh_path is not None:
                from mrgc.geometry.bullet import quiet_output

                with quiet_output():
                    vs = pb.createVisualShape(
                        pb.GEOM_MESH, fileName=d.mesh_path, meshScale=list(d.size), rgbaColor=rgba, physicsClientId=cid
                    )
            else:
                assert d.vertices is not None and d.faces is not None
                vs = pb.createVisualShape(
                    pb.GEOM_MESH,
                    vertices=d.vertices.tolist(),
                    indices=d.faces.reshape(-1).tolist(),
                    rgbaColor=rgba,
                    physicsClientId=cid,
                )
            self._shapes[key] = int(vs)
        body = int(pb.createMultiBody(baseMass=0, baseVisualShapeIndex=self._shapes[key], physicsClientId=cid))
        self.bodies[d.name] = body
        return body

    def _place(self, body: int, pose: np.ndarray) -> None:
        pos, orn = to_quaternion(np.asarray(pose, dtype=float))
        self.pb.resetBasePositionAndOrientation(body, pos, orn, physicsClientId=self.cid)

    def pose(self, frame: Frame) -> None:
        """Move every body to ``frame``."""
        w = self.world
        for name, pose in frame.poses.items():
            self._place(self.bodies[name], pose)
        for name, q in frame.configs.items():
            for part, pose in w.robots[name].part_poses(q, frame.fingers.get(name)):
                self._place(self.bodies[part.name], pose)

    def draw(self, frame: Frame, camera: Camera, width: int, height: int) -> np.ndarray:
        """The RGB image (height, width, 3; uint8) of ``frame`` seen by ``camera``, regions translucent."""
        self.pose(frame)
        pb = self.pb
        out = pb.getCameraImage(
            width,
            height,
            camera.view_matrix(),
            camera.projection_matrix(width / height),
            renderer=pb.ER_TINY_RENDERER,
            flags=pb.ER_NO_SEGMENTATION_MASK,
            shadow=0,
            lightDirection=list(LIGHT),
            lightAmbientCoeff=AMBIENT,
            lightDiffuseCoeff=DIFFUSE,
            lightSpecularCoeff=SPECULAR,
            physicsClientId=self.cid,
        )
        rgb = np.asarray(out[2], dtype=np.uint8).reshape(height, width, 4)[..., :3]
        depth = camera.linear_depth(np.asarray(out[3], dtype=float).reshape(height, width))
        key = (camera, width, height)
        if self._patches[0] != key:
            regions = [(b.pose, half_extents(b.shape), colour) for b, colour in self.world.regions]
            self._patches = (key, region_patches(camera, regions, width, height))
        return tint_regions(rgb, depth, self._patches[1])

    def close(self) -> None:
        """Disconnect the private client (a second call does nothing)."""
        cid, self.cid = self.cid, -1
        if cid >= 0:
            with contextlib.suppress(self.pb.error):
                self.pb.disconnect(physicsClientId=cid)

    def __enter__(self) -> "Rasterizer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass(frozen=True)
class RegionPatch:
    """A region as seen by one camera: the pixel rectangle it covers, the eye-space depth of its near face
    per pixel (inf where the ray misses it), and the colour and opacity to blend there."""

    rows: slice
    cols: slice
    near: np.ndarray
    alpha: np.ndarray
    tint: np.ndarray


def region_patches(
    camera: Camera,
    regions: list[tuple[np.ndarray, np.ndarray, RGB]],
    width: int,
    height: int,
    alpha: float = REGION_ALPHA,
) -> list[RegionPatch]:
    """Cast the view rays of the pixels each region box (pose, half extents, colour) covers: faces shaded by
    their direction, edges darker and more opaque.  Depends on the camera only, so it is done once."""
    rays = camera.rays(width, height)
    pixel = 2 * math.tan(math.radians(camera.fov) / 2) / height  # size of a pixel at unit depth
    out = []
    for pose, half, colour in regions:
        box = _pixel_box(camera, pose, half, width, height)
        if box is None:
            continue
        r0, r1, c0, c1 = box
        rot = pose[:3, :3]
        o = rot.T @ (camera.eye - pose[:3, 3])
        d = rays[r0:r1, c0:c1] @ rot  # the rays in the box frame
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (-half - o) / d
            t2 = (half - o) / d
        tmin = np.nan_to_num(np.minimum(t1, t2), nan=-np.inf)
        tmax = np.nan_to_num(np.maximum(t1, t2), nan=np.inf)
        enter, leave = tmin.max(axis=2), tmax.min(axis=2)
        near = np.maximum(enter, 0.0)
        miss = (enter > leave) | (leave <= 0)
        shade = np.array([0.82, 0.92, 1.0])[tmin.argmax(axis=2)]
        local = o + near[..., None] * d
        eps = 1.5 * pixel * np.maximum(near, 1e-6)
        edge = (np.abs(np.abs(local) - half) <= eps[..., None]).sum(axis=2) >= 2
        out.append(
            RegionPatch(
                slice(r0, r1),
                slice(c0, c1),
                np.where(miss, np.inf, near),
                np.where(edge, min(1.0, 2.5 * alpha), alpha)[..., None],
                np.array(colour) * 255 * np.where(edge, 0.55, shade)[..., None],
            )
        )
    return out


def tint_regions(rgb: np.ndarray, depth: np.ndarray, patches: list[RegionPatch]) -> np.ndarray:
    """``rgb`` with each region blended in where its near face lies in front of ``depth`` (eye-space)."""
    out = rgb.copy()
    for p in patches:
        hit = p.near < depth[p.rows, p.cols]
        if not hit.any():
            continue
        patch = out[p.rows, p.cols].astype(float)
        blended = (1 - p.alpha) * patch + p.alpha * p.tint
        out[p.rows, p.cols] = np.where(hit[..., None], blended, patch).clip(0, 255).astype(np.uint8)
    return out


def _pixel_box(camera: Camera, pose: np.ndarray, half: np.ndarray, w: int, h: int) -> tuple[int, int, int, int] | None:
    """Rows and columns [r0, r1) × [c0, c1) covering the box's projection (the whole picture when a corner
    lies behind the eye); None when it is off the picture."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    pts = (signs * half) @ pose[:3, :3].T + pose[:3, 3]
    r, u, f = camera.axes()
    rel = pts - camera.eye
    z = rel @ f
    if (z <= camera.near).any():
        return 0, h, 0, w
    ty = math.tan(math.radians(camera.fov) / 2)
    tx = ty * w / h
    cols = ((rel @ r) / z / tx + 1) / 2 * w
    rows = (1 - (rel @ u) / z / ty) / 2 * h
    c0, c1 = max(0, int(cols.min()) - 1), min(w, int(math.ceil(cols.max())) + 1)
    r0, r1 = max(0, int(rows.min()) - 1), min(h, int(math.ceil(rows.max())) + 1)
    return (r0, r1, c0, c1) if r0 < r1 and c0 < c1 else None
