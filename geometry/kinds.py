"""The robot kinds of the geometry layer: the class implementing :class:`~mrgc.geometry.robot.Robot` for each
base type of the language (``language/model.py``'s ``BASE_TYPES``: a kind's ``:base``).

This table is the one place the geometry layer tells the kinds apart: the grounder makes every robot of a
scene through :func:`robot_for` and asks the object, never its kind (docs/architecture.md, "Robot kinds").
"""

from __future__ import annotations

from typing import Callable

from mrgc.geometry.arm import Arm
from mrgc.geometry.planar import PlanarRobot
from mrgc.geometry.robot import Robot
from mrgc.geometry.scene import RobotSpec

#: base type -> the class of its robots (each built from the robot's scene specification)
KINDS: dict[str, Callable[[RobotSpec], Robot]] = {"fixed": Arm, "planar": PlanarRobot}


def robot_for(spec: RobotSpec) -> Robot:
    """The robot ``spec`` describes, of the class its kind's base type names in :data:`KINDS`."""
    return KINDS[spec.kind.base](spec)
