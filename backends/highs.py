"""``mip``: the skeleton model as a MIP solved by HiGHS (highspy).  The only module importing highspy.

HiGHS has no indicator constraints, so conditional rows arrive as big-M rows (see compiler/lowering.py).
Column and row names are the IR's readable names made LP-safe, so ``--emit model.lp`` is readable and
deterministic; they are given to HiGHS when a model is exported (a solve needs none).  highspy is pinned to
1.12.0: 1.15 cannot share a process with ortools 9.15.
"""

from __future__ import annotations

import os
import re
from typing import Any, Sequence

from mrgc.backends.base import Backend, BackendInfo, solver_library
from mrgc.compiler.ir import Row, SkeletonModel, Solution, SolveStatus
from mrgc.signals import stop_on_signal

INF = float("inf")


def _highspy() -> Any:
    with solver_library(HighsBackend.info):
        import highspy
    return highspy


def lp_names(names: Sequence[str]) -> list[str]:
    """LP-format-safe, unique versions of ``names`` (``-`` → ``_``, ``+`` → ``p``, other symbols → ``_``)."""
    out, seen = [], set()
    for n in names:
        safe = re.sub(r"[^A-Za-z0-9_.]", "_", n.replace("+", "p").replace("@", "_t")).strip("_") or "v"
        if safe[0].isdigit() or safe[0] == ".":
            safe = "v" + safe
        base, k = safe, 1
        while safe in seen:
            k += 1
            safe = f"{base}_{k}"
        seen.add(safe)
        out.append(safe)
    return out


def name_table(cols: Sequence[str], rows: Sequence[str], comment: str) -> str:
    """Comment lines (each starting with ``comment``: ``\\ `` in an LP file, ``* `` in an MPS file) that map
    each column's and row's name in the file back to the model's, for the names :func:`lp_names` changed ('' when
    it changed none): the file's names are legal and unique, but ``X_o1_bin_a_r1_r1_top_top_1`` does not say
    which of ``X(o1,bin-a,r1,r1,top,top)@1`` and a name differing only in a replaced character it stands for.
    ``rows`` are the backend's row names, the model's row name and ``#`` and the row's index (unique): a row's
    line gives the model's name and the index apart (``row c11_3_o2__12 = c11[3,o2] (row 12)``)."""
    lines = [f"{comment}  col {safe} = {name}\n" for safe, name in zip(lp_names(cols), cols) if safe != name]
    for safe, name in zip(lp_names(rows), rows):
        own, _, index = name.rpartition("#")
        if safe != name:
            lines.append(f"{comment}  row {safe} = {own} (row {index})\n")
    if not lines:
        return ""
    return f"{comment}mrgc: the model's names of the columns and rows the file names otherwise\n" + "".join(lines)


class HighsBackend(Backend):
    """The ``mip`` backend: the model as a mixed-integer program for HiGHS (conditional rows as big-M rows)."""

    info = BackendInfo(
        name="mip",
        title="HiGHS MIP (highspy)",
        module="highspy",
        distribution="highspy",
        features=frozenset(),
        exports=("lp", "mps"),
        install="highspy==1.12.0",
    )

    def _load(self, model: SkeletonModel) -> None:
        import numpy as np

        hs = _highspy()
        h = hs.Highs()
        h.setOptionValue("output_flag", False)
        h.setOptionValue("random_seed", int(self.seed))
        h.setOptionValue("threads", int(self.threads))
        h.setOptionValue("mip_rel_gap", 0.0)
        n = len(model.vars)
        h.addVars(
            n,
            np.array([v.lb for v in model.vars], dtype=np.float64),
            np.array([v.ub for v in model.vars], dtype=np.float64),
        )
        if n:
            h.changeColsIntegrality(
                n, np.arange(n, dtype=np.int32), np.full(n, int(hs.HighsVarType.kInteger), dtype=np.uint8)
            )
        cost = np.zeros(n)
        for v, c in model.objectives[0] if model.objectives else ():
            cost[v] += c
        h.changeColsCost(n, np.arange(n, dtype=np.int32), cost)
        self.h, self.rows = h, 0
        self.names: tuple[list[str], list[str]] = ([v.name for v in model.vars], [])  # passed on export
        self._add_rows(model.rows)

    def _add_rows(self, rows: Sequence[Row]) -> None:
        import numpy as np

        if not rows:
            return
        lower = np.array([-INF if r.lo is None else r.lo for r in rows], dtype=np.float64)
        upper = np.array([INF if r.hi is None else r.hi for r in rows], dtype=np.float64)
        starts: list[int] = []
        index: list[int] = []
        value: list[float] = []
        for r in rows:
            starts.append(len(index))
            for v, c in r.terms:
                index.append(v)
                value.append(c)
        self.h.addRows(
            len(rows),
            lower,
            upper,
            len(index),
            np.array(starts, dtype=np.int32),
            np.array(index, dtype=np.int32),
            np.array(value, dtype=np.float64),
        )
        self.names[1].extend(f"{r.name or 'row'}#{self.rows + k}" for k, r in enumerate(rows))
        self.rows += len(rows)

    def _pass_names(self) -> None:
        """Give HiGHS the columns' and rows' LP-safe names (only an export reads them: passing them one call
        per name cost a skeleton model's load more than its solve, 5 ms of a PA10 plan's 40 ms of skeletons)."""
        cols, rows = self.names
        for i, name in enumerate(lp_names(cols)):
            self.h.passColName(i, name)
        for k, name in enumerate(lp_names(rows)):
            self.h.passRowName(k, name)

    def _solve(self, time_limit: float | None) -> Solution:
        hs = _highspy()
        self.h.setOptionValue("time_limit", float(time_limit) if time_limit is not None else INF)
        self.h.HandleUserInterrupt = True  # lets cancelSolve stop the run: Ctrl-C / SIGTERM (mrgc.signals)
        with stop_on_signal(self.h.cancelSolve):
            self.h.run()
        status = self.h.getModelStatus()
        S = hs.HighsModelStatus
        if status == S.kModelEmpty:  # no variables: only constant rows, which hold or not
            assert self.model is not None
            return Solution(SolveStatus.INFEASIBLE if self.model.violated(()) else SolveStatus.OPTIMAL, ())
        if status == S.kOptimal:
            values = tuple(int(round(x)) for x in self.h.getSolution().col_value)
            return Solution(SolveStatus.OPTIMAL, values)
        if status in (S.kInfeasible, S.kUnboundedOrInfeasible):
            return Solution(SolveStatus.INFEASIBLE)
        if status in (S.kTimeLimit, S.kInterrupt, S.kIterationLimit, S.kSolutionLimit):
            info = self.h.getInfo()
            if info.primal_solution_status == 2:  # a feasible incumbent exists
                values = tuple(int(round(x)) for x in self.h.getSolution().col_value)
                return Solution(SolveStatus.FEASIBLE, values, message="time limit")
            return Solution(SolveStatus.TIME_LIMIT, message="time limit")
        return Solution(SolveStatus.ERROR, message=f"HiGHS: {self.h.modelStatusToString(status)}")

    def _export(self, path: str) -> None:
        """``writeModel``, then the names the file uses that are not the model's (:func:`lp_names`) mapped
        back in comment lines at its top (:func:`name_table`); rows without terms (0 >= 1 says "infeasible")
        and models without variables are written with a column ``zero`` fixed at 0 that those rows hold, since
        HiGHS writes neither (the file would reload as an empty, feasible model)."""
        self._write(path)
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            return  # HiGHS wrote nothing: Backend.export says so (no table on top of nothing)
        table = name_table(*self.names, comment="* " if path.lower().endswith(".mps") else "\\ ")
        if table:
            with open(path, encoding="utf-8") as f:
                text = f.read()
            with open(path, "w", encoding="utf-8") as f:
                f.write(table + text)

    def _write(self, path: str) -> None:
        assert self.model is not None
        self._pass_names()
        empty = [i for i, r in enumerate(self.model.rows) if not r.terms]
        if not empty and self.model.vars:
            self.h.writeModel(path)
            return
        h = _highspy().Highs()
        h.setOptionValue("output_flag", False)
        h.passModel(self.h.getModel())
        h.addVar(0.0, 0.0)
        zero = h.getNumCol() - 1
        h.passColName(zero, "zero")
        for i in empty:
            h.changeCoeff(i, zero, 1.0)
        h.writeModel(path)
