"""mrgc: a declarative domain compiler and solver for multi-robot geometric task-and-motion planning.

Public API (docs/api.md; everything the ``mrgc`` command does is a thin layer over these):

- :func:`parse_file`, :func:`parse_string`: read and check a ``.mrg`` file → :class:`MrgFile` holding checked
  :class:`Problem` objects (raises :class:`InputError` listing every diagnostic); :func:`check` adds the
  layout checks of ``mrgc check`` and returns the warnings; :func:`format_source`: canonical text.
- :func:`compute_facts` (phase 1), :func:`facts_summary` (what the facts say, per robot and per goal),
  :func:`compile` (task skeletons and statistics: a :class:`CompileResult`
  with a :class:`CompileStatus`), :func:`export_model` (the skeleton model as a solver file), :func:`plan`
  (a :class:`Plan` with a :class:`PlanStatus`, reasons and statistics),
  :func:`validate` (a :class:`ValidationReport`), :func:`backends` (the registered solver backends).
  Each takes a checked :class:`Problem` or the path of a ``.mrg`` file.  :class:`ExitCode`: the command's
  exit codes, one per outcome.
- For backend plug-in authors: :class:`Backend`, :class:`BackendInfo` and the model they translate
  (:class:`SkeletonModel`, :class:`Row`, :class:`Feature`, :class:`Solution`, :class:`SolveStatus`);
  :mod:`mrgc.testing` holds the conformance kit, the skeleton oracle and hypothesis strategies.

Importing ``mrgc`` is cheap: every name but the exceptions is loaded on first use.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from mrgc.errors import Diagnostic, InputError, MrgcError, Span

__version__ = "0.1.0"

#: public name -> "module:attribute" it is loaded from on first use
_LAZY: dict[str, str] = {
    "MrgFile": "mrgc.language.loader:MrgFile",
    "parse_file": "mrgc.language.loader:parse_file",
    "parse_string": "mrgc.language.loader:parse_string",
    "Domain": "mrgc.language.model:Domain",
    "Fact": "mrgc.language.model:Fact",
    "Problem": "mrgc.language.model:Problem",
    "format_source": "mrgc.language.printer:format_source",
    "check": "mrgc.api:check",
    "load_problem": "mrgc.api:load_problem",
    "compute_facts": "mrgc.api:compute_facts",
    "facts_summary": "mrgc.api:facts_summary",
    "FactsSummary": "mrgc.planner.summary:FactsSummary",
    "compile": "mrgc.api:compile",
    "export_model": "mrgc.api:export_model",
    "plan": "mrgc.api:plan",
    "validate": "mrgc.api:validate",
    "backends": "mrgc.backends:",  # the package, callable: mrgc.backends() lists them (backends/__init__.py)
    "BackendRecord": "mrgc.backends.registry:BackendRecord",
    "CheckReport": "mrgc.api:CheckReport",
    "CompileResult": "mrgc.planner.skeletons:CompileResult",
    "CompileStatus": "mrgc.planner.skeletons:CompileStatus",
    "ExitCode": "mrgc.exits:ExitCode",
    "Skeleton": "mrgc.compiler.skeleton:Skeleton",
    "Plan": "mrgc.planner.plan:Plan",
    "PlanStatus": "mrgc.planner.outcome:PlanStatus",
    "ValidationReport": "mrgc.validator.validate:ValidationReport",
    "FactsResult": "mrgc.geometry.facts:FactsResult",
    "Backend": "mrgc.backends.base:Backend",
    "BackendInfo": "mrgc.backends.base:BackendInfo",
    "SkeletonModel": "mrgc.compiler.ir:SkeletonModel",
    "Row": "mrgc.compiler.ir:Row",
    "Feature": "mrgc.compiler.ir:Feature",
    "Solution": "mrgc.compiler.ir:Solution",
    "SolveStatus": "mrgc.compiler.ir:SolveStatus",
}

if TYPE_CHECKING:
    from mrgc.api import (
        CheckReport,
        backends,
        check,
        compile,
        compute_facts,
        export_model,
        facts_summary,
        load_problem,
        plan,
        validate,
    )
    from mrgc.backends.base import Backend, BackendInfo
    from mrgc.backends.registry import BackendRecord
    from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, SolveStatus
    from mrgc.compiler.skeleton import Skeleton
    from mrgc.exits import ExitCode
    from mrgc.geometry.facts import FactsResult
    from mrgc.language.loader import MrgFile, parse_file, parse_string
    from mrgc.language.model import Domain, Fact, Problem
    from mrgc.language.printer import format_source
    from mrgc.planner.outcome import PlanStatus
    from mrgc.planner.plan import Plan
    from mrgc.planner.skeletons import CompileResult, CompileStatus
    from mrgc.planner.summary import FactsSummary
    from mrgc.validator.validate import ValidationReport


def __getattr__(name: str) -> Any:
    target = _LAZY.get(name)
    if target is None:
        raise AttributeError(f"module 'mrgc' has no attribute {name!r}")
    module, _, attr = target.partition(":")
    found = importlib.import_module(module)
    value = getattr(found, attr) if attr else found
    globals()[name] = value  # the next access is a plain lookup
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "__version__",
    "Diagnostic",
    "InputError",
    "MrgcError",
    "Span",
    "Backend",
    "BackendInfo",
    "BackendRecord",
    "CheckReport",
    "CompileResult",
    "CompileStatus",
    "Domain",
    "ExitCode",
    "Fact",
    "FactsResult",
    "FactsSummary",
    "Feature",
    "MrgFile",
    "Plan",
    "PlanStatus",
    "Problem",
    "Row",
    "Skeleton",
    "SkeletonModel",
    "Solution",
    "SolveStatus",
    "ValidationReport",
    "backends",
    "check",
    "compile",
    "compute_facts",
    "export_model",
    "facts_summary",
    "format_source",
    "load_problem",
    "parse_file",
    "parse_string",
    "plan",
    "validate",
]
