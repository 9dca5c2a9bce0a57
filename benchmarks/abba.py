"""Two source trees compared on the same instances, each instance planned A, B, B, A (CPU seconds).

    python benchmarks/abba.py --a /tmp/before --b /tmp/after --out /tmp/ab FILE.mrg ... [-- PLAN OPTIONS]

``--a`` and ``--b`` are folders holding a copy of the package as ``mrgc/`` (``git archive REV | tar -x -C
DIR/mrgc``); each run is ``benchmarks/cpu_plan.py FILE --seed 0 --time-limit 120`` (plus the options after
``--``) in a fresh process with that folder first on ``PYTHONPATH`` and ``MRGC_NO_CACHE=1``, its CPU the
process's and its workers' (``os.wait4``).  Why A, B, B, A: on this machine the second of two runs of one
instance in a row is a few per cent faster (the files it reads are in the page cache, the CPU's caches
warm), so a comparison that always runs B second favours B by about 3 % (docs/benchmarks.md, "Session 28").
Each tree's time on an instance is the mean of its two runs; the report gives, per instance set (the file
name up to its first ``-``), both medians and the median and mean of the per-instance ratios B / A, and
whether each instance's four plans have the same steps (a run that wrote no plan counts as a difference).
The runs' logs, plans and times go to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

CPU_PLAN = Path(__file__).resolve().parent / "cpu_plan.py"


def run(tree: str, problem: str, out: Path, options: list[str]) -> tuple[float, list[object] | None]:
    """One planning run of ``problem`` with ``tree``'s package: (CPU seconds, the plan's steps or None)."""
    plan = out.with_suffix(".json")
    env = {**os.environ, "PYTHONPATH": tree, "MRGC_NO_CACHE": "1"}
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # the trees keep their compiled modules between runs
    cmd = [sys.executable, str(CPU_PLAN), problem, "--seed", "0", "--time-limit", "120", *options, "-o", str(plan)]
    with open(out.with_suffix(".log"), "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, cwd="/tmp")
        _, _, usage = os.wait4(proc.pid, 0)
    cpu = usage.ru_utime + usage.ru_stime
    steps = json.loads(plan.read_text())["steps"] if plan.exists() else None
    return cpu, steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--a", required=True)
    parser.add_argument("--b", required=True)
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("files", nargs="+")
    argv = sys.argv[1:]
    options = argv[argv.index("--") + 1 :] if "--" in argv else []
    args = parser.parse_args(argv[: argv.index("--")] if "--" in argv else argv)
    args.out.mkdir(parents=True, exist_ok=True)
    sets: dict[str, list[tuple[float, float, bool]]] = defaultdict(list)
    for problem in args.files:
        name = Path(problem).stem
        times: dict[str, list[float]] = {"a": [], "b": []}
        plans = []
        for k, side in enumerate("abba"):
            cpu, steps = run(getattr(args, side), problem, args.out / f"{name}-{k}{side}", options)
            times[side].append(cpu)
            plans.append(None if steps is None else json.dumps(steps, sort_keys=True))
            missing = "" if steps is not None else " (no plan file: see its log)"
            print(f"{name} {side} {cpu:.3f}{missing}", flush=True)
        a, b = statistics.mean(times["a"]), statistics.mean(times["b"])
        sets[name.split("-")[0]].append((a, b, None not in plans and len(set(plans)) == 1))
    for key, rows in sets.items():
        ratios = [b / a for a, b, _ in rows]
        print(
            f"{key}: {len(rows)} instances, median CPU A {statistics.median(a for a, _, _ in rows):.3f} s, "
            f"B {statistics.median(b for _, b, _ in rows):.3f} s; B / A median {statistics.median(ratios):.3f}, "
            f"mean {statistics.mean(ratios):.3f}; same plans on {sum(same for *_, same in rows)}"
        )


if __name__ == "__main__":
    main()
