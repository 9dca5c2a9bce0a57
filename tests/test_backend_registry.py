"""The backend registry: coexistence of the solver libraries, missing-library errors, plug-in backends."""

from __future__ import annotations

import builtins
import itertools
import subprocess
import sys
from typing import Any, Sequence

import pytest
from support import ROOT

from mrgc import cli
from mrgc.backends import registry
from mrgc.backends.base import Backend, BackendInfo
from mrgc.compiler.ir import Row, SkeletonModel, Solution, SolveStatus

CHAIN3 = str(ROOT / "domains" / "symbolic" / "chain-3.mrg")


def test_all_solver_libraries_coexist_in_one_process() -> None:
    # highspy 1.15 and ortools 9.15 clash; the pinned pair must import and solve side by side
    code = """
import highspy, z3, pysmt.shortcuts
from ortools.sat.python import cp_model
h = highspy.Highs(); h.setOptionValue('output_flag', False)
h.addVar(0, 1); h.changeColCost(0, -1); h.run()
m = cp_model.CpModel(); x = m.NewBoolVar('x'); m.Maximize(x)
s = cp_model.CpSolver(); assert s.Solve(m) == cp_model.OPTIMAL
h2 = highspy.Highs(); h2.setOptionValue('output_flag', False); h2.addVar(0, 2); h2.changeColCost(0, 1); h2.run()
print(h.getSolution().col_value[0], s.Value(x), h2.getSolution().col_value[0])
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["1.0", "1", "0.0"]


@pytest.mark.parametrize(
    "backend,library", [("mip", "highspy"), ("smt", "z3"), ("pysmt", "pysmt"), ("cpsat", "ortools")]
)
def test_missing_library_is_a_one_line_error_with_exit_4(
    backend: str, library: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    real_import = builtins.__import__

    def fake_import(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == library or name.startswith(library + "."):
            raise ImportError(f"No module named '{library}'")
        return real_import(name, *args, **kwargs)

    for mod in [m for m in sys.modules if m == library or m.startswith(library + ".")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setattr(builtins, "__import__", fake_import)
    assert cli.main(["compile", CHAIN3, "--backend", backend]) == 4
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "pip install" in err and f"'{backend}'" in err


class BruteForceBackend(Backend):
    """A plug-in backend for tests: enumerates every assignment of a small model."""

    info = BackendInfo(
        name="brute", title="brute force (test plug-in)", module="itertools", distribution="mrgc", features=frozenset()
    )

    def _load(self, model: SkeletonModel) -> None:
        pass

    def _add_rows(self, rows: Sequence[Row]) -> None:
        pass

    def _solve(self, time_limit: float | None) -> Solution:
        model = self.model
        assert model is not None and len(model.vars) <= 22
        best: tuple[int, ...] | None = None
        best_obj = None
        for values in itertools.product(*[range(v.lb, v.ub + 1) for v in model.vars]):
            if model.violated(values):
                continue
            obj = model.evaluate(model.objectives[0], values) if model.objectives else 0
            if best_obj is None or obj < best_obj:
                best, best_obj = values, obj
        if best is None:
            return Solution(SolveStatus.INFEASIBLE)
        return Solution(SolveStatus.OPTIMAL, best)


class _EntryPoint:
    name = "brute"
    value = f"{__name__}:BruteForceBackend"
    group = registry.ENTRY_POINT_GROUP


def test_entry_point_plugins_are_listed_and_usable(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    sys.modules.setdefault(__name__, sys.modules[BruteForceBackend.__module__])
    monkeypatch.setattr(
        registry.importlib.metadata,
        "entry_points",
        lambda group=None: [_EntryPoint()] if group == registry.ENTRY_POINT_GROUP else [],
    )
    assert "brute" in registry.names()
    assert cli.main(["backends"]) == 0
    assert "brute" in capsys.readouterr().out
    tiny = ROOT / "tests" / "golden" / "tiny.mrg"
    assert (
        cli.main(
            [
                "compile",
                str(tiny),
                "--backend",
                "brute",
                "--encoding",
                "time-of-move",
                "--skeletons",
                "3",
                "--format",
                "json",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert '"backend": "brute"' in out and '"makespan": 1' in out


def test_unknown_backend_suggests(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["compile", CHAIN3, "--backend", "cpsta"]) == 2
    assert "error[E301]: unknown backend 'cpsta' (did you mean 'cpsat'?)" in capsys.readouterr().err
