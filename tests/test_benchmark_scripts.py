"""The benchmark scripts take what a study needs: ``benchmarks/planning.py --problems`` names shipped
problems or paths of .mrg files (a file of one's own, a generated one)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from support import ROOT

SCRIPT = ROOT / "benchmarks" / "planning.py"


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def test_planning_takes_paths_of_mrg_files(tmp_path: Path) -> None:
    own = tmp_path / "mine.mrg"
    own.write_text(
        (ROOT / "domains" / "symbolic" / "domain.mrg").read_text(encoding="utf-8")
        + "\n"
        + (ROOT / "domains" / "symbolic" / "chain-3.mrg").read_text(encoding="utf-8"),
        encoding="utf-8",
    )
    out = run(
        "--problems",
        "mine.mrg",
        str(ROOT / "domains" / "symbolic" / "handover.mrg"),
        "--seeds",
        "1",
        "--time-limit",
        "30",
        cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    rows = [line.split(" | ") for line in out.stdout.splitlines()[2:]]
    assert [(r[0], r[1]) for r in rows] == [("| mine", "1/1"), ("| handover", "1/1")], out.stdout
    assert rows[0][4] == "1" and rows[1][4] == "3"  # makespans of chain-3 and handover


def test_planning_refuses_what_is_neither_a_name_nor_a_file(tmp_path: Path) -> None:
    for item, why in (("missing.mrg", "no such file"), ("pa55", "not a shipped problem or a .mrg file")):
        out = run("--problems", "pa5", item, cwd=tmp_path)
        assert out.returncode == 2 and out.stdout == ""
        assert out.stderr.startswith(f"planning.py: error: --problems {item}: {why} (shipped: pa-basic")
