"""The backend conformance kit: every registered backend on small IR models with known optima, and on every
symbolic fixture through compile_problem.

Each IR model's expected optimum is hard-coded *and* recomputed by an exhaustive search written here
(``brute_force``: its own evaluation of rows, conditional rows, at-most-one and no-overlap; it does not use
``SkeletonModel.violated``), so a wrong constant in this file cannot hide a backend bug.
"""

from __future__ import annotations

import functools
import itertools
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import pytest

from mrgc import parse_file
from mrgc.backends.registry import backend_class, names
from mrgc.compiler.ir import AtMostOne, NoOverlap, Row, SkeletonModel, Solution, Status
from mrgc.planner.skeletons import compile_problem

BACKENDS = names()
ENCODINGS = ["paper", "disaggregated", "time-of-move"]
SYMBOLIC = Path(__file__).resolve().parent.parent / "domains" / "symbolic"


import skeleton_oracle as oracle  # noqa: E402 - registered by tests/conftest.py


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
    return tuple(sum(c * values[v] for v, c in terms) for terms in model.objectives)


def brute_force(model: SkeletonModel) -> tuple[Status, tuple[int, ...] | None, list[tuple[int, ...]]]:
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
    return (Status.INFEASIBLE if best is None else Status.OPTIMAL), best, arg


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

    The unique optimum (a=1, b=1, c=0, x=3, y=-2: objective 5) changes if negative literals were read as positive
    ones, or conditions with several literals as their first literal only.
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


MODELS: dict[str, tuple[Callable[[], SkeletonModel], Status, tuple[int, ...] | None]] = {
    "pure-rows": (pure_rows, Status.OPTIMAL, (5,)),
    "ints": (rows_with_ints, Status.OPTIMAL, (6,)),
    "conditional": (conditional_rows, Status.OPTIMAL, (5,)),
    "at-most-one": (at_most_one, Status.OPTIMAL, (-5,)),
    "no-overlap": (no_overlap, Status.OPTIMAL, (-7,)),
    "no-overlap-makespan": (no_overlap_makespan, Status.OPTIMAL, (4,)),
    "lexicographic": (lexicographic, Status.OPTIMAL, (0, 8, -1)),
    "infeasible-bools": (infeasible_bools, Status.INFEASIBLE, None),
    "infeasible-integrality": (infeasible_integrality, Status.INFEASIBLE, None),
    "infeasible-conditional": (infeasible_conditional, Status.INFEASIBLE, None),
}


def solve(backend: str, model: SkeletonModel, time_limit: float | None = None, seed: int = 0) -> Solution:
    solver = backend_class(backend)(seed=seed)
    solver.load(model)
    return solver.solve(time_limit)


def assert_valid(model: SkeletonModel, sol: Solution) -> None:
    """A returned solution satisfies the model by both its own self-check and the independent one."""
    values = sol.values[: len(model.vars)]
    assert len(values) == len(model.vars), sol
    assert model.violated(values) == []
    assert satisfies(model, values)


# ---------------------------------------------------------------- the reference solver agrees with the constants
@pytest.mark.parametrize("name", MODELS)
def test_expected_optima_are_right(name: str) -> None:
    build, status, best = MODELS[name]
    assert brute_force(build())[:2] == (status, best)


def test_conditional_model_tells_negative_literals_apart() -> None:
    """Reading every negative literal as positive would change the optimum (so the test can fail)."""
    m = conditional_rows()
    flipped = SkeletonModel(m.vars, m.rows, [type(cr)(tuple((v, True) for v, _ in cr.when), cr.row, cr.big_m)
                                              for cr in m.cond_rows], objectives=m.objectives)
    first_only = SkeletonModel(m.vars, m.rows, [type(cr)(cr.when[:1], cr.row, cr.big_m) for cr in m.cond_rows],
                               objectives=m.objectives)
    best = brute_force(m)[1]
    assert brute_force(flipped)[1] != best
    assert brute_force(first_only)[1] != best


def test_lexicographic_model_tells_weightings_apart() -> None:
    m = lexicographic()
    status, lex, _ = brute_force(m)
    assert status == Status.OPTIMAL and lex == (0, 8, -1)
    naive = SkeletonModel(m.vars, m.rows, objectives=[((m.objectives[0][0][0], 16),) + m.objectives[1] + m.objectives[2]])
    _, _, arg = brute_force(naive)
    assert arg and all(objectives(m, v)[0] == 1 for v in arg)  # a too-small weight picks a = 1


# ---------------------------------------------------------------- every backend on every model
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("backend", BACKENDS)
def test_backend_reaches_the_known_optimum(backend: str, name: str) -> None:
    build, status, best = MODELS[name]
    model = build()
    sol = solve(backend, model)
    assert sol.status == status, sol.message
    if status == Status.OPTIMAL:
        assert_valid(model, sol)
        assert objectives(model, sol.values) == best
        if len(model.objectives) == 1:
            assert sol.objective == best  # what the backend reports is what the values give
    else:
        assert sol.values == ()


@pytest.mark.parametrize("backend", BACKENDS)
def test_unique_optima_are_found_exactly(backend: str) -> None:
    for build in (at_most_one, conditional_rows, no_overlap_makespan):
        model = build()
        _, _, arg = brute_force(model)
        sol = solve(backend, model)
        values = tuple(sol.values[: len(model.vars)])
        assert values in arg, (model.name, values, arg[:5])
        if build is at_most_one:
            assert values == (0, 1, 0, 1)
        if build is conditional_rows:
            assert values == (1, 1, 0, 3, -2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_loading_does_not_change_the_model(backend: str) -> None:
    model = no_overlap()
    before = (list(model.vars), list(model.rows), list(model.cond_rows), list(model.no_overlap),
              list(model.objectives))
    solver = backend_class(backend)()
    solver.load(model)
    solver.add_rows([Row(((0, 1),), hi=0)])
    solver.solve()
    assert (model.vars, model.rows, model.cond_rows, model.no_overlap, model.objectives) == before


# ---------------------------------------------------------------- incremental cuts
@pytest.mark.parametrize("backend", BACKENDS)
def test_incremental_cuts_walk_through_every_solution_in_order(backend: str) -> None:
    """min x0+x1+x2 s.t. sum >= 1, each solution cut off after it is found: 1,1,1,2,2,2,3, then infeasible."""
    model = SkeletonModel(name="cuts")
    xs = [model.bool_var(f"x{i}") for i in range(3)]
    model.add([(x, 1) for x in xs], lo=1)
    model.add_if([(xs[0], True), (xs[1], True)], [(xs[2], 1)], lo=1)  # x0 & x1 => x2: {x0,x1} alone is out
    model.objectives.append(tuple((x, 1) for x in xs))
    solver = backend_class(backend)()
    solver.load(model)
    found, costs = [], []
    for _ in range(10):
        sol = solver.solve()
        if sol.status == Status.INFEASIBLE:
            break
        assert sol.status == Status.OPTIMAL, sol.message
        values = tuple(sol.values[:3])
        assert_valid(model, sol)
        found.append(values)
        costs.append(sum(values))
        ones = [x for x, v in zip(xs, values) if v]
        solver.add_rows([Row(tuple((x, -1 if v else 1) for x, v in zip(xs, values)), lo=1 - len(ones), name="cut")])
    assert costs == [1, 1, 1, 2, 2, 3]
    assert len(set(found)) == len(found)
    assert (1, 1, 0) not in found


@pytest.mark.parametrize("backend", BACKENDS)
def test_rows_added_after_solving_tighten_the_optimum(backend: str) -> None:
    model = no_overlap_makespan()
    solver = backend_class(backend)()
    solver.load(model)
    assert solver.solve().objective == (4,)
    makespan = len(model.vars) - 1
    solver.add_rows([Row(((makespan, 1),), lo=5, name="C>=5")])
    sol = solver.solve()
    assert sol.status == Status.OPTIMAL and sol.objective == (5,)
    assert_valid(model, sol)
    solver.add_rows([Row(((0, 1),), hi=0, name="p0 absent")])  # contradicts p0 >= 1
    assert solver.solve().status == Status.INFEASIBLE


# ---------------------------------------------------------------- zero variables
@pytest.mark.parametrize("backend", BACKENDS)
def test_model_with_zero_variables(backend: str) -> None:
    empty = SkeletonModel(name="empty")
    sol = solve(backend, empty)
    assert (sol.status, sol.values, sol.objective) == (Status.OPTIMAL, (), ())
    with_objective = SkeletonModel(name="empty-objective", objectives=[()])
    sol = solve(backend, with_objective)
    assert (sol.status, sol.values, sol.objective) == (Status.OPTIMAL, (), (0,))
    true_row = SkeletonModel(name="empty-true", rows=[Row((), lo=0, hi=0)])
    assert solve(backend, true_row).status == Status.OPTIMAL


@pytest.mark.parametrize("backend", BACKENDS)
def test_model_with_zero_variables_and_a_false_row_is_infeasible(backend: str) -> None:
    """0 >= 1 cannot hold.  (The skeleton encodings produce such rows, e.g. constraint (5) of a graph without
    actions, or a cut on an empty selection.)"""
    false_row = SkeletonModel(name="empty-false", rows=[Row((), lo=1)])
    sol = solve(backend, false_row)
    assert sol.status == Status.INFEASIBLE, (sol.status, sol.message)


# ---------------------------------------------------------------- determinism
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


@pytest.mark.parametrize("backend", BACKENDS)
def test_same_model_and_seed_give_the_same_values(backend: str) -> None:
    first = solve(backend, symmetric(), seed=7)
    second = solve(backend, symmetric(), seed=7)
    assert first.status == second.status == Status.OPTIMAL
    assert first.values == second.values
    assert_valid(symmetric(), first)
    assert objectives(symmetric(), first.values) == (3,)


# ---------------------------------------------------------------- time limits
def hard_ish(n: int = 1000) -> SkeletonModel:
    """A weighted covering chain: trivial structure, but large enough that no backend solves it in 1 ms
    (z3 takes ~0.5 s, pysmt's bound tightening minutes)."""
    m = SkeletonModel(name="hard-ish")
    xs = [m.bool_var(f"x{i}") for i in range(n)]
    for i in range(n - 1):
        m.add([(xs[i], 1), (xs[i + 1], 1)], lo=1)
    for i in range(0, n - 2, 3):
        m.add([(xs[i], 1), (xs[i + 1], 1), (xs[i + 2], 1)], hi=2)
    m.objectives.append(tuple((x, 1 + i % 3) for i, x in enumerate(xs)))
    return m


@pytest.fixture(scope="module")
def hard_model() -> SkeletonModel:
    return hard_ish()


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_tiny_time_limit_is_a_status_not_an_error(backend: str, hard_model: SkeletonModel) -> None:
    solver = backend_class(backend)()
    solver.load(hard_model)
    sol = solver.solve(time_limit=0.001)
    assert sol.status in (Status.TIME_LIMIT, Status.FEASIBLE, Status.OPTIMAL), (sol.status, sol.message)
    if sol.status in (Status.FEASIBLE, Status.OPTIMAL):
        assert_valid(hard_model, sol)
    if sol.status == Status.OPTIMAL:
        assert sol.objective == (999,)


@pytest.fixture(scope="module")
def harder_model() -> SkeletonModel:
    return hard_ish(2000)  # z3 needs ~2 s to solve it, the other backends far longer


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_sub_millisecond_time_limit_is_still_a_limit(backend: str, harder_model: SkeletonModel) -> None:
    """The enumerator passes the *remaining* budget, which can be below 1 ms; that must not mean 'no limit'."""
    solver = backend_class(backend)()
    solver.load(harder_model)
    t0 = time.perf_counter()
    sol = solver.solve(time_limit=0.0004)
    elapsed = time.perf_counter() - t0
    assert sol.status in (Status.TIME_LIMIT, Status.FEASIBLE, Status.OPTIMAL), (sol.status, sol.message)
    assert elapsed < 0.3, f"{backend} ran {elapsed:.2f} s on a 0.4 ms time limit ({sol.status})"


# ---------------------------------------------------------------- the symbolic fixtures
FIXTURES = sorted(p.name for p in SYMBOLIC.glob("*.mrg") if p.name != "domain.mrg")


@functools.lru_cache(maxsize=None)
def _fixture(name: str) -> Any:
    path = SYMBOLIC / name
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("; expect: "), first
    spec = first[len("; expect: "):].strip()
    if spec == "infeasible":
        expected = None
    else:
        fields = dict(part.split("=") for part in spec.split())
        expected = (int(fields["makespan"]), int(fields["moved"]))
    return parse_file(str(path)).problem(), expected


def test_fixtures_are_all_found() -> None:
    assert len(FIXTURES) >= 10 and "chain-3.mrg" in FIXTURES and "infeasible.mrg" in FIXTURES


@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("fixture", FIXTURES)
def test_fixture_reaches_its_expected_optimum(fixture: str, backend: str, encoding: str) -> None:
    problem, expected = _fixture(fixture)
    res = compile_problem(problem, backend=backend, encoding=encoding, skeletons=1)
    if expected is None:
        assert res.status == "infeasible" and res.skeletons == [], (res.status, res.reasons)
        return
    assert res.status == "optimal", (res.status, res.reasons)
    assert [s.key for s in res.skeletons] == [expected]
    assert oracle.check_skeleton(_graph(fixture), res.skeletons[0]) == []


@functools.lru_cache(maxsize=None)
def _graph(fixture: str) -> Any:
    problem, _ = _fixture(fixture)
    facts = [(f.predicate, *f.args) for f in problem.init]
    region = {f.args[0]: f.args[1] for f in problem.init if f.predicate == "in-region"}
    must = [o for o, r in problem.goal_regions.items() if region.get(o) != r]
    return oracle.reference_task_graph([r.name for r in problem.robots],
                                       {m.name: problem.grasps_of(m.name) for m in problem.movable},
                                       problem.goal_regions, region, facts, must)


@pytest.mark.parametrize("fixture", FIXTURES)
def test_fixture_expectation_agrees_with_the_brute_force_oracle(fixture: str) -> None:
    _, expected = _fixture(fixture)
    keys = oracle.oracle_keys(_graph(fixture))
    assert (keys[0] if keys else None) == expected
