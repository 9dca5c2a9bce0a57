"""Skeleton generation against an independent brute-force oracle (mrgc.testing.oracle).

Random small symbolic problems (mrgc.testing.strategies: 2-3 robots, 2-5 objects, 2-3 regions, grasps
top/side, random reachability, occlusion and handover facts, 1-2 goal objects, half of them drawn
feasible) are written as .mrg text and parsed; the oracle must agree with the strategy's feasibility.  For
every backend x encoding the first K skeleton keys (makespan, moved) must equal the oracle's, every skeleton
must satisfy the model's definitions, and the action sets of one run must be pairwise distinct; Alg. 1 must build the
same graph as the oracle's own reading of it.  A second property asks what the planner asks during search:
other M*, objects of a grounded suffix excluded, a horizon limit, skeletons fetched a few at a time.  The
oracle itself is checked on hand-broken skeletons, so a vacuous oracle cannot make the properties pass.
A problem whose goal already holds must give the empty skeleton, not "infeasible".
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any, Sequence

import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from mrgc import cli, parse_file, parse_string
from mrgc.backends.registry import backend_class
from mrgc.compiler.diagnose import explain_infeasible, explain_waits, orderable
from mrgc.compiler.encodings import get_encoding
from mrgc.compiler.enumerate import BatchOutcome, SkeletonGenerator, first_horizon
from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, build_task_graph
from mrgc.language.model import Problem
from mrgc.planner.skeletons import SkeletonSource, compile_problem, must_move
from mrgc.testing import oracle
from mrgc.testing.strategies import SymbolicCase, symbolic_problems

BACKENDS = ["mip", "smt", "pysmt", "cpsat"]
ENCODINGS = ["paper", "disaggregated", "time-of-move"]
K = 4
SYMBOLIC = Path(__file__).resolve().parent.parent / "domains" / "symbolic"

DOMAIN = "(define (domain abstract) (:requirements :handover :symbolic) (:grasps top side))\n"


# ---------------------------------------------------------------- problem generation
def problems() -> Any:
    """Random small symbolic problems from mrgc.testing.strategies, half of them drawn feasible."""
    return symbolic_problems(feasible=0.5)


def reference_graph(problem: Problem, must: Sequence[str] | None = None, moved: Sequence[str] = ()) -> Any:
    """Alg. 1 by the oracle, from the problem's raw facts (no mrgc.compiler code)."""
    return oracle.problem_graph(problem, must, moved)


def _to_the_end(source: SkeletonSource | SkeletonGenerator) -> tuple[list[Any], BatchOutcome]:
    """Every skeleton ``source`` gives, three at a time, and why the last batch stopped."""
    got = []
    while True:
        batch = source.next(3)
        got += batch.skeletons
        if batch.outcome is not BatchOutcome.ENOUGH:
            return got, batch.outcome


# ---------------------------------------------------------------- the property
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems())
def test_every_backend_and_encoding_matches_the_brute_force_oracle(case: SymbolicCase) -> None:
    problem, text = case.problem(), case.text
    ref = reference_graph(problem)
    graph = build_task_graph(FactBase.from_problem(problem), must_move(problem))
    assert oracle.graph_signature(graph) == oracle.graph_signature(ref), "Alg. 1 differs from the reference"

    sets = oracle.feasible_action_sets(ref)
    assert bool(sets) == case.feasible, "the strategy's feasibility planting does not hold"
    expected = sorted((m, len(s)) for s, m in sets.items())[:K]
    event(f"{min(len(sets), K)}{'+' if len(sets) > K else ''} feasible action sets")
    event(f"first makespan {expected[0][0] if expected else '-'}, {len(ref.actions) // 5 * 5}+ actions")
    runs: dict[tuple[str, str], list[tuple[int, int]]] = {}
    problems_found: list[str] = []
    for backend in BACKENDS:
        for encoding in ENCODINGS:
            res = compile_problem(problem, backend=backend, encoding=encoding, skeletons=K)
            keys = [s.key for s in res.skeletons]
            runs[(backend, encoding)] = keys
            where = f"{backend}/{encoding}"
            want_status = "optimal" if sets else "infeasible"
            if res.status != want_status:
                problems_found.append(f"{where}: status {res.status!r}, expected {want_status!r} ({res.reasons})")
            if keys != expected:
                problems_found.append(f"{where}: keys {keys}, oracle {expected}")
            seen: set[frozenset[Action]] = set()
            for sk in res.skeletons:
                bad = oracle.check_skeleton(ref, sk)
                if bad:
                    problems_found.append(f"{where}: skeleton {sk.describe()} violates {bad}")
                if sk.actions in seen:
                    problems_found.append(f"{where}: action set returned twice: {sk.describe()}")
                seen.add(sk.actions)
                if sets.get(sk.actions) != sk.makespan:
                    problems_found.append(
                        f"{where}: {sk.describe()} has makespan {sk.makespan}, the oracle's "
                        f"minimum for that action set is {sets.get(sk.actions)}"
                    )
    if len({tuple(keys) for keys in runs.values()}) != 1:
        problems_found.insert(0, f"the 12 backend/encoding combinations disagree: {runs}")
    assert not problems_found, "\n".join(problems_found) + "\n\nproblem:\n" + text


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems(), st.data())
def test_resumed_requests_with_moved_objects_and_a_horizon_limit(case: SymbolicCase, data: Any) -> None:
    """What the planner asks during search: skeletons for some M*, with the grounded suffix's objects
    excluded, a horizon limit, fetched a few at a time (the generator keeps its cuts between calls)."""
    problem, text = case.problem(), case.text
    objects = [m.name for m in problem.movable]
    moved = data.draw(st.lists(st.sampled_from(objects), unique=True, max_size=2), label="moved")
    extra = data.draw(st.lists(st.sampled_from(objects), unique=True, max_size=1), label="extra M*")
    must = [o for o in dict.fromkeys(must_move(problem) + extra) if o not in moved]
    limit = data.draw(st.sampled_from([None, 1, 2]), label="max makespan")
    base = FactBase.from_problem(problem)
    ref = reference_graph(problem, must, moved)
    assert oracle.graph_signature(build_task_graph(base, must, moved)) == oracle.graph_signature(ref)

    sets = oracle.feasible_action_sets(ref)
    cap = limit if limit is not None else max(1, len(ref.objects))
    expected = sorted(k for k in ((m, len(s)) for s, m in sets.items()) if k[0] <= cap)[:K]
    event(f"{len(expected)} skeletons expected, limit {limit}, {len(moved)} moved")
    failures = []
    for backend in ("cpsat", "mip"):
        for encoding in ENCODINGS:
            source = SkeletonSource(base, must, moved, backend, encoding, max_makespan=limit)
            got = []
            for chunk in (1, 2, K - 3):
                got += source.next(chunk).skeletons
            keys = [s.key for s in got]
            if keys != expected:
                failures.append(f"{backend}/{encoding}: keys {keys}, oracle {expected}")
            if len({s.actions for s in got}) != len(got):
                failures.append(f"{backend}/{encoding}: an action set came back twice")
            for sk in got:
                bad = oracle.check_skeleton(ref, sk)
                if bad or any(a.obj in moved for a in sk.actions):
                    failures.append(f"{backend}/{encoding}: {sk.describe()} violates {bad} (moved: {moved})")
    assert not failures, "\n".join(failures) + f"\n\nM* {must}, moved {moved}, limit {limit}\n" + text


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems(), st.data())
def test_deferred_actions_come_last_and_no_skeleton_is_lost(case: SymbolicCase, data: Any) -> None:
    """Actions deferred after the first skeleton (what the planner does with an action whose grounding
    keeps failing): the skeletons without them come first, in (makespan, moved) order, then the deferral
    is lifted and the others follow, so that enumeration to the end still returns every feasible action
    set of the oracle exactly once, each at its minimum makespan."""
    problem, text = case.problem(), case.text
    sets = oracle.feasible_action_sets(reference_graph(problem))
    assume(0 < len(sets) <= 40)
    encoding = data.draw(st.sampled_from(ENCODINGS), label="encoding")
    source = SkeletonSource(FactBase.from_problem(problem), must_move(problem), (), "cpsat", encoding)
    got = source.next(1).skeletons
    actions = sorted(source.generator.graph.actions, key=str)
    deferred = set(data.draw(st.lists(st.sampled_from(actions), max_size=3), label="deferred"))
    source.generator.defer(deferred)
    while True:
        batch = source.next(3)
        got += batch.skeletons
        if batch.outcome is BatchOutcome.EXHAUSTED:
            break
    where = f"{encoding}, deferred {sorted(map(str, deferred))}\n{text}"
    assert {s.actions for s in got} == set(sets), where
    assert len({s.actions for s in got}) == len(got), where
    assert all(sets[s.actions] == s.makespan for s in got), where
    late = [bool(s.actions & deferred) for s in got[1:]]
    assert late == sorted(late), where  # every skeleton without a deferred action before any with one
    first = [s.key for s, d in zip(got[1:], late) if not d]
    last = [s.key for s, d in zip(got[1:], late) if d]
    assert first == sorted(first) and last == sorted(last), where


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems(), st.data())
def test_actions_deferred_after_a_lift_are_kept_back_too_and_no_skeleton_is_lost(case: SymbolicCase, data: Any) -> None:
    """Deferrals at any time, before and after a deferral was lifted (compiler/enumerate.py: a lifted action is
    released, the others deferred later are kept back): no batch gives a skeleton holding an action that was
    deferred when the batch was asked for and not released while it was made, and enumeration to the end
    still returns every feasible action set of the oracle exactly once, at its minimum makespan."""
    problem, text = case.problem(), case.text
    sets = oracle.feasible_action_sets(reference_graph(problem))
    assume(0 < len(sets) <= 40)
    encoding = data.draw(st.sampled_from(ENCODINGS), label="encoding")
    source = SkeletonSource(FactBase.from_problem(problem), must_move(problem), (), "cpsat", encoding)
    gen = source.generator
    actions = sorted(gen.graph.actions, key=str)
    index = {a: i for i, a in enumerate(gen.graph.actions)}
    got: list[Any] = []
    for _ in range(60):
        now = data.draw(st.lists(st.sampled_from(actions), max_size=2), label="deferred now")
        gen.defer(now)
        held, released = set(gen.deferred), set(gen.released)
        assert gen.done or {index[a] for a in now} - released <= held  # kept back unless released before
        batch = source.next(data.draw(st.integers(1, 3), label="k"))
        kept = held - (gen.released - released)
        assert not [s for s in batch.skeletons if {index[a] for a in s.actions} & kept], text
        got += batch.skeletons
        if batch.outcome is BatchOutcome.EXHAUSTED:
            break
    else:
        raise AssertionError("enumeration did not end\n" + text)
    assert {s.actions for s in got} == set(sets), text
    assert len({s.actions for s in got}) == len(got), text
    assert all(sets[s.actions] == s.makespan for s in got), text


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems(), st.sampled_from([None, 1, 2]))
def test_time_of_move_one_horizon_at_a_time_enumerates_as_one_model_does(case: SymbolicCase, limit: Any) -> None:
    """Time-of-move solved one horizon at a time (``grow_horizon``, CP-SAT's and HiGHS' default) and in one
    model up to the limit (z3's): both enumerate, to the end, every feasible action set of the oracle once,
    at its minimum makespan, in (makespan, moved) order; the horizon loop's infeasible models move it on."""
    problem, text = case.problem(), case.text
    sets = oracle.feasible_action_sets(reference_graph(problem))
    assume(len(sets) <= 40)
    cap = limit if limit is not None else max(1, len(problem.movable))
    wanted = {a: m for a, m in sets.items() if m <= cap}
    graph = build_task_graph(FactBase.from_problem(problem), must_move(problem))
    for grow in (True, False):
        generator = SkeletonGenerator(
            graph, get_encoding("time-of-move"), lambda: backend_class("cpsat")(), limit, grow_horizon=grow
        )
        got, outcome = _to_the_end(generator)
        where = f"grow_horizon={grow}, limit {limit}\n{text}"
        assert outcome is BatchOutcome.EXHAUSTED, where
        assert [s.key for s in got] == sorted((m, len(a)) for a, m in wanted.items()), where
        assert {s.actions: s.makespan for s in got} == wanted, where
        if grow and got and got[-1].makespan:  # a model per horizon from T0 to the last skeleton's makespan
            assert generator.stats["models"] >= got[-1].makespan - generator.first_horizon + 1, where
        if not grow:
            assert generator.stats["models"] <= 1, where


def _preferred_form(graph: Any, actions: frozenset[Action]) -> frozenset[Action]:
    """Each action replaced by the first of the graph's actions interchangeable with it (compiler/
    grasp_order.py's definition, read from the graph's data here: the same object, region, robots and relay
    region, the same pick obstacles and the same place obstacles)."""

    def sig(i: int) -> tuple[Any, ...]:
        a = graph.actions[i]
        blocks = (set(graph.block_pick[i]), set(graph.block_place[i]))
        return (a.obj, a.region, a.pick_robot, a.place_robot, a.via, *blocks)

    index = {a: i for i, a in enumerate(graph.actions)}
    first = [next(j for j in range(len(graph.actions)) if sig(j) == sig(index[a])) for a in actions]
    return frozenset(graph.actions[j] for j in first)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems(), st.sampled_from(["mip", "cpsat"]), st.sampled_from(ENCODINGS))
def test_interchangeable_actions_come_in_declared_grasp_order_and_no_skeleton_is_lost(
    case: SymbolicCase, backend: str, encoding: str
) -> None:
    """compiler/grasp_order.py: enumerated to the end, every feasible action set of the oracle comes once, at its
    minimum makespan and in (makespan, moved) order, and a skeleton whose actions are not all the first of their
    interchangeable ones comes only after the skeleton that has those (its preferred form)."""
    problem, text = case.problem(), case.text
    sets = oracle.feasible_action_sets(reference_graph(problem))
    assume(0 < len(sets) <= 40)
    source = SkeletonSource(FactBase.from_problem(problem), must_move(problem), (), backend, encoding)
    got, outcome = _to_the_end(source)
    where = f"{backend}/{encoding}\n{text}"
    assert outcome is BatchOutcome.EXHAUSTED, where
    assert [s.actions for s in got if s.actions in sets] == [s.actions for s in got], where
    assert len({s.actions for s in got}) == len(got) == len(sets), where
    assert [s.key for s in got] == sorted(s.key for s in got), where
    assert all(sets[s.actions] == s.makespan for s in got), where
    given_at = {s.actions: k for k, s in enumerate(got)}
    swapped = 0
    for k, s in enumerate(got):
        best = _preferred_form(source.generator.graph, s.actions)
        assert given_at[best] <= k, f"{s.describe()} before its preferred form\n{where}"
        swapped += best != s.actions
    event(f"{'some' if swapped else 'no'} skeleton after its preferred form")


@pytest.mark.parametrize("backend", ["mip", "cpsat", "smt"])
@pytest.mark.parametrize("grasps", ["a b c d e f", "f e d c b a"])
def test_the_first_skeleton_takes_the_grasps_declared_first(backend: str, grasps: str) -> None:
    """Four objects any grasp of either robot moves to the goal, nothing in the way: the first skeleton moves
    each with the first grasp the domain declares, in either order of the declaration (HiGHS and CP-SAT,
    left to themselves, take the last one)."""
    objects = ["o1", "o2", "o3", "o4"]
    init = " ".join(f"(in-region {o} start)" for o in objects)
    init += " ".join(
        f" (reachable-pick {o} {g} {r}) (reachable-place {o} goal {g} {r})"
        for o in objects
        for r in ("r1", "r2")
        for g in grasps.split()
    )
    goal = " ".join(f"(in-region {o} goal)" for o in objects)
    text = (
        f"(define (domain g) (:requirements :handover :symbolic) (:grasps {grasps}))\n"
        f"(define (problem p) (:domain g) (:robots r1 r2) (:movable {' '.join(objects)}) (:regions start goal)"
        f" (:init {init}) (:goal (and {goal})))"
    )
    first = compile_problem(parse_string(text).problem(), backend=backend, encoding="time-of-move").skeletons[0]
    assert first.key == (2, 4)
    assert {(a.pick_grasp, a.place_grasp) for a in first.actions} == {(grasps[0], grasps[0])}


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(problems())
def test_the_first_horizon_is_a_lower_bound_on_every_makespan(case: SymbolicCase) -> None:
    """compiler/enumerate.py's ``first_horizon`` never exceeds the makespan of a feasible action set (the
    oracle's minimum): starting the horizon loop there skips only horizons without skeletons."""
    problem = case.problem()
    sets = oracle.feasible_action_sets(reference_graph(problem))
    assume(sets)
    graph = build_task_graph(FactBase.from_problem(problem), must_move(problem))
    bound = first_horizon(graph)
    event(f"bound {'=' if bound == min(sets.values()) else '<'} the smallest makespan")
    assert bound <= min(sets.values()), case.text


# ---------------------------------------------------------------- the oracle is not vacuous
def _chain3() -> tuple[Any, dict[str, Action]]:
    problem = parse_file(str(SYMBOLIC / "chain-3.mrg")).problem()
    graph = reference_graph(problem)
    named = {
        "A1": Action("o1", "goal", "r1", "r1", "top", "top"),
        "A2": Action("o1", "goal", "r2", "r2", "side", "side"),
        "A3": Action("o1", "goal", "r1", "r2", "top", "side"),
        "B": Action("o2", "start", "r1", "r1", "top", "top"),
        "C": Action("o3", "start", "r2", "r2", "side", "side"),
    }
    assert set(graph.actions) == set(named.values())
    return graph, named


def test_oracle_on_chain3_lists_exactly_the_documented_action_sets() -> None:
    graph, a = _chain3()
    assert oracle.feasible_action_sets(graph) == {
        frozenset({a["A2"]}): 1,
        frozenset({a["B"], a["A3"]}): 2,
        frozenset({a["B"], a["C"], a["A1"]}): 2,
    }
    assert oracle.oracle_keys(graph) == [(1, 1), (2, 2), (2, 3)]
    assert oracle.min_makespan(graph, [a["A1"]]) is None  # its obstacles are not moved
    assert oracle.min_makespan(graph, [a["A2"], a["B"]]) is None  # o2 moved without need


def test_oracle_accepts_valid_and_flags_each_kind_of_violation() -> None:
    graph, a = _chain3()
    A1, A2, A3, B, C = a["A1"], a["A2"], a["A3"], a["B"], a["C"]
    assert oracle.check_skeleton(graph, [[A2]]) == []
    assert oracle.check_skeleton(graph, [[B, C], [A1]]) == []
    assert oracle.check_skeleton(graph, [[B], [A1, C]]) == []  # a place obstacle may share the step
    assert oracle.check_skeleton(graph, [[B], [A3]]) == []

    def flagged(steps: list[list[Action]], needle: str) -> None:
        bad = oracle.check_skeleton(graph, steps)
        assert any(needle in b for b in bad), (steps, bad)

    flagged([[B, C, A1]], "not strictly earlier")  # pick obstacle in the same step (also: r1 twice)
    flagged([[B], [A1], [C]], "moves later")  # place obstacle after the action
    flagged([[B], [], [A3]], "empty")
    flagged([[B, A3]], "robot r1 does two actions")  # the handover also occupies r1
    flagged([[C], [A3, B]], "robot r1")
    flagged([[B], [A2]], "obstructs no selected action")
    flagged([[B]], "in M* but is not moved")
    flagged([[A2], [A1]], "moved twice")
    flagged([[C], [A1]], "never moved")
    flagged([[Action("o1", "goal", "r2", "r2", "top", "top")]], "not an action of the task graph")


def test_min_makespan_respects_handover_robots_and_strict_pick_order() -> None:
    text = (
        DOMAIN
        + """(define (problem p) (:domain abstract)
      (:robots r1 r2 r3) (:movable o1 o2 o3) (:regions ra rb)
      (:init (in-region o1 ra) (in-region o2 ra) (in-region o3 ra)
        (reachable-pick o1 top r1) (enable-goal-handover o1 top side r1 r2) (reachable-place o1 rb side r2)
        (reachable-pick o2 top r2) (reachable-place o2 rb top r2)
        (reachable-pick o3 top r3) (reachable-place o3 rb top r3) (occludes-pick o2 o3 top r3))
      (:goal (and (in-region o1 rb) (in-region o2 rb) (in-region o3 rb))))"""
    )
    graph = reference_graph(parse_string(text).problem())
    # o2 before o3 (strict); the o1 handover shares r2 with o2: o1 | o2 | o3 or o2 | o1+o3 -> 2 steps
    assert oracle.oracle_keys(graph) == [(2, 3)]


# ---------------------------------------------------------------- a goal that already holds
ALREADY_DONE = (
    DOMAIN
    + """(define (problem done) (:domain abstract)
  (:robots r1 r2) (:movable o1 o2) (:regions ra rb)
  (:init (in-region o1 rb) (in-region o2 ra) (reachable-pick o1 top r1) (reachable-place o1 rb top r1))
  (:goal (in-region o1 rb)))
"""
)


def test_oracle_says_a_satisfied_goal_needs_the_empty_skeleton() -> None:
    graph = reference_graph(parse_string(ALREADY_DONE).problem())
    assert graph.must_move == ()
    assert oracle.oracle_keys(graph) == [(0, 0)]


def test_a_satisfied_goal_is_not_infeasible() -> None:
    """M* is empty: the empty skeleton (makespan 0, nothing moved) is a plan, so 'infeasible' is wrong."""
    problem = parse_string(ALREADY_DONE).problem()
    outcome = {}
    for backend in BACKENDS:
        for encoding in ENCODINGS:
            res = compile_problem(problem, backend=backend, encoding=encoding)
            outcome[(backend, encoding)] = (res.status, [s.key for s in res.skeletons])
    assert all(status == "optimal" and set(keys) <= {(0, 0)} for status, keys in outcome.values()), outcome


def test_cli_compile_of_a_satisfied_goal_exits_0(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "done.mrg"
    path.write_text(ALREADY_DONE, encoding="utf-8")
    code = cli.main(["compile", str(path)])
    out = capsys.readouterr().out
    assert code == 0, out


# ---------------------------------------------------------------- the cheap reasons are sound
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(symbolic_problems(feasible=0.3, objects=(3, 5)), st.booleans())
def test_a_cheap_infeasibility_reason_means_the_oracle_finds_no_skeleton(case: SymbolicCase, drives: bool) -> None:
    """explain_infeasible (dead actions, blocking cycles, objects that wait for each other with
    alternatives) runs before any solver and stops the search: it must never fire on a problem with a
    skeleton.  Also with every robot driving (place obstacles strict, as for carts)."""
    problem = case.problem()
    base = FactBase.from_problem(problem)
    if drives:
        base = replace(base, drivers=frozenset(base.robots))
    graph = build_task_graph(base, must_move(problem))
    reasons = explain_infeasible(graph, base)
    has_skeleton = bool(oracle.feasible_action_sets(graph))
    event(f"{'reason' if reasons else 'no reason'}, {'feasible' if has_skeleton else 'infeasible'}")
    event(f"waits: {bool(explain_waits(graph))}, orderable M*: {set(graph.must_move) <= orderable(graph)}")
    assert not (reasons and has_skeleton), f"{reasons}\n\n{case.text}"
    # the fixpoint is a relaxation: an unorderable object of M* means no skeleton
    assert has_skeleton <= (set(graph.must_move) <= orderable(graph)), case.text


def test_objects_that_wait_for_each_other_with_alternatives_are_named() -> None:
    """o3 blocks every place of o1 and o2 (a doorway); r1's pick of o3 waits for o1, r2's for o2: no single
    blocker is forced (no blocking cycle), yet no order of moves exists."""
    text = (
        DOMAIN
        + """(define (problem waits) (:domain abstract)
  (:robots r1 r2) (:movable o1 o2 o3) (:regions ra rb)
  (:init (in-region o1 ra) (in-region o2 ra) (in-region o3 ra)
    (reachable-pick o1 top r1) (reachable-place o1 rb top r1) (occludes-goal-place o3 o1 rb top r1)
    (reachable-pick o2 top r2) (reachable-place o2 rb top r2) (occludes-goal-place o3 o2 rb top r2)
    (reachable-pick o3 top r1) (reachable-pick o3 side r2) (reachable-place o3 ra top r1)
    (reachable-place o3 ra side r2) (occludes-pick o1 o3 top r1) (occludes-pick o2 o3 side r2))
  (:goal (and (in-region o1 rb) (in-region o2 rb))))"""
    )
    problem = parse_string(text).problem()
    base = FactBase.from_problem(problem)
    graph = build_task_graph(base, must_move(problem))
    assert not oracle.feasible_action_sets(graph) and orderable(graph) == set()
    assert explain_infeasible(graph, base) == [
        "no order of moves exists for o1, o2 (each object moves once, a goal object only into its goal region; "
        "every action waits for an object that itself waits): o1 waits for o3 (the place of top by r1); "
        "o2 waits for o3 (the place of top by r2); o3 waits for o1 (the pick of top by r1) or o2 (the pick of "
        "side by r2)"
    ]
    res = compile_problem(problem)
    assert res.status == "infeasible" and res.reasons == explain_infeasible(graph, base)
