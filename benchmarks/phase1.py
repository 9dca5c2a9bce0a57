"""Phase 1 (geometric facts) on the packaging benchmark scenes, and the cost of one configuration check.

    python benchmarks/phase1.py --repeat 5

Each repeat runs in a fresh process (no warm IK cache, robot models loaded from scratch), timing
``compute_facts`` with its default worker count (one process per robot, at most one per core).  The
configuration check is one Panda configuration (all its link hulls) against the PA10 scene (table and
10 boxes), amortised over 2,000 random configurations.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ["pa3-handover", "pa5", "pa10", "pa18-4arms"]

CHILD = """
import json, sys, time
t0 = time.perf_counter()
from mrgc import parse_file
from mrgc.geometry.predicates import compute_facts
from mrgc.geometry.scene import scene_from_problem
problem = parse_file(sys.argv[1]).problem()
t1 = time.perf_counter()
result = compute_facts(scene_from_problem(problem))
t2 = time.perf_counter()
print(json.dumps({"facts_seconds": t2 - t1, "with_imports": t2 - t0, **result.stats}))
"""


def phase1(name: str, repeat: int) -> dict[str, float]:
    runs = []
    for _ in range(repeat):
        out = subprocess.run(
            [sys.executable, "-c", CHILD, str(ROOT / "domains" / "packaging" / f"{name}.mrg")],
            capture_output=True,
            text=True,
            check=True,
        )
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    return {
        "median": statistics.median(r["facts_seconds"] for r in runs),
        "min": min(r["facts_seconds"] for r in runs),
        "with_imports": statistics.median(r["with_imports"] for r in runs),
        "facts": runs[0]["facts"],
        "ik_solves": runs[0]["ik_solves"],
        "workers": runs[0]["workers"],
    }


def config_check(n: int = 2000) -> float:
    import numpy as np

    from mrgc import parse_file
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.collision import scene_world
    from mrgc.geometry.scene import scene_from_problem

    scene = scene_from_problem(parse_file(ROOT / "domains" / "packaging" / "pa10.mrg").problem())
    arm, world = Arm(scene.robots[0]), scene_world(scene)
    shapes, _ = arm.probes
    rng = np.random.default_rng(0)
    qs = rng.uniform(arm.model.lower, arm.model.upper, size=(n, arm.model.dof))
    transforms = arm.link_transforms(qs)  # batched FK, as the predicates use it
    world.batch_collides(shapes, transforms[0])
    t0 = time.perf_counter()
    for t in transforms:
        world.batch_collides(shapes, t)
    check = (time.perf_counter() - t0) / n
    t0 = time.perf_counter()
    for q in qs[:200]:
        world.batch_collides(shapes, arm.link_transforms(q))
    with_fk = (time.perf_counter() - t0) / 200
    return check, with_fk


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    args = ap.parse_args()
    print(
        "| scene | robots | objects | facts | IK solves | workers | phase 1 median (s) | min (s) | incl. imports (s) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name in args.scenes:
        r = phase1(name, args.repeat)
        from mrgc import parse_file

        p = parse_file(ROOT / "domains" / "packaging" / f"{name}.mrg").problem()
        print(
            f"| {name} | {len(p.robots)} | {len(p.movable)} | {r['facts']:.0f} | {r['ik_solves']:.0f} | "
            f"{r['workers']:.0f} | {r['median']:.2f} | {r['min']:.2f} | {r['with_imports']:.2f} |",
            flush=True,
        )
    check, with_fk = config_check()
    print()
    print(
        f"one Panda configuration vs the PA10 scene: {check * 1e6:.1f} µs (FK batched), "
        f"{with_fk * 1e6:.1f} µs with single-configuration FK"
    )


if __name__ == "__main__":
    main()
