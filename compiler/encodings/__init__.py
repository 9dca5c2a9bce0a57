"""Encodings of skeleton generation as a SkeletonModel; each module one encoding, registered here.

- ``paper``: the 12 constraints of the paper, literally; pick/place precedence (11)/(12) as conditional
  rows with the paper's big-M hints T+1 / T.
- ``disaggregated``: the same variables, precedence as big-M-free rows per time step.
- ``time-of-move``: an integer step per object, no-overlap per robot, lexicographic (makespan, moved)
  objective; one model for the whole horizon, no horizon loop.
"""

from __future__ import annotations

from mrgc.compiler.encodings.base import Encoded, Encoding
from mrgc.compiler.encodings.disaggregated import DisaggregatedEncoding
from mrgc.compiler.encodings.paper import PaperEncoding
from mrgc.compiler.encodings.time_of_move import TimeOfMoveEncoding

ENCODINGS: dict[str, type[Encoding]] = {
    "paper": PaperEncoding,
    "disaggregated": DisaggregatedEncoding,
    "time-of-move": TimeOfMoveEncoding,
}


def get_encoding(name: str) -> Encoding:
    """The encoding called ``name`` (a ValueError naming the choices otherwise)."""
    try:
        return ENCODINGS[name]()
    except KeyError:
        raise ValueError(f"unknown encoding '{name}' (choose from {', '.join(ENCODINGS)})") from None


__all__ = ["ENCODINGS", "Encoded", "Encoding", "get_encoding"]
