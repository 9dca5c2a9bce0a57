"""Rewriting optional model features into plain rows, for backends that do not translate them natively.

- no-overlap of unit tasks  → one order bool per pair and two conditional rows (tasks sharing a start
  variable instead get ``p_i + p_j <= 1``);
- at-most-one               → one row;
- lexicographic objective   → one weighted sum, weights from the bounds of the lower-priority terms, so
  the weighted optimum is exactly the lexicographic optimum;
- conditional rows          → big-M rows (the row's own ``big_m`` when the encoding gives one, else the
  tightest M the variable bounds allow).  This is the only place big-M appears.
"""

from __future__ import annotations

from itertools import combinations

from mrgc.compiler.ir import AtMostOne, CondRow, Feature, NoOverlap, Row, SkeletonModel, Terms
from mrgc.compiler.ir import merge_terms as _merge


def lower(model: SkeletonModel, native: frozenset[Feature]) -> SkeletonModel:
    """A copy of ``model`` using only the features in ``native`` (plus linear rows and bounds)."""
    out = SkeletonModel(
        list(model.vars),
        list(model.rows),
        list(model.cond_rows),
        list(model.at_most_one),
        list(model.no_overlap),
        list(model.objectives),
        model.name,
    )
    if Feature.NO_OVERLAP not in native:
        for no in out.no_overlap:
            _no_overlap(out, no)
        out.no_overlap = []
    if Feature.AT_MOST_ONE not in native:
        for amo in out.at_most_one:
            _at_most_one(out, amo)
        out.at_most_one = []
    if Feature.LEXICOGRAPHIC not in native and len(out.objectives) > 1:
        out.objectives = [weighted(out, out.objectives)]
    if Feature.CONDITIONAL not in native:
        for cr in out.cond_rows:
            out.rows.extend(big_m_rows(out, cr))
        out.cond_rows = []
    return out


def _no_overlap(model: SkeletonModel, no: NoOverlap) -> None:
    for (p1, s1), (p2, s2) in combinations(no.tasks, 2):
        if s1 == s2:
            model.add([(p1, 1), (p2, 1)], hi=1, name=f"{no.name}:excl")
            continue
        order = model.bool_var(f"{no.name}:order({model.vars[s1].name},{model.vars[s2].name})")
        model.add_if([(p1, True), (p2, True), (order, True)], [(s2, 1), (s1, -1)], lo=1, name=f"{no.name}:before")
        model.add_if([(p1, True), (p2, True), (order, False)], [(s1, 1), (s2, -1)], lo=1, name=f"{no.name}:after")


def _at_most_one(model: SkeletonModel, amo: AtMostOne) -> None:
    model.add([(v, 1) for v in amo.vars], hi=1, name=amo.name)


def weighted(model: SkeletonModel, objectives: list[Terms]) -> Terms:
    """One objective whose minimisers are exactly the lexicographic minimisers of ``objectives``."""
    weight = 1
    total: dict[int, int] = {}
    for terms in reversed(objectives):
        for v, c in terms:
            total[v] = total.get(v, 0) + weight * c
        lo, hi = model.bounds(terms)
        weight *= hi - lo + 1
    return tuple((v, c) for v, c in total.items() if c)


def big_m_rows(model: SkeletonModel, cr: CondRow) -> list[Row]:
    """The linear rows equivalent to ``cr`` for 0/1 literals (``slack`` counts literals that fail)."""
    row = cr.row
    lo_e, hi_e = model.bounds(row.terms)
    n_true = sum(1 for _, val in cr.when if val)
    out = []
    if row.lo is not None and row.lo > lo_e:
        m = cr.big_m if cr.big_m is not None else row.lo - lo_e
        terms = list(row.terms) + [(v, -m if val else m) for v, val in cr.when]
        out.append(Row(_merge(terms), lo=row.lo - m * n_true, name=row.name))
    if row.hi is not None and row.hi < hi_e:
        m = cr.big_m if cr.big_m is not None else hi_e - row.hi
        terms = list(row.terms) + [(v, m if val else -m) for v, val in cr.when]
        out.append(Row(_merge(terms), hi=row.hi + m * n_true, name=row.name))
    return out
