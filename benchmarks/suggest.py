"""Time "did you mean" on a problem full of misspelt names (issue 9: it was quadratic).

    python benchmarks/suggest.py --names 1000 5000

For each N it writes a symbolic problem with N movable objects whose ``:init`` names every object once
with one character changed (so every fact is an E211 error carrying a suggestion), and times
``parse_string`` (parse, check, and N suggestions).  It prints N, the seconds, and how many suggestions
name the intended object.
"""

from __future__ import annotations

import argparse
import random
import re
import time

from mrgc import parse_string
from mrgc.errors import InputError


def generate(n: int, seed: int = 0) -> tuple[str, list[str]]:
    """A problem with ``n`` objects ``obj-<k>-<word>`` and ``n`` misspelt references; the intended names."""
    rng = random.Random(seed)
    words = ["box", "cup", "can", "jar", "tin", "mug", "pot", "bag"]
    objs = [f"obj-{k}-{rng.choice(words)}" for k in range(n)]
    wrong = []
    for o in objs:
        i = rng.randrange(len(o))
        c = rng.choice([ch for ch in "abcdefghijklmnopqrstuvwxyz" if ch != o[i]])
        wrong.append(o[:i] + c + o[i + 1 :])
    lines = [
        "(define (domain d) (:grasps top))",
        "(define (problem p) (:domain d)",
        "  (:robots r1)",
        f"  (:movable {' '.join(objs)})",
        "  (:regions a b)",
        "  (:init",
    ]
    lines += [f"    (in-region {o} a)" for o in objs]
    lines += [f"    (reachable-pick {w} top r1)" for w in wrong]
    lines += ["  )", f"  (:goal (in-region {objs[0]} b)))"]
    return "\n".join(lines) + "\n", objs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--names", type=int, nargs="+", default=[1000, 5000])
    args = ap.parse_args()
    for n in args.names:
        text, objs = generate(n)
        t0 = time.perf_counter()
        try:
            parse_string(text, "misspelt.mrg")
            raise SystemExit("expected errors")
        except InputError as exc:
            seconds = time.perf_counter() - t0
            hints = [re.search(r"did you mean '([^']+)'", d.message) for d in exc.diagnostics]
        good = sum(1 for h, o in zip(hints, objs) if h is not None and h.group(1) == o)
        print(
            f"names={n} seconds={seconds:.2f} errors={len(hints)} suggestions={sum(h is not None for h in hints)} "
            f"intended={good}"
        )


if __name__ == "__main__":
    main()
