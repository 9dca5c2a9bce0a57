"""The table of benchmarks/backends-skeletons.yaml for docs/benchmarks.md: per backend × encoding and
instance, the seconds to the first task skeleton and to all K (``mrgc compile`` statistics
``first_seconds`` and ``total_seconds``, read from the study's ``*.compile.json`` files), and where phase 1
came from (``facts_seconds``: the facts cache's lookup).

    python benchmarks/backends_table.py WORK   # WORK: the study's files folder (bench run's --work)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

INSTANCES = ["medium", "pa5", "pa10", "pa18-4arms", "bo8-two-doors"]
BACKENDS = ["cpsat", "mip", "smt", "pysmt"]
ENCODINGS = ["time-of-move", "paper", "disaggregated"]


def cell(path: Path) -> str:
    """``first / K`` seconds, or the status when no skeleton came."""
    if not path.is_file():
        return "not run"
    try:
        doc = json.loads(path.read_text())
    except ValueError:  # empty: the run was stopped at the study's time limit
        return "time limit"
    stats = doc.get("stats", {})
    if not doc.get("skeletons"):
        return doc.get("status", "?")
    k = len(doc["skeletons"])
    return f"{stats['first_seconds']:.2f} / {stats['total_seconds']:.2f}" + ("" if k == 5 else f" ({k})")


def main(work: str) -> None:
    runs = next(Path(work).glob("*/runs"))
    print("| backend | encoding | " + " | ".join(INSTANCES) + " |")
    print("| --- | --- | " + " | ".join("---:" for _ in INSTANCES) + " |")
    facts = []
    for backend in BACKENDS:
        for encoding in ENCODINGS:
            folder = runs / f"{backend}-{encoding}"
            cells = [cell(folder / f"{i}-s0.compile.json") for i in INSTANCES]
            print(f"| {backend} | {encoding} | " + " | ".join(cells) + " |")
            for i in INSTANCES:
                p = folder / f"{i}-s0.compile.json"
                if p.is_file() and p.stat().st_size:
                    facts.append(json.loads(p.read_text())["stats"].get("facts_seconds", 0.0))
    if facts:
        print(f"\nphase 1 per run: median {sorted(facts)[len(facts) // 2]:.3f} s, max {max(facts):.1f} s")


if __name__ == "__main__":
    main(sys.argv[1])
