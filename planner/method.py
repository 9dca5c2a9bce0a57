"""The planner interface: a planning method is a :class:`Planner` class with a name, the options it declares
as data (:class:`Option`) and ``solve(context, deadline)``.

What every method shares is done once, by the harness (:mod:`mrgc.planner.harness`): phase 1 (the facts),
the plan record, the referee (the independent validator, :mod:`mrgc.planner.referee`), statuses, summaries
and statistics.  A method gets a :class:`Context` (the problem, its facts, its options, the referee, a log)
and returns a :class:`Result` (the steps of a plan the referee accepted, or why there is none).  The command
line (``mrgc plan --planner NAME``) and ``mrgc bench`` build their options from :attr:`Planner.options`;
the registry (:mod:`mrgc.planner.registry`) names each method's class, so adding a method is one file and
one registry line (docs/architecture.md, "Where to add ...").

This module imports nothing heavy: the command line reads the declarations of every method.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, ClassVar

from mrgc.planner.outcome import Failure, PlanStatus, Why

if TYPE_CHECKING:
    from mrgc.compiler.facts import FactBase
    from mrgc.language.model import Fact, Problem
    from mrgc.planfile.format import PlannedAction

#: a search log line sink (``mrgc plan --verbose`` prints them)
Log = Callable[[str], None]

#: the kinds of option values: an integer (bounded as ``mrgc.limits.count``), a number (``limits.number``),
#: a string, a flag (true when given)
KINDS = ("count", "number", "text", "flag")


@dataclass(frozen=True)
class Option:
    """An option a method declares: its keyword ``name`` (``max_makespan``; on the command line
    ``--max-makespan``, one letter ``-c``), value ``kind`` (:data:`KINDS`), ``default``, ``help``; ``choices``
    restricts a text; ``bounds`` a number's least and largest value on the command line when
    ``mrgc.limits.BOUNDS`` has no row for the flag (a row there bounds the flag alike for every method that
    declares it); ``cli`` False keeps it out of the command line (Python API only)."""

    name: str
    kind: str
    default: Any
    help: str
    metavar: str | None = None
    choices: tuple[str, ...] | None = None
    bounds: tuple[float, float] = (0, 1_000_000)
    cli: bool = True

    @property
    def flag(self) -> str:
        """The command-line flag: ``-c``, ``--max-makespan``."""
        return f"-{self.name}" if len(self.name) == 1 else "--" + self.name.replace("_", "-")


#: the horizon limit of methods that plan over a growing number of steps (``--max-makespan``)
HORIZON_LIMIT = Option(
    "max_makespan", "count", None, "horizon limit in steps (default and cap: the task graph's objects)", metavar="T"
)


@dataclass
class Context:
    """What the harness gives a method: the problem and its facts (``base``: indexed; ``goals``: the goal
    objects not yet in their goal region, M* at the start), its options (every declared one, defaults filled
    in), the seed, the arms' motion model, the time limit, when the run started (``time.perf_counter``) and
    how long phase 1 took, the run's reasons (``why``), the referee and a log."""

    problem: Problem
    facts: list[Fact]
    base: FactBase
    goals: list[str]
    options: dict[str, Any]
    seed: int
    motions: str
    time_limit: float
    started: float
    facts_seconds: float
    why: Why
    referee: Callable[[list[list[PlannedAction]]], Failure | None]
    log: Log

    @property
    def full(self) -> bool:
        """Arms' empty-handed motions planned as paths too (``--motions full``)."""
        return self.motions == "full"


@dataclass
class Result:
    """How a method's search ended: ``steps`` of a plan the referee accepted (status solved), else the
    status; ``summary`` replaces the harness's one-line summary of that status (None: the harness's);
    ``note`` is appended to the summary; ``stats`` join the plan's statistics."""

    status: PlanStatus
    steps: list[list[PlannedAction]] | None = None
    summary: str | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    note: str | None = None


class Planner(ABC):
    """A planning method (see the module docstring).  Subclasses set :attr:`name`, :attr:`title`,
    :attr:`options`, :attr:`exhausted` (the summary of a search that ran to its end) and implement
    :meth:`solve`; :meth:`record` names the skeleton backend and encoding the plan file records."""

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    options: ClassVar[tuple[Option, ...]] = ()
    exhausted: ClassVar[str] = "the search ran to its end without a valid plan"
    #: the arms' motion models the method plans (``motions``)
    motions: ClassVar[tuple[str, ...]] = ("configurations", "full")

    def check(self, problem: Problem) -> None:
        """Refuse a problem this method cannot plan (InputError, exit code 2); default: every problem."""
        return None

    def record(self, options: dict[str, Any]) -> tuple[str, str]:
        """The (backend, encoding) the plan file records; ``none`` for methods without task skeletons."""
        return "none", "none"

    @abstractmethod
    def solve(self, context: Context, deadline: float) -> Result:
        """Search for a plan until ``deadline`` (a ``time.perf_counter`` value); every plan it returns solved
        must have been accepted by ``context.referee``."""


__all__ = ["HORIZON_LIMIT", "KINDS", "Context", "Log", "Option", "Planner", "Result"]
