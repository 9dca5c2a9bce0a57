"""Where a search's time went, read off its ``mrgc plan -v`` log: each grounding line (``[t=...s] skeleton N
...``) classed by where it was grounded (at the root, or under a partial suffix: a node the paper's M* made)
and, at the root, by the action of its first failure (a move, a handover or a relay, its region) and how it
ended (partial: a suffix grounded, other objects to move first; fail), with the seconds from the line before
(the grounding and the skeletons made for it).

    mrgc plan big-0.mrg --seed 0 --time-limit 300 -v 2> run.log      # or benchmarks/cpu_plan.py: CPU seconds
    python benchmarks/search_log.py run.log
    python benchmarks/search_log.py --by check run-*.log     # by the check that failed, over many logs
    python benchmarks/search_log.py --by partial run-*.log   # partial groundings by their strict failure

Session 33 read the 6-arm, 40-object instance of seed 0 this way (docs/benchmarks.md, "Session 33"): more than
half of its 1,200 s went to root skeletons that found no place to park an obstacle, or to set a relay's object
down, in the crowded start region.  ``--by check`` classes each grounding instead by the check its first failure
names (``pick: robots of the step collide``, ``place by R: no inverse kinematics``; the failing action's robots
and object written R and O, the bodies named in brackets left out), or as partial or plan, over all the logs
given: session 41 read 9,172 groundings of the 6-arm runs of sessions 35-41 this way (docs/planner.md, "Where
the 6-arm runs' time goes, by failure").  The line format is :func:`mrgc.planner.search._log_line`'s
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
FAILS = re.compile(r"fails at step \d+, (?P<label>.*?): (?P<check>.*)")
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


def check(rest: str) -> str:
    """The class of one grounding line by what failed (``--by check``, see the module docstring)."""
    if rest.startswith("plan found"):
        return "plan"
    if rest.startswith("grounded"):
        return "partial"
    m = FAILS.match(rest)
    if m is None:  # a failure no step's check stands for (a refused plan): its reason
        return "fail: " + rest.removeprefix("fails at ")
    said = re.sub(r" \(as grounding \d+[^)]*\)$", "", m["check"])
    said = re.sub(r" ?\[[^]]*\]", "", said)
    words = m["label"].split()  # "R moves O to ...", "R->R hand O over ...", "R->R relay O ..."
    robots = words[0].split("->") if words else []
    acts = len(words) >= 3 and words[1] in ("moves", "hand", "relay")
    names = dict.fromkeys(robots, "R") | ({words[2]: "O"} if acts else {})
    for name, mark in names.items():
        said = re.sub(rf"(?<![\w.-]){re.escape(name)}(?![\w.-])", mark, said)
    return "fail: " + said


STRICT = re.compile(r"must move \[[^]]*\] \((?P<why>step \d+, .*)\)$")


def partial(rest: str) -> str:
    """The class of one grounding line by the strict failure a partial grounding's relaxed attempt got past
    (``--by partial``: the failure in brackets after its M*, written as :func:`check` writes failures), or
    "not partial"."""
    m = STRICT.search(rest) if rest.startswith("grounded") else None
    if m is None:
        return "not partial" if not rest.startswith("grounded") else "partial: other"
    return "partial after: " + check("fails at " + m["why"]).removeprefix("fail: ")


CLASSES = {"where": lambda under, rest: category(under, rest), "check": lambda _, rest: check(rest)}
CLASSES["partial"] = lambda _, rest: partial(rest)


def breakdown(lines: list[str], by: str = "where") -> tuple[dict[str, list[float]], int, float]:
    """Per category [groundings, seconds]; the number of grounding lines and the time of the last one.
    ``by``: "where" (:func:`category`), "check" (:func:`check`) or "partial" (:func:`partial`)."""
    table: dict[str, list[float]] = defaultdict(lambda: [0, 0.0])
    before, count = 0.0, 0
    for line in lines:
        m = LINE.match(line)
        if m is None:
            continue
        t = float(m["t"])
        row = table[CLASSES[by](m["under"] is not None, m["rest"])]
        row[0] += 1
        row[1] += t - before
        before, count = t, count + 1
    return dict(table), count, before


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log", type=Path, nargs="+", help="the stderr of `mrgc plan -v` (or benchmarks/cpu_plan.py -v)")
    ap.add_argument("--by", choices=tuple(CLASSES), default="where", help="class groundings by (default: where)")
    args = ap.parse_args(argv)
    table: dict[str, list[float]] = defaultdict(lambda: [0, 0.0])
    count, last = 0, 0.0
    for log in args.log:
        try:
            lines = log.read_text(encoding="utf-8", errors="replace").splitlines()
        except OSError as e:
            ap.error(f"{log}: {e.strerror or e}")
        one, n, end = breakdown(lines, args.by)
        if not n:
            ap.error(f"{log}: no grounding line (was the plan run with -v?)")
        for name, (k, secs) in one.items():
            table[name][0] += k
            table[name][1] += secs
        count, last = count + n, last + end
    logs = f"the last at t={last:.1f} s" if len(args.log) == 1 else f"{last:.1f} s in {len(args.log)} logs"
    out = [f"{count} groundings, {logs}", ""]
    head = {"where": "where, how, first failure", "check": "first failure", "partial": "strict failure"}[args.by]
    out += [f"| {head} | groundings | seconds | share |", "| --- | ---: | ---: | ---: |"]
    for name, (k, secs) in sorted(table.items(), key=lambda kv: (-kv[1][1], kv[0])):
        out.append(f"| {name} | {int(k)} | {secs:.1f} | {100 * secs / last if last else 0:.0f} % |")
    try:
        print("\n".join(out), flush=True)
    except BrokenPipeError:  # read by `head`: what it did not read is not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
