"""The public Python API: what every ``mrgc`` command runs (the CLI only parses arguments and prints).

Every function takes a checked :class:`~mrgc.language.model.Problem` (from :func:`parse_file` /
:func:`parse_string`) or the path of a ``.mrg`` file (``name`` picks a problem of a file holding several;
``allow_outside`` are the folders, besides the file's own tree, its meshes and URDFs may come from).
Bad input raises :class:`~mrgc.errors.InputError` carrying located diagnostics; outcomes (infeasible, a
time limit, an invalid plan) are values: a status on the result.  Nothing here asks for file hashes or
version strings: plans record them themselves.  docs/api.md documents each function with examples (a test
runs them).

Heavy libraries (solvers, geometry) load only when a function needs them; importing this module is cheap.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, Sequence, Union

from mrgc.errors import Diagnostic, InputError
from mrgc.limits import checked
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING, DEFAULT_PLANNER, DEFAULT_TIME_LIMIT

if TYPE_CHECKING:
    from mrgc.backends.base import Backend
    from mrgc.backends.registry import BackendRecord
    from mrgc.geometry.facts import FactsResult
    from mrgc.language.loader import MrgFile
    from mrgc.language.model import Fact, Problem, RobotKind
    from mrgc.planner.plan import Plan
    from mrgc.planner.skeletons import CompileResult
    from mrgc.planner.summary import FactsSummary
    from mrgc.validator.validate import ValidationReport

#: a problem as the API takes it: checked, or the path of its ``.mrg`` file
ProblemSource = Union["Problem", str, "os.PathLike[str]"]
#: a backend as the API takes it: a registered name (``mrgc backends``) or a Backend subclass (a plug-in
#: under test, not registered)
BackendSpec = Union[str, "type[Backend]"]


# ---------------------------------------------------------------- reading problems
@dataclass(frozen=True)
class CheckReport:
    """A checked file (``file``) and the warnings about it (``W###``: accepted, but part of it will not be
    used, e.g. an object in no region); errors are raised instead."""

    file: "MrgFile"
    warnings: tuple[Diagnostic, ...] = ()
    #: what was worked out for the user, one line each (``FILE:LINE:COL: note: ...``): the tool centre point
    #: derived for a robot kind without ``:tcp`` (docs/language.md, "Robot kinds")
    notes: tuple[str, ...] = ()


def check(path: str | os.PathLike[str], *, allow_outside: Sequence[str] = ()) -> CheckReport:
    """What ``mrgc check`` does for one file: parse and check it (every error at once, as InputError), then
    the layout checks of its geometric problems that need no robot model beyond the URDF files
    (docs/errors.md: overlapping objects, a robot's footprint on an object, a ``:home`` of the wrong length,
    objects in no region, regions no robot reaches)."""
    from mrgc.language.loader import parse_file

    mf = parse_file(path, allow_outside=tuple(allow_outside))
    warnings: list[Diagnostic] = []
    errors: list[Diagnostic] = []
    for p in mf.problems:
        for d in _layout(p, False):
            (warnings if d.severity == "warning" else errors).append(d)
    if errors:
        raise InputError(errors, {mf.path: mf.text})
    return CheckReport(mf, tuple(warnings), tuple(_tcp_notes(mf)))


def _tcp_notes(mf: "MrgFile") -> list[str]:
    """A note for each fixed-base robot kind of the file (its domains and its problems' domains) without
    ``:tcp`` whose tool centre point is derived from its URDF."""
    kinds: dict[tuple[str, object, str], "RobotKind"] = {}
    for domain in [*mf.domains, *(p.domain for p in mf.problems)]:
        for kind in domain.robot_kinds:
            kinds.setdefault((kind.source, kind.span, kind.name), kind)
    if not any(k.tcp is None and not k.driven for k in kinds.values()):
        return []
    from mrgc.geometry.tcp import derive_tcp

    notes = []
    for kind in kinds.values():
        derived = derive_tcp(kind) if kind.tcp is None else None
        if derived is not None:
            notes.append(
                f"{kind.span}: note: robot kind '{kind.name}' has no :tcp: using {derived.text()} from the "
                f"{derived.source} of '{kind.urdf}'"
            )
    return notes


def load_problem(source: ProblemSource, *, name: str | None = None, allow_outside: Sequence[str] = ()) -> "Problem":
    """The checked problem ``source`` stands for: itself, or problem ``name`` (default: the only one) of the
    file at that path."""
    return _resolve(source, name, allow_outside)[0]


def _resolve(source: ProblemSource, name: str | None, allow_outside: Sequence[str]) -> tuple["Problem", str | None]:
    """(problem, the path of the file it was read from, when it was read from an existing file)."""
    from mrgc.language.model import Problem

    if isinstance(source, Problem):
        if name is not None and name != source.name:
            raise InputError([Diagnostic("E230", f"the problem given is '{source.name}', not '{name}'")])
        return source, source.source if source.source and os.path.isfile(source.source) else None
    from mrgc.language.loader import parse_file

    if not isinstance(source, (str, os.PathLike)):
        what = type(source).__name__
        raise InputError([Diagnostic("E000", f"a problem is a file's path or a Problem, not a {what}")])
    path = os.fspath(source)
    return parse_file(path, allow_outside=tuple(allow_outside)).problem(name), path


#: the layout warnings that can explain why a plan was not found (named first among its reasons)
NO_PLAN_WARNINGS = ("W277", "W278", "W279")


def _layout(problem: "Problem", robots: bool, arms: bool = True) -> list[Diagnostic]:
    """The layout diagnostics of a geometric problem (none for a symbolic one): those ``check`` reports, or
    (``robots``) those that need the robots' models (docs/errors.md, E263-E268, W270-W272); ``arms`` False
    leaves out the warnings W274-W276 (:mod:`mrgc.geometry.arm_diagnosis`)."""
    if problem.symbolic:
        return []
    from mrgc.geometry import layout

    return layout.robot_diagnostics(problem, arms) if robots else layout.layout_diagnostics(problem, arms)


def _checked_layout(problem: "Problem", robots: bool = True, arms: bool = True) -> list[Diagnostic]:
    """InputError when the layout of a geometric problem has errors (of ``check``'s checks, and with
    ``robots`` of those needing the robots' models too); else the warnings of the robot-model checks
    (without W274-W276 when not ``arms``: warnings, never errors)."""
    errors = [d for d in _layout(problem, False, arms) if d.severity != "warning"]
    found = _layout(problem, True, arms) if robots and not errors else []
    errors += [d for d in found if d.severity != "warning"]
    if errors:
        raise InputError(errors)
    return found


# ---------------------------------------------------------------- phase 1
def compute_facts(
    source: ProblemSource,
    *,
    name: str | None = None,
    seed: int = 0,
    workers: int | None = None,
    allow_outside: Sequence[str] = (),
) -> "FactsResult":
    """Phase 1: every geometric fact of a geometric problem (``.facts``, sorted) and timing statistics
    (``.stats``); ``workers`` processes (default one per robot).  InputError E402 for a symbolic problem."""
    from mrgc.planner.phase1 import compute_problem_facts

    checked("seed", seed, "count")
    checked("workers", workers, "count", none=True)
    problem = load_problem(source, name=name, allow_outside=allow_outside)
    warnings = _checked_layout(problem, robots=True)
    result = compute_problem_facts(problem, seed=seed, workers=workers)
    result.warnings = tuple(warnings)
    return result


def facts_summary(
    source: ProblemSource,
    *,
    name: str | None = None,
    facts: Iterable["Fact"] | None = None,
    seed: int = 0,
    allow_outside: Sequence[str] = (),
) -> "FactsSummary":
    """What the facts of a problem say, for a person (``mrgc facts --summary``): per robot the objects it
    can pick, the regions it can place in, its handover and relay partners; per goal how it can be
    delivered (``direct``, ``handover``, ``relay``, ``none``); the objects and goals nobody reaches, each
    with its nearest miss (:class:`~mrgc.planner.summary.FactsSummary`; ``.text()`` as the command prints
    it, ``.to_json()``).  ``facts`` default to the problem's ``:init``, or phase 1 run now."""
    from mrgc.planner.skeletons import needs_facts, problem_facts
    from mrgc.planner.summary import summarize

    checked("seed", seed, "count")
    problem = load_problem(source, name=name, allow_outside=allow_outside)
    warnings = _checked_layout(problem, robots=facts is None and needs_facts(problem))
    fact_list, _ = problem_facts(problem, facts, seed=seed)
    summary = summarize(problem, fact_list)
    summary.warnings = tuple(warnings)
    return summary


# ---------------------------------------------------------------- skeletons
def compile(  # noqa: A001
    source: ProblemSource,
    *,
    name: str | None = None,
    backend: BackendSpec = DEFAULT_BACKEND,
    encoding: str = DEFAULT_ENCODING,
    skeletons: int = 1,
    max_makespan: int | None = None,
    time_limit: float | None = None,
    facts: Iterable["Fact"] | None = None,
    seed: int = 0,
    allow_outside: Sequence[str] = (),
) -> "CompileResult":
    """The first ``skeletons`` task skeletons of a problem in (makespan, objects moved) order, with a status
    (``optimal``, ``infeasible``, ``time limit``, ``error``), the compiler's reasons when there is none, and
    statistics (``stats``: task-graph size, solver calls, seconds per phase).  ``facts``: an iterable of
    :class:`~mrgc.language.model.Fact` (``mrgc.Fact``; e.g. ``compute_facts(p).facts``) used as the
    problem's facts; default: its ``:init``, or phase 1 run now for a geometric problem without them
    (through the facts cache, docs/geometry.md)."""
    from mrgc.planner.skeletons import compile_problem, needs_facts, problem_facts

    checked("seed", seed, "count")
    checked("skeletons", skeletons, "count")
    checked("max_makespan", max_makespan, "count", none=True)
    checked("time_limit", time_limit, "number", none=True, positive=True)
    problem = load_problem(source, name=name, allow_outside=allow_outside)
    _checked_layout(problem, robots=facts is None and needs_facts(problem))
    fact_list, facts_seconds = problem_facts(problem, facts, seed=seed)
    result = compile_problem(
        problem,
        backend=DEFAULT_BACKEND if backend is None else backend,
        encoding=encoding,
        skeletons=skeletons,
        max_makespan=max_makespan,
        time_limit=time_limit,
        facts=fact_list,
        seed=seed,
    )
    result.stats["facts_seconds"] = round(facts_seconds, 6)
    return result


def export_model(
    source: ProblemSource,
    path: str | os.PathLike[str],
    *,
    name: str | None = None,
    backend: BackendSpec = DEFAULT_BACKEND,
    encoding: str = DEFAULT_ENCODING,
    horizon: int | None = None,
    max_makespan: int | None = None,
    facts: Iterable["Fact"] | None = None,
    seed: int = 0,
    allow_outside: Sequence[str] = (),
) -> int:
    """Write the skeleton model of a problem to ``path`` in the backend's format (its extension: ``.lp`` /
    ``.mps`` for ``mip``, ``.smt2`` for ``smt``, ``.pbtxt`` for ``cpsat``) and return its horizon.

    The model is the one the backend solves for the first skeleton, without cuts: its optimum is the first
    skeleton's (makespan, objects moved).  ``horizon`` T chooses another: for the ``paper`` and
    ``disaggregated`` encodings the model of skeletons of exactly T steps, for ``time-of-move`` of at most T
    steps.  By default T is the makespan of the first skeleton (compiled now; when the goals hold at the start
    and it is 0, 1 for ``time-of-move`` and InputError E304 for the encodings of exactly T non-empty steps,
    :func:`emit_horizon`), or, when there is none, the horizon limit (``max_makespan``, capped at the number
    of objects in the task graph).
    docs/backends.md says what each file holds and how to load it into its solver.
    """
    from mrgc.planner.skeletons import export_model as write_model
    from mrgc.planner.skeletons import needs_facts, problem_facts

    checked("seed", seed, "count")
    checked("horizon", horizon, "count", none=True)
    checked("max_makespan", max_makespan, "count", none=True)
    backend = DEFAULT_BACKEND if backend is None else backend
    problem = load_problem(source, name=name, allow_outside=allow_outside)
    _checked_layout(problem, robots=facts is None and needs_facts(problem))
    fact_list, _ = problem_facts(problem, facts, seed=seed)
    if horizon is None:
        result = compile(
            problem, backend=backend, encoding=encoding, max_makespan=max_makespan, facts=fact_list, seed=seed
        )
        horizon = emit_horizon(problem.name, result, encoding)
    return write_model(
        problem,
        os.fspath(path),
        backend=backend,
        encoding=encoding,
        horizon=horizon,
        facts=fact_list,
        max_makespan=max_makespan,
        seed=seed,
    )


def emit_horizon(name: str, result: "CompileResult", encoding: str) -> int | None:
    """The horizon of the model ``compile --emit`` writes by default: the first skeleton's makespan (None
    when there is no skeleton: the horizon limit).  When it is 0 (the goals of problem ``name`` hold at the
    start): 1 for an encoding whose model of T steps covers every makespan up to T (``time-of-move``: its
    model of one step has the empty skeleton as its optimum), else InputError E304 (an encoding of exactly
    T non-empty steps, ``horizon_loop``: no model of it has that optimum)."""
    from mrgc.compiler.encodings import get_encoding

    horizon = result.skeletons[0].makespan if result.skeletons else None
    if horizon == 0 and not get_encoding(encoding).horizon_loop:
        return 1
    if horizon == 0:
        raise InputError(
            [
                Diagnostic(
                    "E304",
                    f"{name}: the goals hold at the start (makespan 0): the {encoding} encoding has no model with "
                    "that optimum (its steps are never empty), nothing to export (give a horizon H for the "
                    "model of H steps)",
                )
            ]
        )
    return horizon


# ---------------------------------------------------------------- planning
def plan(
    source: ProblemSource,
    *,
    name: str | None = None,
    planner: str = DEFAULT_PLANNER,
    backend: str | None = None,
    encoding: str | None = None,
    seed: int = 0,
    time_limit: float = DEFAULT_TIME_LIMIT,
    log: Callable[[str], None] | None = None,
    allow_outside: Sequence[str] = (),
    facts: Iterable["Fact"] | None = None,
    **options: Any,
) -> "Plan":
    """Plan a problem end to end: phase 1 (unless the file holds its facts), task skeletons, then the
    planner's search; a geometric plan counts only once the independent validator accepted it.

    Returns a :class:`~mrgc.planner.plan.Plan`: ``status`` (:class:`~mrgc.planner.outcome.PlanStatus`:
    solved, infeasible, exhausted, time limit, interrupted), ``why`` (the reasons behind it), ``steps``,
    ``stats`` and ``dumps()`` (the plan JSON, docs/plan.schema.json).  ``planner`` names a method of
    :data:`mrgc.planner.registry.PLANNERS` (``mcts``, the paper's method, or a baseline, docs/baselines.md);
    ``options`` are the options it declares (``mcts``: ``backend`` and ``encoding`` (default cpsat,
    time-of-move), ``c``, ``alpha``, ``skeletons``, ``max_makespan``, ``anytime``, ``max_iterations``; every
    method: ``motions``); an option the method does not declare is InputError E000; ``log`` gets the
    search's log lines.  The plan records the problem's content digest, so it validates
    against any file holding the same problem (its facts file too).

    ``facts`` (an iterable of :class:`~mrgc.language.model.Fact`, e.g. ``compute_facts(p).facts`` or the
    ``:init`` of a facts file) are used as the problem's facts, skipping phase 1; default: the file's
    ``:init`` when it holds geometric facts, else phase 1, through the facts cache (docs/geometry.md, "The
    facts cache").  Facts of another problem give wrong plans, which the validator then rejects.
    """
    import time

    from mrgc import __version__
    from mrgc.language.digest import problem_digest
    from mrgc.planfile.format import file_sha256
    from mrgc.planner.baselines import plan_with
    from mrgc.planner.outcome import PlanStatus

    started = time.perf_counter()  # the time limit covers the layout checks, which load the robots' models
    checked("seed", seed, "count")
    checked("time_limit", time_limit, "number", positive=True)
    problem, path = _resolve(source, name, allow_outside)
    _checked_layout(problem, arms=False)  # W274-W276 (warnings) only explain a plan not found: asked for then
    digest = problem_digest(problem)
    problem_file = path if path is not None else (problem.source or "<string>")
    sha256 = file_sha256(path) if path is not None else digest
    result = plan_with(
        planner,
        problem,
        problem_file,
        sha256,
        __version__,
        seed=seed,
        time_limit=time_limit,
        log=log,
        started=started,
        **{k: v for k, v in (("backend", backend), ("encoding", encoding)) if v is not None},
        **({"facts": list(facts)} if facts is not None else {}),
        **options,
    )
    result.problem_digest = digest
    if result.why is not None and result.status is not PlanStatus.SOLVED:  # an arm that reaches nothing, and why
        from mrgc.geometry.arm_diagnosis import arm_diagnostics, reasons

        # the layout's warnings that explain a plan not found (a floor that holds nothing up, a load no cart
        # carries, a goal too tall for its region): their reasons come first, not only "no robot can reach"
        explained = [
            f"{d.span}: {d.code} {d.message}" if d.span is not None else f"{d.code} {d.message}"
            for d in _layout(problem, False, False)
            if d.code in NO_PLAN_WARNINGS
        ]
        result.why.facts[:0] = explained + reasons(arm_diagnostics(problem))
    return result


def validate(
    source: ProblemSource,
    plan: "Plan | Mapping[str, Any] | str | os.PathLike[str]",
    *,
    name: str | None = None,
    allow_outside: Sequence[str] = (),
) -> "ValidationReport":
    """Independently re-check ``plan`` (a :class:`~mrgc.planner.plan.Plan`, parsed plan JSON, or the path of
    a plan file) against a problem: a :class:`~mrgc.validator.validate.ValidationReport` whose ``ok`` is the
    verdict and whose ``violations`` list every way the plan fails (docs/validator.md).  A plan file that
    cannot be used at all raises InputError (E500-E504).  A file holding several problems is read for the
    one the plan names (unless ``name`` says otherwise).  The plan must be for the same problem contents:
    the file it was made from or its facts file are both accepted."""
    from mrgc.planfile.reader import load_plan
    from mrgc.validator.validate import validate as run

    doc: Any = plan
    if isinstance(plan, (str, os.PathLike)):
        doc = load_plan(os.fspath(plan))
    if isinstance(source, (str, os.PathLike)):
        from mrgc.language.loader import parse_file

        path: str | None = os.fspath(source)
        mf = parse_file(os.fspath(source), allow_outside=tuple(allow_outside))
        wanted = _plan_problem(doc)
        if name is None and len(mf.problems) > 1 and any(p.name == wanted for p in mf.problems):
            name = wanted
        problem = mf.problem(name)
    else:
        problem, path = _resolve(source, name, allow_outside)
    return run(problem, doc, path)  # no layout checks: the validator's geometry is pybullet's alone (no coal)


def _plan_problem(doc: Any) -> str | None:
    if isinstance(doc, Mapping):
        value = doc.get("problem")
        return value if isinstance(value, str) else None
    return getattr(doc, "problem", None)


# ---------------------------------------------------------------- backends
def backends() -> "list[BackendRecord]":
    """Every registered backend (the built-in ones, then plug-ins of the ``mrgc.backends`` entry-point
    group) as :class:`~mrgc.backends.registry.BackendRecord` values, in registry order; looking them up
    imports no solver library.  (``mrgc.backends()`` calls this.)"""
    from mrgc.backends.registry import records

    return records()


__all__ = [
    "BackendSpec",
    "CheckReport",
    "ProblemSource",
    "backends",
    "check",
    "compile",
    "compute_facts",
    "export_model",
    "facts_summary",
    "load_problem",
    "plan",
    "validate",
]
