"""Deferred actions (planner/deferral.py): what a failed grounding names is counted by its part (a place: object,
region, robot; a pick: object, robot; otherwise the action), and at three failures the skeleton sources give
the skeletons without it first, then the others (none is lost).  The enumeration itself is property-tested
against the oracle in tests/test_skeletons_property.py."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from mrgc import parse_file
from mrgc.compiler.facts import FactBase
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.planner.deferral import DEFER_AFTER, Deferrals, describe
from mrgc.planner.ground import label
from mrgc.planner.outcome import Failure
from mrgc.planner.search import _order, _Sources
from mrgc.planner.skeletons import must_move

CHAIN3 = Path(__file__).resolve().parent.parent / "domains" / "symbolic" / "chain-3.mrg"
A1 = Action("o1", "goal", "r1", "r1", "top", "top")
A2 = Action("o1", "goal", "r2", "r2", "side", "side")
A3 = Action("o1", "goal", "r1", "r2", "top", "side")
B = Action("o2", "start", "r1", "r1", "top", "top")
C = Action("o3", "start", "r2", "r2", "side", "side")


def sources() -> _Sources:
    problem = parse_file(str(CHAIN3)).problem()
    base = FactBase.from_problem(problem)
    return _Sources(base, _order(problem), "cpsat", "time-of-move", None, 0, time.perf_counter() + 600)


def test_a_place_failing_three_times_defers_every_action_placing_there_then_the_rest_follow() -> None:
    src = sources()
    more = src(set(must_move(parse_file(str(CHAIN3)).problem())), set())
    first = more(1)
    assert [s.actions for s in first] == [frozenset({A2})]  # the optimum: r2 moves o1
    fail = Failure(1, label(A2), "place by r2: no inverse kinematics")
    said = [src.deferrals.failed(first[0], fail) for _ in range(DEFER_AFTER)]
    assert said == [None] * (DEFER_AFTER - 1) + [("place", "o1", "goal", "r2")]
    assert describe(said[-1]) == "r2 places o1 in goal"
    # A3 (the handover to r2) places there too: {B, C, A1} comes before {B, A3}, which comes, not lost
    assert [s.actions for s in more(5)] == [frozenset({B, C, A1}), frozenset({B, A3})]
    assert more(5) == [] and more.infeasible is False


def test_without_failures_the_order_is_the_papers() -> None:
    src = sources()
    more = src({"o1"}, set())
    assert [s.actions for s in more(5)] == [frozenset({A2}), frozenset({B, A3}), frozenset({B, C, A1})]


def test_reach_failures_count_by_part_other_failures_by_action() -> None:
    d = Deferrals(after=2)
    skel = Skeleton(((B,), (A3,)))
    a1 = Skeleton(((B, C), (A1,)))
    assert d.failed(skel, Failure(2, label(A3), "pick by r1: collision", ("o2",))) is None  # the action's
    assert d.failed(skel, Failure(2, label(A3), "pick by r1: no inverse kinematics")) is None
    # out of reach with another grasp (A1's top, the same as A3's here) and robot r1: the same part
    assert d.failed(a1, Failure(2, label(A1), "pick by r1: no inverse kinematics")) == ("pick", "o1", "r1")
    assert d.covers(A1) and d.covers(A3) and not d.covers(A2)  # every pick of o1 by r1
    # a handover check, the validator's verdict (step 0) and a step without that action
    assert d.failed(skel, Failure(2, label(A3), "handover: no handover point usable for o1")) == ("action", A3)
    assert d.failed(skel, Failure(0, "validator (1 violation)", "collision-robot-robot")) is None
    assert d.failed(skel, Failure(1, label(A3), "place by r2: no inverse kinematics")) is None
    assert d.counts == {("pick", "o1", "r1"): 2, ("action", A3): 2}
    relay = Action("o1", "goal", "r1", "r2", "top", "side", via="start")
    down, onward = relay.halves
    rskel = Skeleton(((relay,),))
    assert d.failed(rskel, Failure(1, label(onward), "place by r2: no inverse kinematics")) is None
    assert d.failed(rskel, Failure(1, label(down), "place by r1: collision")) == ("action", relay)
    assert d.covers(relay) and d.among([A2, relay, C]) == [relay]


def test_the_checks_grounding_writes_are_the_ones_counted_by_part() -> None:
    """The part of a failure is read from the check text that planner/ground.py writes: built here by its own
    formatter, so a reworded message fails this test instead of quietly deferring whole actions."""
    from mrgc.geometry.answers import Answer, GroundStatus
    from mrgc.planner.ground import _failed

    skel = Skeleton(((A3,),))
    for what, part in (
        ("place by r2", ("place", "o1", "goal", "r2")),
        ("carry to the placement by r2", ("place", "o1", "goal", "r2")),
        ("pick by r1", ("pick", "o1", "r1")),
    ):
        d = Deferrals(after=1)
        failure = replace(_failed(what, Answer(GroundStatus.NO_IK)), step=1, action=label(A3))
        assert d.failed(skel, failure) == part, what
        collided = replace(_failed(what, Answer(GroundStatus.COLLISION)), step=1, action=label(A3))
        assert Deferrals(after=1).failed(skel, collided) == ("action", A3), what


def test_a_finished_source_is_not_reopened_by_a_deferral() -> None:
    src = sources()
    more = src({"o1"}, set())
    assert len(more(10)) == 3 and more(10) == []
    gen = more.source.generator
    solves = gen.stats["solves"]
    gen.defer([A2, B])
    assert more(10) == [] and gen.stats["solves"] == solves and not gen.deferred


def test_a_pick_failing_on_what_never_moves_defers_that_pick_with_its_grasp_at_once() -> None:
    """A pick whose every attempt failed on what never moves (``Failure.static``: the table, the arm itself,
    out of reach) fails again in every skeleton holding it: the pick with that grasp is deferred at its first
    failure; the action's own count goes on as before, and a relay (picked elsewhere) is not."""
    d = Deferrals()
    skel = Skeleton(((B,), (A3,)))
    hit = Failure(2, label(A3), "pick by r1: collision", (), "hits table", static=True)
    part = d.failed(skel, hit)
    assert part == ("grasp", "o1", "r1", "top") and describe(part) == "r1 picks o1 with top"
    assert d.reason(part) == "at its first failure, on what never moves"
    assert d.covers(A1) and d.covers(A3) and not d.covers(A2)  # every pick of o1 by r1 with top
    assert d.counts[("action", A3)] == 1 and ("action", A3) not in d.deferred
    assert d.failed(skel, hit) is None  # deferred once
    moving = Deferrals()
    assert moving.failed(skel, replace(hit, static=False)) is None and not moving.deferred  # counted by action
    relay = Action("o1", "goal", "r1", "r2", "top", "side", via="start")
    rskel = Skeleton(((relay,),))
    down = relay.halves[0]
    assert Deferrals().failed(rskel, replace(hit, step=1, action=label(down))) is None


def test_a_place_failing_on_what_never_moves_at_every_placement_defers_that_place_with_its_grasp_at_once() -> None:
    d = Deferrals()
    skel = Skeleton(((B,), (A3,)))
    hit = Failure(2, label(A3), "place by r2: collision", (), "hits table", static=True)
    part = d.failed(skel, hit)
    assert part == ("put", "o1", "goal", "r2", "side") and describe(part) == "r2 places o1 in goal with side"
    assert d.covers(A2) and d.covers(A3) and not d.covers(A1)  # r2 placing o1 in goal with side
    assert Deferrals().failed(skel, replace(hit, static=False)) is None
