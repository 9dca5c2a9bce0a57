"""What is drawn: every body of a scene and every robot part as a coloured :class:`Drawable`, and where
each one is for given robot configurations and object poses.

Robots are drawn with the geometry the planner and the validator check: an arm's links are its URDF's
*collision* shapes (:class:`~mrgc.geometry.kinematics.RobotModel`), placed by the geometry layer's forward
kinematics (:func:`~mrgc.geometry.fk.fk`, which agrees with pybullet's to 1e-7 m), fingers at the opening
the validator uses; a planar robot is its footprint (:class:`~mrgc.geometry.planar.PlanarRobot`) with a
flat white arrowhead on top pointing where it faces.  A held
object rides at its grasp: an arm's tool pose composed with the inverse of the grasp frame
(:mod:`mrgc.geometry.grasps`), a planar robot's carry pose.  Both renderers (the TinyRenderer images and
the HTML replay) draw from this one description.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterator, Mapping

import numpy as np

from mrgc.geometry.conventions import wrap_angle
from mrgc.geometry.scene import Body, SceneSpec, outline, scene_from_problem
from mrgc.geometry.transforms import from_pose, inverse
from mrgc.language.model import Box, Cylinder, Mesh, Problem, Shape, Sphere
from mrgc.render.palette import (
    FIXED,
    GOAL_REGION,
    HEADING,
    OTHER_REGION,
    RGB,
    ROLE_COLOURS,
    moved_objects,
    robot_colours,
    roles,
)


@dataclass(frozen=True, eq=False)
class Drawable:
    """One rigid piece to draw, in its own frame.

    ``kind`` is ``box`` (``size``: full side lengths), ``sphere`` (radius), ``cylinder`` or ``capsule``
    (radius, length along z) or ``mesh`` (``size``: scale per axis; ``mesh_path`` its file and, when known,
    ``vertices`` (V, 3, already scaled) and ``faces`` (F, 3)).  ``opacity`` below 1 draws it translucent.
    """

    name: str
    kind: str
    size: tuple[float, ...]
    colour: RGB
    mesh_path: str | None = None
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    opacity: float = 1.0


def shape_drawable(name: str, shape: Shape, colour: RGB, opacity: float = 1.0) -> Drawable:
    """The drawable of a ``.mrg`` shape (a mesh's triangles are read from its file)."""
    if isinstance(shape, Box):
        return Drawable(name, "box", (shape.sx, shape.sy, shape.sz), colour, opacity=opacity)
    if isinstance(shape, Cylinder):
        return Drawable(name, "cylinder", (shape.radius, shape.height), colour, opacity=opacity)
    if isinstance(shape, Sphere):
        return Drawable(name, "sphere", (shape.radius,), colour, opacity=opacity)
    assert isinstance(shape, Mesh)
    from mrgc.geometry.kinematics import read_mesh

    v, f = read_mesh(shape.path)
    return Drawable(name, "mesh", (shape.scale,) * 3, colour, shape.path, v * shape.scale, f, opacity)


def heading_marker(name: str, hx: float, hy: float) -> Drawable:
    """A flat arrowhead lying on a planar robot's footprint (half length ``hx``, half width ``hy``), its tip
    at the front edge (+x): where the robot faces.  Its frame is the footprint's top centre."""
    thick = max(0.004, 0.05 * min(hx, hy))
    tri = [(0.95 * hx, 0.0), (-0.45 * hx, 0.6 * hy), (-0.2 * hx, 0.0), (-0.45 * hx, -0.6 * hy)]
    vertices = np.array([(x, y, z) for z in (0.0, thick) for x, y in tri], dtype=float)
    faces = [(4, 5, 6), (4, 6, 7), (0, 2, 1), (0, 3, 2)]  # top and bottom (two triangles each)
    faces += [(i, (i + 1) % 4, 4 + (i + 1) % 4) for i in range(4)] + [(i, 4 + (i + 1) % 4, 4 + i) for i in range(4)]
    return Drawable(name, "mesh", (1.0, 1.0, 1.0), HEADING, vertices=vertices, faces=np.array(faces, dtype=int))


class RobotView:
    """A robot as drawn: home configuration, parts at a configuration, tool and held-object poses."""

    def __init__(self, scene: SceneSpec, name: str, colour: RGB) -> None:
        self.spec = scene.robot(name)
        self.name = name
        self.colour = colour
        from mrgc.geometry.kinds import approaches

        self.planar = not approaches(self.spec.kind)  # drawn as its footprint, else as its links
        self._scene = scene
        if self.planar:
            from mrgc.geometry.conventions import to_se2
            from mrgc.geometry.planar import PlanarRobot

            self.mobile = PlanarRobot(self.spec)
            self.home: np.ndarray = to_se2(self.spec.base)
            hx, hy, hz = (float(v) for v in self.mobile.half)
            top = np.eye(4)
            top[2, 3] = hz
            self.parts: list[tuple[int, Drawable, np.ndarray]] = [
                (-1, shape_drawable(f"{name}/footprint", self.mobile.footprint, colour), np.eye(4)),
                (-1, heading_marker(f"{name}/heading", hx, hy), top),
            ]
            return
        from mrgc.geometry.kinematics import model_for_kind

        self.model = model_for_kind(self.spec.kind, self.spec.base_dir)
        self.tcp = from_pose(self.spec.kind.tcp) if self.spec.kind.tcp is not None else np.eye(4)
        m = self.model
        home = np.array(self.spec.kind.home, dtype=float)
        self.home = np.clip(home[: m.dof], m.lower, m.upper) if len(home) >= m.dof else (m.lower + m.upper) / 2
        self.parts = []
        for link in m.links:
            for k, c in enumerate(link.collisions):
                part = Drawable(
                    f"{name}/{link.name}/{k}",
                    c.kind,
                    tuple(c.size),
                    colour,
                    c.mesh_path,
                    c.vertices if c.kind == "mesh" else None,
                    c.faces if c.kind == "mesh" else None,
                )
                self.parts.append((link.index, part, c.origin))

    def part_poses(self, q: np.ndarray, fingers: float | None = None) -> Iterator[tuple[Drawable, np.ndarray]]:
        """Every part of the robot and its world pose at configuration ``q`` (fingers ``fingers`` m apart;
        None: fully open)."""
        if self.planar:
            body = self.mobile.body_transform(q)
            for _, part, origin in self.parts:
                yield part, body @ origin
            return
        from mrgc.geometry.fk import fk

        drive = None if fingers is None else self.model.finger_value(fingers)  # the opening as the gripper's drive
        frames = fk(self.model, np.asarray(q, dtype=float), self.spec.base, drive)
        for link, part, origin in self.parts:
            yield part, frames[link] @ origin

    def held_pose(self, q: np.ndarray, shape: Shape, grasp: str) -> np.ndarray:
        """Where an object of ``shape`` held with ``grasp`` is when the robot is at ``q``."""
        if self.planar:
            from mrgc.geometry.conventions import se2

            return se2(q[0], q[1], q[2]) @ self.mobile.carry_transform(shape, grasp)  # type: ignore[no-any-return]
        from mrgc.geometry.fk import ee_pose
        from mrgc.geometry.grasps import grasp_transform

        tool = ee_pose(self.model, np.asarray(q, dtype=float), self.spec.base) @ self.tcp
        return tool @ inverse(grasp_transform(self._scene.grasp(grasp), shape))  # type: ignore[no-any-return]

    def opening(self, shape: Shape, grasp: str | None) -> float | None:
        """An arm's finger opening while it approaches or holds an object with ``grasp`` (None: open)."""
        if grasp is None or self.planar or grasp not in self._scene.grasp_specs:
            return None
        from mrgc.geometry.grasps import finger_opening

        return finger_opening(self._scene.grasp(grasp), shape)

    def distance(self, a: np.ndarray, b: np.ndarray) -> float:
        """How far apart two configurations are for timing: the largest joint move (rad or m; a planar
        base's metres plus its turn in radians scaled by the footprint's half length)."""
        d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
        if self.planar:
            turn = abs(wrap_angle(float(d[2])))
            return float(math.hypot(d[0], d[1]) + turn * float(self.mobile.half[0]))
        return float(np.abs(d).max()) if d.size else 0.0


class World:
    """The drawables of a geometric problem, coloured for a plan (JSON, or None for the scene alone)."""

    def __init__(self, problem: Problem, plan: Mapping[str, Any] | None = None) -> None:
        self.scene = scene_from_problem(problem)  # E402 for a symbolic problem
        scene = self.scene
        self.problem = problem
        self.roles = roles([b.name for b in scene.movable], scene.goal, moved_objects(plan or {}))
        goal_regions = set(scene.goal.values())
        self.fixed = [(shape_drawable(b.name, b.shape, FIXED), b.pose) for b in scene.fixed]
        self.regions: list[tuple[Body, RGB]] = [
            (b, GOAL_REGION if b.name in goal_regions else OTHER_REGION) for b in scene.regions
        ]
        self.objects = {
            b.name: shape_drawable(b.name, b.shape, ROLE_COLOURS[self.roles[b.name]]) for b in scene.movable
        }
        self.start = {b.name: np.array(b.pose, dtype=float) for b in scene.movable}
        self.shapes = {b.name: b.shape for b in scene.movable}
        self.colours = robot_colours(r.name for r in scene.robots)
        self.robots = {r.name: RobotView(scene, r.name, self.colours[r.name]) for r in scene.robots}

    def static_points(self) -> np.ndarray:
        """Bounding-box corners (mesh vertices) of every fixed object, region and object at its start (for
        framing a camera)."""
        pts = []
        for b in (*self.scene.fixed, *self.scene.regions, *self.scene.movable):
            pts.append(outline(b.shape) @ b.pose[:3, :3].T + b.pose[:3, 3])
        return np.concatenate(pts) if pts else np.zeros((1, 3))

    def robot_points(self, configs: Mapping[str, np.ndarray]) -> np.ndarray:
        """Origins of every robot part at ``configs`` (for framing a camera)."""
        pts = [pose[:3, 3] for name, q in configs.items() for _, pose in self.robots[name].part_poses(q)]
        return np.array(pts) if pts else np.zeros((1, 3))
