"""``smt``: the skeleton model in z3's Optimize (an OMT solver).  The only module importing z3.

Bools are z3 Bools; integers are bounded z3 Ints; a row is a linear (in)equality; a conditional row is
``Implies(And(literals), row)``; at-most-one is ``AtMost``; a lexicographic objective is z3's native
``lex`` priority.  ``--emit model.smt2`` writes ``Optimize.sexpr()``: SMT-LIB2 with z3's ``(minimize)``
extension, as a script z3 runs (``z3 model.smt2``, ``z3.Optimize().from_file``): the seed as SMT-LIB's
``:random-seed``, then ``(check-sat)`` and ``(get-objectives)`` (:func:`smt2_script`).
"""

from __future__ import annotations

import math
import threading
from typing import Any, Sequence

from mrgc.backends.base import Backend, BackendInfo, solver_library
from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, SolveStatus, Terms
from mrgc.signals import shielded, stop_on_signal


def _z3() -> Any:
    with solver_library(Z3Backend.info):
        import z3
    return z3


class Z3Backend(Backend):
    """The ``smt`` backend: the model for z3's Optimize (lexicographic objectives, native at-most-one)."""

    info = BackendInfo(
        name="smt",
        title="z3 Optimize (OMT)",
        module="z3",
        distribution="z3-solver",
        features=frozenset({Feature.CONDITIONAL, Feature.AT_MOST_ONE, Feature.LEXICOGRAPHIC}),
        exports=("smt2",),
        grow_horizon=False,  # a model per horizon costs z3 a load each (docs/compiler.md, "time-of-move")
    )

    def _load(self, model: SkeletonModel) -> None:
        # a signal while z3's Python API builds terms would cut a ctypes call short (an ArgumentError, or a
        # half-made term whose __del__ then fails): building is shielded, the signal raised when it is done
        with shielded():
            self._build(model)

    def _build(self, model: SkeletonModel) -> None:
        z3 = _z3()
        self.ctx = z3.Context()
        opt = z3.Optimize(ctx=self.ctx)
        opt.set(priority="lex")
        opt.set("random_seed", int(self.seed))
        self.x = []
        for v in model.vars:
            if v.is_bool:
                self.x.append(z3.Bool(v.name, self.ctx))
            else:
                var = z3.Int(v.name, self.ctx)
                opt.add(var >= v.lb, var <= v.ub)
                self.x.append(var)
        self.is_bool = [v.is_bool for v in model.vars]
        for row in model.rows:
            opt.add(*self._row(row))
        for cr in model.cond_rows:
            lits = [self.x[v] if val else z3.Not(self.x[v]) for v, val in cr.when]
            cond = lits[0] if len(lits) == 1 else z3.And(*lits)
            opt.add(z3.Implies(cond, z3.And(*self._row(cr.row))))
        for amo in model.at_most_one:
            opt.add(z3.AtMost(*[self.x[v] for v in amo.vars], 1))
        self.objectives = [opt.minimize(self._sum(terms)) for terms in model.objectives]
        self.opt = opt

    def _sum(self, terms: Terms) -> Any:
        z3 = _z3()
        parts = [
            z3.If(self.x[v], z3.IntVal(c, self.ctx), z3.IntVal(0, self.ctx)) if self.is_bool[v] else self.x[v] * c
            for v, c in terms
        ]
        return z3.Sum(parts) if parts else z3.IntVal(0, self.ctx)

    def _row(self, row: Row) -> list[Any]:
        e = self._sum(row.terms)
        out = []
        if row.lo is not None and row.hi is not None and row.lo == row.hi:
            return [e == row.lo]
        if row.lo is not None:
            out.append(e >= row.lo)
        if row.hi is not None:
            out.append(e <= row.hi)
        return out or [_z3().BoolVal(True, self.ctx)]

    def _add_rows(self, rows: Sequence[Row]) -> None:
        for row in rows:
            self.opt.add(*self._row(row))

    def _solve(self, time_limit: float | None) -> Solution:
        z3 = _z3()
        # z3 reads a timeout of 0 as none, and Optimize sometimes overruns its own timeout: round up to
        # 1 ms and back the limit with a watchdog that interrupts the context
        self.opt.set("timeout", max(1, math.ceil(time_limit * 1000)) if time_limit is not None else 4294967295)
        watchdog = None
        if time_limit is not None:
            watchdog = threading.Timer(time_limit + 0.05, self.ctx.interrupt)
            watchdog.daemon = True
            watchdog.start()
        # z3's own SIGINT handler would swallow Ctrl-C (check() returns unknown: a wrong "time limit"
        # verdict): mrgc.signals stops the check through the context instead
        self.opt.set("ctrl_c", False)
        try:
            with stop_on_signal(self.ctx.interrupt):
                res = self.opt.check()
        finally:
            if watchdog is not None:
                watchdog.cancel()
        if res == z3.unsat:
            return Solution(SolveStatus.INFEASIBLE)
        if res == z3.unknown:
            reason = self.opt.reason_unknown()
            if time_limit is not None or "timeout" in reason or "canceled" in reason:
                return Solution(SolveStatus.TIME_LIMIT, message=reason or "time limit")
            return Solution(SolveStatus.ERROR, message=f"z3: {reason}")
        m = self.opt.model()
        values = tuple(
            (1 if z3.is_true(m.eval(x, model_completion=True)) else 0)
            if b
            else m.eval(x, model_completion=True).as_long()
            for x, b in zip(self.x, self.is_bool)
        )
        return Solution(SolveStatus.OPTIMAL, values)

    def _export(self, path: str) -> None:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(smt2_script(self.opt.sexpr(), self.seed))


def smt2_script(sexpr: str, seed: int) -> str:
    """``Optimize.sexpr()`` as a script z3 loads and runs: its ``opt.random_seed`` option (which z3's own
    parser rejects: no such parameter of module ``opt``) becomes SMT-LIB's ``:random-seed``, and it ends
    with ``(check-sat)`` and ``(get-objectives)``."""
    lines = sexpr.splitlines()
    out: list[str] = []
    skip_comment = False
    for line in lines:
        if line.startswith("(set-option :opt.random_seed"):
            out.append(f"(set-option :random-seed {int(seed)})")
            skip_comment = True
            continue
        if skip_comment and line.startswith(";"):
            skip_comment = False
            continue
        skip_comment = False
        out.append(line)
    while out and out[-1].strip() in ("", "(check-sat)", "(get-objectives)"):
        out.pop()
    return "\n".join(out + ["(check-sat)", "(get-objectives)"]) + "\n"
