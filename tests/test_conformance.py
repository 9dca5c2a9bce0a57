"""The backend conformance kit (mrgc.testing.conformance) run against every registered backend, and the kit
itself checked: its constants agree with its exhaustive reference, its models tell wrong readings apart,
and it fails backends that break the contract (so a passing backend means something).
"""

from __future__ import annotations

from typing import Sequence

import pytest

from mrgc.backends.base import BackendInfo
from mrgc.backends.registry import backend_class, names
from mrgc.compiler.ir import Row, SkeletonModel, Solution, SolveStatus
from mrgc.testing import conformance as kit

BACKENDS = names()


# ---------------------------------------------------------------- every backend, every check
@pytest.mark.parametrize("check", [c for c in kit.CHECKS if c != "symbolic-fixtures"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_backend_passes_the_kit(backend: str, check: str) -> None:
    kit.CHECKS[check](backend_class(backend))


@pytest.mark.parametrize("encoding", ["paper", "disaggregated", "time-of-move"])
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("fixture", sorted(kit.fixtures()))
def test_fixture_reaches_its_expected_optimum(fixture: str, backend: str, encoding: str) -> None:
    kit.check_fixture(backend_class(backend), fixture, encoding)


def test_fixtures_are_all_found() -> None:
    found = kit.fixtures()
    assert len(found) >= 10 and "chain-3.mrg" in found and found["infeasible.mrg"][1] is None


@pytest.mark.parametrize("fixture", sorted(kit.fixtures()))
def test_fixture_expectation_agrees_with_the_brute_force_oracle(fixture: str) -> None:
    from mrgc.language.loader import parse_file
    from mrgc.testing.oracle import oracle_keys, problem_graph

    path, expected = kit.fixtures()[fixture]
    keys = oracle_keys(problem_graph(parse_file(path).problem()))
    assert (keys[0] if keys else None) == expected


# ---------------------------------------------------------------- the kit's reference agrees with its constants
@pytest.mark.parametrize("name", kit.MODELS)
def test_expected_optima_are_right(name: str) -> None:
    case = kit.MODELS[name]
    assert kit.brute_force(case.build())[:2] == (case.status, case.optimum)


def test_conditional_model_tells_negative_literals_apart() -> None:
    """Reading every negative literal as positive would change the optimum (so the kit can fail)."""
    m = kit.conditional_rows()
    flipped = SkeletonModel(
        m.vars,
        m.rows,
        [type(cr)(tuple((v, True) for v, _ in cr.when), cr.row, cr.big_m) for cr in m.cond_rows],
        objectives=m.objectives,
    )
    first_only = SkeletonModel(
        m.vars, m.rows, [type(cr)(cr.when[:1], cr.row, cr.big_m) for cr in m.cond_rows], objectives=m.objectives
    )
    best = kit.brute_force(m)[1]
    assert kit.brute_force(flipped)[1] != best
    assert kit.brute_force(first_only)[1] != best


def test_lexicographic_model_tells_weightings_apart() -> None:
    m = kit.lexicographic()
    status, lex, _ = kit.brute_force(m)
    assert status == SolveStatus.OPTIMAL and lex == (0, 8, -1)
    naive = SkeletonModel(
        m.vars, m.rows, objectives=[((m.objectives[0][0][0], 16),) + m.objectives[1] + m.objectives[2]]
    )
    _, _, arg = kit.brute_force(naive)
    assert arg and all(kit.objectives(m, v)[0] == 1 for v in arg)  # a too-small weight picks a = 1


# ---------------------------------------------------------------- the kit fails broken backends
def _broken(name: str, fault: str) -> type:
    """A registered backend's class with one fault injected into what it returns."""
    base = backend_class("cpsat")

    class Broken(base):  # type: ignore[misc, valid-type]
        info = BackendInfo(
            name, f"cpsat with {fault}", "ortools", "ortools", base.info.features, encodings=("time-of-move",)
        )

        def _solve(self, time_limit: float | None) -> Solution:
            sol: Solution = super()._solve(time_limit)
            if fault == "infeasible-as-optimal" and sol.status == SolveStatus.INFEASIBLE:
                assert self.model is not None
                return Solution(SolveStatus.OPTIMAL, tuple(v.lb for v in self.model.vars))
            if fault == "ignores-added-rows":
                return self._first if hasattr(self, "_first") else self._remember(sol)
            return sol

        def _remember(self, sol: Solution) -> Solution:
            self._first = sol
            return sol

        def _add_rows(self, rows: Sequence[Row]) -> None:
            if fault != "ignores-added-rows":
                super()._add_rows(rows)

    return Broken


@pytest.mark.parametrize(
    ("fault", "fails"),
    [
        ("infeasible-as-optimal", {"known-optima", "zero-variables"}),
        ("ignores-added-rows", {"incremental-cuts", "rows-after-solving"}),
    ],
)
def test_the_kit_fails_a_broken_backend(fault: str, fails: set[str]) -> None:
    report = kit.check_backend(
        _broken(f"broken-{fault}", fault),
        checks=[c for c in kit.CHECKS if c not in ("time-limit", "symbolic-fixtures")],
    )
    assert not report.ok
    assert fails <= set(report.failed), report.lines()
    assert all(name in kit.CHECKS for name in report.passed)


def test_a_crashing_check_is_a_failure_not_an_exception() -> None:
    class Crashing(backend_class("mip")):  # type: ignore[misc, valid-type]
        info = BackendInfo("crashing", "raises on load", "highspy", "highspy", frozenset())

        def _load(self, model: SkeletonModel) -> None:
            raise RuntimeError("no solver here")

    report = kit.check_backend(Crashing, checks=["known-optima"])
    assert report.failed == {"known-optima": "RuntimeError: no solver here"}
    assert "crashing: 0 of 1 checks passed" in report.lines()[0]
