"""Relays (beyond the paper): a goal object set down on its way and picked up again by another robot or
with another grasp.  The compiler's relay actions against the reference oracle, the plan's two moves,
phase 1's ``enable-relay`` facts (only for goal objects no single action takes to their goal), and a
generated packaging table that had no plan before relays, planned and validated."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import ROOT

from mrgc import __version__
from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, build_task_graph
from mrgc.geometry.relays import stranded
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.loader import parse_file
from mrgc.language.model import Problem
from mrgc.planner.outcome import PlanStatus
from mrgc.planner.phase1 import compute_problem_facts
from mrgc.planner.plan import file_sha256
from mrgc.planner.search import plan_problem
from mrgc.planner.validate import validate
from mrgc.testing.oracle import graph_signature, reference_task_graph

SYMBOLIC = ROOT / "tests" / "data" / "relay.mrg"
GENERATED = ROOT / "tests" / "data" / "relay-packaging.mrg"


def _problem(path: Path) -> Problem:
    return parse_file(str(path)).problems[0]


def _plan(problem: Problem, path: Path, seed: int = 0):  # type: ignore[no-untyped-def]
    return plan_problem(problem, str(path), file_sha256(str(path)), __version__, seed=seed, time_limit=120)


def test_relay_actions_match_the_reference_graph() -> None:
    problem = _problem(SYMBOLIC)
    facts = FactBase.from_problem(problem)
    graph = build_task_graph(facts, list(problem.goal_regions))
    reference = reference_task_graph(
        [r.name for r in problem.robots],
        {m.name: problem.grasps_of(m.name) for m in problem.movable},
        problem.goal_regions,
        facts.region,
        [(f.predicate, *f.args) for f in problem.init],
        list(problem.goal_regions),
    )
    assert graph_signature(graph) == graph_signature(reference)
    relays = [a for a in graph.actions if a.via is not None]
    # (o1 mid top side r1 r2) has r2's goal placement with side; (o1 mid top side r1 r1) has no place by r1
    assert relays == [Action("o1", "goal", "r1", "r2", "top", "side", "mid")]
    (i,) = [graph.actions.index(a) for a in relays]
    assert graph.block_pick[i] == ("o2",) and graph.block_place[i] == ("o3",)
    assert not relays[0].handover and relays[0].robots == ("r1", "r2")


def test_a_symbolic_relay_is_two_moves_the_validator_accepts() -> None:
    problem = _problem(SYMBOLIC)
    plan = _plan(problem, SYMBOLIC)
    assert plan.status is PlanStatus.SOLVED
    moves = [(t, a.object, a.region, a.pick_robot, a.relay) for t, step in enumerate(plan.steps) for a in step]
    down = [m for m in moves if m[4]]
    assert [m[1:] for m in down] == [("o1", "mid", "r1", True)]
    onward = [m for m in moves if m[1] == "o1" and not m[4]]
    assert [m[1:] for m in onward] == [("o1", "goal", "r2", False)] and onward[0][0] == down[0][0] + 1
    report = validate(problem, plan, str(SYMBOLIC))
    assert report.ok, [str(v) for v in report.violations]


def test_phase1_finds_relays_only_for_stranded_goals() -> None:
    problem = _problem(GENERATED)
    facts = compute_problem_facts(problem, seed=0).facts
    paper = [f for f in facts if f.predicate != "enable-relay"]
    scene = scene_from_problem(problem)
    assert stranded(scene, paper) == ["o3"]
    relays = [f.args for f in facts if f.predicate == "enable-relay"]
    assert relays and {r[0] for r in relays} == {"o3"}
    pick = {f.args for f in facts if f.predicate == "reachable-pick"}
    place = {f.args for f in facts if f.predicate == "reachable-place"}
    for obj, region, g1, g2, r1, r2 in relays:  # each one links a pick to a goal placement
        assert region != problem.goal_regions[obj] and (obj, g1, r1) in pick
        assert (obj, problem.goal_regions[obj], g2, r2) in place


@pytest.mark.parametrize("seed", [0, 1])
def test_a_generated_table_without_a_one_move_plan_is_planned_with_a_relay(seed: int) -> None:
    problem = _problem(GENERATED)
    plan = _plan(problem, GENERATED, seed)
    assert plan.status is PlanStatus.SOLVED, plan.summary()
    set_down = [a for step in plan.steps for a in step if a.relay]
    assert [a.object for a in set_down] == ["o3"] and set_down[0].region != problem.goal_regions["o3"]
    assert plan.validation is not None and plan.validation["valid"] is True
    report = validate(problem, plan, str(GENERATED))  # the referee again, outside the search
    assert report.ok, [str(v) for v in report.violations]


def test_compile_json_names_the_relay_region(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from mrgc import cli

    assert cli.main(["compile", str(SYMBOLIC), "--format", "json"]) == 0
    (skeleton,) = json.loads(capsys.readouterr().out)["skeletons"]
    acts = [a for step in skeleton["steps"] for a in step]
    assert [a.get("via") for a in acts if a["object"] == "o1"] == ["mid"]
    assert all("via" not in a for a in acts if a["object"] != "o1")


def test_pictures_of_a_relay_plan_say_set_down_and_count_objects_and_moves() -> None:
    from mrgc.render.frames import build_timeline
    from mrgc.render.world import World

    problem = _problem(GENERATED)
    plan = _plan(problem, GENERATED).to_json()
    timeline = build_timeline(World(problem, plan), plan)
    assert timeline.title.endswith("3 objects moved in 4 moves")
    labels = {p.caption for p in timeline.phases if p.step == 3}
    assert any("o3 set down in start" in label for label in labels), labels
