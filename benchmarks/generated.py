"""Planning on generated instances nobody tuned: success, validity and the reason of every failure.

    python benchmarks/generated.py --packaging 60 --box-moving 20 --seeds 0 1 --time-limit 120 \
        --out benchmarks/results/generated.jsonl
    python benchmarks/generated.py --report benchmarks/results/generated.jsonl

Instance i of each family is generated with `mrgc generate` from parameters derived from i alone
(packaging: 2-4 arms, 3-5 goals, 2-13 others; box-moving: 2 carts, 2 goals, 2-6 others; generator seed
1000 + i, or --seed-base + i: layouts nobody looked at for the same parameters; --first skips the first
instances), so the suite is reproducible.  Each run is a fresh `mrgc plan --seed S --time-limit T`
process (with --cpu-time, through benchmarks/cpu_plan.py: the limit in CPU seconds of that process, so two
trees compared on a loaded machine are not compared by its load); a plan it calls solved is then checked by
a separate `mrgc validate` process.  Every finished
run is appended to the JSONL file at once, and a rerun skips the runs already there (an interrupted study
loses nothing it finished).  The report counts the outcomes by category: solved and valid, solved but
INVALID (must be 0), infeasible by the facts (with the reason), every skeleton tried, time limit, crash.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path


def instances(packaging: int, box_moving: int, seed_base: int = 1000, first: int = 0) -> list[tuple[str, list[str]]]:
    """(name, `mrgc generate` arguments), the two families interleaved so a partial run samples both:
    instances ``first`` to ``first + n - 1`` of each family, generator seed ``seed_base + i`` (another base
    draws other layouts for the same parameters; their names end in ``-g<generator seed>``)."""
    tag = (lambda i: "") if seed_base == 1000 else (lambda i: f"-g{seed_base + i}")
    pa = []
    for i in range(first, first + packaging):
        robots, goals, others = 2 + i % 3, 3 + (i // 3) % 3, 2 + (7 * i) % 12
        pa.append(
            (
                f"pa-r{robots}-g{goals}-o{others}-i{i}{tag(i)}",
                [
                    "packaging",
                    "--robots",
                    str(robots),
                    "--goals",
                    str(goals),
                    "--others",
                    str(others),
                    "--seed",
                    str(seed_base + i),
                ],
            )
        )
    bo = []
    for i in range(first, first + box_moving):
        others = 2 + i % 5
        bo.append(
            (
                f"bo-r2-g2-o{others}-i{i}{tag(i)}",
                ["box-moving", "--robots", "2", "--goals", "2", "--others", str(others), "--seed", str(seed_base + i)],
            )
        )
    out: list[tuple[str, list[str]]] = []
    ratio = max(1, round(len(pa) / max(1, len(bo))))
    while pa or bo:
        out += pa[:ratio] + bo[:1]
        pa, bo = pa[ratio:], bo[1:]
    return out


#: `mrgc plan` with its clock in CPU seconds (--cpu-time)
CPU_PLAN = Path(__file__).with_name("cpu_plan.py")


def mrgc(*args: str, timeout: float, cpu: bool = False) -> subprocess.CompletedProcess[str]:
    """Run an `mrgc` command; with ``cpu``, `mrgc plan` (args without the command) through CPU_PLAN."""
    command = [str(CPU_PLAN)] if cpu else ["-m", "mrgc.cli"]
    return subprocess.run([sys.executable, *command, *args], capture_output=True, text=True, timeout=timeout)


def run_one(name: str, gen: list[str], seed: int, limit: float, work: Path, cpu: bool = False) -> dict[str, object]:
    src, plan = work / f"{name}.mrg", work / f"{name}-s{seed}.plan.json"
    if not src.exists():
        made = mrgc("generate", *gen, "-o", str(src), timeout=120)
        if made.returncode != 0:
            return {"outcome": "generator error", "detail": made.stderr.strip()[-300:]}
    t0 = time.perf_counter()
    try:
        args = (str(src), "--seed", str(seed), "--time-limit", str(limit), "-o", str(plan))
        proc = mrgc(*args, timeout=limit * 6 + 300, cpu=True) if cpu else mrgc("plan", *args, timeout=limit * 3 + 300)
    except subprocess.TimeoutExpired:
        return {"outcome": "crash", "detail": "plan process hung past 3x its time limit"}
    wall = time.perf_counter() - t0
    if not plan.exists():
        return {
            "outcome": "crash",
            "exit": proc.returncode,
            "seconds": round(wall, 2),
            "detail": proc.stderr.strip()[-300:],
        }
    data = json.loads(plan.read_text(encoding="utf-8"))
    row: dict[str, object] = {
        "exit": proc.returncode,
        "status": data["status"],
        "seconds": round(wall, 2),
        "planner_seconds": data["stats"].get("seconds"),  # CPU seconds with --cpu-time
        "clock": "cpu" if cpu else "wall",
        "facts_seconds": data["stats"].get("facts_seconds"),
        "makespan": data["makespan"],
        "moved": data["motion_cost"],
        "why": data.get("why", {}),
    }
    if data["status"] == "solved":
        check = mrgc("validate", str(src), str(plan), timeout=600)
        row["valid"] = check.returncode == 0
        row["outcome"] = "solved, valid" if check.returncode == 0 else "solved but INVALID"
        if check.returncode != 0:
            row["detail"] = check.stdout.strip()[-500:]
    else:
        row["outcome"] = str(data["status"])
    return row


def category(row: dict[str, object]) -> str:
    """The outcome, with the kind of reason for infeasible runs."""
    out = str(row["outcome"])
    why = row.get("why") or {}
    assert isinstance(why, dict)
    if out == "infeasible":
        facts = " ".join(why.get("facts", []))
        if "blocking cycle" in facts or why.get("cycles"):  # cycles told with evidence are not in facts
            return "infeasible: blocking cycle"
        if "no order of moves" in facts:
            return "infeasible: objects wait for each other (no order of moves)"
        if "no robot can reach" in facts:
            return "infeasible: a goal region out of reach"
        if "no robot can pick" in facts:
            return "infeasible: an object nobody can pick"
        if "can also place it" in facts:
            return "infeasible: no robot or handover takes a goal object from its pick to its bin"
        if "obstructed by an object no robot can move" in facts:
            return "infeasible: obstructed by an object nobody can move"
        if "no robot can place" in facts:
            return "infeasible: a goal object fits its bin for nobody"
        return "infeasible: other"
    if out in ("time limit", "exhausted"):
        failures = why.get("grounding_failures") or []
        if failures:  # the most frequent grounding failure names the kind
            return f"{out}: mostly {failure_kind(failures[0])}"
    return out


def failure_kind(failure: dict[str, object]) -> str:
    """A grounding failure without its names (robots, objects, regions, points): its kind, to count."""
    check = re.sub(r" by r\d+| at h\d+| of o\d+ in [\w-]+", "", str(failure.get("check", "")))
    if str(failure.get("action", "")).startswith("validator"):
        return "the validator rejected the plan"
    if str(failure.get("detail", "")).startswith("another robot of the step"):
        return f"{check} (robots of one step)"
    return check


def report(path: Path) -> None:
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
    for family in ("pa", "bo"):
        mine = [r for r in rows if r["instance"].startswith(family)]
        if not mine:
            continue
        cats = Counter(category(r) for r in mine)
        solved = [r for r in mine if r["outcome"] == "solved, valid"]
        cpu = any(r.get("clock") == "cpu" for r in mine)  # then the planner's CPU seconds
        secs = sorted(float(r["planner_seconds"] if cpu else r["seconds"]) for r in solved)
        med = secs[len(secs) // 2] if secs else float("nan")
        print(
            f"\n{'packaging' if family == 'pa' else 'box-moving'}: {len(mine)} runs "
            f"({len({r['instance'] for r in mine})} instances), solved and valid {len(solved)} "
            f"({100 * len(solved) / len(mine):.0f} %), median {'CPU' if cpu else 'wall'} time of those {med:.1f} s\n"
        )
        print("| outcome | runs |\n| --- | --- |")
        for cat, n in sorted(cats.items(), key=lambda kv: -kv[1]):
            print(f"| {cat} | {n} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--packaging", type=int, default=60)
    ap.add_argument("--box-moving", type=int, default=20)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--first", type=int, default=0, help="index of the first instance of each family (default 0)")
    ap.add_argument(
        "--seed-base", type=int, default=1000, help="generator seed of instance i is this + i (default 1000)"
    )
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument(
        "--cpu-time",
        action="store_true",
        help="the time limit in CPU seconds of each plan process (benchmarks/cpu_plan.py), not wall-clock ones",
    )
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results/generated.jsonl"))
    ap.add_argument("--work", type=Path, default=None, help="folder for instances and plans (default: a temp dir)")
    ap.add_argument("--report", type=Path, default=None, help="only print the tables of a results file")
    args = ap.parse_args()
    if args.report:
        report(args.report)
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    done = set()
    if args.out.exists():
        done = {(r["instance"], r["seed"]) for r in map(json.loads, args.out.read_text().splitlines()) if r}
    work = args.work or Path(tempfile.mkdtemp(prefix="mrgc-generated-"))
    work.mkdir(parents=True, exist_ok=True)
    for name, gen in instances(args.packaging, args.box_moving, args.seed_base, args.first):
        for seed in args.seeds:
            if (name, seed) in done:
                continue
            row = {
                "instance": name,
                "generate": "mrgc generate " + " ".join(gen),
                "seed": seed,
                "time_limit": args.time_limit,
                **run_one(name, gen, seed, args.time_limit, work, args.cpu_time),
            }
            with open(args.out, "a", encoding="utf-8") as fh:
                fh.write(json.dumps(row) + "\n")
                fh.flush()
                os.fsync(fh.fileno())
            print(f"{name} seed {seed}: {category(row)} ({row.get('seconds', '-')} s)", flush=True)
    report(args.out)


if __name__ == "__main__":
    main()
