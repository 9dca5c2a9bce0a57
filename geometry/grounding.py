"""The geometric queries the planner's grounding (reverse search) makes, as one stateful service.

A :class:`Grounder` holds the scene with the *current* object poses (the planner moves objects as it
grounds steps) and answers, each job in a module of its own:

- :meth:`~Grounder.placement`: a collision-free pose of an object inside a region, avoiding given objects and a
  swept volume (the future volume V_fut of the paper's reverse search): :mod:`mrgc.geometry.placements`;
- :meth:`~Grounder.pick` / :meth:`~Grounder.place`: an arm's approach configurations for a grasp of an object at
  a pose, and :meth:`~Grounder.handover`: both arms' configurations holding an object at a handover point, not
  colliding: :mod:`mrgc.geometry.approaches`;
- :meth:`~Grounder.transfer`, :meth:`~Grounder.transit`, :meth:`~Grounder.arm_path`: an arm's joint-space paths,
  optionally holding an object, remembered: :mod:`mrgc.geometry.arm_paths`;
- :meth:`~Grounder.base_path`: an SE(2) path for a planar robot, optionally carrying an object:
  :mod:`mrgc.geometry.base_paths`;
- :meth:`~Grounder.volumes`: any robot's volume at each configuration of a motion (:meth:`~Grounder.arm_volume`:
  an arm's, its self-collision checked by :meth:`~Grounder.free_volume`), and :meth:`~Grounder.hits`: which
  objects a volume overlaps: :mod:`mrgc.geometry.volumes`.

What they share (the scene as moved, the robots -- :meth:`~Grounder.robot`, each a
:class:`~mrgc.geometry.robot.Robot` of its kind's class, asked, never tested for its kind -- at home and where
the step's arms stand, the run's deadline, the caches) is :class:`~mrgc.geometry.step_world.StepWorld`; what
every query answers is :mod:`mrgc.geometry.answers`, and the execution model the queries keep to is
:mod:`mrgc.geometry.stances`.
Every answer carries a status; failures are values, never exceptions.  Seeds derive from the query, so the
same queries in the same order give the same answers.
"""

from __future__ import annotations

from mrgc.geometry.approaches import Approaches
from mrgc.geometry.arm_paths import ArmPaths
from mrgc.geometry.base_paths import BasePaths
from mrgc.geometry.placements import Placements


class Grounder(Placements, Approaches, ArmPaths, BasePaths):
    """Geometric queries over a scene whose movable objects can be moved (see the module docstring)."""
