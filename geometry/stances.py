"""The execution model a plan means, as the grounding reads it: the phases of a step and where each arm is.

A step runs in the :data:`PHASES` (docs/validator.md, "What a plan means"; validator/replay.py replays them).
Each arm of the step has a role in its action (``pick-place``, ``giver`` or ``taker``), and its role fixes
its :class:`Stance` in every phase (:data:`STANCES`): at home, moving, or standing still where its last motion
left it.  Every arm starts the step at home; an arm in no action of the step stays there.  Its empty-handed
transits (:data:`TRANSITS`) are paths only under ``--motions full``; without one the arm jumps at the end of
the phase.  The grounder keeps each query of a phase clear of the other arms where this model puts them
(:meth:`Grounder.step <mrgc.geometry.grounding.Grounder.step>`).
"""

from __future__ import annotations

import enum
from typing import Iterable

#: the phases of a step, in the order they run (docs/validator.md, "What a plan means")
PHASES = ("to-pick", "pick", "to-handover", "handover", "giver-home", "to-place", "place", "home")


class Stance(str, enum.Enum):
    """Where an arm of the step is during one of its :data:`PHASES` (:data:`STANCES`); the value names it in
    a failure line (``hits r2 at its exchange, holding``)."""

    HOME = "at home"
    #: its own motion of the phase: a path, an approach, its exchange configuration in the handover phase
    MOVES = "moving"
    #: standing at its last pick configuration, holding its object (fingers at the grasp's opening)
    PICKED = "at its grasp"
    #: a giver standing at its exchange configuration, the object let go (fingers at the grasp's opening)
    EXCHANGE = "at its exchange"
    #: a taker standing at its exchange configuration, holding the object
    RECEIVED = "at its exchange, holding"
    #: standing at its last place configuration, the object released (fingers at the grasp's opening)
    PLACED = "at its release"


#: **The execution model a plan means** (docs/validator.md; validator/replay.py replays it), the one place
#: the grounding reads it from: an arm's stance in each phase of :data:`PHASES`, by its role in its action,
#: under the ``configurations`` motion model.  Every arm starts the step at home; between its own motions it
#: stands where its last motion left it, its fingers as that motion left them; an arm in no action of the
#: step stays at home.
STANCES: dict[str, tuple[Stance, ...]] = {
    # to-pick, pick, to-handover, handover, giver-home, to-place, place, home
    "pick-place": (
        Stance.HOME,  # no to-pick path: it is at its pre-grasp when the pick phase starts
        Stance.MOVES,
        Stance.PICKED,  # while the handovers of the step run
        Stance.PICKED,
        Stance.PICKED,
        Stance.MOVES,
        Stance.MOVES,
        Stance.PLACED,  # no home path: at home when the next step starts
    ),
    "giver": (
        Stance.HOME,
        Stance.MOVES,
        Stance.MOVES,  # its to-handover transfer
        Stance.MOVES,  # at its exchange, holding
        Stance.EXCHANGE,  # no giver-home path: it lets go, and is at home when the phase ends
        Stance.HOME,
        Stance.HOME,
        Stance.HOME,
    ),
    "taker": (
        Stance.HOME,
        Stance.HOME,
        Stance.HOME,  # no taker-to-handover path: at its exchange when the handover phase starts
        Stance.MOVES,  # at its exchange, holding
        Stance.RECEIVED,  # while the giver withdraws
        Stance.MOVES,
        Stance.MOVES,
        Stance.PLACED,
    ),
}
#: each role's empty-handed transits: without a path (``configurations``) the arm jumps at the end of the
#: phase, so it stands where it was until then (:data:`STANCES`); with ``--motions full`` they are paths,
#: and the arm moves then
TRANSITS: dict[str, tuple[str, ...]] = {
    "pick-place": ("to-pick", "home"),
    "giver": ("to-pick", "giver-home"),
    "taker": ("to-handover", "home"),
}


def roles(actions: Iterable[tuple[str, str]]) -> dict[str, str]:
    """Each robot's role in a step whose actions are (picking robot, placing robot) pairs: ``pick-place`` for
    one robot, ``giver`` and ``taker`` for a handover's two."""
    out: dict[str, str] = {}
    for pick_robot, place_robot in actions:
        if pick_robot == place_robot:
            out[pick_robot] = "pick-place"
        else:
            out[pick_robot], out[place_robot] = "giver", "taker"
    return out


def stance(role: str, phase: str, full: bool = False) -> Stance:
    """Where an arm of ``role`` (``pick-place``, ``giver``, ``taker``) is in ``phase``: :data:`STANCES`, or
    moving on its :data:`TRANSITS` when they are paths (``full``)."""
    if full and phase in TRANSITS[role]:
        return Stance.MOVES
    return STANCES[role][PHASES.index(phase)]
