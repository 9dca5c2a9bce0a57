"""Write the valid plans of issue 21's doctored-plan tests into tests/data/round2/.

    .venv/bin/python tests/make_round2_plans.py            # every plan below (a few minutes)
    .venv/bin/python tests/make_round2_plans.py pa5 pa10   # only these

Each plan is ``mrgc.plan`` of a shipped problem with the seed and arm motion model of :data:`PLANS`.  Before a
plan is stored its numbers are rounded to 6 decimals (1 µm, 1 µrad: far inside every tolerance of the
validator; the files stay small), its timings dropped from ``stats`` (a rerun writes the same file), and it
is checked twice:

- by ``mrgc.validate`` (it must be accepted: the planner's validator said so before the rounding);
- by tests/doctor.py's own pybullet audit (:func:`doctor.audit`), which asks what issue 21's new checks ask
  and the validator may not yet: no two links of an arm whose tree path crosses two or more chain joints
  (fingers and fixed joints do not count) closer than 0, the held object clear of every link of its holding
  arm but the fingers, every arm clear of every other arm and what it holds, moving or standing as
  validator/replay.py's execution model has them (a giver withdraws home while its taker stands at the
  exchange holding the object), at every configuration and at most 0.01 rad between checked ones.

A plan that fails either is not stored (exit 1).  The seeds, and why: the planner these files were made
with keeps each arm clear of itself and plans a giver's withdrawal before its taker moves on (as
validator/replay.py replays a plan); the planner of commit 6e003bf did neither, and none of the seeds it was
tried with gave a clean ``pa5-full`` or ``pa10``:

- ``pa5`` (default motion model: approaches, exchanges and transfers; a handover of o5 from r1 to r2 in
  step 1): seed 0 (it was clean with 6e003bf's planner too).
- ``pa5-full`` (``--motions full``, the same handover): seed 0, its least arm-to-arm distance 4.7 mm (r1's
  finger withdrawing past o5).  With 6e003bf's planner seeds 0, 2 and 5 withdrew the giver through the
  taker's o5 or hand (5.5-51 mm), seed 4 moved r1 into itself (o4 26 mm inside its panda_link1), seeds 1
  and 3 ran out of time.
- ``pa10`` (default model; r1's top pick of o3 in step 3, for class 3): seed 0.  With 6e003bf's planner
  seeds 0-3 and 5-9 moved r1 into itself in step 1 (panda_link6 43-82 mm inside panda_link0, or link5
  inside link1 or link2; seeds 7 and 9 also carried o9 10-13 mm into its panda_link1), and seed 4's place
  approach strays 5.9 mm from the grasp's approach line (the validator allows 4 mm).
- ``bo-alcove`` (carts, planar ``paths``): seed 0.
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # support.py and doctor.py, beside this script

import doctor  # noqa: E402 - importable once HERE is on the path
from support import ROOT  # noqa: E402

import mrgc  # noqa: E402

#: name -> (problem file relative to the repository, seed, arms' motion model); names as doctor.STORED
PLANS: dict[str, tuple[str, int, str]] = {
    "pa5": ("domains/packaging/pa5.mrg", 0, "configurations"),
    "pa5-full": ("domains/packaging/pa5.mrg", 0, "full"),
    "pa10": ("domains/packaging/pa10.mrg", 0, "configurations"),
    "bo-alcove": ("domains/box-moving/bo-alcove.mrg", 0, "configurations"),
}
TIME_LIMIT = 600.0
DIGITS = 6


def rounded(x: Any) -> Any:
    """``x`` with every float rounded to :data:`DIGITS` decimals (integers, strings and booleans kept)."""
    if isinstance(x, float):
        return round(x, DIGITS)
    if isinstance(x, list):
        return [rounded(v) for v in x]
    if isinstance(x, dict):
        return {k: rounded(v) for k, v in x.items()}
    return x


def make(name: str) -> bool:
    """Plan, check and store plan ``name``; whether it was stored."""
    problem, seed, motions = PLANS[name]
    result = mrgc.plan(problem, seed=seed, time_limit=TIME_LIMIT, motions=motions)
    if result.status != "solved":
        print(f"{name}: seed {seed}: {result.status}", file=sys.stderr)
        return False
    plan = rounded(json.loads(result.dumps()))
    plan["stats"] = {k: v for k, v in plan["stats"].items() if not k.endswith("seconds")}  # the same file each run
    report = mrgc.validate(problem, plan)
    if not report.ok:
        print(f"{name}: seed {seed}: rejected after rounding:", *report.lines(), sep="\n  ", file=sys.stderr)
        return False
    found = doctor.audit(plan)
    bad = {k: v for k, v in found.items() if v[0] < 0}
    summary = ", ".join(f"{k} {v[0] * 1000:.1f} mm ({v[1]})" for k, v in found.items() if math.isfinite(v[0]))
    if bad:
        print(f"{name}: seed {seed}: not physically valid: {summary}", file=sys.stderr)
        return False
    path = doctor.DATA / doctor.STORED[name][1]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(plan, separators=(",", ":")) + "\n", encoding="utf-8")
    print(f"{name}: seed {seed}, {len(plan['steps'])} steps -> {path.relative_to(ROOT)}; least {summary or '-'}")
    return True


def main(argv: list[str]) -> int:
    os.chdir(ROOT)  # the plans name their problem files relative to the repository
    names = argv or list(PLANS)
    unknown = [n for n in names if n not in PLANS]
    if unknown:
        print(f"unknown plan(s) {unknown}; known: {list(PLANS)}", file=sys.stderr)
        return 2
    stored = [make(n) for n in names]  # every one tried, even after a failure
    return 0 if all(stored) else 1


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
