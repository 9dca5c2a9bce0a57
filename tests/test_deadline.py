"""The time limit is a promise in grounding (issue 22): every long loop of the grounding reads the run's
deadline and stops there with a status, and a grounding the deadline cut short is discarded.

tests/data/deadline-6arms.facts.mrg is ``mrgc generate packaging --robots 6 --goals 10 --others 30 --seed 1``
with its phase-1 facts (``mrgc facts``, seed 0: 2,380 facts, about 50 CPU s), so that planning it starts
grounding at once: before this change such a grounding ran to its end before the limit was read (a 6-arm,
40-object instance returned after 458 s with ``--time-limit 300``).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from support import ROOT

from mrgc import parse_file
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.lattice import LatticePlanner
from mrgc.geometry.motion import MotionStatus, plan_joint_path
from mrgc.geometry.scene import scene_from_problem

BIG = ROOT / "tests" / "data" / "deadline-6arms.facts.mrg"
LIMIT = 20.0
#: what the process may take beyond the limit: starting Python, imports, reading the problem, writing the
#: plan, on a loaded 2-core machine
SLACK = 8.0


def test_a_large_instance_returns_within_its_time_limit(tmp_path: Path) -> None:
    out = tmp_path / "plan.json"
    t0 = time.perf_counter()
    res = subprocess.run(
        [sys.executable, "-m", "mrgc.cli", "plan", str(BIG), "--seed", "0", "--time-limit", str(LIMIT), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=10 * LIMIT,
    )
    elapsed = time.perf_counter() - t0
    assert res.returncode == 3, res.stdout + res.stderr  # the exit code of "time limit"
    assert json.loads(out.read_text())["status"] == "time limit"
    assert elapsed <= LIMIT + SLACK, f"returned after {elapsed:.1f} s with --time-limit {LIMIT:g}"


def test_queries_past_the_deadline_stop_at_once_with_a_status() -> None:
    """Placements, arm paths and the lattice search read the deadline; past it they stop, the grounder says
    it was cut, and RRT and the lattice answer TIME_LIMIT."""
    problem = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    assert g.placement("o2", "start").ok and not g.cut
    g.deadline = time.perf_counter() - 1.0
    assert not g.placement("o2", "start").ok and g.cut
    arm = g.arm("r1")
    assert g.arm_path("r1", arm.home, arm.home + 0.3).status.value == "time limit"

    def free(q: np.ndarray) -> bool:
        return bool(abs(q[0]) > 0.2 or abs(q[1]) > 0.2)

    past = time.perf_counter() - 1.0
    rrt = plan_joint_path([-1, -1], [1, 1], [-0.5, 0], [0.5, 0], free, seed=0, deadline=past)
    assert rrt.status is MotionStatus.TIME_LIMIT
    assert plan_joint_path([-1, -1], [1, 1], [-0.5, 0], [0.5, 0], free, seed=0).solved
    lattice = LatticePlanner((0.0, 1.0, 0.0, 1.0))
    occupied = np.zeros((32, lattice.nx, lattice.ny), dtype=bool)
    start, goal = np.array([0.1, 0.1, 0.0]), np.array([0.9, 0.9, 0.0])
    ok = lattice.plan(occupied, start, goal, lambda q: True, 0.01, 0.01)
    assert ok.solved
    assert (
        lattice.plan(occupied, start, goal, lambda q: True, 0.01, 0.01, deadline=past).status is MotionStatus.TIME_LIMIT
    )
