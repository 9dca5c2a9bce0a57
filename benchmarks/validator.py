"""The validator's time per plan: reading the file (limits, JSON, schema, typed actions) and replaying it.

    python benchmarks/validator.py PROBLEM.mrg PLAN.json [PROBLEM.mrg PLAN.json ...] [--repeat 3]
    python benchmarks/validator.py --ping-pong N PLAN.json OUT.json   # a long path to measure speed on

Plans are made beforehand with ``mrgc plan PROBLEM.mrg -o PLAN.json``.  Each pair is read and validated
``--repeat`` times in this process (the problem parsed once, outside the timing); the table gives the
median seconds of reading and of validating (CPU seconds of this process: the machine is shared), the
verdict, the checked configurations and pybullet distance queries the replay made, and the speed in
*samples per CPU second*: the plan's motions measured in samples at the validator's resolution (0.01 rad
or m between samples, the measure of its size limits and of the sampled validator before issue 21; the
``configurations`` of a validator before that), divided by the validating time.  Run the same script
with ``PYTHONPATH`` pointing at another checkout to compare commits in one run.

``--ping-pong N`` writes a copy of a plan whose first action's ``to-place`` goes back and forth N times
between its two ends (the kind of plan the issue timed: ~97,000 samples in 115 s).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path


def main() -> None:
    from mrgc.language.loader import parse_file
    from mrgc.planfile.reader import load_plan
    from mrgc.validator.validate import validate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pairs", nargs="+", help="PROBLEM.mrg PLAN.json pairs")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ping-pong", type=int, default=0, metavar="N")
    args = ap.parse_args()
    if args.ping_pong:
        ping_pong(args.pairs[0], args.pairs[1], args.ping_pong)
        return
    if len(args.pairs) % 2:
        ap.error("give PROBLEM.mrg PLAN.json pairs")
    print(
        "| plan | size (kB) | read (s) | validate (CPU s) | verdict | configurations | distance queries | samples / s |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for problem_path, plan_path in zip(args.pairs[::2], args.pairs[1::2]):
        problem = parse_file(problem_path).problem(None)
        reads, checks = [], []
        for _ in range(args.repeat):
            t0 = time.process_time()
            plan = load_plan(plan_path)
            t1 = time.process_time()
            report = validate(problem, plan, problem_path)
            t2 = time.process_time()
            reads.append(t1 - t0)
            checks.append(t2 - t1)
        verdict = "valid" if report.ok else f"invalid ({', '.join(sorted({v.code for v in report.violations}))})"
        size = Path(plan_path).stat().st_size / 1e3
        samples = report.stats.get("resolution_samples", report.stats.get("configurations", 0))
        check = statistics.median(checks)
        print(
            f"| {Path(plan_path).name} | {size:.1f} | {statistics.median(reads):.3f} | "
            f"{check:.3f} | {verdict} | {report.stats.get('configurations', '-')} | "
            f"{report.stats.get('distance_queries', '-')} | {samples / max(check, 1e-9):,.0f} |",
            flush=True,
        )


def ping_pong(plan_path: str, out: str, n: int) -> None:
    """Write ``out``: the plan with its first action's ``to-place`` going back and forth ``n`` times."""
    import json

    doc = json.loads(Path(plan_path).read_text(encoding="utf-8"))
    a = doc["steps"][0]["actions"][0]
    start = a["configs"]["handover"][1] if a["kind"] == "handover" else a["configs"]["pick"][-1]
    end = a["configs"]["place"][0]
    a["paths"]["to-place"] = [start] + [end if k % 2 == 0 else start for k in range(n | 1)]
    Path(out).write_text(json.dumps(doc), encoding="utf-8")


if __name__ == "__main__":
    main()
