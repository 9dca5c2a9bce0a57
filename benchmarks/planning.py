"""End-to-end planning on the shipped geometric problems: time, makespan, motion cost, time per phase.

    python benchmarks/planning.py --seeds 10
    python benchmarks/planning.py --problems pa5 pa10 --seeds 10
    python benchmarks/planning.py --problems some/file.mrg other.mrg --seeds 3

``--problems`` takes the names of shipped problems (the stems of domains/packaging/pa*.mrg and
domains/box-moving/bo*.mrg) or paths of .mrg files (each holding one problem, symbolic or geometric).

Each run is a fresh process (cold caches) calling the planner with one seed; the table gives the success
rate (plans the validator accepts, re-checked in the child after planning), the median and max wall time
of the planner (phase 1 included, interpreter start-up excluded), the median makespan and motion cost
(objects moved), and the median share of time in each phase.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROBLEMS = {
    p.stem: p
    for p in sorted((ROOT / "domains" / "packaging").glob("pa*.mrg"))
    + sorted((ROOT / "domains" / "box-moving").glob("bo*.mrg"))
}

CHILD = """
import json, sys
import mrgc
path, seed, limit = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
plan = mrgc.plan(path, seed=seed, time_limit=limit)
valid = plan.status == "solved" and mrgc.validate(path, plan).ok  # re-checked here, not trusted
print(json.dumps({"status": str(plan.status), "valid": valid, "makespan": plan.makespan, "cost": plan.motion_cost,
                  **plan.stats}))
"""


def problem_path(item: str) -> Path:
    """A shipped problem's file by name, or the .mrg file ``item`` names; a one-line error (exit 2) else."""
    if item in PROBLEMS:
        return PROBLEMS[item]
    path = Path(item)
    if path.suffix == ".mrg" and path.is_file():
        return path
    what = "no such file" if path.suffix == ".mrg" else "not a shipped problem or a .mrg file"
    print(f"planning.py: error: --problems {item}: {what} (shipped: {', '.join(PROBLEMS)})", file=sys.stderr)
    raise SystemExit(2)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", nargs="+", default=list(PROBLEMS))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--time-limit", type=float, default=120.0)
    args = ap.parse_args()
    paths = [problem_path(item) for item in args.problems]  # every one checked before the first run
    print("| problem | solved | median (s) | max (s) | makespan | moved | facts % | skeletons % | grounding % |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for path in paths:
        name = path.stem
        runs = []
        for seed in range(args.seeds):
            out = subprocess.run(
                [sys.executable, "-c", CHILD, str(path), str(seed), str(args.time_limit)],
                capture_output=True,
                text=True,
            )
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
        med = lambda key, ok=ok: statistics.median(r[key] for r in ok)  # noqa: E731
        share = lambda key, ok=ok: statistics.median(  # noqa: E731
            100 * r.get(key, 0) / max(r["seconds"], 1e-9) for r in ok
        )
        print(
            f"| {name} | {len(ok)}/{args.seeds} | {med('seconds'):.2f} | {max(r['seconds'] for r in ok):.2f} | "
            f"{med('makespan'):g} | {med('cost'):g} | {share('facts_seconds'):.0f} | "
            f"{share('skeleton_seconds'):.0f} | {share('grounding_seconds'):.0f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
