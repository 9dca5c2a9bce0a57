"""``cpsat``: the skeleton model in OR-Tools CP-SAT.  The only module importing ortools.

The model is written straight into CP-SAT's model message (``CpModelProto``, OR-Tools'
``cp_model.proto``) through ``ortools.sat.python.cp_model_helper``, the native module under OR-Tools'
Python API, and solved by its ``SolveWrapper``.  ``cp_model.CpModel`` and ``CpSolver`` are thin Python
layers over the same two objects, but ``cp_model`` imports pandas and numpy when it loads (0.3 s of
every start-up, docs/benchmarks.md); written the way ``cp_model`` writes it, the message is the same
field for field (tests/test_cpsat.py compares the two on every shipped symbolic problem), so the solver
sees the same model and returns the same skeletons.

Rows are ``linear`` constraints (the terms of a variable summed, zero coefficients dropped, variables in
index order: ``cp_model``'s normal form); conditional rows carry ``enforcement_literal`` (a conjunction of
literals, ``-v - 1`` for "v is false"); at-most-one is ``at_most_one``; the unit tasks of a no-overlap
are optional fixed-size ``interval`` constraints under one ``no_overlap``.  One search worker by default,
so the same model and seed give the same skeletons.
"""

from __future__ import annotations

from typing import Any, Sequence

from mrgc.backends.base import Backend, BackendInfo, solver_library
from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, SolveStatus, Terms
from mrgc.errors import MrgcError
from mrgc.signals import stop_on_signal

#: the bound ``cp_model`` users write for a missing side of a row (CP-SAT's domains stay within int64)
UNBOUNDED = 2**62


def _helper() -> Any:
    """OR-Tools' native CP-SAT module (``ortools.sat.python.cp_model_helper``, no pandas or numpy)."""
    with solver_library(CpSatBackend.info):
        from ortools.sat.python import cp_model_helper
    return cp_model_helper


def _interval(lo: int, hi: int) -> list[int]:
    """The flattened domain ``[lo, hi]``: empty when ``lo > hi`` (as OR-Tools' ``Domain(lo, hi)``)."""
    return [lo, hi] if lo <= hi else []


def normal_form(terms: Terms) -> tuple[list[int], list[int]]:
    """Variables and coefficients of ``sum(c * x)`` as ``cp_model`` writes them: the coefficients of a
    variable summed, zeros dropped, variables in index order."""
    summed: dict[int, int] = {}
    for v, c in terms:
        summed[v] = summed.get(v, 0) + c
    variables = sorted(v for v, c in summed.items() if c)
    return variables, [summed[v] for v in variables]


class CpSatBackend(Backend):
    """The skeleton model as a CP-SAT model message, solved by OR-Tools (module docstring)."""

    info = BackendInfo(
        name="cpsat",
        title="OR-Tools CP-SAT",
        module="ortools",
        distribution="ortools",
        features=frozenset({Feature.CONDITIONAL, Feature.AT_MOST_ONE, Feature.NO_OVERLAP}),
        exports=("pbtxt",),
        install="ortools>=9.15,<9.16",
    )

    def _load(self, model: SkeletonModel) -> None:
        proto = self.proto = _helper().CpModelProto()
        for v in model.vars:
            var = proto.variables.add()
            var.name = v.name
            var.domain.extend(_interval(0, 1) if v.is_bool else _interval(v.lb, v.ub))
        self._add_rows(model.rows)
        for cr in model.cond_rows:
            self._constraint(cr.row).enforcement_literal.extend([v if val else -v - 1 for v, val in cr.when])
        for amo in model.at_most_one:
            proto.constraints.add().at_most_one.literals.extend(amo.vars)
        for no in model.no_overlap:
            first = len(proto.constraints)
            for i, (present, start) in enumerate(no.tasks):
                ct = proto.constraints.add()
                ct.name = f"{no.name}#{i}"
                ct.enforcement_literal.append(present)
                interval = ct.interval
                interval.start.vars.append(start)
                interval.start.coeffs.append(1)
                interval.end.vars.append(start)
                interval.end.coeffs.append(1)
                interval.end.offset = 1
                interval.size.offset = 1
            proto.constraints.add().no_overlap.intervals.extend(range(first, first + len(no.tasks)))
        if model.objectives:
            variables, coeffs = normal_form(model.objectives[0])
            proto.objective.vars.extend(variables)
            proto.objective.coeffs.extend(coeffs)
            proto.objective.scaling_factor = 1.0

    def _constraint(self, row: Row) -> Any:
        """Add ``row`` and return its constraint message.  A row without terms is ``cp_model``'s constant
        constraint: an empty ``bool_and`` (true) if 0 is within its bounds, else an empty ``bool_or``."""
        lo = row.lo if row.lo is not None else -UNBOUNDED
        hi = row.hi if row.hi is not None else UNBOUNDED
        ct = self.proto.constraints.add()
        if not row.terms:
            # reading a message field of the constraint is what sets its kind
            _ = ct.bool_and if lo <= 0 <= hi else ct.bool_or
            return ct
        variables, coeffs = normal_form(row.terms)
        linear = ct.linear
        linear.vars.extend(variables)
        linear.coeffs.extend(coeffs)
        linear.domain.extend(_interval(lo, hi))
        return ct

    def _add_rows(self, rows: Sequence[Row]) -> None:
        for row in rows:
            self._constraint(row)

    def _solve(self, time_limit: float | None) -> Solution:
        cmh = _helper()
        parameters = cmh.SatParameters()
        parameters.num_workers = max(1, int(self.threads))
        parameters.random_seed = int(self.seed)
        # CP-SAT's own SIGINT handler would swallow Ctrl-C (the solve just stops and the run goes on to a
        # wrong verdict): the CLI's handler must see it
        parameters.catch_sigint_signal = False
        if time_limit is not None:
            parameters.max_time_in_seconds = max(0.001, float(time_limit))
        solver = cmh.SolveWrapper()
        solver.set_parameters(parameters)
        with stop_on_signal(solver.stop_search):  # Ctrl-C / SIGTERM stop the search at once (mrgc.signals)
            response = solver.solve(self.proto)
        status, statuses = response.status, cmh.CpSolverStatus
        if status in (statuses.OPTIMAL, statuses.FEASIBLE):
            values = tuple(int(x) for x in response.solution)  # one value per variable, in order
            if status == statuses.OPTIMAL:
                return Solution(SolveStatus.OPTIMAL, values)
            return Solution(SolveStatus.FEASIBLE, values, message="time limit")
        if status == statuses.INFEASIBLE:
            return Solution(SolveStatus.INFEASIBLE)
        if status == statuses.UNKNOWN:
            return Solution(SolveStatus.TIME_LIMIT, message="time limit")
        return Solution(SolveStatus.ERROR, message=f"CP-SAT: {status.name}")

    def _export(self, path: str) -> None:
        if not _helper().CpSatHelper.write_model_to_file(self.proto, path):
            raise MrgcError(f"CP-SAT could not write {path}")
