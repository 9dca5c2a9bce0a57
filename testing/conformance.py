"""The backend conformance kit: what every solver backend must do, as checks a backend (a plug-in too)
runs against itself.

A backend is a :class:`~mrgc.backends.base.Backend` subclass (registered or not).  :func:`check_backend`
runs every check of :data:`CHECKS` and returns a :class:`ConformanceReport`; each check is also a plain
function that raises :class:`ConformanceError` (an ``AssertionError``), so a pytest file can run them one
by one (docs/testing.md has a plug-in author's test):

- ``known-optima``: small IR models with known optima (rows, integers with negative bounds, conditional
  rows with multi-literal and negative conditions, at-most-one, no-overlap, lexicographic objectives, three
  kinds of infeasibility), the solution valid by the model's own check and by an independent one;
- ``unique-optima``: models with one optimal assignment return exactly it;
- ``load-keeps-model``: loading and solving do not change the caller's model;
- ``incremental-cuts``: rows added between solves walk through every solution in order, then infeasible;
- ``rows-after-solving``: rows added after a solve tighten the optimum;
- ``zero-variables``: models without variables (and a false constant row) solve correctly;
- ``determinism``: the same model and seed give the same values;
- ``time-limit``: a tiny time limit is a status (time limit, or a valid solution), never an error; and a
  sub-millisecond limit still stops the solver within 0.3 s (the planner passes the remaining budget);
- ``symbolic-fixtures``: every shipped symbolic fixture (``domains/symbolic``, whose first line states its
  optimum) compiled with every encoding the backend supports reaches that optimum, and the skeleton passes
  the independent oracle (:mod:`mrgc.testing.oracle`).

Each model's expected optimum is hard-coded *and* recomputed by an exhaustive search written here
(:func:`brute_force`: its own evaluation of rows, conditional rows, at-most-one and no-overlap; it does not
use ``SkeletonModel.violated``), so a wrong constant cannot hide a backend bug.
"""

from __future__ import annotations

import functools
import itertools
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from mrgc.backends.base import Backend
from mrgc.compiler.ir import AtMostOne, NoOverlap, Row, SkeletonModel, Solution, SolveStatus

#: the shipped symbolic fixtures (installed with the package)
FIXTURES = Path(__file__).resolve().parent.parent / "domains" / "symbolic"

#: a backend under test: its class
BackendClass = type[Backend]


class ConformanceError(AssertionError):
    """A backend broke the contract; the message says how."""


def _require(ok: bool, message: str) -> None:
    if not ok:
        raise ConformanceError(message)


# ---------------------------------------------------------------- an independent reference solver
def _row_ok(row: Row, values: Sequence[int]) -> bool:
    s = sum(c * values[v] for v, c in row.terms)
    return (row.lo is None or s >= row.lo) and (row.hi is None or s <= row.hi)


def satisfies(model: SkeletonModel, values: Sequence[int]) -> bool:
    """Does ``values`` satisfy ``model``?  Written from the IR's definitions, independently of ir.py."""
    if len(values) < len(model.vars):
        return False
    for i, var in enumerate(model.vars):
        if not var.lb <= values[i] <= var.ub:
            return False
    if not all(_row_ok(r, values) for r in model.rows):
        return False
    for cr in model.cond_rows:
        if all((values[v] == 1) == want for v, want in cr.when) and not _row_ok(cr.row, values):
            return False
    for amo in model.at_most_one:
        if sum(values[v] for v in amo.vars) > 1:
            return False
    for no in model.no_overlap:
        starts = [values[s] for p, s in no.tasks if values[p] == 1]
        if len(starts) != len(set(starts)):
            return False
    return True


def objectives(model: SkeletonModel, values: Sequence[int]) -> tuple[int, ...]:
    """The model's objectives (lexicographic order) at ``values``."""
    return tuple(sum(c * values[v] for v, c in terms) for terms in model.objectives)


def brute_force(model: SkeletonModel) -> tuple[SolveStatus, tuple[int, ...] | None, list[tuple[int, ...]]]:
    """(status, lexicographic optimum, every optimal assignment) by trying every assignment."""
    best: tuple[int, ...] | None = None
    arg: list[tuple[int, ...]] = []
    for values in itertools.product(*[range(v.lb, v.ub + 1) for v in model.vars]):
        if not satisfies(model, values):
            continue
        obj = objectives(model, values)
        if best is None or obj < best:
            best, arg = obj, [values]
        elif obj == best:
            arg.append(values)
    return (SolveStatus.INFEASIBLE if best is None else SolveStatus.OPTIMAL), best, arg


# ---------------------------------------------------------------- the models
def pure_rows() -> SkeletonModel:
    """Vertex cover of a triangle a-b-c with a pendant c-d, and a range row 1 <= a + d <= 1."""
    m = SkeletonModel(name="pure-rows")
    a, b, c, d = (m.bool_var(n) for n in "abcd")
    m.add([(a, 1), (b, 1)], lo=1)
    m.add([(b, 1), (c, 1)], lo=1)
    m.add([(a, 1), (c, 1)], lo=1)
    m.add([(c, 1), (d, 1)], lo=1)
    m.add([(a, 1), (d, 1)], lo=1, hi=1)
    m.objectives.append(((a, 3), (b, 2), (c, 2), (d, 2)))
    return m


def rows_with_ints() -> SkeletonModel:
    """Integers with negative bounds, an equality, non-unit coefficients and a fractional LP optimum."""
    m = SkeletonModel(name="ints")
    x = m.int_var("x", -5, 5)
    y = m.int_var("y", 0, 7)
    z = m.int_var("z", -3, 3)
    b = m.bool_var("b")
    m.add([(x, 1), (y, 2), (z, -1)], lo=4)
    m.add([(x, 3), (y, -1)], hi=2)
    m.add([(x, 1), (y, 1), (z, 1)], lo=3, hi=3)
    m.add([(x, 2), (z, 4), (b, 3)], lo=1)  # odd right-hand side against even coefficients
    m.objectives.append(((x, 2), (y, 3), (z, -1), (b, 5)))
    return m


def conditional_rows() -> SkeletonModel:
    """Conditional rows with multi-literal conditions, negative literals, upper and equality rows.

    The unique optimum (a=1, b=1, c=0, x=3, y=-2: objective 5) changes if negative literals were read as
    positive ones, or conditions with several literals as their first literal only.
    """
    m = SkeletonModel(name="conditional")
    a, b, c = m.bool_var("a"), m.bool_var("b"), m.bool_var("c")
    x = m.int_var("x", 0, 10)
    y = m.int_var("y", -4, 4)
    m.add([(a, 1)], lo=1, hi=1)
    m.add_if([(a, True), (b, False)], [(x, 1)], lo=7, name="a&!b=>x>=7")
    m.add_if([(a, True), (b, True)], [(x, 1)], lo=3, name="a&b=>x>=3")
    m.add_if([(b, True), (c, False)], [(y, 1)], hi=-2, name="b&!c=>y<=-2")
    m.add_if([(a, True), (b, True), (c, True)], [(x, 1), (y, -1)], lo=9, hi=9, name="a&b&c=>x-y=9")
    m.add_if([(c, False)], [(x, 1), (y, 1)], lo=1, name="!c=>x+y>=1")
    m.objectives.append(((x, 2), (b, 1), (c, 2), (y, 1)))
    return m


def at_most_one() -> SkeletonModel:
    """A model with an at-most-one constraint and a known optimum."""
    m = SkeletonModel(name="amo")
    xs = [m.bool_var(f"x{i}") for i in range(4)]
    m.at_most_one.append(AtMostOne((xs[0], xs[1], xs[2]), "amo012"))
    m.at_most_one.append(AtMostOne((xs[2], xs[3]), "amo23"))
    m.objectives.append(tuple((x, -w) for x, w in zip(xs, (1, 2, 4, 3))))
    return m


def no_overlap() -> SkeletonModel:
    """Unit tasks on three slots; tasks 2 and 3 share a start variable; s0 + s1 <= 2 forces s0 = s1 = 1."""
    m = SkeletonModel(name="no-overlap")
    p = [m.bool_var(f"p{i}") for i in range(4)]
    s = [m.int_var(f"s{i}", 1, 3) for i in range(3)]
    m.add([(s[0], 1), (s[1], 1)], hi=2)
    m.no_overlap.append(NoOverlap(((p[0], s[0]), (p[1], s[1]), (p[2], s[2]), (p[3], s[2])), "machine"))
    m.objectives.append(((p[0], -2), (p[1], -2), (p[2], -3), (p[3], -5)))
    return m


def no_overlap_makespan() -> SkeletonModel:
    """Four present unit tasks on one machine: the smallest makespan is 4."""
    m = SkeletonModel(name="no-overlap-makespan")
    p = [m.bool_var(f"p{i}") for i in range(4)]
    s = [m.int_var(f"s{i}", 1, 5) for i in range(4)]
    c = m.int_var("C", 0, 5)
    for i in range(4):
        m.add([(p[i], 1)], lo=1)
        m.add([(c, 1), (s[i], -1)], lo=0)
    m.no_overlap.append(NoOverlap(tuple(zip(p, s)), "machine"))
    m.objectives.append(((c, 1),))
    return m


def lexicographic() -> SkeletonModel:
    """(a, x - 3y, -c) lexicographically.  a = 1 would lower the second objective by 17, so a weighting that
    gives the first objective a weight below 17 (e.g. one that misjudges the range of x - 3y by ignoring
    its negative coefficient) returns a = 1; the lexicographic optimum is (0, 8, -1)."""
    m = SkeletonModel(name="lex")
    a = m.bool_var("a")
    x = m.int_var("x", 0, 5)
    y = m.int_var("y", -3, 3)
    c = m.bool_var("c")
    m.add([(a, 5), (x, 1)], lo=5)
    m.add([(x, 1), (y, 1)], hi=4)
    m.objectives.append(((a, 1),))
    m.objectives.append(((x, 1), (y, -3)))
    m.objectives.append(((c, -1),))
    return m


def infeasible_bools() -> SkeletonModel:
    """A model of booleans with no solution."""
    m = SkeletonModel(name="infeasible-bools")
    x, y, z = (m.bool_var(n) for n in "xyz")
    m.add([(x, 1), (y, 1), (z, 1)], lo=2)
    m.add([(x, 1), (y, 1)], hi=0)
    m.objectives.append(((x, 1),))
    return m


def infeasible_integrality() -> SkeletonModel:
    """2x = 3 has the LP solution x = 1.5 but no integer one."""
    m = SkeletonModel(name="infeasible-int")
    x = m.int_var("x", 0, 3)
    m.add([(x, 2)], lo=3, hi=3)
    m.objectives.append(((x, 1),))
    return m


def infeasible_conditional() -> SkeletonModel:
    """b is forced, and b => x >= 4 with x <= 3."""
    m = SkeletonModel(name="infeasible-cond")
    b = m.bool_var("b")
    x = m.int_var("x", 0, 3)
    m.add([(b, 1)], lo=1)
    m.add_if([(b, True)], [(x, 1)], lo=4)
    m.objectives.append(((x, 1),))
    return m


@dataclass(frozen=True)
class Case:
    """A model of the kit with its expected status and lexicographic optimum."""

    build: Callable[[], SkeletonModel]
    status: SolveStatus
    optimum: tuple[int, ...] | None


#: model name -> its case
MODELS: dict[str, Case] = {
    "pure-rows": Case(pure_rows, SolveStatus.OPTIMAL, (5,)),
    "ints": Case(rows_with_ints, SolveStatus.OPTIMAL, (6,)),
    "conditional": Case(conditional_rows, SolveStatus.OPTIMAL, (5,)),
    "at-most-one": Case(at_most_one, SolveStatus.OPTIMAL, (-5,)),
    "no-overlap": Case(no_overlap, SolveStatus.OPTIMAL, (-7,)),
    "no-overlap-makespan": Case(no_overlap_makespan, SolveStatus.OPTIMAL, (4,)),
    "lexicographic": Case(lexicographic, SolveStatus.OPTIMAL, (0, 8, -1)),
    "infeasible-bools": Case(infeasible_bools, SolveStatus.INFEASIBLE, None),
    "infeasible-integrality": Case(infeasible_integrality, SolveStatus.INFEASIBLE, None),
    "infeasible-conditional": Case(infeasible_conditional, SolveStatus.INFEASIBLE, None),
}


def symmetric() -> SkeletonModel:
    """Many optimal solutions (choose any 3 of 8, subject to a few side conditions): a solver must still
    return the same one for the same model and seed."""
    m = SkeletonModel(name="symmetric")
    xs = [m.bool_var(f"x{i}") for i in range(8)]
    t = [m.int_var(f"t{i}", 1, 4) for i in range(4)]
    m.add([(x, 1) for x in xs], lo=3)
    m.at_most_one.append(AtMostOne((xs[0], xs[1]), "amo"))
    m.add_if([(xs[2], True), (xs[3], False)], [(t[0], 1), (t[1], -1)], lo=1)
    m.no_overlap.append(NoOverlap(tuple(zip(xs[4:], t)), "robot"))
    m.objectives.append(tuple((x, 1) for x in xs))
    return m


@functools.lru_cache(maxsize=4)
def hard_ish(n: int = 1000) -> SkeletonModel:
    """A weighted covering chain: trivial structure, but large enough that no backend solves it in 1 ms
    (z3 takes ~0.5 s for n = 1000, ~2 s for 2000).  Cached: treat it as read-only."""
    m = SkeletonModel(name=f"hard-ish-{n}")
    xs = [m.bool_var(f"x{i}") for i in range(n)]
    for i in range(n - 1):
        m.add([(xs[i], 1), (xs[i + 1], 1)], lo=1)
    for i in range(0, n - 2, 3):
        m.add([(xs[i], 1), (xs[i + 1], 1), (xs[i + 2], 1)], hi=2)
    m.objectives.append(tuple((x, 1 + i % 3) for i, x in enumerate(xs)))
    return m


# ---------------------------------------------------------------- helpers
def solve(backend: BackendClass, model: SkeletonModel, time_limit: float | None = None, seed: int = 0) -> Solution:
    """Load ``model`` into a new ``backend(seed=seed)`` and solve it."""
    solver = backend(seed=seed)
    solver.load(model)
    return solver.solve(time_limit)


def require_valid(model: SkeletonModel, sol: Solution, what: str = "") -> None:
    """A returned solution satisfies the model by both its own self-check and the independent one."""
    values = sol.values[: len(model.vars)]
    where = f"{model.name}{what}"
    _require(len(values) == len(model.vars), f"{where}: {len(values)} values for {len(model.vars)} variables")
    _require(model.violated(values) == [], f"{where}: the solution violates {model.violated(values)[:3]}")
    _require(satisfies(model, values), f"{where}: the solution breaks the model (independent check)")


# ---------------------------------------------------------------- the checks
def check_known_optima(backend: BackendClass) -> None:
    """Every model of :data:`MODELS` reaches its known status and optimum with a valid solution."""
    for name, case in MODELS.items():
        model = case.build()
        sol = solve(backend, model)
        _require(
            sol.status == case.status,
            f"{name}: status {sol.status.value}, expected {case.status.value} ({sol.message})",
        )
        if case.status == SolveStatus.OPTIMAL:
            require_valid(model, sol)
            got = objectives(model, sol.values)
            _require(got == case.optimum, f"{name}: objective {got}, the optimum is {case.optimum}")
            if len(model.objectives) == 1:
                _require(
                    sol.objective == case.optimum,
                    f"{name}: reports objective {sol.objective}, its values give {case.optimum}",
                )
        else:
            _require(sol.values == (), f"{name}: values returned with status {sol.status.value}")


def check_unique_optima(backend: BackendClass) -> None:
    """Models with a single optimal assignment get exactly that assignment."""
    for build, want in ((at_most_one, (0, 1, 0, 1)), (conditional_rows, (1, 1, 0, 3, -2)), (no_overlap_makespan, None)):
        model = build()
        _, _, arg = brute_force(model)
        values = tuple(solve(backend, model).values[: len(model.vars)])
        _require(values in arg, f"{model.name}: {values} is not optimal (optimal: {arg[:5]})")
        _require(want is None or values == want, f"{model.name}: {values}, the unique optimum is {want}")


def check_load_keeps_model(backend: BackendClass) -> None:
    """Loading, adding rows and solving leave the caller's model unchanged."""
    model = no_overlap()
    before = (list(model.vars), list(model.rows), list(model.cond_rows), list(model.no_overlap), list(model.objectives))
    solver = backend()
    solver.load(model)
    solver.add_rows([Row(((0, 1),), hi=0)])
    solver.solve()
    _require(
        (model.vars, model.rows, model.cond_rows, model.no_overlap, model.objectives) == before,
        "loading or solving changed the model it was given",
    )


def check_incremental_cuts(backend: BackendClass) -> None:
    """min x0+x1+x2 s.t. sum >= 1 and x0 & x1 => x2, each solution cut off after it is found: costs
    1, 1, 1, 2, 2, 3, then infeasible."""
    model = SkeletonModel(name="cuts")
    xs = [model.bool_var(f"x{i}") for i in range(3)]
    model.add([(x, 1) for x in xs], lo=1)
    model.add_if([(xs[0], True), (xs[1], True)], [(xs[2], 1)], lo=1)
    model.objectives.append(tuple((x, 1) for x in xs))
    solver = backend()
    solver.load(model)
    found: list[tuple[int, ...]] = []
    costs: list[int] = []
    for _ in range(10):
        sol = solver.solve()
        if sol.status == SolveStatus.INFEASIBLE:
            break
        _require(sol.status == SolveStatus.OPTIMAL, f"cuts: status {sol.status.value} ({sol.message})")
        values = tuple(sol.values[:3])
        require_valid(model, sol, f" after {len(found)} cuts")
        found.append(values)
        costs.append(sum(values))
        ones = [x for x, v in zip(xs, values) if v]
        solver.add_rows([Row(tuple((x, -1 if v else 1) for x, v in zip(xs, values)), lo=1 - len(ones), name="cut")])
    _require(costs == [1, 1, 1, 2, 2, 3], f"cuts: costs {costs}, expected [1, 1, 1, 2, 2, 3]")
    _require(len(set(found)) == len(found), f"cuts: a cut-off solution came back: {found}")
    _require((1, 1, 0) not in found, "cuts: (1, 1, 0) breaks x0 & x1 => x2")


def check_rows_after_solving(backend: BackendClass) -> None:
    """Rows added after a solve tighten the optimum (4, then 5, then infeasible)."""
    model = no_overlap_makespan()
    solver = backend()
    solver.load(model)
    first = solver.solve()
    _require(first.objective == (4,), f"no-overlap-makespan: objective {first.objective}, the optimum is (4,)")
    makespan = len(model.vars) - 1
    solver.add_rows([Row(((makespan, 1),), lo=5, name="C>=5")])
    sol = solver.solve()
    _require(
        sol.status == SolveStatus.OPTIMAL and sol.objective == (5,),
        f"after C >= 5: {sol.status.value} {sol.objective}, expected optimal (5,)",
    )
    require_valid(model, sol, " after C >= 5")
    solver.add_rows([Row(((0, 1),), hi=0, name="p0 absent")])  # contradicts p0 >= 1
    sol = solver.solve()
    _require(
        sol.status == SolveStatus.INFEASIBLE, f"after p0 <= 0 (p0 >= 1 holds): {sol.status.value}, expected infeasible"
    )


def check_zero_variables(backend: BackendClass) -> None:
    """Models without variables: optimal with no values (objective 0 when there is one); a constant row
    0 >= 1 is infeasible (the encodings produce such rows)."""
    sol = solve(backend, SkeletonModel(name="empty"))
    _require((sol.status, sol.values, sol.objective) == (SolveStatus.OPTIMAL, (), ()), f"empty model: {sol}")
    sol = solve(backend, SkeletonModel(name="empty-objective", objectives=[()]))
    _require((sol.status, sol.values, sol.objective) == (SolveStatus.OPTIMAL, (), (0,)), f"empty objective: {sol}")
    sol = solve(backend, SkeletonModel(name="empty-true", rows=[Row((), lo=0, hi=0)]))
    _require(sol.status == SolveStatus.OPTIMAL, f"0 == 0: {sol.status.value}, expected optimal")
    sol = solve(backend, SkeletonModel(name="empty-false", rows=[Row((), lo=1)]))
    _require(sol.status == SolveStatus.INFEASIBLE, f"0 >= 1: {sol.status.value}, expected infeasible ({sol.message})")


def check_determinism(backend: BackendClass) -> None:
    """The same model and seed give the same values (the model has many optima)."""
    first = solve(backend, symmetric(), seed=7)
    second = solve(backend, symmetric(), seed=7)
    _require(
        first.status == second.status == SolveStatus.OPTIMAL, f"symmetric: {first.status.value}, {second.status.value}"
    )
    _require(first.values == second.values, f"symmetric, seed 7: {first.values} then {second.values}")
    require_valid(symmetric(), first)
    _require(
        objectives(symmetric(), first.values) == (3,),
        f"symmetric: objective {objectives(symmetric(), first.values)}, optimum (3,)",
    )


def check_time_limit(backend: BackendClass) -> None:
    """A 1 ms limit is a status (time limit, or a valid solution), and a 0.4 ms limit stops the solver
    within 0.3 s: the enumerator passes the *remaining* budget, which can be below 1 ms, and that must not
    mean "no limit"."""
    hard = hard_ish(1000)
    sol = solve(backend, hard, time_limit=0.001)
    _require(
        sol.status in (SolveStatus.TIME_LIMIT, SolveStatus.FEASIBLE, SolveStatus.OPTIMAL),
        f"1 ms limit: status {sol.status.value} ({sol.message})",
    )
    if sol.status in (SolveStatus.FEASIBLE, SolveStatus.OPTIMAL):
        require_valid(hard, sol, " (1 ms limit)")
    if sol.status == SolveStatus.OPTIMAL:
        _require(sol.objective == (999,), f"1 ms limit: claims optimal {sol.objective}, the optimum is (999,)")
    harder = hard_ish(2000)
    solver = backend()
    solver.load(harder)
    t0 = time.perf_counter()
    sol = solver.solve(time_limit=0.0004)
    elapsed = time.perf_counter() - t0
    _require(
        sol.status in (SolveStatus.TIME_LIMIT, SolveStatus.FEASIBLE, SolveStatus.OPTIMAL),
        f"0.4 ms limit: status {sol.status.value} ({sol.message})",
    )
    _require(elapsed < 0.3, f"0.4 ms limit: ran {elapsed:.2f} s ({sol.status.value})")


@functools.lru_cache(maxsize=None)
def fixtures() -> dict[str, tuple[str, tuple[int, int] | None]]:
    """Shipped symbolic fixture file name -> (its path, its expected first key (makespan, moved), None when
    infeasible), read from each file's first line ``; expect: ...``."""
    out: dict[str, tuple[str, tuple[int, int] | None]] = {}
    for path in sorted(FIXTURES.glob("*.mrg")):
        if path.name == "domain.mrg":
            continue
        first = path.read_text(encoding="utf-8").splitlines()[0]
        if not first.startswith("; expect: "):
            continue
        spec = first[len("; expect: ") :].strip()
        if spec == "infeasible":
            out[path.name] = (str(path), None)
        else:
            fields = dict(part.split("=") for part in spec.split())
            out[path.name] = (str(path), (int(fields["makespan"]), int(fields["moved"])))
    return out


def check_fixture(backend: BackendClass, fixture: str, encoding: str) -> None:
    """One shipped symbolic fixture compiled with ``encoding`` reaches its stated optimum, and its first
    skeleton passes the independent oracle."""
    from mrgc.language.loader import parse_file
    from mrgc.planner.skeletons import compile_problem
    from mrgc.testing.oracle import check_skeleton, problem_graph

    path, expected = fixtures()[fixture]
    problem = parse_file(path).problem()
    res = compile_problem(problem, backend=backend, encoding=encoding, skeletons=1)
    where = f"{fixture} ({encoding})"
    if expected is None:
        _require(
            res.status == "infeasible" and res.skeletons == [],
            f"{where}: {res.status}, expected infeasible ({res.reasons})",
        )
        return
    _require(res.status == "optimal", f"{where}: {res.status}, expected optimal ({res.reasons})")
    keys = [s.key for s in res.skeletons]
    _require(keys == [expected], f"{where}: first skeleton {keys}, expected {[expected]}")
    bad = check_skeleton(problem_graph(problem), res.skeletons[0])
    _require(not bad, f"{where}: the skeleton breaks the model: {bad}")


def check_symbolic_fixtures(backend: BackendClass) -> None:
    """Every shipped symbolic fixture with every encoding the backend supports (:func:`check_fixture`)."""
    _require(len(fixtures()) >= 10, f"only {len(fixtures())} symbolic fixtures found in {FIXTURES}")
    for fixture in fixtures():
        for encoding in backend.info.encodings:
            check_fixture(backend, fixture, encoding)


#: check name -> check; each raises ConformanceError when the backend fails it
CHECKS: dict[str, Callable[[BackendClass], None]] = {
    "known-optima": check_known_optima,
    "unique-optima": check_unique_optima,
    "load-keeps-model": check_load_keeps_model,
    "incremental-cuts": check_incremental_cuts,
    "rows-after-solving": check_rows_after_solving,
    "zero-variables": check_zero_variables,
    "determinism": check_determinism,
    "time-limit": check_time_limit,
    "symbolic-fixtures": check_symbolic_fixtures,
}


@dataclass
class ConformanceReport:
    """What :func:`check_backend` found: the checks passed, and each failed check with its message."""

    backend: str
    passed: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Whether every check passed."""
        return not self.failed

    def lines(self) -> list[str]:
        """The report in lines: a count, then each failed check with its message."""
        out = [f"backend {self.backend}: {len(self.passed)} of {len(self.passed) + len(self.failed)} checks passed"]
        out += [f"  {name}: {message}" for name, message in self.failed.items()]
        return out


def check_backend(backend: BackendClass, checks: Sequence[str] | None = None) -> ConformanceReport:
    """Run ``checks`` (default: all of :data:`CHECKS`) against ``backend``; a check that raises anything
    (the backend crashed) fails with the exception's type and message."""
    report = ConformanceReport(backend.info.name)
    for name in checks if checks is not None else CHECKS:
        try:
            CHECKS[name](backend)
        except Exception as exc:  # noqa: BLE001 - a crashing backend fails the check, the report goes on
            report.failed[name] = str(exc) if isinstance(exc, ConformanceError) else f"{type(exc).__name__}: {exc}"
        else:
            report.passed.append(name)
    return report
