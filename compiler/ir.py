"""The solver-agnostic skeleton model (IR) that every backend translates, and the Solver protocol.

A model is: bool/int variables with bounds and readable names; linear rows ``lo <= sum(c*x) <= hi``;
conditional rows ``l1 and l2 ... => row`` (literals are a variable and the value it must take); optional
globals (at-most-one over bools, no-overlap of unit-length tasks); a linear or lexicographic objective to
minimise.  Coefficients are integers.  Backends declare which of the optional features they translate
natively; :mod:`mrgc.compiler.lowering` rewrites the others into rows before a backend sees the model.
Cuts are added as ordinary rows with :meth:`Solver.add_rows`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Protocol, Sequence

Terms = tuple[tuple[int, int], ...]  # (variable index, integer coefficient)


@dataclass(frozen=True)
class Var:
    """A decision variable; ``is_bool`` means 0/1."""

    name: str
    lb: int
    ub: int
    is_bool: bool


@dataclass(frozen=True)
class Row:
    """``lo <= sum(c * x) <= hi`` (a missing side is unbounded)."""

    terms: Terms
    lo: int | None = None
    hi: int | None = None
    name: str = ""


@dataclass(frozen=True)
class CondRow:
    """If every literal holds (``var == value``), then ``row`` holds.

    ``big_m`` optionally gives a valid big-M for a MIP translation when the encoding knows a tighter one
    than the variable bounds imply (e.g. the paper's T+1 for pick precedence).
    """

    when: tuple[tuple[int, bool], ...]
    row: Row
    big_m: int | None = None


@dataclass(frozen=True)
class AtMostOne:
    """At most one of the bool variables is true."""

    vars: tuple[int, ...]
    name: str = ""


@dataclass(frozen=True)
class NoOverlap:
    """Unit-length tasks (presence bool, start int): present tasks start at pairwise different times."""

    tasks: tuple[tuple[int, int], ...]
    name: str = ""


class Feature(str, enum.Enum):
    """Optional model features a backend may translate natively (else they are lowered)."""

    CONDITIONAL = "conditional rows"
    AT_MOST_ONE = "at-most-one"
    NO_OVERLAP = "no-overlap"
    LEXICOGRAPHIC = "lexicographic objective"


@dataclass
class SkeletonModel:
    """A model under construction; encodings fill it, backends translate it."""

    vars: list[Var] = field(default_factory=list)
    rows: list[Row] = field(default_factory=list)
    cond_rows: list[CondRow] = field(default_factory=list)
    at_most_one: list[AtMostOne] = field(default_factory=list)
    no_overlap: list[NoOverlap] = field(default_factory=list)
    #: objectives to minimise in priority order (one entry: a plain linear objective)
    objectives: list[Terms] = field(default_factory=list)
    name: str = "skeleton"

    def bool_var(self, name: str) -> int:
        """A new boolean variable; its index."""
        self.vars.append(Var(name, 0, 1, True))
        return len(self.vars) - 1

    def int_var(self, name: str, lb: int, ub: int) -> int:
        """A new integer variable in ``[lb, ub]``; its index."""
        self.vars.append(Var(name, lb, ub, False))
        return len(self.vars) - 1

    def add(
        self, terms: Sequence[tuple[int, int]], lo: int | None = None, hi: int | None = None, name: str = ""
    ) -> Row:
        """Add the row ``lo <= sum(terms) <= hi`` (repeated variables merged); the row."""
        row = Row(merge_terms(terms), lo, hi, name)
        self.rows.append(row)
        return row

    def add_if(
        self,
        when: Sequence[tuple[int, bool]],
        terms: Sequence[tuple[int, int]],
        lo: int | None = None,
        hi: int | None = None,
        name: str = "",
        big_m: int | None = None,
    ) -> None:
        """Add a row that holds only when every ``(variable, value)`` of ``when`` does (``big_m``: the bound a
        backend without indicator constraints uses)."""
        self.cond_rows.append(CondRow(tuple(when), Row(merge_terms(terms), lo, hi, name), big_m))

    def bounds(self, terms: Terms) -> tuple[int, int]:
        """Smallest and largest value of ``sum(c * x)`` over the variable bounds."""
        lo = hi = 0
        for v, c in terms:
            a, b = c * self.vars[v].lb, c * self.vars[v].ub
            lo += min(a, b)
            hi += max(a, b)
        return lo, hi

    def evaluate(self, terms: Terms, values: Sequence[int]) -> int:
        """The value of a linear expression at ``values``."""
        return sum(c * values[v] for v, c in terms)

    def violated(self, values: Sequence[int]) -> list[str]:
        """Names of rows, conditional rows and globals that ``values`` violates (a self-check for backends)."""
        bad = []
        for i, var in enumerate(self.vars):
            if not var.lb <= values[i] <= var.ub:
                bad.append(f"bounds of {var.name}")
        for row in self.rows:
            if not _holds(row, self.evaluate(row.terms, values)):
                bad.append(row.name or "row")
        for cr in self.cond_rows:
            active = all(bool(values[v]) == val for v, val in cr.when)
            if active and not _holds(cr.row, self.evaluate(cr.row.terms, values)):
                bad.append(cr.row.name or "conditional row")
        for amo in self.at_most_one:
            if sum(values[v] for v in amo.vars) > 1:
                bad.append(amo.name or "at-most-one")
        for no in self.no_overlap:
            starts = [values[s] for p, s in no.tasks if values[p]]
            if len(starts) != len(set(starts)):
                bad.append(no.name or "no-overlap")
        return bad


def _holds(row: Row, value: int) -> bool:
    return (row.lo is None or value >= row.lo) and (row.hi is None or value <= row.hi)


def merge_terms(terms: Sequence[tuple[int, int]]) -> Terms:
    """Combine repeated variables and drop zero coefficients, keeping first-appearance order."""
    acc: dict[int, int] = {}
    for v, c in terms:
        acc[v] = acc.get(v, 0) + c
    return tuple((v, c) for v, c in acc.items() if c)


class SolveStatus(enum.StrEnum):
    """How one solve of a skeleton model ended (``mrgc.SolveStatus``)."""

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    INFEASIBLE = "infeasible"
    TIME_LIMIT = "time limit"
    ERROR = "error"


@dataclass(frozen=True)
class Solution:
    """A solver's answer: a status, and for OPTIMAL/FEASIBLE the value of every variable."""

    status: SolveStatus
    values: tuple[int, ...] = ()
    objective: tuple[int, ...] = ()
    seconds: float = 0.0
    message: str = ""


class Solver(Protocol):
    """What skeleton enumeration needs of a backend (backends/ implements it; compiler/ never imports it;
    mypy checks that :class:`mrgc.backends.base.Backend` satisfies it)."""

    @property
    def name(self) -> str:
        """The backend's registered name."""

    def load(self, model: SkeletonModel) -> None:
        """Take a (lowered) model; replaces any previous one."""

    def add_rows(self, rows: Sequence[Row]) -> None:
        """Add rows (cuts) to the loaded model; the next solve respects them."""

    def solve(self, time_limit: float | None = None) -> Solution:
        """Minimise the objective; a status value, never an exception for infeasibility or time-outs."""

    def export(self, path: str) -> None:
        """Write the loaded model to ``path`` in a format chosen by its extension."""
