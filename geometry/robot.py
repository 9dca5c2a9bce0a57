"""Robots behind one protocol: what the grounding and the search ask of a robot, whatever its kind.

A robot *kind* is a base type of the language (``:base`` of a robot kind, ``language/model.py``'s
``BASE_TYPES``): ``fixed``, an arm bolted in place (:class:`~mrgc.geometry.arm.Arm`), or ``planar``, a cart
driven over the floor (:class:`~mrgc.geometry.planar.PlanarRobot`).  Each kind is one class implementing
:class:`Robot`, named in :data:`mrgc.geometry.kinds.KINDS`; the grounder makes each robot of a scene once
(:func:`mrgc.geometry.kinds.robot_for`) and asks it, without testing its kind:

- **its states**: a *configuration* is an arm's joint vector (dof,) or a cart's base pose ``(x, y, yaw)``;
  :attr:`Robot.home` is the state it starts every step from and comes back to (an arm's ``:home``, a cart's
  ``:base`` pose);
- **its volume** (:meth:`Robot.volumes`): the collision shapes it occupies at each of some configurations,
  at world transforms, with the object it holds (an arm's probed link hulls, its fingers at an opening; a
  cart's footprint) -- what swept volumes, the step's robots against each other and the failure lines read;
- **how it holds an object** (:meth:`Robot.hold`): the finger opening and the object's pose in the frame
  that carries it (an arm's tool frame: the inverse grasp transform; a cart's base frame: its carry pose);
- **what it leaves in the world** (:meth:`Robot.rest`): itself at home, and the parts that never move;
- **its reach** (:meth:`Robot.in_reach`, :meth:`Robot.comfort`): a cheap test of a world point, and a rank of
  tool poses by how far beyond a share of its reach they lie;
- **the shape of its plan** (:attr:`Robot.approaches`, :attr:`Robot.parks`): whether its pick and place are
  an approach it moves along (found by IK) or the one state grasp geometry gives, and whether it waits parked
  at home with every motion a path, or stands where the execution model puts it phase by phase
  (:mod:`mrgc.geometry.stances`).

What needs the world (collision checks, IK with restarts, path searches) is not the robot's: the grounder's
job modules do it for the kinds they serve (:mod:`mrgc.geometry.approaches` and :mod:`mrgc.geometry.arm_paths`
for arms, :mod:`mrgc.geometry.base_paths` and :func:`~mrgc.geometry.planar.PlanarRobot.grasp_base` for carts),
and the planner's reverse search grounds an action by one of two procedures, chosen by
:attr:`Robot.approaches` (planner/ground.py).  docs/architecture.md, "Robot kinds", lists the files a new kind
touches.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Protocol, Sequence, Union, runtime_checkable

import numpy as np

from mrgc.geometry.collision import CollisionShape, Posed
from mrgc.language.model import GraspSpec, Shape

#: collision shapes at world transforms: what a robot (and what it holds) occupies
Volume = list[tuple[CollisionShape, np.ndarray]]
#: a volume as the queries read it (what other robots sweep meanwhile, ``busy``): any sequence of pieces
Pieces = Sequence[tuple[CollisionShape, np.ndarray]]
#: a volume to keep clear of (V_fut): pieces, or a set the kernel already reads (a grounded suffix's, kept
#: compact: :meth:`Posed.join <mrgc.geometry.collision.Posed.join>`)
Sweep = Union[Pieces, Posed]
#: a held object: its collision shape and its pose in the robot's holding frame (:meth:`Robot.hold`)
Held = tuple[CollisionShape, np.ndarray]


@dataclass(frozen=True)
class Rest:
    """What a robot leaves in the world between its own motions (obstacles to the other robots)."""

    #: the robot at :attr:`Robot.home`
    home: Volume
    #: parts that never move, each named (an arm's mount links: bolted in place, there home or not)
    mount: tuple[tuple[str, CollisionShape, np.ndarray], ...] = ()


@runtime_checkable
class Robot(Protocol):
    """A robot of a scene as the grounding and the search see it (see the module docstring)."""

    #: the robot's name in the problem
    name: str

    @property
    def approaches(self) -> bool:
        """Whether its pick and place are an approach it moves along, found by IK (an arm: the plan's ``pick``
        and ``place`` configurations are that approach, pre-grasp first, and it hands over); False: the one
        state grasp geometry gives, where it stands (a cart: its base pose facing the grasped face)."""
        ...

    @property
    def parks(self) -> bool:
        """Whether it waits parked at home between its motions, an obstacle to every other query whatever the
        phase, and every motion it makes is a path, in any motion model (a cart drives from home and back in
        each action); False: it stands where the execution model puts it, phase by phase, and its
        empty-handed transits are paths only under ``--motions full`` (an arm: :mod:`mrgc.geometry.stances`)."""
        ...

    @property
    def home(self) -> np.ndarray:
        """The configuration it starts every step from and comes back to."""
        ...

    def volumes(self, configs: np.ndarray, held: Held | None = None, opening: float | None = None) -> list[Volume]:
        """Its volume at each of ``configs`` (C, state size), one per configuration, holding ``held`` (its
        shape and pose in the holding frame: :meth:`hold`) when given, its fingers ``opening`` apart (None:
        fully open; a robot without fingers ignores it)."""
        ...

    def hold(self, shape: Shape, grasp: str, grasps: Mapping[str, GraspSpec]) -> tuple[float | None, np.ndarray]:
        """How it holds an object of ``shape`` with ``grasp`` (``grasps``: the scene's grasp geometries): the
        finger opening (None: no fingers) and the object's pose in its holding frame."""
        ...

    def rest(self) -> Rest:
        """What it leaves in the world between its motions: itself at home, and its parts that never move."""
        ...

    def in_reach(self, point: np.ndarray, margin: float = 0.0) -> bool:
        """Whether it may reach world ``point`` (a cheap test that never says no wrongly)."""
        ...

    def comfort(self, tools: np.ndarray, share: float) -> np.ndarray:
        """A rank of each world tool pose of ``tools`` (..., 4, 4; one array of ranks of their leading shape,
        made in one go: a placement search ranks hundreds of candidates): 0 within ``share`` of its reach,
        else how far beyond (m; nearer first)."""
        ...
