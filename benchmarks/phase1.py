"""Phase 1 (geometric facts) on the packaging benchmark scenes, and the cost of one configuration check.

    python benchmarks/phase1.py --repeat 5
    python benchmarks/phase1.py --cpu pa10 --seeds 0 1 2 3 4 5 --repeat 7

Each repeat runs in a fresh process (no warm IK cache, robot models loaded from scratch), timing
``compute_facts`` with its default worker count (one process per robot, at most one per core).  The
configuration check is one Panda configuration (all its link hulls) against the PA10 scene (table and
10 boxes), amortised over 2,000 random configurations.

``--cpu PRESET``: the CPU seconds of phase 1 on the suite's generated instances (``mrgc generate packaging
--preset PRESET --seed S``), in this process and one worker (``compute_facts(scene, workers=1)``: what the
robots' workers spend together), the robot models built first, the IK cache cleared before each repeat; the
median and the minimum of the repeats after the first.  CPU seconds on a shared machine grow with the other
cores' load: compare two trees in one sitting, alternately.
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


def phase1_cpu(name: str, seed: int, repeat: int) -> tuple[float, float, int]:
    """Median and minimum CPU seconds of phase 1 (one worker) on instance ``seed`` of preset ``name``, and its
    fact count."""
    from mrgc import parse_string
    from mrgc.generate import preset
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.ik import clear_ik_cache
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.predicates import compute_facts
    from mrgc.geometry.scene import scene_from_problem

    text = preset(name, seed)
    scene = scene_from_problem(parse_string(text, f"{name}-s{seed}.mrg", str(ROOT / "domains" / "packaging")).problem())
    for spec in scene.robots:
        if approaches(spec.kind):
            _ = Arm(spec).hulls  # the models and their hulls, built once per process as a plan builds them
    times, facts = [], 0
    for _ in range(repeat + 1):
        clear_ik_cache()
        t0 = time.process_time()
        facts = len(compute_facts(scene, seed=0, workers=1).facts)
        times.append(time.process_time() - t0)
    return statistics.median(times[1:]), min(times[1:]), facts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    from mrgc.generate import PRESETS

    ap.add_argument("--cpu", metavar="PRESET", choices=sorted(PRESETS), help="phase 1's CPU on a preset's instances")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4, 5])
    args = ap.parse_args()
    if args.cpu:
        print("| instance | facts | phase 1 CPU median (s) | min (s) |")
        print("| --- | ---: | ---: | ---: |")
        for seed in args.seeds:
            med, low, facts = phase1_cpu(args.cpu, seed, args.repeat)
            print(f"| {args.cpu}-s{seed} | {facts} | {med:.3f} | {low:.3f} |", flush=True)
        return
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
