"""The geometric facts a task graph is built from, indexed for Alg. 1 of the paper.

Facts are plain data: the ``:init`` of a symbolic problem (or of a problem completed by ``mrgc facts``),
or facts the planner passes in from the geometry layer.  The compiler never computes geometry.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any, Iterable

from mrgc.language.model import Fact, Problem

#: the obstruction predicates: (M1, *what M1 obstructs)
_OCCLUDES = ("occludes-pick", "occludes-goal-place", "occludes-handover", "occludes-relay")


@dataclass(frozen=True)
class FactBase:
    """The facts of one problem, indexed the way Alg. 1 asks for them.

    ``goal`` maps each goal object to its goal region; ``region`` each object to its current region;
    ``robots`` and ``objects`` keep the problem's declaration order, which fixes every later ordering.
    """

    robots: tuple[str, ...]
    objects: tuple[str, ...]
    grasps: dict[str, tuple[str, ...]]
    goal: dict[str, str]
    region: dict[str, str]
    reachable_pick: frozenset[tuple[str, str, str]] = frozenset()  # (M, g, R)
    reachable_place: frozenset[tuple[str, str, str, str]] = frozenset()  # (M, Re, g, R)
    handover: frozenset[tuple[str, str, str, str, str]] = frozenset()  # (M, g1, g2, R1, R2)
    #: ``enable-relay`` (beyond the paper): M set down in Re by R1 holding it with g1, picked there by R2 with g2
    relay: frozenset[tuple[str, str, str, str, str, str]] = frozenset()  # (M, Re, g1, g2, R1, R2)
    occludes_pick: dict[tuple[str, str, str], tuple[str, ...]] = field(default_factory=dict)  # (M2, g, R) -> M1s
    occludes_place: dict[tuple[str, str, str, str], tuple[str, ...]] = field(default_factory=dict)  # (M2, Re, g, R)
    #: ``occludes-handover`` (beyond the paper): (M2, g1, g2, R1, R2) -> the M1s in the way of the exchange
    occludes_handover: dict[tuple[str, str, str, str, str], tuple[str, ...]] = field(default_factory=dict)
    #: ``occludes-relay`` (beyond the paper): (M2, Re, g1, g2, R1, R2) -> the M1s in the way at the relay's spot
    occludes_relay: dict[tuple[str, str, str, str, str, str], tuple[str, ...]] = field(default_factory=dict)
    #: handovers that can happen at once (the number of handover points); None: no limit (symbolic)
    handover_capacity: int | None = None
    #: robots that drive to their placements (planar bases): their place obstacles lie on the path and must
    #: be gone before the step starts, not moved in the same step
    drivers: frozenset[str] = frozenset()

    @classmethod
    def from_problem(cls, problem: Problem, facts: Iterable[Fact] | None = None) -> "FactBase":
        """Index ``facts`` (default: the problem's ``:init``) for ``problem``'s robots, objects and goal."""
        return cls.from_facts(
            robots=[r.name for r in problem.robots],
            objects=[m.name for m in problem.movable],
            grasps={m.name: problem.grasps_of(m.name) for m in problem.movable},
            goal=problem.goal_regions,
            facts=problem.init if facts is None else facts,
            handover_capacity=None if problem.symbolic else len(problem.handover_points),
            drivers=[r.name for r in problem.robots if r.kind is not None and problem.domain.kind(r.kind).driven],
        )

    @classmethod
    def from_facts(
        cls,
        robots: Iterable[str],
        objects: Iterable[str],
        grasps: dict[str, tuple[str, ...]],
        goal: dict[str, str],
        facts: Iterable[Fact],
        handover_capacity: int | None = None,
        drivers: Iterable[str] = (),
    ) -> "FactBase":
        """A fact base from its parts (the symbolic problem's facts, or phase 1's)."""
        region: dict[str, str] = {}
        pick: set[tuple[str, str, str]] = set()
        place: set[tuple[str, str, str, str]] = set()
        hand: set[tuple[str, str, str, str, str]] = set()
        relay: set[tuple[str, str, str, str, str, str]] = set()
        # an occludes-* fact (M1, *key): the objects M1 that obstruct key, in the order of the facts
        occ: dict[str, dict[Any, list[str]]] = {p: defaultdict(list) for p in _OCCLUDES}
        for f in facts:
            a = f.args
            if f.predicate == "in-region":
                region.setdefault(a[0], a[1])
            elif f.predicate == "reachable-pick":
                pick.add((a[0], a[1], a[2]))
            elif f.predicate == "reachable-place":
                place.add((a[0], a[1], a[2], a[3]))
            elif f.predicate == "enable-goal-handover":
                hand.add((a[0], a[1], a[2], a[3], a[4]))
            elif f.predicate == "enable-relay":
                relay.add((a[0], a[1], a[2], a[3], a[4], a[5]))
            elif f.predicate in occ and a[0] != a[1] and a[0] not in occ[f.predicate][a[1:]]:
                occ[f.predicate][a[1:]].append(a[0])
        objects = tuple(objects)
        order = {o: i for i, o in enumerate(objects)}
        rank = lambda o: (order.get(o, len(order)), o)  # noqa: E731 - undeclared objects last, by name
        return cls(
            robots=tuple(robots),
            objects=tuple(objects),
            grasps=dict(grasps),
            goal=dict(goal),
            region=region,
            reachable_pick=frozenset(pick),
            reachable_place=frozenset(place),
            handover=frozenset(hand),
            relay=frozenset(relay),
            occludes_pick={k: tuple(sorted(v, key=rank)) for k, v in occ["occludes-pick"].items()},
            occludes_place={k: tuple(sorted(v, key=rank)) for k, v in occ["occludes-goal-place"].items()},
            occludes_handover={k: tuple(sorted(v, key=rank)) for k, v in occ["occludes-handover"].items()},
            occludes_relay={k: tuple(sorted(v, key=rank)) for k, v in occ["occludes-relay"].items()},
            handover_capacity=handover_capacity,
            drivers=frozenset(drivers),
        )
