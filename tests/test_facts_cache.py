"""The facts cache (planner/facts_cache.py, issue 24): phase 1 computed once per (problem content, seed,
mrgc version and code), verified on read, never storing a phase 1 cut short, bypassed by --no-cache; and
``mrgc.plan``/``mrgc.compile`` taking facts."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from support import ROOT, run_cli

import mrgc
from mrgc.planner import facts_cache
from mrgc.planner.phase1 import compute_problem_facts

SMALL = ROOT / "tests" / "golden" / "errors" / "W272.mrg"  # one arm, one object: phase 1 in about a second


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The cache on, in a folder of this test's own."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv("MRGC_NO_CACHE", raising=False)
    return tmp_path / "xdg" / "mrgc" / "facts"


def test_phase_1_is_computed_once_and_the_entry_is_verified(cache: Path) -> None:
    problem = mrgc.load_problem(SMALL)
    first = compute_problem_facts(problem)
    assert "cached" not in first.stats and first.facts
    (entry,) = cache.glob("*.json")
    again = compute_problem_facts(problem)
    assert again.facts == first.facts and again.stats["cached"] == 1.0
    assert again.stats["computed_seconds"] == first.stats["seconds"] and again.stats["seconds"] < 0.5
    # the same problem read from another file (reformatted, moved) shares the entry
    moved = cache.parent.parent / "moved.mrg"
    moved.write_text("; moved\n" + SMALL.read_text())
    assert compute_problem_facts(mrgc.load_problem(moved)).stats.get("cached") == 1.0
    # a tampered entry (a fact changed, its checksum not) is not used: removed, recomputed, stored again
    doc = json.loads(entry.read_text())
    doc["facts"][0][-1] = "r9"
    entry.write_text(json.dumps(doc))
    fresh = compute_problem_facts(problem)
    assert "cached" not in fresh.stats and fresh.facts == first.facts
    assert json.loads(entry.read_text())["sha256"] == doc["sha256"]
    entry.write_text('{"format": "mrgc-facts-cache/1", "fa')  # truncated
    assert "cached" not in compute_problem_facts(problem).stats
    # another seed is another entry
    compute_problem_facts(problem, seed=3)
    assert len(list(cache.glob("*.json"))) == 2


def test_a_phase_1_cut_short_is_never_stored(cache: Path) -> None:
    result = compute_problem_facts(mrgc.load_problem(SMALL), deadline=time.perf_counter())
    assert not result.complete and not result.facts
    assert not cache.exists() or not list(cache.glob("*.json"))


def test_no_cache_neither_reads_nor_writes(cache: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, _ = run_cli(capsys, "compile", SMALL, "--no-cache")
    assert code == 0 and not cache.exists()
    code, _, _ = run_cli(capsys, "compile", SMALL)
    assert code == 0 and len(list(cache.glob("*.json"))) == 1
    code, out, _ = run_cli(capsys, "facts", SMALL, "--no-cache", "--stats", "-o", tmp_path / "f.mrg")
    assert code == 0 and '"cached"' not in out
    code, out, _ = run_cli(capsys, "facts", SMALL, "--stats", "-o", tmp_path / "g.mrg")
    assert code == 0 and '"cached": 1.0' in out
    assert (tmp_path / "f.mrg").read_text().split("\n", 1)[1] == (tmp_path / "g.mrg").read_text().split("\n", 1)[1]


def test_the_cache_folder_follows_xdg(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert facts_cache.folder() == tmp_path / "mrgc" / "facts"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/path")  # not absolute: ignored, as the spec says
    assert facts_cache.folder() == Path.home() / ".cache" / "mrgc" / "facts"


def test_plan_and_compile_take_the_facts_given() -> None:
    """No facts given to a geometric problem: nothing is reachable, so no skeleton; phase 1 did not run."""
    plan = mrgc.plan(SMALL, facts=[], time_limit=30)
    assert plan.status == "infeasible" and plan.stats["seconds"] < 10
    assert mrgc.compile(SMALL, facts=[]).status == "infeasible"
    facts = mrgc.compute_facts(SMALL).facts
    assert mrgc.compile(SMALL, facts=facts).status == mrgc.compile(SMALL).status
