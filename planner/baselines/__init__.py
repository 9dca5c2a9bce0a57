"""Planning methods selectable by name: the paper's method and the baselines it is compared with.

:data:`PLANNERS` is the registry ``mrgc plan --planner NAME`` (and ``mrgc bench``) dispatch through:

- ``mcts``: the paper's method (phase 1, task skeletons from the MIP, MCTS with reverse-search grounding;
  :func:`mrgc.planner.search.plan_problem`), the default;
- ``ap1``: the paper's baseline Ap1, a multi-robot ResolveSpatialConstraints (Stilman et al. 2007):
  the robots as one composite robot, reverse-time depth-first search, each object moved at most once
  (:func:`mrgc.planner.baselines.ap1.plan_ap1`, docs/baselines.md).

Every method takes the same problem and returns the same :class:`~mrgc.planner.plan.Plan` (same JSON, same
statuses, every plan checked by the same validator).  Entries name their module, so this registry imports
nothing heavy; a method is loaded when it is used.
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

from mrgc.errors import Diagnostic, InputError

if TYPE_CHECKING:
    from mrgc.language.model import Problem
    from mrgc.planner.plan import Plan


@dataclass(frozen=True)
class Method:
    """A planning method: the module and function of its entry point, which takes ``(problem, problem_file,
    sha256, version)`` and keyword options (every method takes ``seed``, ``time_limit``, ``log`` and
    ``started``, the ``time.perf_counter`` value the time limit counts from)."""

    module: str
    function: str
    title: str

    def entry(self) -> Callable[..., "Plan"]:
        """The baseline's planning function (imported on first use)."""
        fn: Callable[..., Plan] = getattr(importlib.import_module(self.module), self.function)
        return fn


#: method name (as on the command line) -> method
PLANNERS: dict[str, Method] = {
    "mcts": Method("mrgc.planner.search", "plan_problem", "the paper's method: skeletons + MCTS + reverse grounding"),
    "ap1": Method("mrgc.planner.baselines.ap1", "plan_ap1", "baseline Ap1: multi-robot ResolveSpatialConstraints"),
}

DEFAULT_PLANNER = "mcts"


def plan_with(name: str, problem: "Problem", problem_file: str, sha256: str, version: str, **options: Any) -> "Plan":
    """Plan ``problem`` with method ``name``.  ``options`` a method does not take must be left at the
    default the ``mcts`` method gives them (the command line passes all of them); otherwise, as for an
    unknown method, InputError E000 (a usage error, exit code 2)."""
    method = PLANNERS.get(name)
    if method is None:
        raise InputError([Diagnostic("E000", f"unknown planner {name!r} (choose from {', '.join(PLANNERS)})")])
    entry = method.entry()
    takes = inspect.signature(entry).parameters
    defaults = inspect.signature(PLANNERS[DEFAULT_PLANNER].entry()).parameters
    passed = {}
    for key, value in options.items():
        if key in takes:
            passed[key] = value
        elif key in defaults and defaults[key].default == value:
            continue  # an option of another method, left at its default
        else:
            flag = "-c" if key == "c" else "--" + key.replace("_", "-")
            raise InputError([Diagnostic("E000", f"{flag} is not an option of the {name} planner")])
    return entry(problem, problem_file, sha256, version, **passed)


__all__ = ["DEFAULT_PLANNER", "PLANNERS", "Method", "plan_with"]
