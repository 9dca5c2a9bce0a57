"""What phase 1 finds: one robot's facts (:class:`RobotFacts`, from the arm evaluator of
:mod:`mrgc.geometry.predicates` or the planar one of :mod:`mrgc.geometry.path_predicates`) and all facts
of a scene (:class:`FactsResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mrgc.errors import Diagnostic
from mrgc.language.model import Fact


@dataclass(frozen=True)
class HandoverConfig:
    """One configuration of an arm holding a goal object at a handover point, free of the fixed objects and
    of every other arm at home; ``movables``: the movable objects (at their initial poses) its links or the
    object it holds there hit (``occludes-handover``)."""

    q: np.ndarray
    movables: frozenset[str] = frozenset()


@dataclass
class RobotFacts:
    """What one robot's worker found: facts, handover configurations and counters."""

    facts: list[Fact] = field(default_factory=list)
    #: (M, point, g) -> the distinct configurations found holding M with g at the point, each with the other
    #: arms whose links at home it hits (the partner may be one of them: it is at the exchange then, not at
    #: home); the first one found from home first
    handover: dict[tuple[str, str, str], list[HandoverConfig]] = field(default_factory=dict)
    ik_solves: int = 0
    collision_checks: int = 0


@dataclass
class FactsResult:
    """All facts of a scene (sorted, deterministic) and statistics; ``warnings`` about the problem's layout
    (W271, W272: docs/errors.md) when :func:`mrgc.compute_facts` ran the layout checks.  ``complete`` is
    False when a deadline cut phase 1 short: then there are no facts (none of a cut phase 1 is kept, so
    that facts never depend on how fast the machine was)."""

    facts: list[Fact]
    stats: dict[str, float]
    warnings: tuple[Diagnostic, ...] = ()
    complete: bool = True
