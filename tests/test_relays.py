"""Relays (beyond the paper): a goal object set down on its way and picked up again by another robot or
with another grasp.  The compiler's relay actions against the reference oracle, the plan's two moves,
phase 1's ``enable-relay`` facts (only for goal objects no single action takes to their goal), and a
generated packaging table that had no plan before relays, planned and validated."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc import __version__
from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, TaskGraph, build_task_graph
from mrgc.geometry.relays import STAGING, staging, stranded
from mrgc.geometry.scene import inside, scene_from_problem
from mrgc.language.loader import parse_file, parse_string
from mrgc.language.model import Problem
from mrgc.planfile.format import file_sha256
from mrgc.planner.outcome import PlanStatus
from mrgc.planner.phase1 import compute_problem_facts
from mrgc.planner.search import plan_problem
from mrgc.planner.skeletons import compile_problem
from mrgc.testing.oracle import graph_signature, reference_task_graph
from mrgc.validator.validate import validate

SYMBOLIC = ROOT / "tests" / "data" / "relay.mrg"
GENERATED = ROOT / "tests" / "data" / "relay-packaging.mrg"
TABLE = ROOT / "tests" / "data" / "relay-table.mrg"
CROWDED = ROOT / "tests" / "data" / "relay-crowded.mrg"
#: ``mrgc plan tests/data/relay-table.mrg --seed 0`` (relays on the table at steps 4 and 6)
TABLE_PLAN = ROOT / "tests" / "data" / "relay-table-plan.json"


def _problem(path: Path) -> Problem:
    return parse_file(str(path)).problems[0]


def _plan(problem: Problem, path: Path, seed: int = 0):  # type: ignore[no-untyped-def]
    return plan_problem(problem, str(path), file_sha256(str(path)), __version__, seed=seed, time_limit=120)


def _graph(problem: Problem) -> TaskGraph:
    """The compiler's task graph of ``problem``'s goals, after checking it against the reference oracle's."""
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
    return graph


def test_relay_actions_match_the_reference_graph() -> None:
    graph = _graph(_problem(SYMBOLIC))
    relays = [a for a in graph.actions if a.via is not None]
    # (o1 mid top side r1 r2) has r2's goal placement with side; (o1 mid top side r1 r1) has no place by r1
    assert relays == [Action("o1", "goal", "r1", "r2", "top", "side", "mid")]
    (i,) = [graph.actions.index(a) for a in relays]
    assert graph.block_pick[i] == ("o2",) and graph.block_place[i] == ("o3",)
    assert not relays[0].handover and relays[0].robots == ("r1", "r2")


@settings(max_examples=25, deadline=None)
@given(st.sets(st.sampled_from(["o2", "o3", "o4"])), st.booleans())
def test_the_objects_in_the_way_at_a_relays_spot_are_its_pick_obstacles(in_way: set[str], other: bool) -> None:
    """``occludes-relay`` (session 44): the objects in the way at a relay's spot are pick obstacles of that relay
    and of no other action, as the reference graph says for any set of them; a fact naming a relay that is no
    action (``other``: the regrasp r1 -> r1, which no goal placement by r1 follows) adds nothing."""
    key = "o1 mid top side r1 r1" if other else "o1 mid top side r1 r2"
    facts = " ".join(f"(occludes-relay {o} {key})" for o in sorted(in_way))
    last = "(occludes-goal-place o4 o1 mid top r1))"
    text = SYMBOLIC.read_text()
    before, after = (
        _graph(parse_string(text.replace(last, f"{last[:-1]} {extra})"), str(SYMBOLIC)).problems[0])
        for extra in ("", facts)
    )
    assert before.actions == after.actions
    for a, was, now in zip(after.actions, before.block_pick, after.block_pick):
        assert set(now) == set(was) | (in_way if a.via is not None and not other else set())


def test_a_skeleton_clears_a_relays_spot_before_the_relay(tmp_path: Path) -> None:
    """With o4 in the way at the spot in mid (``occludes-relay``) and movable by r1, every skeleton moves o4
    in a step before the relay of o1, and the plan (symbolic: the skeleton) still validates."""
    last = "(occludes-goal-place o4 o1 mid top r1))"
    extra = "(reachable-pick o4 top r1) (reachable-place o4 start top r1) (occludes-relay o4 o1 mid top side r1 r2)"
    path = tmp_path / "relay-spot.mrg"
    path.write_text(SYMBOLIC.read_text().replace(last, f"{last[:-1]} {extra})"))
    problem = _problem(path)
    result = compile_problem(problem, skeletons=3)
    assert result.skeletons
    for skel in result.skeletons:
        when = {a.obj: t for t, step in enumerate(skel.steps) for a in step}
        assert "o4" in when and when["o4"] < when["o1"], skel
    plan = _plan(problem, path)
    assert plan.status is PlanStatus.SOLVED
    report = validate(problem, plan, str(path))
    assert report.ok, [str(v) for v in report.violations]


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


def test_a_relay_with_no_spot_left_in_its_region_sets_its_object_down_on_the_table() -> None:
    """tests/data/relay-crowded.mrg: relay-packaging with the part of start both arms reach filled.  Phase 1
    relays o3 via start with fillers in the way at its spot (``occludes-relay``, session 44), and so also via
    the table between r1 and r2, where nothing is; the plan sets o3 down on the table (session 42: grounding
    found no spot in start and fell back to the table; before, the search first moved four of the fillers
    out of the way: 7 objects moved in 8 moves, makespan 7).  The plan is valid."""
    problem = _problem(CROWDED)
    facts = compute_problem_facts(problem, seed=0).facts
    relays = {f.args[1:] for f in facts if f.predicate == "enable-relay" and f.args[0] == "o3"}
    assert {r[0] for r in relays} == {"start", "table"}
    in_way = {f.args[2:] for f in facts if f.predicate == "occludes-relay" and f.args[1] == "o3"}
    assert {r[0] for r in in_way} == {"start"} and all(r in relays for r in in_way)
    plan = _plan(problem, CROWDED, 0)
    assert plan.status is PlanStatus.SOLVED, plan.summary()
    set_down = [a for step in plan.steps for a in step if a.relay]
    assert [(a.object, a.region) for a in set_down] == [("o3", "table")]
    scene = scene_from_problem(problem)
    assert not inside(scene.region("start"), scene.body("o3").shape, np.array(set_down[0].place_pose))
    report = validate(problem, plan, str(CROWDED))
    assert report.ok, [str(v) for v in report.violations]
    # the pictures draw a plan that sets objects down on a fixed top (an E510 "not a region" before)
    from mrgc.render.frames import build_timeline
    from mrgc.render.world import World

    data = plan.to_json()
    captions = {p.caption for p in build_timeline(World(problem, data), data).phases}
    assert any("o3 set down in table" in c for c in captions), captions


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


def test_phase1_finds_relays_on_the_table_between_two_arms_when_no_region_serves() -> None:
    problem = _problem(TABLE)
    facts = compute_problem_facts(problem, seed=0).facts
    relays = sorted(f.args for f in facts if f.predicate == "enable-relay")
    assert {r[0] for r in relays} == {"o5", "o9"} and {r[1] for r in relays} == {"table"}, relays
    assert all((r[4], r[5]) == ("r1", "r2") for r in relays)  # r1 picks them in start, r2 places in bin-a
    scene = scene_from_problem(problem)
    square = staging(scene, "table", "r1", "r2")  # where both look: between their bases, on the top
    mid = (scene.robot("r1").base[:3, 3] + scene.robot("r2").base[:3, 3]) / 2
    assert np.allclose(square.pose[:2, 3], mid[:2]) and abs(square.pose[2, 3] - 0.5) < 1e-9
    assert (square.shape.sx, square.shape.sy) == (STAGING, STAGING)


def test_the_validator_accepts_a_relay_on_the_table_and_rejects_edits_of_it() -> None:
    problem = _problem(TABLE)
    plan = json.loads(TABLE_PLAN.read_text())
    report = validate(problem, plan, str(TABLE))
    assert report.ok, [str(v) for v in report.violations]
    moves = [(s["index"], a) for s in plan["steps"] for a in s["actions"]]
    assert [(t, a["object"], a["region"]) for t, a in moves if a.get("relay")] == [
        (4, "o9", "table"),
        (6, "o5", "table"),
    ]

    def codes(edit) -> set[str]:  # type: ignore[no-untyped-def]
        bad = copy.deepcopy(plan)
        edit([a for s in bad["steps"] for a in s["actions"]])
        return {v.code for v in validate(problem, bad, str(TABLE)).violations}

    def off_the_table(acts) -> None:  # type: ignore[no-untyped-def]
        next(a for a in acts if a.get("relay"))["place_pose"][0][3] += 1.0  # 1 m along x: beyond the edge

    def on_a_shelf(acts) -> None:  # type: ignore[no-untyped-def]
        next(a for a in acts if a.get("relay"))["region"] = "shelf"

    assert "outside-region" in codes(off_the_table)
    assert "unknown-name" in codes(on_a_shelf)
    # a slab under the table: the spots lie inside its top's box, but the objects rest on the table
    text = TABLE.read_text().replace(
        "(table :shape (box 1.41 1.34 0.05) :pose (0 0 -0.025 0))",
        "(table :shape (box 1.41 1.34 0.05) :pose (0 0 -0.025 0)) (floor :shape (box 2 2 0.02) :pose (0 0 -0.07 0))",
    )
    slab = parse_string(text, str(TABLE)).problems[0]
    # the slab changes nothing for the plan as it is, but the problem's digest
    assert {v.code for v in validate(slab, plan).violations} == {"problem-changed"}
    on_the_floor = copy.deepcopy(plan)
    for a in (a for s in on_the_floor["steps"] for a in s["actions"] if a.get("relay")):
        a["region"] = "floor"
    said = [(v.code, v.message) for v in validate(slab, on_the_floor).violations]
    assert ("outside-region", "o9 is set down on floor but does not rest on it") in said, said
    # any move may set its object down on a fixed top (an obstacle set aside on a table), and must rest on it:
    # o9's onward move, into its bin on the table, said to be onto the slab
    onward = copy.deepcopy(plan)
    next(a for s in onward["steps"] for a in s["actions"] if a["object"] == "o9" and not a.get("relay"))["region"] = (
        "floor"
    )
    said = [(v.code, v.message) for v in validate(slab, onward).violations]
    assert ("outside-region", "o9 is set down on floor but does not rest on it") in said, said
    # a fixed object that is not a box has no top: nothing lies on it
    post = parse_string(
        TABLE.read_text().replace(
            "(table :shape (box 1.41 1.34 0.05) :pose (0 0 -0.025 0))",
            "(table :shape (box 1.41 1.34 0.05) :pose (0 0 -0.025 0))"
            " (post :shape (cylinder 0.1 0.4) :pose (0.6 0.6 0.2 0))",
        ),
        str(TABLE),
    ).problems[0]
    on_post = copy.deepcopy(plan)
    next(a for s in on_post["steps"] for a in s["actions"] if a["object"] == "o9" and not a.get("relay"))["region"] = (
        "post"
    )
    codes_post = {v.code for v in validate(post, on_post).violations}
    assert "outside-region" in codes_post, codes_post
