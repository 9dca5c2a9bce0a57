"""The validator's time per plan: reading the file (limits, JSON, schema, typed actions) and replaying it.

    python benchmarks/validator.py PROBLEM.mrg PLAN.json [PROBLEM.mrg PLAN.json ...] [--repeat 3]

Plans are made beforehand with ``mrgc plan PROBLEM.mrg -o PLAN.json``.  Each pair is read and validated
``--repeat`` times in this process (the problem parsed once, outside the timing); the table gives the
median seconds of reading and of validating, the verdict, and the configurations and pybullet distance
queries the replay made.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path


def main() -> None:
    from mrgc.language.loader import parse_file
    from mrgc.planner.validate import load_plan, validate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pairs", nargs="+", help="PROBLEM.mrg PLAN.json pairs")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    if len(args.pairs) % 2:
        ap.error("give PROBLEM.mrg PLAN.json pairs")
    print("| plan | size (kB) | read (s) | validate (s) | verdict | configurations | distance queries |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for problem_path, plan_path in zip(args.pairs[::2], args.pairs[1::2]):
        problem = parse_file(problem_path).problem(None)
        reads, checks = [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            plan = load_plan(plan_path)
            t1 = time.perf_counter()
            report = validate(problem, plan, problem_path)
            t2 = time.perf_counter()
            reads.append(t1 - t0)
            checks.append(t2 - t1)
        verdict = "valid" if report.ok else f"invalid ({', '.join(sorted({v.code for v in report.violations}))})"
        size = Path(plan_path).stat().st_size / 1e3
        print(
            f"| {Path(plan_path).name} | {size:.1f} | {statistics.median(reads):.3f} | "
            f"{statistics.median(checks):.3f} | {verdict} | {report.stats.get('configurations', '-')} | "
            f"{report.stats.get('distance_queries', '-')} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
