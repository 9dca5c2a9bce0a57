"""The time limit covers phase 1: worker processes cut at a deadline leave nothing running, and a planner
whose limit passes during phase 1 says so (status ``time limit``, no facts kept)."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import pytest

from mrgc import api
from mrgc.geometry.predicates import compute_facts
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.loader import parse_file
from mrgc.planner.outcome import PlanStatus
from mrgc.workers import map_in_workers, map_until

ROOT = Path(__file__).resolve().parent.parent
PA10 = ROOT / "domains" / "packaging" / "pa10.mrg"


def _square_after(args: tuple[int, float]) -> tuple[int, int]:
    x, pause = args
    time.sleep(pause)
    return x, x * x


def test_map_until_answers_like_map_in_workers_when_the_jobs_end_in_time() -> None:
    jobs = [(x, 0.0) for x in range(5)]
    assert map_until(_square_after, jobs, 2, 60.0) == map_in_workers(_square_after, jobs, 2)
    assert map_until(_square_after, [], 2, 0.0) == []


def test_map_until_kills_every_worker_when_the_time_passes() -> None:
    before = {p.pid for p in multiprocessing.active_children()}
    t0 = time.monotonic()
    assert map_until(_square_after, [(1, 0.0), (2, 30.0), (3, 30.0)], 2, 0.5) is None
    assert time.monotonic() - t0 < 20  # not the 30 s the jobs wanted
    left = [p for p in multiprocessing.active_children() if p.pid not in before]
    assert not left, f"workers left running: {left}"


def test_a_deadline_cuts_phase_1_and_keeps_no_fact() -> None:
    scene = scene_from_problem(parse_file(str(PA10)).problem())
    cut = compute_facts(scene, deadline=time.perf_counter() + 0.05)
    assert not cut.complete and cut.facts == []
    whole = compute_facts(scene, workers=1)
    assert whole.complete and whole.facts
    assert compute_facts(scene, deadline=time.perf_counter() + 600).facts == whole.facts  # the cut decides nothing


@pytest.mark.parametrize("planner", ["mcts", "ap1"])
def test_a_planner_whose_limit_passes_in_phase_1_says_so(planner: str) -> None:
    # 50 ms: far below PA10's phase 1 even in a process that has its robot models and hulls already (0.3 s
    # was not, once phase 1's workers stopped loading pybullet: the search then ran out of time instead)
    t0 = time.monotonic()
    plan = api.plan(PA10, planner=planner, time_limit=0.05)
    assert plan.status == PlanStatus.TIME_LIMIT and not plan.steps
    assert plan.why is not None and "phase 1" in plan.why.summary
    assert plan.stats["facts"] == 0 and plan.stats["seconds"] >= 0.05
    assert time.monotonic() - t0 < 30
