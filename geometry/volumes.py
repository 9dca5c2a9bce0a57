"""Swept volumes: what a robot occupies at configurations or along a path, and which objects that hits.

A volume is a list of collision shapes at world transforms (:data:`~mrgc.geometry.robot.Volume`), as the robot
makes it (:meth:`Robot.volumes <mrgc.geometry.robot.Robot.volumes>`, :meth:`Volumes.volumes`): an arm's probed
link hulls at each configuration, its fingers at the opening of the grasp it holds or approaches (fully open
otherwise), plus the held object at each configuration (its pose in the tool frame is the inverse grasp
transform); a planar robot's footprint at each state of an SE(2) path, plus the object it carries at its carry
pose.  How a robot holds an object is asked once per (robot, object, grasp) (:meth:`Volumes._grip`).  Every
arm configuration the grounding answers with is checked here for self-collision first
(:meth:`Volumes.free_volume`).  Volumes are what the reverse search accumulates (V_fut, what the step's other
robots sweep) and what :meth:`Volumes.hits` tests against the world's objects.
"""

from __future__ import annotations

from functools import cached_property
from typing import Callable, Iterable

import numpy as np

from mrgc.geometry.collision import CollisionShape, Posed
from mrgc.geometry.robot import Held, Sweep, Volume
from mrgc.geometry.step_world import StepWorld


class Volumes(StepWorld):
    """The swept volumes of the grounder's robots (see the module docstring)."""

    @cached_property
    def _grips(self) -> dict[tuple[str, str, str], tuple[float | None, np.ndarray]]:
        """(robot, object, grasp) -> how the robot holds the object (:meth:`_grip`)."""
        return {}

    def volumes(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        fingers: tuple[str, str] | None = None,
    ) -> list[Volume]:
        """``robot`` at each of ``configs`` (an arm's joint configurations, a planar robot's base poses), one
        volume per configuration (a motion's samples), holding ``holding`` (object, grasp), its fingers at the
        opening of ``fingers`` (object, grasp: approaching it, or letting it go) or of what it holds, else
        fully open (:meth:`Robot.volumes <mrgc.geometry.robot.Robot.volumes>`, whatever its kind)."""
        grip = fingers or holding
        opening = None if grip is None else self._grip(robot, *grip)[0]
        return self.robot(robot).volumes(np.atleast_2d(configs), self._held(robot, holding), opening)

    def arm_volume(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
    ) -> Volume:
        """An arm's link hulls at each of ``configs`` (C, dof), then the held object at each; the fingers
        stand at the opening of the (object, grasp) held, or of ``grasp`` (approaching it), else fully open."""
        return self._arm_volume(robot, configs, holding, grasp)[0]

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
        held = volume[len(volume) - len(transforms) :] if holding is not None else []
        poses = np.stack([pose for _, pose in held]) if held else None
        return None if self._itself(robot, transforms, held[0][0] if held else None, poses) else volume

    def free_posed(
        self,
        robot: str,
        configs: np.ndarray,
        holding: tuple[str, str] | None = None,
        grasp: tuple[str, str] | None = None,
        clear: Callable[[Posed], bool] | None = None,
    ) -> Posed | None:
        """:meth:`free_volume` as the collision kernel reads it (:meth:`Arm.posed
        <mrgc.geometry.arm.Arm.posed>`: no list of pieces made): the motion checks' form.  ``clear``: what
        else the volume must be clear of (the world, what other robots sweep), tested before the arm's
        self-collision check, which then runs only on volumes it clears (None when it does not: the same
        answer as testing it afterwards, the cheaper test first)."""
        if self.late():
            return None
        held = self._held(robot, holding)
        posed, transforms, poses = self.arm(robot).posed(configs, held, self._opening(robot, holding, grasp))
        if clear is not None and not clear(posed):
            return None
        return None if self._itself(robot, transforms, held[0] if held else None, poses) else posed

    def _itself(
        self, robot: str, transforms: np.ndarray, shape: CollisionShape | None, poses: np.ndarray | None
    ) -> bool:
        """Whether the arm at its probed links' ``transforms`` collides with itself, or the object of ``shape``
        it holds at ``poses`` (None: it holds nothing) with the arm holding it."""
        return self.arm(robot).collides_with_itself_at(transforms, shape, poses)

    def _arm_volume(
        self, robot: str, configs: np.ndarray, holding: tuple[str, str] | None, grasp: tuple[str, str] | None
    ) -> tuple[Volume, np.ndarray]:
        """:meth:`arm_volume` and the probed links' transforms it was made of."""
        return self.arm(robot).volume(configs, self._held(robot, holding), self._opening(robot, holding, grasp))

    def _opening(self, robot: str, holding: tuple[str, str] | None, grasp: tuple[str, str] | None) -> float | None:
        """The finger opening of the (object, grasp) held, or of ``grasp`` (approaching it), else None (fully
        open)."""
        fingers = holding or grasp
        return None if fingers is None else self._grip(robot, *fingers)[0]

    def _grip(self, robot: str, obj: str, grasp: str) -> tuple[float | None, np.ndarray]:
        """How ``robot`` holds ``obj`` with ``grasp``: the finger opening and the object's pose in its holding
        frame (:meth:`Robot.hold <mrgc.geometry.robot.Robot.hold>`), computed once per triple: volumes ask for
        them at every configuration."""
        key = (robot, obj, grasp)
        if key not in self._grips:
            self._grips[key] = self.robot(robot).hold(self.scene.body(obj).shape, grasp, self.scene.grasp_specs)
        return self._grips[key]

    def _held(self, robot: str, holding: tuple[str, str] | None) -> Held | None:
        """What ``robot`` holds holding ``holding`` (object, grasp): its shape and pose in the holding frame."""
        if holding is None:
            return None
        obj, grasp = holding
        return self.shape(obj), self._grip(robot, obj, grasp)[1]

    def hits(self, volume: Sweep, among: Iterable[str] | str = "movable", ignore: Iterable[str] = ()) -> set[str]:
        """The objects of ``among`` (names or a group) that ``volume`` overlaps."""
        self.queries += 1
        return self.world.probe_hits(volume, against=_against(among), ignore=tuple(ignore))


def _against(among: Iterable[str] | str) -> str | tuple[str, ...]:
    return among if isinstance(among, str) else tuple(among)
