"""Studies: methods compared on suites of instances and seeds, results in an SQLite database (docs/bench.md).

The Python API that ``mrgc bench run`` / ``mrgc bench report`` wrap:

- :func:`load_study` / :func:`parse_study`: read and check a study file → :class:`Study` (its
  :class:`InstanceSpec` entries, :class:`Method` entries, seeds and :class:`Limits`); InputError located
  at ``file:line:col`` otherwise.
- :func:`run_study`: run a study's unfinished runs into a database (``jobs`` local processes at a time, or
  ``executor="ray"``), each finished run committed at once → :class:`StudySummary`.
- :class:`ResultsDB`: the database; ``runs()`` yields the recorded rows (columns of :class:`RunResult`,
  status a :class:`RunStatus`).
- :func:`render` (``markdown``, ``wide``, ``csv``, ``runs``) and :func:`aggregate` → :class:`Row` for the
  tables; :func:`write_figures` (matplotlib) for the figures; :func:`export_planner_arena` for OMPL's
  benchmark database format (Planner Arena).

Example::

    from mrgc.bench import ResultsDB, render, run_study
    run_study("benchmarks/smoke.yaml", db="smoke.db", jobs=2)
    with ResultsDB("smoke.db", readonly=True) as db:
        print(render(db, "markdown"))

Nothing here is imported by ``import mrgc``; this package imports the rest of mrgc, never the reverse.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mrgc.bench.arena import export_planner_arena
    from mrgc.bench.db import ResultsDB
    from mrgc.bench.figures import write_figures
    from mrgc.bench.outcome import RunResult, RunStatus
    from mrgc.bench.report import Row, aggregate, render
    from mrgc.bench.run import DEFAULT_DB, StudySummary, run_study
    from mrgc.bench.schema import load_study, parse_study
    from mrgc.bench.study import InstanceSpec, Limits, Method, Study

#: public name -> the module defining it (loaded on first use: ``mrgc`` builds its parser with
#: :mod:`mrgc.bench.command`, and that must not load the rest of the package)
_API = {
    "ResultsDB": "db",
    "export_planner_arena": "arena",
    "write_figures": "figures",
    "RunResult": "outcome",
    "RunStatus": "outcome",
    "Row": "report",
    "aggregate": "report",
    "render": "report",
    "DEFAULT_DB": "run",
    "StudySummary": "run",
    "run_study": "run",
    "InstanceSpec": "study",
    "Limits": "study",
    "Method": "study",
    "Study": "study",
    "load_study": "schema",
    "parse_study": "schema",
}


def __getattr__(name: str) -> Any:
    if name in _API:
        return getattr(importlib.import_module(f"mrgc.bench.{_API[name]}"), name)
    raise AttributeError(f"module 'mrgc.bench' has no attribute {name!r}")


__all__ = [
    "DEFAULT_DB",
    "InstanceSpec",
    "Limits",
    "Method",
    "ResultsDB",
    "Row",
    "RunResult",
    "RunStatus",
    "Study",
    "StudySummary",
    "aggregate",
    "export_planner_arena",
    "load_study",
    "parse_study",
    "render",
    "run_study",
    "write_figures",
]
