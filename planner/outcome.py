"""How a planning run ended, and why: the status of a plan and the reasons behind "no plan".

Every run of ``mrgc plan`` ends in exactly one :class:`PlanStatus`; each status has its own exit code
(the table is :data:`EXIT_CODES`, documented in docs/errors.md and docs/planner.md):

===============  ====  ==========================================================================
status           exit  meaning
===============  ====  ==========================================================================
``solved``       0     a plan was found **and the independent validator accepted it**
``infeasible``   1     no task skeleton exists under the facts (the reasons name the goals, the
                       missing facts, the blocking cycle or the objects that wait for each
                       other); more time cannot help
``exhausted``    5     every skeleton the compiler could generate was tried and none could be
                       grounded into a valid plan (the grounding-failure summary says why)
``time limit``   3     the time limit (or the search's iteration limit) ended the search first
``interrupted``  130   Ctrl-C / SIGINT ended the search (143 for SIGTERM)
===============  ====  ==========================================================================

A :class:`Why` travels with every plan that is not ``solved`` (and with a ``solved`` one, holding the
failures met on the way): one summary line, the compiler's reasons (goals without an achievable action and
the facts they miss), blocking cycles (objects that obstruct every pick of each other, with the bodies
that overlap and by how much), and a count of grounding failures by (step, action, check, bodies).
"""

from __future__ import annotations

import enum
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Mapping

from mrgc.exits import ExitCode


class PlanStatus(enum.StrEnum):
    """The outcome of a planning run (see the module docstring for the exit codes)."""

    SOLVED = "solved"
    INFEASIBLE = "infeasible"
    EXHAUSTED = "exhausted"
    TIME_LIMIT = "time limit"
    INTERRUPTED = "interrupted"


#: status -> process exit code of ``mrgc plan`` (the codes of :mod:`mrgc.exits`)
EXIT_CODES: dict[PlanStatus, ExitCode] = {
    PlanStatus.SOLVED: ExitCode.OK,
    PlanStatus.INFEASIBLE: ExitCode.NO_PLAN,
    PlanStatus.TIME_LIMIT: ExitCode.TIME_LIMIT,
    PlanStatus.EXHAUSTED: ExitCode.EXHAUSTED,
    PlanStatus.INTERRUPTED: ExitCode.INTERRUPTED,
}


def not_solved(path: str, doc: Mapping[str, Any]) -> str | None:
    """The one-line message of ``mrgc render`` about a plan file whose status is not ``solved`` (a planner's
    record of a run that found no plan: nothing in it is a plan), else None.  (``mrgc validate`` reports
    such a plan as invalid, violation ``[status]``.)"""
    status = doc.get("status")
    if status == "solved":
        return None
    why = doc.get("why")
    summary = why.get("summary") if isinstance(why, Mapping) else None
    reason = f" ({summary})" if isinstance(summary, str) and summary else ""
    return f"{path}: warning: the plan's status is '{status}', not 'solved': mrgc plan found no plan{reason}"


@dataclass(frozen=True)
class Failure:
    """Why one grounding of a skeleton failed: the skeleton step (1-based), the action that could not be
    grounded (``"r1 picks o3 (top)"``), the check that failed (``"pick: no inverse kinematics"``,
    ``"pick: collision"``, ``"placement: no free pose in bin-a"``, ``"robots collide"``, ``"validator"``
    ...), the bodies involved (sorted names), and a detail line (a depth, a validator message)."""

    step: int
    action: str
    check: str
    bodies: tuple[str, ...] = ()
    detail: str = ""
    #: every attempt failed on what never moves (no inverse kinematics, fixed bodies, robots' bases, the arm
    #: itself; :attr:`Answer.static <mrgc.geometry.answers.Answer.static>`): the same query fails again in
    #: any state of the movable objects and the other robots
    static: bool = False

    def key(self) -> tuple[int, str, str, tuple[str, ...]]:
        """What identifies the failure when failures are counted (everything but the detail)."""
        return (self.step, self.action, self.check, self.bodies)

    def line(self) -> str:
        """The failure in one line."""
        bodies = f" [{', '.join(self.bodies)}]" if self.bodies else ""
        detail = f": {self.detail}" if self.detail else ""
        return f"step {self.step}, {self.action}: {self.check}{bodies}{detail}"


class DeadlineReached(Exception):
    """Raised inside a grounding when the search's time limit has passed: the search stops there (a
    grounding of one skeleton can take a minute on a loaded machine; the limit is the user's)."""


@dataclass(frozen=True)
class BlockingCycle:
    """Objects that must each move strictly before the next (every action of one is obstructed by the next
    at its pick), closing a cycle: no order of moves exists.  ``edges`` are (object, blocker, how), and
    ``how`` lists the picks and, where the geometry was consulted, the overlapping bodies and the depth."""

    objects: tuple[str, ...]
    edges: tuple[tuple[str, str, str], ...]

    def line(self) -> str:
        """The cycle in one line."""
        ring = " -> ".join(self.objects + self.objects[:1])
        return f"blocking cycle {ring}: " + "; ".join(
            f"every pick of {o} is obstructed by {b} ({how})" for o, b, how in self.edges
        )


@dataclass
class Why:
    """The reasons of a run's outcome (see the module docstring)."""

    summary: str = ""
    facts: list[str] = field(default_factory=list)
    cycles: list[BlockingCycle] = field(default_factory=list)
    failures: Counter[Failure] = field(default_factory=Counter)
    rejected_plans: int = 0  # full plans the validator rejected

    def add(self, failure: Failure) -> None:
        """Count one grounding failure."""
        self.failures[failure] += 1

    def top_failures(self, n: int = 10) -> list[tuple[Failure, int]]:
        """The ``n`` most frequent failures, ties in a stable order (step, action, check, bodies)."""
        return sorted(self.failures.items(), key=lambda fc: (-fc[1], fc[0].key(), fc[0].detail))[:n]

    def lines(self, n: int = 10) -> list[str]:
        """The reasons as the CLI prints them (the ``n`` most frequent failures)."""
        out = [f"why: {self.summary}"] if self.summary else []
        out += [f"  {r}" for r in self.facts]
        out += [f"  {c.line()}" for c in self.cycles]
        if self.rejected_plans:
            out.append(f"  {self.rejected_plans} complete plan(s) rejected by the validator")
        top = self.top_failures(n)
        if top:
            out.append(f"  grounding failures ({sum(self.failures.values())} in all; most frequent first):")
            out += [f"    {count} x {f.line()}" for f, count in top]
        return out

    def to_json(self, n: int = 20) -> dict[str, Any]:
        """The reasons as the plan's ``why`` (the ``n`` most frequent failures)."""
        return {
            "summary": self.summary,
            "facts": list(self.facts),
            "cycles": [
                {
                    "objects": list(c.objects),
                    "edges": [{"object": o, "blocker": b, "how": how} for o, b, how in c.edges],
                }
                for c in self.cycles
            ],
            "rejected_plans": self.rejected_plans,
            "grounding_failures": [
                {
                    "step": f.step,
                    "action": f.action,
                    "check": f.check,
                    "bodies": list(f.bodies),
                    "detail": f.detail,
                    "count": count,
                }
                for f, count in self.top_failures(n)
            ],
        }
