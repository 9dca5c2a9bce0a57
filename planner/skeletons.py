"""Skeleton generation wired to a backend: facts → task graph → encoding → solver → skeletons.

A geometric problem without cached facts gets them from phase 1 (the geometry layer) first.  This is what
``mrgc compile`` runs, and what the planner calls whenever grounding needs new skeletons
(for other objects M*, with the grounded suffix's objects excluded).
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass, field
from typing import Any, Iterable

from mrgc.backends.base import Backend
from mrgc.backends.registry import backend_class, check_export
from mrgc.compiler.diagnose import explain_infeasible
from mrgc.compiler.encodings import get_encoding
from mrgc.compiler.enumerate import Batch, BatchOutcome, SkeletonGenerator
from mrgc.compiler.facts import FactBase
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import TaskGraph, build_task_graph
from mrgc.errors import Diagnostic, InputError
from mrgc.exits import ExitCode
from mrgc.language.model import Fact, Problem
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING


class CompileStatus(enum.StrEnum):
    """How compiling a problem ended (``mrgc.CompileStatus``; its value is what the JSON holds)."""

    #: the skeletons asked for, or every one that exists, in proven order
    OPTIMAL = "optimal"
    #: no skeleton within the horizon limit
    INFEASIBLE = "infeasible"
    TIME_LIMIT = "time limit"
    #: the solver failed (the reasons say how)
    ERROR = "error"


#: status -> exit code of ``mrgc compile`` when it found no skeleton (with a skeleton it exits 0)
COMPILE_EXIT_CODES: dict[CompileStatus, ExitCode] = {
    CompileStatus.OPTIMAL: ExitCode.OK,
    CompileStatus.INFEASIBLE: ExitCode.NO_PLAN,
    CompileStatus.TIME_LIMIT: ExitCode.TIME_LIMIT,
    CompileStatus.ERROR: ExitCode.INTERNAL,
}


@dataclass
class CompileResult:
    """The outcome of compiling a problem: a status and the skeletons in (makespan, moved) order."""

    problem: str
    backend: str
    encoding: str
    status: CompileStatus
    skeletons: list[Skeleton]
    reasons: list[str] = field(default_factory=list)
    stats: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The result as ``mrgc compile --format json`` prints it."""
        return {
            "problem": self.problem,
            "backend": self.backend,
            "encoding": self.encoding,
            "status": str(self.status),
            "skeletons": [s.to_json() for s in self.skeletons],
            "reasons": list(self.reasons),
            "stats": self.stats,
        }


def must_move(problem: Problem, facts: Iterable[Fact] | None = None) -> list[str]:
    """M* at the start: the goal objects not already in their goal region."""
    where = {f.args[0]: f.args[1] for f in (problem.init if facts is None else facts) if f.predicate == "in-region"}
    return [o for o, r in problem.goal_regions.items() if where.get(o) != r]


def needs_facts(problem: Problem) -> bool:
    """A geometric problem whose ``:init`` holds no geometric facts (phase 1 has not been run or cached)."""
    return not problem.symbolic and all(f.predicate == "in-region" for f in problem.init)


def problem_facts(problem: Problem, facts: Iterable[Fact] | None = None, seed: int = 0) -> tuple[list[Fact], float]:
    """The facts to compile with: given ones, the file's ``:init``, or phase 1 run now (and its seconds)."""
    found, seconds = facts_until(problem, facts, seed, None)
    assert found is not None  # no deadline: phase 1 runs to its end
    return found, seconds


def facts_until(
    problem: Problem, facts: Iterable[Fact] | None, seed: int, deadline: float | None
) -> tuple[list[Fact] | None, float]:
    """:func:`problem_facts` for a planner with a ``deadline`` (a ``time.perf_counter`` value): None for the
    facts when phase 1 had to run and the deadline cut it short."""
    if facts is not None:
        return list(facts), 0.0
    if needs_facts(problem):
        from mrgc.planner.phase1 import compute_problem_facts

        result = compute_problem_facts(problem, seed=seed, deadline=deadline)
        return (list(result.facts) if result.complete else None), float(result.stats["seconds"])
    return list(problem.init), 0.0


class SkeletonSource:
    """Skeletons for one (M*, already moved) request, from a chosen backend and encoding; resumable."""

    def __init__(
        self,
        facts: FactBase,
        must: Iterable[str],
        moved: Iterable[str] = (),
        backend: str | type[Backend] = DEFAULT_BACKEND,
        encoding: str = DEFAULT_ENCODING,
        max_makespan: int | None = None,
        seed: int = 0,
    ) -> None:
        cls = backend if isinstance(backend, type) else backend_class(backend)
        backend = cls.info.name
        self.backend, self.encoding = backend, encoding
        try:
            enc = get_encoding(encoding)
        except ValueError as exc:
            raise InputError([Diagnostic("E303", str(exc))]) from None
        if encoding not in cls.info.encodings:
            raise InputError([Diagnostic("E302", f"backend '{backend}' does not support encoding '{encoding}'")])
        t0 = time.perf_counter()
        self.graph: TaskGraph = build_task_graph(facts, must, moved)
        self.reasons = explain_infeasible(self.graph, facts)
        self.graph_seconds = time.perf_counter() - t0
        self.generator = SkeletonGenerator(
            self.graph, enc, lambda: cls(seed=seed), max_makespan, grow_horizon=cls.info.grow_horizon
        )
        if self.reasons:
            self.generator.done = True

    def next(self, k: int, deadline: float | None = None) -> Batch:
        """Up to ``k`` further skeletons, in (makespan, moved) order, by ``deadline`` (a ``time.perf_counter()``
        instant; None: none)."""
        return self.generator.next(k, deadline)


def compile_problem(
    problem: Problem,
    backend: str | type[Backend] = DEFAULT_BACKEND,
    encoding: str = DEFAULT_ENCODING,
    skeletons: int = 1,
    max_makespan: int | None = None,
    time_limit: float | None = None,
    facts: Iterable[Fact] | None = None,
    seed: int = 0,
) -> CompileResult:
    """The first ``skeletons`` skeletons of ``problem`` (facts default to its ``:init``); ``backend`` is a
    registered name or a :class:`~mrgc.backends.base.Backend` subclass."""
    fact_list, facts_seconds = problem_facts(problem, facts, seed)
    base = FactBase.from_problem(problem, fact_list)
    source = SkeletonSource(base, must_move(problem, fact_list), (), backend, encoding, max_makespan, seed)
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + time_limit
    batch = source.next(min(1, skeletons), deadline)  # the first alone, to time it; then the rest
    first = time.perf_counter() - t0 + source.graph_seconds if batch.skeletons else None
    if skeletons > 1 and batch.outcome is BatchOutcome.ENOUGH:
        more = source.next(skeletons - 1, deadline)
        batch = Batch(batch.skeletons + more.skeletons, more.outcome, more.message, more.stats or batch.stats)
    stats: dict[str, Any] = {
        "objects": len(source.graph.objects),
        "actions": len(source.graph.actions),
        "must_move": list(source.graph.must_move),
        "facts": len(fact_list),
        "facts_seconds": round(facts_seconds, 6),
        "graph_seconds": round(source.graph_seconds, 6),
        "total_seconds": round(time.perf_counter() - t0 + source.graph_seconds, 6),
        "first_seconds": None if first is None else round(first, 6),  # the task graph and the first skeleton
        **{k: (round(v, 6) if isinstance(v, float) else v) for k, v in batch.stats.items()},
    }
    if batch.outcome is BatchOutcome.ERROR:
        status = CompileStatus.ERROR
    elif batch.outcome is BatchOutcome.TIME_LIMIT:
        status = CompileStatus.TIME_LIMIT
    elif not batch.skeletons and batch.outcome is BatchOutcome.EXHAUSTED:
        status = CompileStatus.INFEASIBLE
    else:
        status = CompileStatus.OPTIMAL
    reasons = list(source.reasons) or ([batch.message] if batch.message else [])
    return CompileResult(problem.name, source.backend, encoding, status, batch.skeletons, reasons, stats)


def export_model(
    problem: Problem,
    path: str,
    backend: str | type[Backend] = DEFAULT_BACKEND,
    encoding: str = DEFAULT_ENCODING,
    horizon: int | None = None,
    facts: Iterable[Fact] | None = None,
    max_makespan: int | None = None,
    seed: int = 0,
) -> int:
    """Write the skeleton model of horizon ``horizon`` to ``path`` and return the horizon written (default:
    the horizon limit, ``max_makespan`` capped at the number of objects of the task graph).  The model holds
    no cuts: its optimum is the first skeleton of that horizon.  ``seed``: the backend's seed, which formats
    that carry one write (SMT-LIB's ``:random-seed``)."""
    fact_list, _ = problem_facts(problem, facts)
    base = FactBase.from_problem(problem, fact_list)
    source = SkeletonSource(base, must_move(problem, fact_list), (), backend, encoding, max_makespan)
    gen = source.generator
    chosen = horizon or gen.limit
    enc = gen.encoding.build(gen.graph, chosen)
    check_export(backend, path)
    solver = (backend if isinstance(backend, type) else backend_class(backend))(seed=seed)
    solver.load(enc.model)
    solver.export(path)
    return chosen
