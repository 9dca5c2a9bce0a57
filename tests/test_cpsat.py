"""The ``cpsat`` backend writes CP-SAT's model message itself (backends/cpsat.py, no ``cp_model``, so no
pandas at start-up): the message must be the one ``cp_model.CpModel`` writes for the same skeleton model,
field for field, and the solves must return the same skeletons.

The reference is the backend as it was written on ``cp_model`` (``CpModel``, ``CpSolver``), kept here.
A twin backend loads, cuts and solves both side by side and compares at every step; the shipped
symbolic problems are compiled through it with every encoding, several skeletons each (so the
generator's cuts go through ``add_rows`` too), and so are random problems and hand-made corner cases.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any, ClassVar, Sequence

import pytest
from hypothesis import HealthCheck, given, settings

from mrgc.backends.cpsat import CpSatBackend, normal_form
from mrgc.compiler.ir import AtMostOne, CondRow, NoOverlap, Row, SkeletonModel, Solution, SolveStatus, Var
from mrgc.language.loader import parse_file
from mrgc.planner.skeletons import compile_problem
from mrgc.testing import conformance as kit
from mrgc.testing.strategies import SymbolicCase, symbolic_problems

ROOT = Path(__file__).resolve().parent.parent
SYMBOLIC = sorted(p for p in (ROOT / "domains" / "symbolic").glob("*.mrg") if p.name != "domain.mrg")
ENCODINGS = ["paper", "disaggregated", "time-of-move"]


class CpModelReference:
    """The skeleton model through ``cp_model`` (the backend before it wrote the message itself)."""

    def __init__(self, model: SkeletonModel, seed: int, threads: int) -> None:
        from ortools.sat.python import cp_model as cp

        self.cp, self.seed, self.threads = cp, seed, threads
        m = self.m = cp.CpModel()
        self.x = [m.NewBoolVar(v.name) if v.is_bool else m.NewIntVar(v.lb, v.ub, v.name) for v in model.vars]
        self.add_rows(model.rows)
        for cr in model.cond_rows:
            ct = self._constraint(cr.row)
            ct.OnlyEnforceIf([self.x[v] if val else self.x[v].Not() for v, val in cr.when])
        for amo in model.at_most_one:
            m.AddAtMostOne([self.x[v] for v in amo.vars])
        for no in model.no_overlap:
            intervals = [
                m.NewOptionalFixedSizeIntervalVar(self.x[s], 1, self.x[p], f"{no.name}#{i}")
                for i, (p, s) in enumerate(no.tasks)
            ]
            m.AddNoOverlap(intervals)
        if model.objectives:
            m.Minimize(sum(c * self.x[v] for v, c in model.objectives[0]))

    def _constraint(self, row: Row) -> Any:
        expr = sum(c * self.x[v] for v, c in row.terms)
        lo = row.lo if row.lo is not None else -(2**62)
        hi = row.hi if row.hi is not None else 2**62
        return self.m.AddLinearConstraint(expr, lo, hi)

    def add_rows(self, rows: Sequence[Row]) -> None:
        for row in rows:
            self._constraint(row)

    def solve(self, time_limit: float | None) -> tuple[str, tuple[int, ...]]:
        cp = self.cp
        solver = cp.CpSolver()
        solver.parameters.num_workers = max(1, int(self.threads))
        solver.parameters.random_seed = int(self.seed)
        solver.parameters.catch_sigint_signal = False
        if time_limit is not None:
            solver.parameters.max_time_in_seconds = max(0.001, float(time_limit))
        status = solver.Solve(self.m)
        values = tuple(int(solver.Value(x)) for x in self.x) if status in (cp.OPTIMAL, cp.FEASIBLE) else ()
        return solver.StatusName(status), values


class Twin(CpSatBackend):
    """The backend, with the ``cp_model`` reference loaded, cut and solved beside it and compared."""

    compared: ClassVar[list[str]] = []  # what was compared, for the tests to see that it happened

    def _load(self, model: SkeletonModel) -> None:
        super()._load(model)
        self.reference = CpModelReference(model, self.seed, self.threads)
        self._compare("load")

    def _add_rows(self, rows: Sequence[Row]) -> None:
        super()._add_rows(rows)
        if hasattr(self, "reference"):  # _load adds its rows before the reference exists
            self.reference.add_rows(rows)
            self._compare("cut")

    def _solve(self, time_limit: float | None) -> Solution:
        sol = super()._solve(time_limit)
        name, values = self.reference.solve(time_limit)
        statuses = {
            "OPTIMAL": SolveStatus.OPTIMAL,
            "FEASIBLE": SolveStatus.FEASIBLE,
            "INFEASIBLE": SolveStatus.INFEASIBLE,
            "UNKNOWN": SolveStatus.TIME_LIMIT,
        }
        expected = statuses.get(name, SolveStatus.ERROR)
        assert (sol.status, sol.values) == (expected, values), name
        Twin.compared.append("solve")
        return sol

    def _compare(self, what: str) -> None:
        assert str(self.proto) == str(self.reference.m.Proto()), what
        Twin.compared.append(what)


@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize("path", SYMBOLIC, ids=[p.name for p in SYMBOLIC])
def test_shipped_problems_give_cp_models_message_and_skeletons(path: Path, encoding: str) -> None:
    problem = parse_file(str(path)).problem()
    Twin.compared.clear()
    result = compile_problem(problem, Twin, encoding, skeletons=4)
    reference = compile_problem(problem, CpSatBackend, encoding, skeletons=4)
    assert (result.status, result.skeletons) == (reference.status, reference.skeletons)
    if result.skeletons:
        assert {"load", "solve"} <= set(Twin.compared)
    if len(result.skeletons) > 1:
        assert "cut" in Twin.compared


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=symbolic_problems(feasible=0.7))
def test_random_problems_give_cp_models_message_and_skeletons(case: SymbolicCase) -> None:
    compile_problem(case.problem(), Twin, "time-of-move", skeletons=3)


@pytest.mark.parametrize("name", kit.MODELS)
def test_conformance_models_give_cp_models_message(name: str) -> None:
    case, backend = kit.MODELS[name], Twin()
    backend.load(case.build())
    sol = backend.solve(time_limit=30)
    assert sol.status == case.status
    assert (kit.objectives(case.build(), sol.values) if sol.values else None) == case.optimum


def corner_cases() -> SkeletonModel:
    """Rows without terms (true and false), terms that cancel, a zero coefficient, a variable twice, an
    empty range, unbounded sides, negative literals, an empty variable domain."""
    b = [Var(f"b{i}", 0, 1, True) for i in range(3)]
    vars_ = [*b, Var("t", 0, 5, False), Var("u", -3, 5, False), Var("empty", 4, 2, False)]
    rows = [
        Row((), 0, 1),
        Row((), 1, 1),
        Row((), None, None),
        Row(((0, 1), (0, -1)), 1, 1),
        Row(((1, 0),), 0, 2),
        Row(((3, 2), (1, -1), (3, 3), (2, 0)), 1, None),
        Row(((4, 1),), None, None),
        Row(((3, 1),), 3, 2),
        Row(((3, -1), (4, 1)), None, 4),
    ]
    cond = [
        CondRow(((0, True), (2, False)), Row(((3, 1), (2, 2)), 0, 3)),
        CondRow(((1, False),), Row((), 1, 1)),
        CondRow((), Row(((3, 1),), 1, None)),
    ]
    return SkeletonModel(
        vars_,
        rows,
        cond,
        [AtMostOne((0, 2)), AtMostOne((1,))],
        [NoOverlap(((0, 3), (2, 4)), "no"), NoOverlap((), "none")],
        objectives=[((4, 2), (0, 1), (4, 1), (1, 0))],
    )


@pytest.mark.parametrize("objective", ["terms", "cancelled", "none", "absent"])
def test_corner_cases_give_cp_models_message(objective: str) -> None:
    model = corner_cases()
    model.objectives = {"terms": model.objectives, "cancelled": [((3, 1), (3, -1))], "none": [()], "absent": []}[
        objective
    ]
    backend = Twin()
    backend.load(model)
    assert backend.solve().status == SolveStatus.ERROR  # the empty domain makes the model invalid: the same verdict
    feasible = SkeletonModel(
        model.vars[:5],
        [model.rows[k] for k in (0, 2, 4, 5, 6, 8)],
        model.cond_rows,
        model.at_most_one,
        model.no_overlap,
        objectives=model.objectives,
    )
    backend = Twin()
    backend.load(feasible)
    assert backend.solve().status == SolveStatus.OPTIMAL
    backend.add_rows([Row(((3, 1), (4, 1)), 2, None), Row((), None, 0)])
    assert backend.solve().status == SolveStatus.OPTIMAL
    backend.add_rows([Row((), 1, None)])  # false: an empty bool_or
    assert backend.solve().status == SolveStatus.INFEASIBLE


def test_normal_form_sums_a_variable_drops_zeros_sorts() -> None:
    assert normal_form(((5, 2), (1, -1), (5, 3), (2, 0), (7, 1), (7, -1))) == ([1, 5], [-1, 5])
    assert normal_form(()) == ([], [])


def test_starting_cpsat_does_not_import_pandas_or_numpy() -> None:
    """The point of writing the message: a symbolic compile with cpsat loads neither (a fresh process)."""
    code = (
        "import sys; from mrgc.cli import main; code = main(['compile', sys.argv[1]]); "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'pandas', 'numpy', 'google'})); sys.exit(code)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, str(ROOT / "domains" / "symbolic" / "chain-3.mrg")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "optimal" in out.stdout and out.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize("order", [("cpsat", "mip", "cpsat"), ("mip", "cpsat", "mip")])
def test_cpsat_and_mip_share_a_process_in_either_order(order: tuple[str, ...]) -> None:
    """The highspy / ortools pin (docs/backends.md) still holds with cp_model_helper loaded first or second:
    both backends solve the same problem in one fresh process, to the same (makespan, objects moved) keys, and
    the backend used twice to the same skeletons both times."""
    code = (
        "import sys, mrgc; p = mrgc.parse_file(sys.argv[1]).problem(); "
        "print([[s.makespan, list(s.moved)] for b in sys.argv[2:] "
        "for s in mrgc.compile(p, backend=b, skeletons=3).skeletons])"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, str(ROOT / "domains" / "symbolic" / "medium.mrg"), *order],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    found = eval(out.stdout)  # noqa: S307 - our own printed list
    assert len(found) == 9 and found[:3] == found[6:]
    assert [(m, len(moved)) for m, moved in found[:3]] == [(m, len(moved)) for m, moved in found[3:6]]
