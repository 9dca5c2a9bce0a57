"""The Ap1 baseline (planner/baselines/ap1.py) and the planner registry behind ``mrgc plan --planner``.

Geometric: Ap1 solves a shipped packaging problem whose goal place is obstructed, and ``mrgc validate``
accepts the plan it writes.  Symbolic: on random small problems Ap1's answer agrees with the brute-force
oracle of mrgc.testing.oracle (a plan exactly when some action set has a schedule), every plan moves
each object at most once and is accepted by the validator, and the same seed gives the same plan.
Statuses: infeasible (with the facts' reason), exhausted (the search ran to its end), time limit.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc import cli, parse_file, parse_string
from mrgc.language.model import Problem
from mrgc.planner.baselines import PLANNERS, plan_with
from mrgc.planner.outcome import PlanStatus
from mrgc.planner.plan import Plan
from mrgc.testing import oracle
from mrgc.validator.validate import validate

SYMBOLIC = ROOT / "domains" / "symbolic"
PLACE_OBSTACLE = ROOT / "domains" / "packaging" / "pa3-place-obstacle.mrg"


def ap1(problem: Problem, seed: int = 0, time_limit: float = 20.0) -> Plan:
    """Ap1 through the registry, on a problem that need not come from a file."""
    return plan_with("ap1", problem, "<string>", "0" * 64, "test", seed=seed, time_limit=time_limit)


def moved(plan: dict[str, Any]) -> list[str]:
    return [a["object"] for step in plan["steps"] for a in step["actions"]]


# ---------------------------------------------------------------- geometric
def test_ap1_solves_a_packaging_problem_and_mrgc_validate_accepts_its_plan(tmp_path: Path) -> None:
    out = tmp_path / "plan.json"
    assert cli.main(["plan", str(PLACE_OBSTACLE), "--planner", "ap1", "--time-limit", "60", "-o", str(out)]) == 0
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert doc["status"] == "solved" and doc["validation"]["valid"] and doc["stats"]["planner"] == "ap1"
    objects = moved(doc)
    assert "o1" in objects and len(objects) == len(set(objects))  # the goal moves, nothing moves twice
    assert all(a.get("place_pose") and a.get("configs") for step in doc["steps"] for a in step["actions"])
    assert cli.main(["validate", str(PLACE_OBSTACLE), str(out)]) == 0


def test_ap1_plans_full_motions_like_the_planner(tmp_path: Path) -> None:
    out = tmp_path / "plan.json"
    assert (
        cli.main(
            ["plan", str(PLACE_OBSTACLE), "--planner", "ap1", "--motions", "full", "--time-limit", "60", "-o", str(out)]
        )
        == 0
    )
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert doc["motion_model"]["arms"] == "full" and all(
        {"to-pick", "to-place", "home"} <= set(a["paths"]) for step in doc["steps"] for a in step["actions"]
    )
    assert cli.main(["validate", str(PLACE_OBSTACLE), str(out)]) == 0


def test_a_time_limit_is_a_status_with_its_reason(capsys: Any) -> None:
    assert cli.main(["plan", str(PLACE_OBSTACLE), "--planner", "ap1", "--time-limit", "0.001"]) == 3
    doc = json.loads(capsys.readouterr().out.split("\nplan for")[0])
    assert doc["status"] == "time limit" and "time limit" in doc["why"]["summary"] and not doc["steps"]


# ---------------------------------------------------------------- symbolic, shipped
def test_ap1_on_a_symbolic_problem_is_valid_and_deterministic() -> None:
    problem = parse_file(str(SYMBOLIC / "medium.mrg")).problem()
    first, again = ap1(problem, seed=3), ap1(problem, seed=3)
    assert first.status is PlanStatus.SOLVED and first.validation and first.validation["valid"]
    doc = first.to_json()
    assert validate(problem, doc).ok
    assert len(moved(doc)) == len(set(moved(doc))) and {"g1", "g2", "g3", "g4"} <= set(moved(doc))
    assert [[a.to_json() for a in s] for s in first.steps] == [[a.to_json() for a in s] for s in again.steps]


def test_ap1_moves_mutual_place_obstacles_in_one_step() -> None:
    plan = ap1(parse_file(str(SYMBOLIC / "mutual-place.mrg")).problem())
    assert plan.status is PlanStatus.SOLVED and [sorted(a.object for a in s) for s in plan.steps] == [["o1", "o2"]]


def test_infeasible_problems_say_why(capsys: Any) -> None:
    assert cli.main(["plan", str(SYMBOLIC / "infeasible.mrg"), "--planner", "ap1"]) == 1
    doc = json.loads(capsys.readouterr().out.split("\nplan for")[0])
    assert doc["status"] == "infeasible" and any("o2" in r for r in doc["why"]["facts"]), doc["why"]
    plan = ap1(parse_file(str(SYMBOLIC / "pick-cycle.mrg")).problem())
    assert plan.status is PlanStatus.INFEASIBLE and plan.why and "blocking cycle" in " ".join(plan.why.facts)


def test_a_search_run_to_its_end_is_exhausted() -> None:
    # each goal is in the way of placing the other, so both must move in one step; only r1 can move either
    text = (
        DOMAIN + "(define (problem one-arm) (:domain abstract) (:robots r1 r2) (:movable a b) (:regions x y)\n"
        "(:init (in-region a x) (in-region b y) (reachable-pick a top r1) (reachable-place a y top r1)\n"
        "  (reachable-pick b top r1) (reachable-place b x top r1)\n"
        "  (occludes-goal-place b a y top r1) (occludes-goal-place a b x top r1))\n"
        "(:goal (and (in-region a y) (in-region b x))))\n"
    )
    plan = ap1(parse_string(text).problem())
    assert plan.status is PlanStatus.EXHAUSTED and plan.why and "to its end" in plan.why.summary
    assert plan.why.failures  # the failed steps are told
    # numbered from the end, and the summary says so (issue 24)
    assert all(f.step < 0 for f in plan.why.failures)
    assert plan.why.summary.endswith("Ap1 numbers steps from the end (step -1: the plan's last, -2: the one before)")


# ---------------------------------------------------------------- symbolic, random
DOMAIN = "(define (domain abstract) (:requirements :handover :symbolic) (:grasps top side))\n"


@st.composite
def obstacle_problems(draw: Any) -> str:
    """A random symbolic problem: objects in a row of regions, some to be moved to another region, each
    object reachable by random robots and grasps, random obstructions of picks and of goal places."""
    robots = [f"r{k}" for k in range(1, draw(st.integers(1, 3)) + 1)]
    names = [f"m{k}" for k in range(1, draw(st.integers(2, 5)) + 1)]
    regions = ("left", "mid", "right")
    at = {o: draw(st.sampled_from(regions)) for o in names}
    goals = draw(st.lists(st.sampled_from(names), min_size=1, max_size=3, unique=True))
    goal = {o: draw(st.sampled_from([r for r in regions if r != at[o]])) for o in goals}
    lines = [f"(in-region {o} {at[o]})" for o in names]
    for o in names:
        for r in robots:
            for g in draw(st.sets(st.sampled_from(["top", "side"]), max_size=2)):
                lines.append(f"(reachable-pick {o} {g} {r})")
                if draw(st.integers(0, 3)):
                    lines.append(f"(reachable-place {o} {goal.get(o, at[o])} {g} {r})")
    pairs = [(a, b) for a in names for b in names if a != b]
    for a, b in draw(st.lists(st.sampled_from(pairs), max_size=6)):
        lines.append(
            f"(occludes-pick {a} {b} {draw(st.sampled_from(['top', 'side']))} {draw(st.sampled_from(robots))})"
        )
    for a, b in draw(st.lists(st.sampled_from([p for p in pairs if p[1] in goal]), max_size=3)):
        lines.append(
            f"(occludes-goal-place {a} {b} {goal[b]} {draw(st.sampled_from(['top', 'side']))} "
            f"{draw(st.sampled_from(robots))})"
        )
    if len(robots) > 1:
        for o in goals:
            if draw(st.booleans()):
                lines.append(f"(enable-goal-handover {o} top side {robots[0]} {robots[-1]})")
    return (
        DOMAIN + f"(define (problem random) (:domain abstract) (:robots {' '.join(robots)})\n"
        f"  (:movable {' '.join(names)}) (:regions {' '.join(regions)})\n"
        f"  (:init {' '.join(dict.fromkeys(lines))})\n"
        f"  (:goal (and {' '.join(f'(in-region {o} {r})' for o, r in goal.items())})))\n"
    )


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(obstacle_problems(), st.integers(0, 3))
def test_ap1_agrees_with_the_oracle_and_moves_each_object_once(text: str, seed: int) -> None:
    problem = parse_string(text).problem()
    plan = ap1(problem, seed=seed)
    region = {f.args[0]: f.args[1] for f in problem.init if f.predicate == "in-region"}
    must = [o for o, r in problem.goal_regions.items() if region[o] != r]
    graph = oracle.reference_task_graph(
        [r.name for r in problem.robots],
        {m.name: ("top", "side") for m in problem.movable},
        problem.goal_regions,
        region,
        [(f.predicate, *f.args) for f in problem.init],
        must,
        (),
    )
    feasible = bool(oracle.feasible_action_sets(graph))
    event(f"{plan.status}")
    assert plan.status in (PlanStatus.SOLVED, PlanStatus.INFEASIBLE, PlanStatus.EXHAUSTED), plan.why
    assert (plan.status is PlanStatus.SOLVED) == feasible, (plan.status, plan.why and plan.why.lines())
    if plan.status is PlanStatus.SOLVED:
        doc = plan.to_json()
        assert len(moved(doc)) == len(set(moved(doc)))
        assert validate(problem, doc).ok
        assert set(must) <= set(moved(doc))


# ---------------------------------------------------------------- the registry on the command line
def test_planner_names_and_options_are_checked(capsys: Any) -> None:
    assert set(PLANNERS) == {"mcts", "ap1", "ap2"}
    medium = str(SYMBOLIC / "medium.mrg")
    assert cli.main(["plan", medium, "--planner", "ap9"]) == 2
    assert cli.main(["plan", medium, "--planner", "ap1", "--anytime"]) == 2
    assert cli.main(["plan", medium, "--planner", "ap1", "--backend", "mip"]) == 2
    err = capsys.readouterr().err
    assert "unknown planner 'ap9'" in err and "--anytime is not an option of the ap1 planner" in err
    assert "Traceback" not in err
    assert cli.main(["plan", medium, "--planner", "mcts"]) == 0
