"""The robot kinds of the geometry layer: the class implementing :class:`~mrgc.geometry.robot.Robot` for each
base type of the language (``language/model.py``'s ``BASE_TYPES``: a kind's ``:base``).

This table is the one place the geometry layer tells the kinds apart: the grounder makes every robot of a
scene through :func:`robot_for` and asks the object, never its kind (docs/architecture.md, "Robot kinds").
"""

from __future__ import annotations

from mrgc.geometry.arm import Arm
from mrgc.geometry.planar import PlanarRobot
from mrgc.geometry.robot import Robot
from mrgc.geometry.scene import RobotSpec
from mrgc.language.model import RobotKind

#: base type -> the class of its robots (each built from the robot's scene specification; :func:`robot_for`
#: returns it as a :class:`~mrgc.geometry.robot.Robot`, which mypy checks each class implements)
KINDS: dict[str, type[Arm] | type[PlanarRobot]] = {"fixed": Arm, "planar": PlanarRobot}


def robot_for(spec: RobotSpec) -> Robot:
    """The robot ``spec`` describes, of the class its kind's base type names in :data:`KINDS`."""
    return KINDS[spec.kind.base](spec)


def approaches(kind: RobotKind) -> bool:
    """:attr:`Robot.approaches <mrgc.geometry.robot.Robot.approaches>` of the robots of ``kind``, read from
    their class without building one: whether phase 1's arm predicates (IK approaches, handovers, relays), the
    arms' layout checks and diagnoses apply to them, or their facts come from paths (a cart's)."""
    return KINDS[kind.base].approaches
