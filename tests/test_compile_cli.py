"""``mrgc compile`` and ``mrgc backends`` through cli.main: output contract, exit codes, model export.

Golden exports of chain-3 live in tests/golden/exports/; regenerate them with MRGC_UPDATE_GOLDEN=1.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
from pathlib import Path
from typing import Any

import pytest
from support import ROOT
from support import run_cli as run

from mrgc import cli

SYMBOLIC = ROOT / "domains" / "symbolic"
CHAIN3 = str(SYMBOLIC / "chain-3.mrg")
INFEASIBLE = str(SYMBOLIC / "infeasible.mrg")
GOLDEN = Path(__file__).resolve().parent / "golden" / "exports"
BACKENDS = ["mip", "smt", "pysmt", "cpsat"]
STEP_KEYS = {"object", "region", "pick_robot", "place_robot", "pick_grasp", "place_grasp"}

# chain-3's three feasible action sets, as documented in the fixture
A1 = ("o1", "goal", "r1", "r1", "top", "top")
A2 = ("o1", "goal", "r2", "r2", "side", "side")
A3 = ("o1", "goal", "r1", "r2", "top", "side")
B = ("o2", "start", "r1", "r1", "top", "top")
C = ("o3", "start", "r2", "r2", "side", "side")


def compile_json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict[str, Any]]:
    code, out, err = run(capsys, "compile", *argv, "--format", "json")
    return code, json.loads(out)


def action_sets(doc: dict[str, Any]) -> list[frozenset[tuple[str, ...]]]:
    return [
        frozenset(
            (a["object"], a["region"], a["pick_robot"], a["place_robot"], a["pick_grasp"], a["place_grasp"])
            for step in sk["steps"]
            for a in step
        )
        for sk in doc["skeletons"]
    ]


# ---------------------------------------------------------------- text output
def test_text_output_of_chain3(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "compile", CHAIN3)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].startswith(
        "problem chain-3: backend cpsat, encoding time-of-move: optimal, 1 skeleton "
        "(3 objects, 5 actions in the task graph, "
    )
    assert lines[1:] == ["skeleton 1: makespan 1, moves 1 (o1)", "  step 1: r2 moves o1 to goal (side)"]


def test_text_output_lists_several_skeletons_with_handover_steps(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "compile", CHAIN3, "--skeletons", "3", "--backend", "mip", "--encoding", "paper")
    assert code == 0
    assert "optimal, 3 skeletons" in out.splitlines()[0]
    assert "skeleton 2: makespan 2, moves 2 (o2 o1)" in out
    assert "  step 1: r1 moves o2 to start (top)\n  step 2: r1->r2 moves o1 to goal (top->side)" in out
    assert "skeleton 3: makespan 2, moves 3 (" in out


def test_text_output_of_an_infeasible_problem(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "compile", INFEASIBLE)
    assert code == 1
    assert "infeasible, 0 skeletons" in out.splitlines()[0]
    assert "  reason: every action moving o1 is obstructed by an object no robot can move: o2" in out


# ---------------------------------------------------------------- JSON output
@pytest.mark.parametrize("backend", BACKENDS)
def test_json_contract(backend: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = compile_json(capsys, CHAIN3, "--skeletons", "3", "--backend", backend)
    assert code == 0
    assert {"problem", "backend", "encoding", "status", "skeletons", "stats"} <= set(doc)
    assert (doc["problem"], doc["backend"], doc["encoding"], doc["status"]) == (
        "chain-3",
        backend,
        "time-of-move",
        "optimal",
    )
    assert isinstance(doc["stats"], dict) and doc["stats"]["objects"] == 3 and doc["stats"]["actions"] == 5
    sks = doc["skeletons"]
    assert [(s["makespan"], len(s["moved"])) for s in sks] == [(1, 1), (2, 2), (2, 3)]
    for s in sks:
        assert set(s) >= {"makespan", "moved", "steps"}
        assert len(s["steps"]) == s["makespan"] and all(s["steps"])
        assert sorted(a["object"] for step in s["steps"] for a in step) == sorted(s["moved"])
        for step in s["steps"]:
            for a in step:
                assert set(a) == STEP_KEYS and all(isinstance(v, str) for v in a.values())
    assert action_sets(doc) == [frozenset({A2}), frozenset({B, A3}), frozenset({B, C, A1})]
    # the order of steps: o2 (pick obstacle) strictly before o1; o3 (place obstacle) no later than o1
    third = {a["object"]: t for t, step in enumerate(sks[2]["steps"]) for a in step}
    assert third["o2"] < third["o1"] and third["o3"] <= third["o1"]


def test_json_of_an_infeasible_problem(capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = compile_json(capsys, INFEASIBLE, "--backend", "smt", "--encoding", "paper")
    assert code == 1
    assert doc["status"] == "infeasible" and doc["skeletons"] == []
    assert doc["stats"]["must_move"] == ["o1"]


def test_json_asks_for_more_skeletons_than_exist(capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = compile_json(capsys, CHAIN3, "--skeletons", "10", "--backend", "pysmt", "--encoding", "disaggregated")
    assert code == 0 and doc["status"] == "optimal" and len(doc["skeletons"]) == 3


# ---------------------------------------------------------------- input errors: exit code 2
def test_unknown_backend_is_E301(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "compile", CHAIN3, "--backend", "gurobi")
    assert code == 2 and out == ""
    assert "error[E301]: unknown backend 'gurobi'" in err and "mip, smt, pysmt, cpsat" in err


def test_unknown_encoding_is_E303(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "compile", CHAIN3, "--encoding", "big-m")
    assert code == 2 and out == ""
    assert "error[E303]" in err, err
    assert "paper" in err and "disaggregated" in err and "time-of-move" in err


@pytest.mark.parametrize(("backend", "ext"), [("mip", "smt2"), ("smt", "lp"), ("cpsat", "mps"), ("pysmt", "lp")])
def test_emit_with_a_wrong_extension_is_E300(
    backend: str, ext: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / f"model.{ext}"
    code, out, err = run(capsys, "compile", CHAIN3, "--backend", backend, "--emit", str(target))
    assert code == 2
    assert f"error[E300]: backend '{backend}' cannot write .{ext} files" in err
    assert not target.exists()


GEOMETRIC = """(define (domain packaging)
  (:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand")
  (:grasps top side-x+))
(define (problem geo1)
  (:domain packaging)
  (:robots (r1 :kind panda :base (0 -0.6 0 90)))
  (:fixed (table :shape (box 1.2 0.8 0.05) :pose (0 0 -0.025 0)))
  (:regions
    (start :shape (box 0.4 0.4 0.3) :pose (0 0 0.15 0))
    (bin-a :shape (box 0.2 0.2 0.15) :pose (0.45 -0.3 0.075 0)))
  (:movable (o1 :shape (box 0.05 0.05 0.1) :pose (0.05 0 0.05 0)))
  (:goal (in-region o1 bin-a)))
"""


def test_geometric_problem_without_facts_gets_them_from_phase_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """(Formerly E310; since b81418d compile runs phase 1 itself.)  The :init is empty, so a skeleton and a
    non-empty task graph can only come from facts computed by the geometry layer."""
    path = tmp_path / "geo.mrg"
    path.write_text(GEOMETRIC, encoding="utf-8")
    assert cli.main(["check", str(path)]) == 0
    assert "(geometric: 1 robot, 1 movable, 2 regions, 1 goal, 0 facts)" in capsys.readouterr().out
    code, doc = compile_json(capsys, str(path))
    assert code == 0, doc
    assert doc["status"] == "optimal" and doc["stats"]["actions"] >= 1
    assert doc["stats"]["facts"] >= 3  # in-region, reachable-pick, reachable-place at least
    assert doc["skeletons"][0]["steps"][0][0]["object"] == "o1"
    assert doc["skeletons"][0]["steps"][0][0]["region"] == "bin-a"


def test_bad_skeleton_count_and_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "compile", CHAIN3, "--skeletons", "0")
    assert code == 2 and "error[E000]" in err
    code, _, err = run(capsys, "compile", str(tmp_path / "missing.mrg"))
    assert code == 2 and "error[E001]" in err


# ---------------------------------------------------------------- --emit
EMITS = [
    ("mip", "paper", "lp"),
    ("mip", "time-of-move", "mps"),
    ("smt", "disaggregated", "smt2"),
    ("cpsat", "paper", "pbtxt"),
]
# (lines that must occur, substrings that must occur) per format
MARKERS = {
    "lp": (["min", "st", "bin", "end"], []),
    "mps": (["ROWS", "COLUMNS", "RHS", "ENDATA"], []),
    "smt2": (["(check-sat)"], ["(declare-fun", "(minimize", "(assert"]),
    "pbtxt": ([], ["variables {", "constraints {", "objective {"]),
}


@pytest.mark.parametrize(("backend", "encoding", "ext"), EMITS)
def test_emit_writes_a_model_file(
    backend: str, encoding: str, ext: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / f"chain-3.{ext}"
    code, out, err = run(capsys, "compile", CHAIN3, "--backend", backend, "--encoding", encoding, "--emit", str(target))
    assert code == 0, err
    assert out.splitlines()[-1].startswith(f"model written to {target} (horizon ")
    text = target.read_text(encoding="utf-8")
    assert text.strip()
    lines, parts = MARKERS[ext]
    stripped = {line.strip() for line in text.splitlines()}
    for marker in lines:
        assert marker in stripped, (marker, text[:300])
    for marker in parts:
        assert marker in text, (marker, text[:300])
    assert "o1" in text  # readable variable names, not c0, c1, ...


def test_emit_with_json_keeps_stdout_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "m.smt2"
    code, doc = compile_json(capsys, INFEASIBLE, "--backend", "smt", "--emit", str(target))
    assert code == 1 and doc["status"] == "infeasible"
    assert target.stat().st_size > 0


@pytest.mark.parametrize(("backend", "encoding", "ext"), EMITS)
def test_emit_is_deterministic(
    backend: str, encoding: str, ext: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first, second = tmp_path / f"a.{ext}", tmp_path / f"b.{ext}"
    for target in (first, second):
        assert cli.main(["compile", CHAIN3, "--backend", backend, "--encoding", encoding, "--emit", str(target)]) == 0
    capsys.readouterr()
    assert first.read_bytes() == second.read_bytes()


GOLDENS = [
    ("paper", "lp", "mip"),
    ("paper", "mps", "mip"),
    ("disaggregated", "lp", "mip"),
    ("time-of-move", "smt2", "smt"),
]


@pytest.mark.parametrize(("encoding", "ext", "backend"), GOLDENS)
def test_golden_export_of_chain3(
    encoding: str, ext: str, backend: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    golden = GOLDEN / f"chain-3.{encoding}.{ext}"
    target = tmp_path / golden.name
    assert cli.main(["compile", CHAIN3, "--backend", backend, "--encoding", encoding, "--emit", str(target)]) == 0
    capsys.readouterr()
    data = target.read_bytes()
    assert data.strip()
    if os.environ.get("MRGC_UPDATE_GOLDEN") == "1":
        golden.parent.mkdir(parents=True, exist_ok=True)
        golden.write_bytes(data)
    assert golden.exists(), f"{golden} is missing: run the tests once with MRGC_UPDATE_GOLDEN=1"
    assert data == golden.read_bytes(), f"{golden.name} changed; if intended, regenerate with MRGC_UPDATE_GOLDEN=1"


# ---------------------------------------------------------------- mrgc backends
def _version(dist: str) -> str:
    return importlib.metadata.version(dist)


EXPECTED_LIBRARIES = {"mip": "highspy", "smt": "z3-solver", "pysmt": "PySMT", "cpsat": "ortools"}


def test_backends_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "backends")
    assert code == 0
    lines = out.splitlines()
    for name, dist in EXPECTED_LIBRARIES.items():
        line = next(line for line in lines if line.split()[:1] == [name])
        assert f"installed ({dist} {_version(dist)})" in line, line
        assert "encodings: paper, disaggregated, time-of-move" in line
    assert any(line.startswith("backend") and "conditional rows" in line for line in lines)  # the feature table


def test_backends_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "backends", "--format", "json")
    assert code == 0
    rows = {r["name"]: r for r in json.loads(out)}
    assert set(EXPECTED_LIBRARIES) <= set(rows)
    for name, dist in EXPECTED_LIBRARIES.items():
        r = rows[name]
        assert r["installed"] is True
        assert r["library"] == dist and r["version"] == _version(dist) and r["version"] != "-"
        assert r["encodings"] == ["paper", "disaggregated", "time-of-move"]
    assert rows["mip"]["exports"] == ["lp", "mps"] and rows["smt"]["exports"] == ["smt2"]
    assert rows["cpsat"]["exports"] == ["pbtxt"] and rows["pysmt"]["exports"] == []


def test_options_that_would_be_ignored_are_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """--horizon without --emit, graph --backend without --skeleton: they did nothing, silently."""
    src = str(Path(__file__).resolve().parent.parent / "domains" / "symbolic" / "medium.mrg")
    assert cli.main(["compile", src, "--horizon", "3"]) == 2
    assert "--horizon is the horizon of the model --emit writes" in capsys.readouterr().err
    assert cli.main(["graph", src, "-o", str(tmp_path / "g.dot"), "--backend", "smt"]) == 2
    assert "give --skeleton" in capsys.readouterr().err and not (tmp_path / "g.dot").exists()
