"""Methods as command lines: a study's method becomes ``mrgc plan ...`` or ``mrgc compile ...`` arguments.

The options a method may give are the options of the installed ``mrgc plan`` / ``mrgc compile`` (read from
the command line's own parser, :mod:`mrgc.commands`, which builds ``mrgc plan``'s from the options each
planning method declares, :mod:`mrgc.planner.registry`: an option a planner declares is usable in studies at
once, and an option its planner does not declare is refused); an unknown option, a value of the wrong
type, an unknown backend or encoding is a located study error (E601).  A planner that this mrgc does not offer
(``planner: ap1`` before ``mrgc plan --planner ap1`` exists) is *not* an error: the spec stays valid for the mrgc
that offers it, and ``bench run`` skips that method's runs with the reason, storing none of them, so that a later
``bench run`` of the same study runs them (docs/bench.md).
"""

from __future__ import annotations

import argparse
from typing import Any

from mrgc.bench.study import E_STUDY_SCHEMA, Method, Study
from mrgc.errors import Diagnostic
from mrgc.planner.defaults import DEFAULT_PLANNER

#: options the runner sets itself; a method may not give them in ``options``
RESERVED = {
    "-o",
    "--output",
    "--seed",
    "--time-limit",
    "--format",
    "--problem",
    "--backend",
    "--encoding",
    "--planner",
    "--emit",
    "-h",
    "--help",
    "-v",
    "--verbose",
}


def _command_parser(command: str) -> argparse.ArgumentParser:
    from mrgc.commands import build_parser, subcommands

    parser = subcommands(build_parser()).choices[command]
    with_methods = getattr(parser, "with_planner_options", None)  # mrgc plan: the methods' declared options
    return with_methods() if with_methods is not None else parser


def _options(command: str) -> dict[str, argparse.Action]:
    return {s: a for a in _command_parser(command)._actions for s in a.option_strings}


def planners() -> tuple[str, ...] | None:
    """The planners ``mrgc plan --planner`` offers (the planner registry, else the option's choices; only
    the default planner when ``mrgc plan`` has no ``--planner``); None when that cannot be known."""
    try:
        from mrgc.planner.baselines import PLANNERS
    except ImportError:
        action = _options("plan").get("--planner")
        if action is None:
            return (DEFAULT_PLANNER,)
        return tuple(str(c) for c in action.choices) if action.choices else None
    return tuple(PLANNERS)


def option_flag(key: str) -> str:
    """``skeletons`` → ``--skeletons``, ``max_makespan`` → ``--max-makespan``, ``c`` → ``-c``."""
    return f"-{key}" if len(key) == 1 else "--" + key.replace("_", "-")


def check_methods(study: Study) -> tuple[list[Diagnostic], dict[str, str]]:
    """Located errors in the study's methods, and the methods this mrgc cannot run → why (to skip them)."""
    from mrgc.backends.registry import names as backend_names

    diags: list[Diagnostic] = []
    skip: dict[str, str] = {}
    offered = planners()
    tables = {"plan": _options("plan"), "compile": _options("compile")}
    backends = backend_names()
    for m in study.methods:
        diags += [
            Diagnostic(E_STUDY_SCHEMA, f"method '{m.name}': {message}", m.span)
            for message in _method_problems(m, tables, backends)
        ]
        if not m.compile and offered is not None and m.planner not in offered:
            skip[m.name] = f"planner '{m.planner}' is not offered by this mrgc (mrgc plan offers: {', '.join(offered)})"
    return diags, skip


def _method_problems(m: Method, tables: dict[str, dict[str, argparse.Action]], backends: list[str]) -> list[str]:
    """What is wrong with the method's backend, encoding and options (given the option tables of ``mrgc
    plan`` and ``mrgc compile`` and the backends' names)."""
    from mrgc.compiler.encodings import ENCODINGS
    from mrgc.language.suggest import did_you_mean

    out: list[str] = []
    if m.backend is not None and m.backend not in backends:
        out.append(f"unknown backend '{m.backend}'{did_you_mean(m.backend, backends)} (known: {', '.join(backends)})")
    if m.encoding is not None and m.encoding not in ENCODINGS:
        out.append(
            f"unknown encoding '{m.encoding}'{did_you_mean(m.encoding, ENCODINGS)} (known: {', '.join(ENCODINGS)})"
        )
    command = "compile" if m.compile else "plan"
    table = tables[command]
    declared = None if m.compile else _declared_by(m.planner)
    if declared is not None:
        out += [
            f"planner '{m.planner}' has no option {key} (it declares: {', '.join(sorted(declared)) or 'none'})"
            for key, given in (("backend", m.backend), ("encoding", m.encoding))
            if given is not None and key not in declared
        ]
    for key, value in m.options:
        flag = option_flag(key)
        action = table.get(flag)
        if declared is not None and flag not in RESERVED and action is not None and key not in declared:
            out.append(
                f"planner '{m.planner}' has no option {key} (it declares: {', '.join(sorted(declared)) or 'none'})"
            )
        elif flag in RESERVED:
            out.append(f"option '{key}' is set by the study itself (seeds:, limits:, backend:, encoding:, planner:)")
        elif action is None:
            known = sorted(s.lstrip("-") for s in table if s not in RESERVED and s.startswith("--"))
            out.append(f"mrgc {command} has no option {flag}{did_you_mean(key.replace('_', '-'), known)}")
        else:
            problem = _bad_value(action, value)
            if problem:
                out.append(f"option '{key}': {problem}")
    return out


def _declared_by(planner: str) -> set[str] | None:
    """The options planner ``planner`` declares (:attr:`Planner.options <mrgc.planner.method.Planner.options>`);
    None for a planner this mrgc does not offer (its runs are skipped, not refused)."""
    from mrgc.planner.registry import PLANNERS, planner_class

    if planner not in PLANNERS:
        return None
    return {o.name for o in planner_class(planner).options}


def _bad_value(action: argparse.Action, value: Any) -> str:
    """Why ``value`` is not acceptable for ``action`` ('' if it is)."""
    if action.nargs == 0:  # a flag
        return "" if isinstance(value, bool) else "is a flag: give true or false"
    if isinstance(value, bool):
        return "takes a value, not true/false"
    try:
        converted = action.type(str(value)) if callable(action.type) else str(value)
    except argparse.ArgumentTypeError as exc:  # the command line's own words: the bounds (limits.py)
        return str(exc)
    except (TypeError, ValueError):
        kind = getattr(action.type, "__name__", "value")
        return f"'{value}' is not {'an' if kind[0] in 'aeiou' else 'a'} {kind}"
    if action.choices is not None and converted not in action.choices:
        return f"'{value}' is not one of {', '.join(map(str, action.choices))}"
    return ""


def method_args(method: Method) -> list[str]:
    """The subcommand and the method's own arguments (the runner adds the file, output, seed, time limit)."""
    out = ["compile", "--format", "json"] if method.compile else ["plan"]
    if not method.compile and method.planner != DEFAULT_PLANNER:
        out += ["--planner", method.planner]
    if method.backend is not None:
        out += ["--backend", method.backend]
    if method.encoding is not None:
        out += ["--encoding", method.encoding]
    for key, value in method.options:
        if isinstance(value, bool):
            out += [option_flag(key)] if value else []
        else:
            out += [option_flag(key), str(value)]
    return out
