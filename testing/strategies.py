"""Hypothesis strategies for random symbolic problems, with a knob for the share of feasible ones.

Needs hypothesis (``pip install mrgc[testing]``).  :func:`symbolic_problems` draws
:class:`SymbolicCase` values: the ``.mrg`` text of a small symbolic problem (its domain included) and
whether it was drawn feasible.  Naive random facts make most problems infeasible (about 82 % with the
project's own generator: some goal object lacks a pick or a place, or its obstacles cannot be cleared), so
each case is first drawn at random and then made

- **feasible** (with probability ``feasible``): every goal object that must move gets a witness action,
  a pick and a place into its goal region by one robot with one grasp, whose obstacle facts are removed;
  those actions, one per step, are a skeleton;
- **infeasible** (otherwise): one goal object that must move loses every pick, or every place into its
  goal region, so nothing can move it.

``feasible=None`` leaves the random draw as it is (``case.feasible`` is then None).  The rest of the draw
is the same either way: robots, objects, regions, grasps, reachability at a drawn density, decoy places,
occlusions and handovers.  docs/testing.md shows a property test of one's own domain with it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

try:
    from hypothesis import strategies as st
except ImportError as exc:  # pragma: no cover - hypothesis is in the testing extra
    raise ImportError(f"mrgc.testing.strategies needs hypothesis: pip install 'mrgc[testing]' ({exc})") from exc

if TYPE_CHECKING:
    from mrgc.language.model import Problem


@dataclass(frozen=True)
class SymbolicCase:
    """A drawn problem: ``text`` (domain and problem, ``.mrg``), and ``feasible``: True when a skeleton was
    planted, False when a goal object was made immovable, None when left to chance."""

    text: str
    feasible: bool | None

    def problem(self) -> "Problem":
        """The checked problem (parsed from :attr:`text`)."""
        from mrgc.language.loader import parse_string

        return parse_string(self.text, "<random>").problem()


def symbolic_problems(
    *,
    robots: tuple[int, int] = (2, 3),
    objects: tuple[int, int] = (2, 5),
    regions: Sequence[str] = ("ra", "rb", "rc"),
    min_regions: int = 2,
    goals: tuple[int, int] = (1, 2),
    grasps: Sequence[str] = ("top", "side"),
    feasible: float | None = 0.5,
    handover: bool = True,
    domain: str = "abstract",
) -> st.SearchStrategy[SymbolicCase]:
    """Random small symbolic problems (see the module docstring).

    ``robots``, ``objects`` and ``goals`` are (least, most) counts (robots are named r1, r2 ..., objects o1,
    o2 ...); ``regions`` the region names (distinct, none of those: ValueError), of which at least
    ``min_regions`` are used; ``grasps`` the domain's grasp vocabulary; ``feasible`` the share of
    cases made feasible (0 to 1; None: no planting); ``handover`` whether ``enable-goal-handover`` facts are
    drawn.  The first goal object is never already in its goal region, so there is always something to
    move; a second one may be (it then moves only as an obstacle, back into its goal region).
    """
    if feasible is not None and not 0.0 <= feasible <= 1.0:
        raise ValueError(f"feasible is a share from 0 to 1, not {feasible}")
    if len(regions) < max(2, min_regions):
        raise ValueError("symbolic_problems needs at least two regions")
    taken = [r for r in dict.fromkeys(regions) if re.fullmatch(r"[ro][1-9][0-9]*", r)]
    if taken or len(set(regions)) != len(regions):
        why = f"{taken[0]!r} is a name it gives a robot or an object (r1, r2 ..., o1, o2 ...)" if taken else "repeated"
        raise ValueError(f"symbolic_problems: the region names must be distinct and not robots' or objects': {why}")
    return _cases(
        (robots[0], robots[1]),
        (objects[0], objects[1]),
        tuple(regions),
        min_regions,
        (goals[0], goals[1]),
        tuple(grasps),
        feasible,
        handover,
        domain,
    )


@st.composite
def _cases(
    draw: Any,
    robots_n: tuple[int, int],
    objects_n: tuple[int, int],
    region_names: tuple[str, ...],
    min_regions: int,
    goals_n: tuple[int, int],
    grasps: tuple[str, ...],
    feasible: float | None,
    handover: bool,
    domain: str,
) -> SymbolicCase:
    robots = [f"r{i}" for i in range(1, draw(st.integers(*robots_n)) + 1)]
    objects = [f"o{i}" for i in range(1, draw(st.integers(*objects_n)) + 1)]
    regions = list(region_names[: draw(st.integers(max(2, min_regions), len(region_names)))])
    region = {o: draw(st.sampled_from(regions)) for o in objects}
    most = min(goals_n[1], len(objects))
    goal_objs = draw(st.lists(st.sampled_from(objects), min_size=min(goals_n[0], most), max_size=most, unique=True))
    goal: dict[str, str] = {}
    for k, o in enumerate(goal_objs):
        choices = [r for r in regions if r != region[o]] if k == 0 else regions
        goal[o] = draw(st.sampled_from(choices))
    target = {o: goal.get(o, region[o]) for o in objects}

    density = draw(st.sampled_from([35, 50, 70]))  # percent of the reachability facts that hold

    def some(candidates: list[tuple[str, ...]], dense: bool, cap: int = 4) -> list[tuple[str, ...]]:
        if not candidates:
            return []
        if dense:
            flags = draw(st.lists(st.integers(0, 99), min_size=len(candidates), max_size=len(candidates)))
            return [c for c, f in zip(candidates, flags) if f < density]
        return sorted(draw(st.sets(st.sampled_from(candidates), max_size=cap)))

    facts: list[tuple[str, ...]] = [("in-region", o, region[o]) for o in objects]
    facts += [("reachable-pick", *c) for c in some([(o, g, r) for o in objects for g in grasps for r in robots], True)]
    facts += [
        ("reachable-place", *c)
        for c in some([(o, target[o], g, r) for o in objects for g in grasps for r in robots], True)
    ]
    facts += [
        ("reachable-place", *c)  # decoys: places in regions that are nobody's target
        for c in some(
            [(o, re, g, r) for o in objects for re in regions if re != target[o] for g in grasps for r in robots],
            False,
            2,
        )
    ]
    facts += [
        ("occludes-pick", *c)
        for c in some(
            [(m1, m2, g, r) for m1 in objects for m2 in objects if m1 != m2 for g in grasps for r in robots], False, 8
        )
    ]
    facts += [
        ("occludes-goal-place", *c)
        for c in some(
            [(m1, m2, goal[m2], g, r) for m1 in objects for m2 in goal if m1 != m2 for g in grasps for r in robots],
            False,
            4,
        )
    ]
    if handover and len(robots) > 1:
        facts += [
            ("enable-goal-handover", *c)
            for c in some(
                [
                    (m, g1, g2, r1, r2)
                    for m in objects
                    for g1 in grasps
                    for g2 in grasps
                    for r1 in robots
                    for r2 in robots
                    if r1 != r2
                ],
                False,
                6,
            )
        ]
        facts += [
            ("occludes-handover", *m1, *h[1:])
            for h in facts
            if h[0] == "enable-goal-handover"
            for m1 in some([(m1,) for m1 in objects if m1 != h[1]], False, 1)
        ]

    must = [o for o in goal_objs if goal[o] != region[o]]
    made: bool | None = None
    if feasible is not None:
        # a uniform draw from a seed hypothesis chooses (its integers favour small values: a share of 0.1 came out
        # near one half); hypothesis still favours some seeds, so the share over a run is near p, not exact
        made = draw(st.randoms(use_true_random=True, note_method_calls=False)).random() < feasible
        if made:
            for o in must:  # a witness action with no obstacles for every object that must move
                r, g = draw(st.sampled_from(robots)), draw(st.sampled_from(grasps))
                facts = [
                    f
                    for f in facts
                    if not (f[0] == "occludes-pick" and f[2:] == (o, g, r))
                    and not (f[0] == "occludes-goal-place" and f[2:] == (o, goal[o], g, r))
                ]
                facts += [("reachable-pick", o, g, r), ("reachable-place", o, goal[o], g, r)]
        else:
            o = draw(st.sampled_from(must))
            lose = draw(st.sampled_from(["reachable-pick", "reachable-place"]))
            facts = [
                f for f in facts if not (f[0] == lose and f[1] == o and (lose == "reachable-pick" or f[2] == goal[o]))
            ]
    init = "\n    ".join(f"({' '.join(f)})" for f in dict.fromkeys(facts))
    goals = " ".join(f"(in-region {o} {r})" for o, r in goal.items())
    requirements = ":handover :symbolic" if handover else ":symbolic"
    text = (
        f"(define (domain {domain}) (:requirements {requirements}) (:grasps {' '.join(grasps)}))\n"
        f"(define (problem random)\n  (:domain {domain})\n"
        f"  (:robots {' '.join(robots)})\n  (:movable {' '.join(objects)})\n  (:regions {' '.join(regions)})\n"
        f"  (:init\n    {init})\n  (:goal (and {goals})))\n"
    )
    return SymbolicCase(text, made)
