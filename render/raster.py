"""Images of a :class:`~mrgc.render.world.World` with pybullet's TinyRenderer (CPU, headless, no display).

The one render module that imports pybullet.  A :class:`Rasterizer` owns a private DIRECT client holding a
visual body per drawable (fixed objects, movable objects, each robot part); :meth:`Rasterizer.draw` moves
them to a frame's poses and renders.  Robots are their collision shapes (see :mod:`mrgc.render.world`):
pybullet's Panda visual meshes hold about 30 times more triangles and cost about 0.08 s per image whatever
its size, four times the collision meshes' cost at 320×240.

The TinyRenderer ignores alpha, so regions are not bodies: they are drawn afterwards by casting each
pixel's view ray against the region boxes (:func:`tint_regions`): the region's floor is tinted where it is
what the pixel sees (nothing stands in front of it), and the box's edges are drawn where they lie in front
of the rendered depth.  Robots and objects inside a region are therefore never blended with its colour.  A
region that is not a box is drawn as its bounding box.
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
from mrgc.render.palette import REGION_FLOOR_ALPHA, RGB, darker
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
        # a mesh given by its triangles (no file) is its own shape
        key = (d.kind, d.size, d.mesh_path, d.colour, d.name if d.kind == "mesh" and d.mesh_path is None else "")
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
    """A region as seen by one camera: the pixel rectangle it covers; per pixel the eye-space depth where the
    view ray meets the region's floor (its bottom face; inf where it does not), and where it crosses one of
    the box's edges, near or far (inf where it does not); the floor's tint and the edges' colour."""

    rows: slice
    cols: slice
    floor: np.ndarray
    near_edge: np.ndarray
    far_edge: np.ndarray
    tint: np.ndarray
    line: np.ndarray


#: how opaque a region's near and far edges are drawn
NEAR_EDGE_ALPHA, FAR_EDGE_ALPHA = 0.9, 0.55


def region_patches(
    camera: Camera, regions: list[tuple[np.ndarray, np.ndarray, RGB]], width: int, height: int
) -> list[RegionPatch]:
    """Cast the view rays of the pixels each region box (pose, half extents, colour) covers: where they meet
    its floor and cross its edges (1.5 pixels wide).  Depends on the camera only, so it is done once."""
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
        enter = np.nan_to_num(np.minimum(t1, t2), nan=-np.inf).max(axis=2)
        leave = np.nan_to_num(np.maximum(t1, t2), nan=np.inf).min(axis=2)
        miss = (enter > leave) | (leave <= 0)
        near = np.maximum(enter, 0.0)
        t_floor = np.nan_to_num(t1[..., 2], nan=-1.0, posinf=-1.0, neginf=-1.0)
        on_floor = np.abs(o[:2] + t_floor[..., None] * d[..., :2]) <= half[:2]
        floor = np.where((t_floor > 0) & on_floor.all(axis=2), t_floor, np.inf)
        hits = ~miss
        out.append(
            RegionPatch(
                slice(r0, r1),
                slice(c0, c1),
                floor,
                _edge(o, d, half, near, pixel, hits),
                _edge(o, d, half, leave, pixel, hits),
                np.array(colour) * 255,
                np.array(darker(colour, 0.55)) * 255,
            )
        )
    return out


def _edge(o: np.ndarray, d: np.ndarray, half: np.ndarray, t: np.ndarray, pixel: float, hits: np.ndarray) -> np.ndarray:
    """``t`` where the ray from ``o`` along ``d`` (box frame), at ``t``, lies on an edge of the box of half
    extents ``half`` (within 1.5 pixels), inf elsewhere."""
    local = o + t[..., None] * d
    eps = 1.5 * pixel * np.maximum(t, 1e-6)
    on = (np.abs(np.abs(local) - half) <= eps[..., None]).sum(axis=2) >= 2
    return np.where(on & hits, t, np.inf)


def tint_regions(rgb: np.ndarray, depth: np.ndarray, patches: list[RegionPatch]) -> np.ndarray:
    """``rgb`` with each region's floor tinted where nothing stands in front of it (what stands in a region
    keeps its colour) and its edges drawn where they are in front of ``depth`` (eye-space)."""
    out = rgb.copy()
    for p in patches:
        seen = depth[p.rows, p.cols]
        slack = 0.003 + 0.002 * seen  # the depth buffer's precision: a table top under a region is its floor
        floor = p.floor <= seen + slack
        near = p.near_edge <= seen + slack
        far = (p.far_edge <= seen + slack) & ~near
        if not (floor.any() or near.any() or far.any()):
            continue
        patch = out[p.rows, p.cols].astype(float)
        alpha = np.where(floor, REGION_FLOOR_ALPHA, 0.0)[..., None]
        patch = (1 - alpha) * patch + alpha * p.tint
        alpha = np.where(near, NEAR_EDGE_ALPHA, np.where(far, FAR_EDGE_ALPHA, 0.0))[..., None]
        patch = (1 - alpha) * patch + alpha * p.line
        out[p.rows, p.cols] = patch.clip(0, 255).astype(np.uint8)
    return out


def _pixel_box(camera: Camera, pose: np.ndarray, half: np.ndarray, w: int, h: int) -> tuple[int, int, int, int] | None:
    """Rows and columns [r0, r1) × [c0, c1) covering the box's projection (the whole picture when a corner
    lies behind the eye); None when it is off the picture."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    pts = (signs * half) @ pose[:3, :3].T + pose[:3, 3]
    cols, rows, z = camera.project(pts, w, h)
    if (z <= camera.near).any():
        return 0, h, 0, w
    c0, c1 = max(0, int(cols.min()) - 1), min(w, int(math.ceil(cols.max())) + 1)
    r0, r1 = max(0, int(rows.min()) - 1), min(h, int(math.ceil(rows.max())) + 1)
    return (r0, r1, c0, c1) if r0 < r1 and c0 < c1 else None
