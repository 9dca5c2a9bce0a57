"""The run harness every planning method shares: options, phase 1, the plan record, the referee, statuses,
summaries and statistics, done once here (the method's search is its :meth:`Planner.solve
<mrgc.planner.method.Planner.solve>`).

A run: the options are checked against the method's declarations (an unknown one is a usage error, exit 2);
the problem against what the method plans (:meth:`Planner.check <mrgc.planner.method.Planner.check>`);
phase 1 runs within the time limit (a cut phase 1 is status ``time limit``, no search); the method searches
with a :class:`~mrgc.planner.method.Context` holding the referee; its :class:`~mrgc.planner.method.Result`
becomes the plan's status, steps, the validator's verdict, the summary and the statistics (``planner``,
``robots``, ``facts``, ``facts_seconds``, the method's own, ``validation_seconds`` when the referee judged
anything, ``seconds``).  Ctrl-C during the search is status ``interrupted``.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from mrgc.errors import Diagnostic, InputError
from mrgc.planner.defaults import DEFAULT_TIME_LIMIT
from mrgc.planner.method import Context, Log, Option, Planner, Result
from mrgc.planner.outcome import PlanStatus, Why

if TYPE_CHECKING:
    from mrgc.language.model import Fact, Problem
    from mrgc.planner.plan import Plan
    from mrgc.planner.referee import Referee

#: the arms' motion models a planner can plan (docs/validator.md)
MOTIONS = ("configurations", "full")


def options_for(method: Planner, given: dict[str, Any]) -> dict[str, Any]:
    """Every option ``method`` declares, ``given`` ones over the defaults; an option it does not declare is a
    usage error (InputError E000, exit code 2)."""
    declared = {o.name: o for o in method.options}
    for key, value in given.items():
        if key not in declared:
            flag = f"-{key}" if len(key) == 1 else "--" + key.replace("_", "-")
            raise InputError([Diagnostic("E000", f"{flag} is not an option of the {method.name} planner")])
        _check_value(declared[key], value)
    return {name: given.get(name, o.default) for name, o in declared.items()}


def _check_value(option: Option, value: Any) -> None:
    """A value given to ``option`` through the Python API, checked as the command line checks it (its kind,
    the bounds of ``limits.BOUNDS`` or its own, its choices): InputError E000 otherwise (a max_makespan of 0
    made a feasible problem 'infeasible')."""
    from mrgc import limits

    if value is None and option.default is None:
        return
    if option.kind in ("count", "number"):
        bounds = limits.BOUNDS.get(option.flag, option.bounds)
        limits.checked(option.name, value, option.kind, option=option.flag, bounds=bounds)
    elif option.kind == "flag" and not (isinstance(value, bool) or type(value).__name__ in ("bool", "bool_")):
        raise InputError([Diagnostic("E000", f"{option.name}={value!r}: must be True or False")])
    elif option.kind == "text" and (not isinstance(value, str) or (option.choices and value not in option.choices)):
        choices = f"one of {', '.join(option.choices)}" if option.choices else "a string"
        raise InputError([Diagnostic("E000", f"{option.name}={value!r}: must be {choices}")])


def run(
    method: Planner,
    problem: Problem,
    problem_file: str,
    sha256: str,
    version: str,
    seed: int = 0,
    time_limit: float = DEFAULT_TIME_LIMIT,
    log: Log | None = None,
    motions: str = "configurations",
    started: float | None = None,
    facts: list[Fact] | None = None,
    **given: Any,
) -> Plan:
    """Plan ``problem`` with ``method`` (see the module docstring).  ``started``: the ``time.perf_counter``
    value the time limit and the plan's seconds count from (default: this call); ``facts``: the problem's
    facts when the caller has them (default: the file's ``:init``, or phase 1 run now, through the facts
    cache); ``given``: the method's own options."""
    from mrgc.compiler.facts import FactBase
    from mrgc.planner.plan import Plan, planner_motion_model
    from mrgc.planner.referee import Referee
    from mrgc.planner.skeletons import facts_until, must_move

    if motions not in MOTIONS or motions not in method.motions:
        raise InputError([Diagnostic("E000", f"motions={motions!r}: must be one of {', '.join(method.motions)}")])
    options = options_for(method, given)
    method.check(problem)
    t0 = time.perf_counter() if started is None else started
    deadline = t0 + time_limit
    known, facts_seconds = facts_until(problem, facts, seed, deadline)
    backend, encoding = method.record(options)
    plan = Plan(problem.name, problem_file, sha256, version, backend, encoding, seed, PlanStatus.EXHAUSTED)
    plan.symbolic = problem.symbolic
    plan.motion_model = None if problem.symbolic else planner_motion_model(motions)
    why = plan.why = Why()
    stats: dict[str, Any] = {"planner": method.name, "robots": [r.name for r in problem.robots]}
    stats.update(facts=len(known or []), facts_seconds=round(facts_seconds, 4))
    if known is None:
        plan.status = PlanStatus.TIME_LIMIT
        why.summary = f"phase 1 (the geometric facts) did not finish within the time limit of {time_limit:g} s"
        plan.stats = {**stats, "seconds": round(time.perf_counter() - t0, 4)}
        return plan
    referee = Referee(problem, plan, why)
    say: Log = log or (lambda line: None)
    context = Context(
        problem,
        known,
        FactBase.from_problem(problem, known),
        must_move(problem, known),
        options,
        seed,
        motions,
        time_limit,
        t0,
        facts_seconds,
        why,
        referee,
        say,
    )
    try:
        result = method.solve(context, deadline)
    except KeyboardInterrupt:
        result = Result(PlanStatus.INTERRUPTED)
    _conclude(plan, result, referee, time_limit, method.exhausted)
    stats.update(result.stats)
    if referee.checked or not problem.symbolic:
        stats["validation_seconds"] = round(referee.seconds, 4)
    stats["seconds"] = round(time.perf_counter() - t0, 4)
    plan.stats = stats
    return plan


def _conclude(plan: Plan, result: Result, referee: Referee, time_limit: float, exhausted: str) -> None:
    """The plan's status, steps, verdict and summary from the method's result."""
    plan.status = result.status
    why = plan.why
    assert why is not None
    if result.steps is not None:
        plan.steps = result.steps
        if referee.checked:
            plan.validation = referee.verdict()
    if result.summary is not None:
        why.summary = result.summary
    elif result.status is PlanStatus.SOLVED:
        rejected = why.rejected_plans
        why.summary = "solved" + (f" after the validator rejected {rejected} plan(s)" if rejected else "")
    elif result.status is PlanStatus.TIME_LIMIT:
        why.summary = f"no plan within the time limit of {time_limit:g} s"
    elif result.status is PlanStatus.INTERRUPTED:
        why.summary = "interrupted"
    elif result.status is PlanStatus.INFEASIBLE:
        why.summary = "infeasible by the facts"
    else:
        why.summary = exhausted
    if result.note:
        why.summary += "; " + result.note


__all__ = ["MOTIONS", "options_for", "run"]
