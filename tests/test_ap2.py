"""The Ap2 baseline (planner/baselines/ap2.py): its task encoding against the skeleton oracle, a motion failure
turned into a constraint of the loaded z3 model, the scheduler's reassignment, the refusal of planar-base
robots, and a shipped packaging problem planned and validated end to end."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any, Sequence

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc import cli, parse_file
from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, build_task_graph
from mrgc.planfile.format import PlannedAction
from mrgc.planner.baselines.ap2 import Scheduler, TaskPlanner, without_relays
from mrgc.planner.outcome import Failure
from mrgc.planner.skeletons import must_move
from mrgc.testing import oracle
from mrgc.testing.strategies import SymbolicCase, symbolic_problems

SYMBOLIC = ROOT / "domains" / "symbolic"
FAR = time.perf_counter() + 10**6


def graph_of(path: Path) -> Any:
    problem = parse_file(str(path)).problem()
    return build_task_graph(FactBase.from_problem(problem, problem.init), must_move(problem))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(symbolic_problems(), st.integers(1, 3), st.integers(0, 3))
def test_a_task_plan_exists_exactly_when_the_oracle_finds_one_within_the_horizon(
    case: SymbolicCase, horizon: int, seed: int
) -> None:
    graph = without_relays(oracle.problem_graph(case.problem()))
    keys = oracle.oracle_keys(graph)
    plan = TaskPlanner(graph, seed, max_makespan=horizon).next(FAR)
    within = [k for k in keys if k[0] <= horizon]
    assert (plan is not None) == bool(within), (keys, horizon)
    if plan is not None:  # optimal: the fewest steps, then the fewest moved objects
        assert (plan.skeleton.makespan, len(plan.skeleton.moved)) == min(within)
        assert not oracle.check_skeleton(graph, plan.skeleton)


def test_a_failed_prefix_becomes_a_row_of_the_loaded_model() -> None:
    tasks = TaskPlanner(graph_of(SYMBOLIC / "medium.mrg"))
    first = tasks.next(FAR)
    assert first is not None
    solver, horizon = tasks.solver, tasks.horizon
    tasks.forbid(first.prefix(1))  # step 1 of the first plan "could not be grounded"
    second = tasks.next(FAR)
    assert second is not None and tasks.solver is solver and tasks.horizon == horizon  # added, not rebuilt
    assert second.prefix(1) != first.prefix(1)
    # the no-good holds at every later horizon too: forbid every plan of this horizon, the next one keeps it
    while tasks.horizon == horizon:
        tasks.forbid(second.prefix(len(second.steps)))
        later = tasks.next(FAR)
        assert later is not None
        second = later
    assert not set(first.prefix(1)) <= set(second.prefix(len(second.steps)))
    assert tasks.stats["nogoods"] >= 2


class _Refuses:
    """A motion layer that fails every assignment but the ones whose robots are all in ``allowed``."""

    def __init__(self, allowed: set[str]) -> None:
        self.allowed, self.asked = allowed, []  # type: ignore[var-annotated]

    def ground(
        self, actions: tuple[Action, ...], done: list[list[PlannedAction]], key: str, index: int
    ) -> list[PlannedAction] | Failure:
        self.asked.append(actions)
        if any(set(a.robots) - self.allowed for a in actions):
            return Failure(index, str(actions[0]), "place by r: no inverse kinematics")
        return [
            PlannedAction(a.obj, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp) for a in actions
        ]


def test_the_scheduler_tries_other_robots_for_the_same_actions_before_the_task_planner() -> None:
    tasks = TaskPlanner(graph_of(SYMBOLIC / "medium.mrg"))
    plan = tasks.next(FAR)
    assert plan is not None
    probe = Scheduler(tasks.graph, _Refuses(set()))
    step: Sequence[int] = next(s for s in plan.steps if probe.alternatives(s))
    own = [tasks.graph.actions[i] for i in step]
    alternatives = probe.alternatives(step)
    assert all({(b.obj, b.region) for b in alt} == {(a.obj, a.region) for a in own} for alt in alternatives)
    assert all(len({r for b in alt for r in b.robots}) == sum(len(b.robots) for b in alt) for alt in alternatives)
    usable = alternatives[-1]
    allowed = {r for b in usable for r in b.robots}
    motion = _Refuses(allowed)
    scheduler = Scheduler(tasks.graph, motion)
    got, failure = scheduler.ground(step, [], "k", 1)
    assert got is not None and failure is not None and "no inverse kinematics" in failure.check
    assert motion.asked[0] == tuple(own) and scheduler.stats["reassigned"] == 1
    assert {r for a in got for r in a.robots()} <= allowed


def test_box_moving_is_refused_in_one_line(capsys: Any) -> None:
    assert cli.main(["plan", str(ROOT / "domains" / "box-moving" / "bo-alcove.mrg"), "--planner", "ap2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "manipulators only" in err[0] and "planar-base robots" in err[0]


def test_ap2_plans_pa5_and_the_validator_accepts_it(tmp_path: Path) -> None:
    out = tmp_path / "pa5.ap2.json"
    pa5 = str(ROOT / "domains" / "packaging" / "pa5.mrg")
    assert cli.main(["plan", pa5, "--planner", "ap2", "--time-limit", "300", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["status"] == "solved" and doc["validation"]["valid"] and doc["stats"]["planner"] == "ap2"
    assert cli.main(["validate", pa5, str(out)]) == 0
    again = tmp_path / "again.json"  # the same seed, the same plan
    assert cli.main(["plan", pa5, "--planner", "ap2", "--time-limit", "300", "-o", str(again)]) == 0
    assert json.loads(again.read_text())["steps"] == doc["steps"]
