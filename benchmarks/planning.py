"""End-to-end planning on the shipped geometric problems: time, makespan, motion cost, time per phase.

    python benchmarks/planning.py --seeds 10
    python benchmarks/planning.py --problems pa5 pa10 --seeds 10

Each run is a fresh process (cold caches) calling the planner with one seed; the table gives the success
rate (plans the validator accepts, re-checked in the child after planning), the median and max wall time of the planner (phase 1 included, interpreter start-up excluded), the
median makespan and motion cost (objects moved), and the median share of time in each phase.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROBLEMS = {p.stem: p for p in sorted((ROOT / "domains" / "packaging").glob("pa*.mrg"))
            + sorted((ROOT / "domains" / "box-moving").glob("bo*.mrg"))}

CHILD = """
import json, sys
from mrgc import __version__, parse_file
from mrgc.planner.plan import file_sha256
from mrgc.planner.search import plan_problem
from mrgc.planner.validate import validate
path, seed, limit = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
problem = parse_file(path).problem()
plan = plan_problem(problem, path, file_sha256(path), __version__, seed=seed, time_limit=limit)
valid = plan.status == "solved" and validate(problem, plan.to_json(), path).ok  # re-checked here, not trusted
print(json.dumps({"status": str(plan.status), "valid": valid, "makespan": plan.makespan, "cost": plan.motion_cost,
                  **plan.stats}))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", nargs="+", default=list(PROBLEMS))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--time-limit", type=float, default=120.0)
    args = ap.parse_args()
    print("| problem | solved | median (s) | max (s) | makespan | moved | facts % | skeletons % | grounding % |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name in args.problems:
        runs = []
        for seed in range(args.seeds):
            out = subprocess.run([sys.executable, "-c", CHILD, str(PROBLEMS[name]), str(seed), str(args.time_limit)],
                                 capture_output=True, text=True)
            if out.returncode != 0:
                print(f"{name} seed {seed}: crashed: {out.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
                continue
            runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
        ok = [r for r in runs if r["status"] == "solved" and r["valid"]]  # an invalid plan is a failure
        if any(r["status"] == "solved" and not r["valid"] for r in runs):
            print(f"{name}: a plan called solved failed validation", file=sys.stderr)
        if not ok:
            print(f"| {name} | 0/{args.seeds} | - | - | - | - | - | - | - |", flush=True)
            continue
        med = lambda key: statistics.median(r[key] for r in ok)  # noqa: E731
        share = lambda key: statistics.median(100 * r.get(key, 0) / max(r["seconds"], 1e-9) for r in ok)  # noqa: E731
        print(f"| {name} | {len(ok)}/{args.seeds} | {med('seconds'):.2f} | {max(r['seconds'] for r in ok):.2f} | "
              f"{med('makespan'):g} | {med('cost'):g} | {share('facts_seconds'):.0f} | "
              f"{share('skeleton_seconds'):.0f} | {share('grounding_seconds'):.0f} |", flush=True)


if __name__ == "__main__":
    main()
