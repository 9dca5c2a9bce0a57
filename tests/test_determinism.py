"""Same seed, same plan, on an idle and on a loaded machine: no wall-clock budget decides a result.

``mrgc plan`` runs in a child process twice per problem, the second time while sibling processes burn every
core; the plans' ``steps`` must be byte-identical.  Motion planning counts validity checks instead of
seconds (geometry/motion.py), so a slower machine only makes the same search take longer.  The problems
are small on purpose (a few seconds each): a box-moving room whose only box must be driven through a
doorway (SE(2) paths planned by phase 1 and by grounding) and the shipped two-arm packaging problem.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT

# two rooms (4 × 3 m) joined by a 0.8 m doorway at x = 0: (sx, sy, x, y) of each wall
WALLS = [
    (4.2, 0.1, 0, -1.55),
    (4.2, 0.1, 0, 1.55),
    (0.1, 3.2, -2.05, 0),
    (0.1, 3.2, 2.05, 0),
    (0.1, 1.1, 0, -0.95),
    (0.1, 1.1, 0, 0.95),
]
DOORWAY = f"""
(define (problem bo-through-the-door)
  (:domain box-moving)
  (:robots (r1 :kind mover :base (-1.2 0.8 0 0)))
  (:fixed {
    " ".join(f"(wall{i} :shape (box {sx} {sy} 0.5) :pose ({x} {y} 0.25 0))" for i, (sx, sy, x, y) in enumerate(WALLS))
})
  (:regions
    (start :shape (box 2 3 0.5) :pose (-1 0 0.25 0))
    (goal :shape (box 1.6 2 0.5) :pose (1 0 0.25 0)))
  (:movable (g1 :shape (box 0.3 0.3 0.3) :pose (-1.2 -0.6 0.15 0)))
  (:goal (in-region g1 goal)))
"""

BURN = "while True:\n    pass\n"


def plan_steps(problem: Path, seed: int, out: Path) -> str:
    """The ``steps`` of ``mrgc plan problem --seed seed``, as canonical JSON text."""
    run = subprocess.run(
        [sys.executable, "-m", "mrgc.cli", "plan", str(problem), "--seed", str(seed), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, (run.returncode, run.stdout[-2000:], run.stderr[-2000:])
    plan = json.loads(out.read_text())
    assert plan["status"] == "solved" and plan["steps"], plan.get("why")
    return json.dumps(plan["steps"], sort_keys=True)


def loaded(n: int) -> list[subprocess.Popen[bytes]]:
    """``n`` sibling processes spinning on the CPU."""
    return [subprocess.Popen([sys.executable, "-c", BURN]) for _ in range(n)]


@pytest.fixture(scope="module")
def problems(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("determinism")
    shutil.copy(ROOT / "domains" / "box-moving" / "domain.mrg", folder / "domain.mrg")
    doorway = folder / "bo-through-the-door.mrg"
    doorway.write_text(DOORWAY)
    return {"box-moving": doorway, "packaging": ROOT / "domains" / "packaging" / "pa-basic.mrg"}


@pytest.mark.parametrize("name, seed", [("box-moving", 3), ("packaging", 1)])
def test_same_seed_same_steps_under_load(problems: dict[str, Path], tmp_path: Path, name: str, seed: int) -> None:
    idle = plan_steps(problems[name], seed, tmp_path / "idle.json")
    burners = loaded(os.cpu_count() or 2)
    try:
        busy = plan_steps(problems[name], seed, tmp_path / "busy.json")
    finally:
        for p in burners:
            p.kill()
        for p in burners:
            p.wait()
    assert busy == idle
