"""Where a search's time went, read off its ``mrgc plan -v`` log: each grounding line (``[t=...s] skeleton N
...``) classed by where it was grounded (at the root, or under a partial suffix: a node the paper's M* made)
and, at the root, by the action of its first failure (a move, a handover or a relay, its region) and how it
ended (partial: a suffix grounded, other objects to move first; fail), with the seconds from the line before
(the grounding and the skeletons made for it).

    mrgc plan big-0.mrg --seed 0 --time-limit 300 -v 2> run.log      # or benchmarks/cpu_plan.py: CPU seconds
    python benchmarks/search_log.py run.log

Session 33 read the 6-arm, 40-object instance of seed 0 this way (docs/benchmarks.md, "Session 33"): more than
half of its 1,200 s went to root skeletons that found no place to park an obstacle, or to set a relay's object
down, in the crowded start region.  The line format is :func:`mrgc.planner.search._log_line`'s
(tests/test_benchmark_scripts.py writes its lines with that function).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections import defaultdict
from pathlib import Path

LINE = re.compile(
    r"\[t=(?P<t>[\d.]+)s\] skeleton \d+ \(makespan \d+, moves \d+"
    r"(?P<under>, under a suffix of \d+ steps?)?\): (?P<rest>.*)"
)
ACTION = re.compile(r"step \d+, \S+ (?P<kind>moves|hand|relay) \S+ (?:over )?to (?P<region>\S+)(?: via (?P<via>\S+))?")
KINDS = {"moves": "move", "hand": "handover", "relay": "relay"}


def category(under: bool, rest: str) -> str:
    """The class of one grounding line (see the module docstring)."""
    if rest.startswith("plan found"):
        return "plan"
    if under:
        return "under a partial suffix"
    ended = "partial" if rest.startswith("grounded") else "fail"
    m = ACTION.search(rest)
    if m is None:
        return f"root, {ended}, other"
    where = f"via {m['via']}" if m["via"] else m["region"]
    return f"root, {ended}, {KINDS[m['kind']]} {where}"


def breakdown(lines: list[str]) -> tuple[dict[str, list[float]], int, float]:
    """Per category [groundings, seconds]; the number of grounding lines and the time of the last one."""
    table: dict[str, list[float]] = defaultdict(lambda: [0, 0.0])
    before, count = 0.0, 0
    for line in lines:
        m = LINE.match(line)
        if m is None:
            continue
        t = float(m["t"])
        row = table[category(m["under"] is not None, m["rest"])]
        row[0] += 1
        row[1] += t - before
        before, count = t, count + 1
    return dict(table), count, before


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log", type=Path, help="the stderr of `mrgc plan -v` (or benchmarks/cpu_plan.py -v)")
    args = ap.parse_args(argv)
    try:
        lines = args.log.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as e:
        ap.error(f"{args.log}: {e.strerror or e}")
    table, count, last = breakdown(lines)
    if not count:
        ap.error(f"{args.log}: no grounding line (was the plan run with -v?)")
    out = [f"{count} groundings, the last at t={last:.1f} s", ""]
    out += ["| where, how, first failure | groundings | seconds | share |", "| --- | ---: | ---: | ---: |"]
    for name, (n, secs) in sorted(table.items(), key=lambda kv: (-kv[1][1], kv[0])):
        out.append(f"| {name} | {int(n)} | {secs:.1f} | {100 * secs / last if last else 0:.0f} % |")
    try:
        print("\n".join(out), flush=True)
    except BrokenPipeError:  # read by `head`: what it did not read is not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
