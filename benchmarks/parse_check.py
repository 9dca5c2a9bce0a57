"""Time parse + check of a generated large symbolic problem (issue: language front end).

    python benchmarks/parse_check.py --objects 1000 --repeat 7

Prints the size of the generated file and the median / min wall time of ``mrgc.parse_string`` over the
repeats (each repeat parses and checks from text; the LALR table is built once per process, before timing).
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from mrgc import parse_string


def generate(n_objects: int, n_robots: int = 4, seed: int = 0) -> str:
    """A symbolic problem with ``n_objects`` movable objects and a realistic density of facts."""
    rng = random.Random(seed)
    robots = [f"r{i + 1}" for i in range(n_robots)]
    objs = [f"o{i + 1}" for i in range(n_objects)]
    regions = ["start", "bin-a", "bin-b", "bin-c"]
    grasps = ["top", "side-x+", "side-x-", "side-y+", "side-y-"]
    goals = objs[: max(1, n_objects // 10)]
    lines = [
        f"(define (domain gen) (:grasps {' '.join(grasps)}))",
        "",
        "(define (problem gen-%d)" % n_objects,
        "  (:domain gen)",
        f"  (:robots {' '.join(robots)})",
        f"  (:movable {' '.join(objs)})",
        f"  (:regions {' '.join(regions)})",
        "  (:init",
    ]
    for o in objs:
        lines.append(f"    (in-region {o} start)")
        for r in rng.sample(robots, 2):
            g = rng.choice(grasps)
            lines.append(f"    (reachable-pick {o} {g} {r})")
            lines.append(f"    (reachable-place {o} {rng.choice(regions)} {g} {r})")
            if rng.random() < 0.5:
                lines.append(f"    (occludes-pick {rng.choice(objs)} {o} {g} {r})")
    for o in goals:
        r1, r2 = rng.sample(robots, 2)
        lines.append(f"    (enable-goal-handover {o} top side-x+ {r1} {r2})")
        lines.append(f"    (occludes-goal-place {rng.choice(objs)} {o} bin-a top {r1})")
    lines.append("  )")
    lines.append("  (:goal (and " + " ".join(f"(in-region {o} bin-a)" for o in goals) + ")))")
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--objects", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    text = generate(args.objects)
    parse_string(text, "gen.mrg")  # warm-up: builds the LALR parser once
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        mf = parse_string(text, "gen.mrg")
        times.append(time.perf_counter() - t0)
    p = mf.problem()
    print(f"objects={len(p.movable)} facts={len(p.init)} bytes={len(text)} lines={text.count(chr(10))}")
    print(f"parse+check: median {statistics.median(times):.3f} s, min {min(times):.3f} s over {args.repeat} runs")


if __name__ == "__main__":
    main()
