"""The referee inside every planning run: the independent validator (``mrgc validate``'s code) judges each
complete plan a method finds before the method may call it solved.

A rejection is counted (``why.rejected_plans``) and returned as a :class:`~mrgc.planner.outcome.Failure`
named by the validator's first violation; the method treats it as a grounding failure like any other.  The
referee judges a plan against the problem object it was made for (no file need exist: a problem parsed from
a string is planned too); ``mrgc validate`` checks the file's digest besides.  The candidate goes to the
validator as the typed values of a plan file (:meth:`~mrgc.planner.plan.Plan.as_file`), not as JSON text
checked against the schema again for every candidate.  The first violation is the verdict, so the replay
stops there.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from mrgc.planner.outcome import Failure, Why

if TYPE_CHECKING:
    from mrgc.language.model import Problem
    from mrgc.planfile.format import PlannedAction
    from mrgc.planner.plan import Plan


class Referee:
    """Judges complete plans of one run (``plan``: the run's plan record, whose motion model the candidates
    state); keeps how many it checked and the seconds it took."""

    def __init__(self, problem: Problem, plan: Plan, why: Why) -> None:
        self.problem, self.plan, self.why = problem, plan, why
        self.checked = 0
        self.seconds = 0.0

    def __call__(self, steps: list[list[PlannedAction]]) -> Failure | None:
        """None when the validator accepts the complete plan ``steps``, else the failure it names."""
        from mrgc.validator.validate import validate

        t0 = time.perf_counter()
        robots = [r.name for r in self.problem.robots]
        candidate = self.plan.candidate(steps, robots, symbolic=self.problem.symbolic)
        report = validate(self.problem, candidate.as_file(), None, first_only=True)
        self.seconds += time.perf_counter() - t0
        self.checked += 1
        if report.ok:
            return None
        self.why.rejected_plans += 1
        first = report.violations[0]
        n = len(report.violations)
        return Failure(
            first.step or 0,
            f"validator ({n} violation{'s' * (n != 1)})",
            first.code,
            (first.subject,) if first.subject else (),
            first.message,
        )

    def verdict(self) -> dict[str, Any]:
        """What the plan JSON records of the verdict on the returned plan."""
        replay = "independent replay" if self.problem.symbolic else "independent pybullet replay"
        return {"valid": True, "validator": f"mrgc validate ({replay})", "plans_checked": self.checked}
