"""``cpsat``: the skeleton model in OR-Tools CP-SAT.  The only module importing ortools.

Conditional rows become ``OnlyEnforceIf`` (a conjunction of literals), at-most-one ``AddAtMostOne``,
no-overlap of unit tasks optional fixed-size intervals with ``AddNoOverlap``.  One search worker by
default, so the same model and seed give the same skeletons.
"""

from __future__ import annotations

from typing import Any, Sequence

from mrgc.backends.base import Backend, BackendInfo
from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, Status
from mrgc.errors import MissingBackendError, MrgcError
from mrgc.signals import stop_on_signal


def _cp_model() -> Any:
    try:
        from ortools.sat.python import cp_model
    except ImportError as exc:  # pragma: no cover - installed by default
        raise MissingBackendError(f"backend 'cpsat' needs OR-Tools: pip install 'ortools>=9.15,<9.16' ({exc})") from None
    return cp_model


class CpSatBackend(Backend):
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
        cp = _cp_model()
        m = self.m = cp.CpModel()
        self.x = [m.NewBoolVar(v.name) if v.is_bool else m.NewIntVar(v.lb, v.ub, v.name) for v in model.vars]
        self._add_rows(model.rows)
        for cr in model.cond_rows:
            ct = self._constraint(cr.row)
            ct.OnlyEnforceIf([self.x[v] if val else self.x[v].Not() for v, val in cr.when])
        for amo in model.at_most_one:
            m.AddAtMostOne([self.x[v] for v in amo.vars])
        for k, no in enumerate(model.no_overlap):
            intervals = [m.NewOptionalFixedSizeIntervalVar(self.x[s], 1, self.x[p], f"{no.name}#{i}")
                         for i, (p, s) in enumerate(no.tasks)]
            m.AddNoOverlap(intervals)
        if model.objectives:
            m.Minimize(sum(c * self.x[v] for v, c in model.objectives[0]))

    def _constraint(self, row: Row) -> Any:
        expr = sum(c * self.x[v] for v, c in row.terms)
        lo = row.lo if row.lo is not None else -(2**62)
        hi = row.hi if row.hi is not None else 2**62
        return self.m.AddLinearConstraint(expr, lo, hi)

    def _add_rows(self, rows: Sequence[Row]) -> None:
        for row in rows:
            self._constraint(row)

    def _solve(self, time_limit: float | None) -> Solution:
        cp = _cp_model()
        solver = cp.CpSolver()
        solver.parameters.num_workers = max(1, int(self.threads))
        solver.parameters.random_seed = int(self.seed)
        # CP-SAT's own SIGINT handler would swallow Ctrl-C (the solve just stops and the run goes on to a
        # wrong verdict): the CLI's handler must see it
        solver.parameters.catch_sigint_signal = False
        if time_limit is not None:
            solver.parameters.max_time_in_seconds = max(0.001, float(time_limit))
        with stop_on_signal(solver.StopSearch):  # Ctrl-C / SIGTERM stop the search at once (mrgc.signals)
            status = solver.Solve(self.m)
        if status in (cp.OPTIMAL, cp.FEASIBLE):
            values = tuple(int(solver.Value(x)) for x in self.x)
            if status == cp.OPTIMAL:
                return Solution(Status.OPTIMAL, values)
            return Solution(Status.FEASIBLE, values, message="time limit")
        if status == cp.INFEASIBLE:
            return Solution(Status.INFEASIBLE)
        if status == cp.UNKNOWN:
            return Solution(Status.TIME_LIMIT, message="time limit")
        return Solution(Status.ERROR, message=f"CP-SAT: {solver.StatusName(status)}")

    def _export(self, path: str) -> None:
        if not self.m.ExportToFile(path):
            raise MrgcError(f"CP-SAT could not write {path}")
