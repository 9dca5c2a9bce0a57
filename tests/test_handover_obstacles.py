"""Objects in the way of a handover's exchange (``occludes-handover``, beyond the paper): the compiler makes
them pick obstacles of the handover action only (against the reference oracle), the symbolic validator
checks their order, and phase 1 finds them on a hand-made scene (a tall box under the handover point), whose
first skeleton then moves the box before the handover and grounds."""

from __future__ import annotations

from dataclasses import replace

from support import ROOT

from mrgc import __version__
from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, build_task_graph
from mrgc.language.loader import parse_file, parse_string
from mrgc.language.model import Fact, Problem
from mrgc.planfile.format import Step, file_sha256
from mrgc.planner.outcome import PlanStatus
from mrgc.planner.phase1 import compute_problem_facts
from mrgc.planner.search import plan_problem
from mrgc.testing.oracle import graph_signature, reference_task_graph
from mrgc.validator.validate import validate

TALL_BOX = ROOT / "tests" / "data" / "handover-tall-box.mrg"

#: o1 goes from start (r1's) to goal (r2's) by a handover, or by r1 alone with top; o2 stands in the way of
#: the exchange of the side -> side handover only
SYMBOLIC = """
(define (domain hand) (:requirements :symbolic :handover) (:grasps top side))
(define (problem hand)
  (:domain hand)
  (:robots r1 r2)
  (:movable o1 o2)
  (:regions start goal)
  (:init
    (in-region o1 start) (in-region o2 start)
    (reachable-pick o1 side r1) (reachable-pick o1 top r1)
    (reachable-place o1 goal side r2) (reachable-place o1 goal top r1)
    (enable-goal-handover o1 side side r1 r2)
    (occludes-handover o2 o1 side side r1 r2)
    (reachable-pick o2 top r1) (reachable-place o2 start top r1))
  (:goal (in-region o1 goal)))
"""


def _problem(text: str) -> Problem:
    return parse_string(text, "hand.mrg").problems[0]


def _facts(problem: Problem) -> list[tuple[str, ...]]:
    return [(f.predicate, *f.args) for f in problem.init]


def test_an_exchange_obstacle_blocks_the_handover_only() -> None:
    problem = _problem(SYMBOLIC)
    facts = FactBase.from_problem(problem)
    assert facts.occludes_handover == {("o1", "side", "side", "r1", "r2"): ("o2",)}
    graph = build_task_graph(facts, ["o1"])
    reference = reference_task_graph(
        ["r1", "r2"],
        {"o1": ("top", "side"), "o2": ("top", "side")},
        {"o1": "goal"},
        facts.region,
        _facts(problem),
        ["o1"],
    )
    assert graph_signature(graph) == graph_signature(reference)
    blocks = {a: graph.block_pick[i] for i, a in enumerate(graph.actions)}
    assert blocks[Action("o1", "goal", "r1", "r2", "side", "side")] == ("o2",)  # the handover waits for o2
    assert blocks[Action("o1", "goal", "r1", "r1", "top", "top")] == ()  # r1 alone does not
    assert graph.obstacles(graph.actions.index(Action("o1", "goal", "r1", "r2", "side", "side"))) == [("o2", True)]


def test_the_symbolic_validator_wants_the_exchange_obstacle_moved_strictly_earlier() -> None:
    # only the handover is left: o2 must move at an earlier step than it
    text = SYMBOLIC.replace("(reachable-place o1 goal top r1)", "")
    problem = _problem(text)
    plan = plan_problem(problem, "hand.mrg", "0" * 64, __version__, seed=0, time_limit=60)
    assert plan.status is PlanStatus.SOLVED
    moved = {a.object: t for t, step in enumerate(plan.steps) for a in step}
    assert moved["o2"] < moved["o1"]
    assert validate(problem, plan).ok
    # the same plan with both moves in one step breaks the order: [pick-obstacle] names the handover
    doc = plan.as_file()
    step = Step(1, tuple(a for s in doc.steps for a in s.actions), ())
    report = validate(problem, replace(doc, steps=(step,), makespan=1))
    codes = {v.code for v in report.violations}
    assert "pick-obstacle" in codes, [str(v) for v in report.violations]
    assert any("o2 blocks r1 handing o1 to r2" in str(v) for v in report.violations)


def test_phase1_finds_the_box_under_the_handover_point_and_the_first_skeleton_moves_it() -> None:
    problem = parse_file(str(TALL_BOX)).problems[0]
    result = compute_problem_facts(problem, seed=0, workers=1)
    occluding = [f for f in result.facts if f.predicate == "occludes-handover"]
    handovers = {f.args for f in result.facts if f.predicate == "enable-goal-handover"}
    assert occluding and {f.args[0] for f in occluding} == {"o4"}
    assert all(f.args[1:] in handovers for f in occluding)  # only for handovers that exist
    assert Fact("occludes-handover", ("o4", "o1", "top", "side-x+", "r1", "r2")) in occluding
    plan = plan_problem(problem, str(TALL_BOX), file_sha256(str(TALL_BOX)), __version__, seed=0, time_limit=120)
    assert plan.status is PlanStatus.SOLVED
    moved = {a.object: t for t, step in enumerate(plan.steps) for a in step}
    assert moved["o4"] < moved["o1"]
    assert plan.stats["groundings"] == 1  # the first skeleton grounds: o4 is gone before the exchange
    assert validate(problem, plan, str(TALL_BOX)).ok
