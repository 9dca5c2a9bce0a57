"""A robot arm placed in a scene: its kinematic model, base pose, tool centre point and link hulls.

Everything the predicates and grounding ask of a robot goes through here: where the end effector must be
for a tool pose, where the links are at a configuration (as collision probes), and where a held object is.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from mrgc.geometry.collision import CollisionShape, ConvexHull, collision_shape
from mrgc.geometry.fk import ee_pose, fk_world
from mrgc.geometry.kinematics import RobotModel, model_for_kind
from mrgc.geometry.scene import RobotSpec
from mrgc.geometry.transforms import from_pose, inverse


class Arm:
    """A fixed-base arm of a scene (one per robot; built once per process)."""

    def __init__(self, spec: RobotSpec) -> None:
        self.spec = spec
        self.name = spec.name
        self.model: RobotModel = model_for_kind(spec.kind, spec.base_dir)
        self.base = spec.base
        self.base_inv = inverse(spec.base)
        self.tcp = from_pose(spec.kind.tcp) if spec.kind.tcp is not None else np.eye(4)
        self.tcp_inv = inverse(self.tcp)
        home = np.array(spec.kind.home, dtype=float) if spec.kind.home else None
        self.home = (
            self.model.clamp(home[: self.model.dof])
            if home is not None and len(home) >= self.model.dof
            else self.model.clamp((self.model.lower + self.model.upper) / 2)
        )

    @cached_property
    def probes(self) -> tuple[list[CollisionShape], list[int]]:
        """Collision hulls of the links that can hit anything (the base link, bolted in place, is left out)."""
        shapes, index = [], []
        for link in self.model.links:
            if link.index == 0 or len(link.points) < 4:
                continue
            shapes.append(collision_shape(ConvexHull(np.asarray(link.points, dtype=float))))
            index.append(link.index)
        return shapes, index

    @cached_property
    def base_hull(self) -> tuple[CollisionShape, np.ndarray] | None:
        """The base link's hull and world pose: left out of :attr:`probes` (it cannot move, and this arm's
        own links start on it), it is an obstacle to every other arm (None: the link has no geometry)."""
        link = next((k for k in self.model.links if k.index == 0), None)
        if link is None or len(link.points) < 4:
            return None
        pose: np.ndarray = fk_world(self.model, self.home[None], self.base)[0, 0]
        return collision_shape(ConvexHull(np.asarray(link.points, dtype=float))), pose

    def ee_target(self, tool_world: np.ndarray) -> np.ndarray:
        """The end-effector pose (base frame) that puts the tool centre point at ``tool_world``."""
        target: np.ndarray = self.base_inv @ tool_world @ self.tcp_inv
        return target

    def tool_world(self, q: np.ndarray) -> np.ndarray:
        """Tool centre point pose(s) in the world at configuration(s) ``q``."""
        tool: np.ndarray = self.base @ ee_pose(self.model, q) @ self.tcp
        return tool

    def link_transforms(self, q: np.ndarray, opening: float | None = None) -> np.ndarray:
        """World transforms of the probed links: ``q.shape[:-1] + (L, 4, 4)``, the fingers ``opening``
        metres apart (None: fully open, as the URDF's upper limits)."""
        _, index = self.probes
        fingers = None if opening is None else self.model.finger_value(opening)
        return fk_world(self.model, q, self.base, fingers)[..., index, :, :]

    def in_reach(self, point: np.ndarray, margin: float = 0.0) -> bool:
        """Whether a world point can be within reach of the tool (cheap pre-filter)."""
        local = self.base_inv[:3, :3] @ point + self.base_inv[:3, 3]
        return bool(
            np.linalg.norm(local - self.model.shoulder) <= self.model.reach + np.linalg.norm(self.tcp[:3, 3]) + margin
        )
