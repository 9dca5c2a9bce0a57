"""What a geometric query of the grounding answers: a status, the values found, and what was in the way.

Every query of the :class:`~mrgc.geometry.grounding.Grounder` (a placement, an approach, a handover, a path)
ends with an :class:`Answer` whose :class:`GroundStatus` says how; failures are values, never exceptions.  A
failure names what blocked it: the avoided objects in the way (``blockers``), or a line for the failure report
(``detail``: fixed bodies and arms at home by name, :data:`BUSY` when another robot of the step sweeps there
in the same phase, :data:`SELF` when every answer put the arm in collision with itself), and whether only
what never moves explains it (``static``: the same query fails again whatever moves).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

#: the detail of a failed query whose motion collided with what another robot of the step sweeps in the same
#: phase (the skeleton step may be packed into several: planner/ground.py)
BUSY = "another robot of the step moves there in the same phase"
#: the detail of a failed query whose every answer put the arm in collision with itself (two links that
#: :attr:`~mrgc.geometry.kinematics.RobotModel.self_collision_pairs` keeps apart closer than
#: :data:`~mrgc.geometry.arm.SELF_CLEARANCE`)
SELF = "the arm collides with itself"


class GroundStatus(str, enum.Enum):
    """How a geometric query of the grounding ended (its value is what a failure line says)."""

    OK = "ok"
    NO_PLACEMENT = "no placement"
    NO_IK = "no inverse kinematics"
    COLLISION = "collision"
    NO_PATH = "no path"
    UNKNOWN = "unknown"
    TIME_LIMIT = "time limit"


@dataclass
class Answer:
    """A status and, when OK, the values found (``pose``, ``configs``, ``path``), plus what blocked."""

    status: GroundStatus
    pose: np.ndarray | None = None
    configs: np.ndarray | None = None  # (C, dof): approach configurations, pre-grasp first
    path: list[np.ndarray] = field(default_factory=list)
    blockers: set[str] = field(default_factory=set)
    #: what else was in the way when the status is COLLISION: fixed bodies, another arm at home, or what
    #: another robot of the step sweeps meanwhile (a line for the failure report)
    detail: str = ""
    #: a failure that only what never moves explains (no IK, fixed bodies, other arms' base links): the same
    #: query fails again in any state of the movable objects and the other robots
    static: bool = False

    @property
    def ok(self) -> bool:
        """The query succeeded."""
        return self.status is GroundStatus.OK
