"""``pysmt``: the skeleton model through pysmt's solver-agnostic API (z3 underneath by default).

pysmt 0.9.6 has no optimiser, so the objective is minimised by bound tightening: solve, then assert
``objective < value`` and solve again until unsatisfiable; the last model is optimal.  The bounds are
asserted inside push/pop, so cuts added later apply to the plain model.  Lexicographic objectives arrive
as one exact weighted sum (compiler/lowering.py).  The only module importing pysmt.
"""

from __future__ import annotations

import time
from typing import Any, Sequence

from mrgc.backends.base import Backend, BackendInfo, solver_library
from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, SolveStatus, Terms
from mrgc.signals import stop_on_signal


def _pysmt() -> Any:
    with solver_library(PysmtBackend.info):
        import pysmt.environment
        import pysmt.exceptions
        import pysmt.typing
    return pysmt


class PysmtBackend(Backend):
    """The ``pysmt`` backend: the model as pysmt formulas solved by z3, each objective minimised by tightening its
    bound until the solver answers unsat."""

    info = BackendInfo(
        name="pysmt",
        title="pysmt (z3), optimised by bound tightening",
        module="pysmt",
        distribution="PySMT",
        features=frozenset({Feature.CONDITIONAL}),
        install="pysmt==0.9.6",
    )
    solver_name = "z3"

    def _load(self, model: SkeletonModel) -> None:
        pysmt = _pysmt()
        self.env = pysmt.environment.Environment()  # a private symbol table per model
        mgr = self.mgr = self.env.formula_manager
        INT, BOOL = pysmt.typing.INT, pysmt.typing.BOOL
        self.solver = self.env.factory.Solver(name=self.solver_name, random_seed=int(self.seed))
        if hasattr(self.solver, "z3"):
            self._private_context()
            # z3's own SIGINT handler would swallow Ctrl-C (see _stop)
            self.solver.z3.set("ctrl_c", False)
        self.x = [mgr.Symbol(v.name, BOOL if v.is_bool else INT) for v in model.vars]
        self.is_bool = [v.is_bool for v in model.vars]
        for x, v in zip(self.x, model.vars):
            if not v.is_bool:
                self.solver.add_assertion(mgr.And(mgr.GE(x, mgr.Int(v.lb)), mgr.LE(x, mgr.Int(v.ub))))
        self._add_rows(model.rows)
        for cr in model.cond_rows:
            lits = [self.x[v] if val else mgr.Not(self.x[v]) for v, val in cr.when]
            self.solver.add_assertion(mgr.Implies(mgr.And(lits), self._row(cr.row)))
        self.objective = self._sum(model.objectives[0]) if model.objectives else mgr.Int(0)

    def _private_context(self) -> None:
        """Move the z3 wrapper into a z3 context of its own.  pysmt builds every z3 solver in z3's global
        context, whose terms from earlier solves change the search: the same model and seed gave another
        optimum on the first solve of a process than on later ones (found by the conformance kit's
        determinism check, mrgc.testing.conformance)."""
        from pysmt.solvers import z3 as wrapper

        ctx = wrapper.z3.Context()
        logic = str(self.solver.logic)
        self.solver.z3 = (
            wrapper.z3.SolverFor(logic, ctx=ctx)
            if logic in wrapper.Z3Solver.SOLVERFOR_LOGIC_NAMES
            else wrapper.z3.Solver(ctx=ctx)
        )
        self.solver.options(self.solver)  # the random seed, on the new solver
        self.solver.converter = wrapper.Z3Converter(self.env, z3_ctx=ctx)

    def _sum(self, terms: Terms) -> Any:
        mgr = self.mgr
        parts = [
            mgr.Ite(self.x[v], mgr.Int(c), mgr.Int(0)) if self.is_bool[v] else mgr.Times(mgr.Int(c), self.x[v])
            for v, c in terms
        ]
        return mgr.Plus(parts) if parts else mgr.Int(0)

    def _row(self, row: Row) -> Any:
        mgr, e = self.mgr, self._sum(row.terms)
        if row.lo is not None and row.lo == row.hi:
            return mgr.Equals(e, mgr.Int(row.lo))
        parts = []
        if row.lo is not None:
            parts.append(mgr.GE(e, mgr.Int(row.lo)))
        if row.hi is not None:
            parts.append(mgr.LE(e, mgr.Int(row.hi)))
        return mgr.And(parts)

    def _add_rows(self, rows: Sequence[Row]) -> None:
        for row in rows:
            self.solver.add_assertion(self._row(row))

    def _values(self) -> tuple[int, ...]:
        out = []
        for x, b in zip(self.x, self.is_bool):
            val = self.solver.get_value(x)
            out.append((1 if val.is_true() else 0) if b else int(val.constant_value()))
        return tuple(out)

    def _solve(self, time_limit: float | None) -> Solution:
        pysmt = _pysmt()
        deadline = None if time_limit is None else time.perf_counter() + time_limit
        best: tuple[int, ...] | None = None
        self.solver.push()
        try:
            while True:
                if deadline is not None:
                    left = deadline - time.perf_counter()
                    if left <= 0:
                        return self._timed_out(best)
                    if hasattr(self.solver, "z3"):  # the z3 wrapper takes a per-check timeout
                        self.solver.z3.set("timeout", max(1, int(left * 1000)))
                try:
                    with stop_on_signal(self._stop):
                        sat = self.solver.solve()
                except pysmt.exceptions.SolverReturnedUnknownResultError:
                    return self._timed_out(best)
                if not sat:
                    break
                best = self._values()
                value = sum(c * best[v] for v, c in self._objective_terms())
                self.solver.add_assertion(self.mgr.LT(self.objective, self.mgr.Int(value)))
        finally:
            self.solver.pop()
        if best is None:
            return Solution(SolveStatus.INFEASIBLE)
        return Solution(SolveStatus.OPTIMAL, best)

    def _stop(self) -> None:
        """Interrupt a running check (Ctrl-C / SIGTERM, mrgc.signals); only the z3 wrapper can."""
        if hasattr(self.solver, "z3"):
            self.solver.z3.ctx.interrupt()

    def _objective_terms(self) -> Terms:
        assert self.model is not None
        return self.model.objectives[0] if self.model.objectives else ()

    @staticmethod
    def _timed_out(best: tuple[int, ...] | None) -> Solution:
        if best is None:
            return Solution(SolveStatus.TIME_LIMIT, message="time limit")
        return Solution(SolveStatus.FEASIBLE, best, message="time limit")
