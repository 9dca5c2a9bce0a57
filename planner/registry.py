"""The planning methods by name: ``mrgc plan --planner NAME``, ``mrgc bench`` and :func:`mrgc.plan` dispatch
through :data:`PLANNERS`.

- ``mcts``: the paper's method (phase 1, task skeletons from the MIP, MCTS with reverse-search grounding;
  :mod:`mrgc.planner.search`), the default;
- ``ap1``: the paper's baseline Ap1, a multi-robot ResolveSpatialConstraints (Stilman et al. 2007)
  (:mod:`mrgc.planner.baselines.ap1`, docs/baselines.md);
- ``ap2``: the paper's baseline Ap2 (Pan et al. 2021): optimal task plans on z3 over a growing horizon,
  motion failures back as constraints, a scheduler trying other robot assignments
  (:mod:`mrgc.planner.baselines.ap2`, docs/baselines.md).

Every method is a :class:`~mrgc.planner.method.Planner` class run by the one harness
(:mod:`mrgc.planner.harness`): the same problem, the same :class:`~mrgc.planner.plan.Plan` (JSON, statuses,
every plan checked by the same validator).  Entries name their class as ``module:Class``, loaded on first
use; a new method is one module and one line here.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from mrgc.errors import Diagnostic, InputError
from mrgc.planner.defaults import DEFAULT_PLANNER

if TYPE_CHECKING:
    from mrgc.language.model import Problem
    from mrgc.planner.method import Option, Planner
    from mrgc.planner.plan import Plan

#: method name (as on the command line) -> its Planner class, ``module:Class``
PLANNERS: dict[str, str] = {
    "mcts": "mrgc.planner.search:Mcts",
    "ap1": "mrgc.planner.baselines.ap1:Ap1",
    "ap2": "mrgc.planner.baselines.ap2:Ap2",
}


def planner_class(name: str) -> type[Planner]:
    """The class of method ``name`` (imported on first use); InputError E000 (exit code 2) for an unknown
    name."""
    where = PLANNERS.get(name)
    if where is None:
        raise InputError([Diagnostic("E000", f"unknown planner {name!r} (choose from {', '.join(PLANNERS)})")])
    module, cls = where.split(":")
    found: type[Planner] = getattr(importlib.import_module(module), cls)
    return found


def declared_options() -> dict[str, list[tuple[str, Option]]]:
    """Every method's declared options by name: option name -> [(method, declaration)], in registry order
    (the command line adds each option once, for the methods that declare it)."""
    out: dict[str, list[tuple[str, Option]]] = {}
    for name in PLANNERS:
        for option in planner_class(name).options:
            out.setdefault(option.name, []).append((name, option))
    return out


def plan_with(name: str, problem: Problem, problem_file: str, sha256: str, version: str, **options: Any) -> Plan:
    """Plan ``problem`` with method ``name`` through the harness (:func:`mrgc.planner.harness.run`):
    ``options`` are the harness's (``seed``, ``time_limit``, ``log``, ``motions``, ``started``, ``facts``) and
    the method's own; an option the method does not declare, or an unknown method, is InputError E000 (a
    usage error, exit code 2)."""
    from mrgc.planner.harness import run

    return run(planner_class(name)(), problem, problem_file, sha256, version, **options)


__all__ = ["DEFAULT_PLANNER", "PLANNERS", "declared_options", "plan_with", "planner_class"]
