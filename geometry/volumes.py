"""Swept volumes: what a robot occupies at configurations or along a path, and which objects that hits.

A volume is a list of collision shapes at world transforms (:data:`~mrgc.geometry.step_world.Volume`): an
arm's probed link hulls at each configuration, its fingers at the opening of the grasp it holds or approaches
(fully open otherwise), plus the held object at each configuration (its pose in the tool frame is the inverse
grasp transform); a planar robot's footprint at each state of an SE(2) path, plus the object it carries at its
carry pose.  Every arm configuration the grounding answers with is checked here for self-collision first
(:meth:`Volumes.free_volume`).  Volumes are what the reverse search accumulates (V_fut, what the step's other
robots sweep) and what :meth:`Volumes.hits` tests against the world's objects.
"""

from __future__ import annotations

from functools import cached_property
from typing import Iterable, Sequence

import numpy as np

from mrgc.geometry.collision import CollisionShape
from mrgc.geometry.grasps import finger_opening, grasp_transform
from mrgc.geometry.step_world import StepWorld, Volume


class Volumes(StepWorld):
    """The swept volumes of the grounder's robots (see the module docstring)."""

    @cached_property
    def _grips(self) -> dict[tuple[str, str], tuple[float, np.ndarray]]:
        """(object, grasp) -> the finger opening and the object's pose in the tool frame (:meth:`_grip`)."""
        return {}

    def arm_volume(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> Volume:
        """Link hulls (and the held object) at each of ``configs`` (C, dof); the fingers stand at the opening
        of the (object, grasp) held, or of ``grasp`` (approaching it), else fully open."""
        return self._arm_volume(robot, configs, holding, grasp)[0]

    def arm_volumes(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> list[Volume]:
        """:meth:`arm_volume` at each of ``configs`` separately (one volume per configuration: a motion's
        samples), from one batched forward kinematics."""
        configs = np.atleast_2d(configs)
        volume = self._arm_volume(robot, configs, holding, grasp)[0]
        links = len(self.arm(robot).probes[0])
        out = [volume[k * links : (k + 1) * links] for k in range(len(configs))]
        if holding is not None:  # the held object's pieces follow the links' (one per configuration)
            for k, piece in enumerate(volume[links * len(configs) :]):
                out[k].append(piece)
        return out

    def free_volume(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> Volume | None:
        """:meth:`arm_volume`, or None when the arm collides with itself at one of ``configs``
        (:meth:`~mrgc.geometry.arm.Arm.self_collides`, on the same link transforms): every configuration the
        grounding answers with (approaches, exchanges, transfers, transits, paths) is checked through here.
        Past the run's deadline, None at once (:meth:`late`: every motion fails, the caller stops)."""
        if self.late():
            return None
        volume, transforms = self._arm_volume(robot, configs, holding, grasp)
        return None if self.arm(robot).self_collides_at(transforms) else volume

    def _arm_volume(
        self, robot: str, configs: np.ndarray, holding: tuple[str, str] | None, grasp: tuple[str, str] | None
    ) -> tuple[Volume, np.ndarray]:
        """:meth:`arm_volume` and the probed links' transforms it was made of."""
        arm = self.arm(robot)
        shapes, _ = arm.probes
        out: Volume = []
        fingers = holding or grasp
        opening = None if fingers is None else self._grip(*fingers)[0]
        transforms = arm.link_transforms(np.atleast_2d(configs), opening)
        for t in transforms:
            out.extend(zip(shapes, t))
        if holding is not None:
            obj, held_grasp = holding
            g_inv = self._grip(obj, held_grasp)[1]
            for tool in arm.tool_world(np.atleast_2d(configs)):
                out.append((self.shape(obj), tool @ g_inv))
        return out, transforms

    def _grip(self, obj: str, grasp: str) -> tuple[float, np.ndarray]:
        """The finger opening holding ``obj`` with ``grasp`` and the object's pose in the tool frame (the
        inverse grasp transform), computed once per pair: volumes ask for them at every configuration."""
        key = (obj, grasp)
        if key not in self._grips:
            spec, shape = self.scene.grasp(grasp), self.scene.body(obj).shape
            self._grips[key] = (finger_opening(spec, shape), np.linalg.inv(grasp_transform(spec, shape)))
        return self._grips[key]

    def base_volume(self, robot: str, path: Sequence[np.ndarray], holding: tuple[str, str] | None = None) -> Volume:
        """Footprint (and the carried object) at every state of an SE(2) path."""
        pr = self.planar(robot)
        carried = self._carried(robot, holding)
        out: Volume = []
        for q in path:
            out.extend(pr.probe(np.asarray(q), carried))
        return out

    def _carried(self, robot: str, holding: tuple[str, str] | None) -> tuple[CollisionShape, np.ndarray] | None:
        """What planar ``robot`` carries holding ``holding`` (object, grasp): its shape and carry transform."""
        if holding is None:
            return None
        obj, grasp = holding
        return self.shape(obj), self.planar(robot).carry_transform(self.scene.body(obj).shape, grasp)

    def hits(self, volume: Volume, among: Iterable[str] | str = "movable", ignore: Iterable[str] = ()) -> set[str]:
        """The objects of ``among`` (names or a group) that ``volume`` overlaps."""
        self.queries += 1
        return self.world.probe_hits(volume, against=_against(among), ignore=tuple(ignore))


def _against(among: Iterable[str] | str) -> str | tuple[str, ...]:
    return among if isinstance(among, str) else tuple(among)
