"""Programmatic edits of a syntax tree: what ``mrgc facts`` uses to write a problem with its facts."""

from __future__ import annotations

from typing import Callable, Iterable

from mrgc.language import ast
from mrgc.language.model import Fact


def with_init(problem: ast.ProblemDef, facts: Iterable[Fact]) -> ast.ProblemDef:
    """``problem`` with its ``(:init ...)`` replaced by ``facts`` (added before the goal if it had none)."""
    init = ast.Init(tuple(ast.Atom(f.predicate, f.args) for f in facts))
    sections: list[ast.ProblemSection] = []
    placed = False
    for sec in problem.sections:
        if isinstance(sec, ast.Init):
            if not placed:
                sections.append(init)
                placed = True
            continue
        if isinstance(sec, ast.Goal) and not placed:
            sections.append(init)
            placed = True
        sections.append(sec)
    if not placed:
        sections.append(init)
    return ast.ProblemDef(problem.name, tuple(sections))


def strip_spans(tree: ast.SourceFile) -> ast.SourceFile:
    """The tree with every span replaced by the generated marker, so the printer ignores old positions."""
    out = _strip(tree)
    assert isinstance(out, ast.SourceFile)
    return out


def _strip(node: object) -> object:
    from dataclasses import fields, is_dataclass, replace

    if isinstance(node, tuple):
        return tuple(_strip(n) for n in node)
    if not is_dataclass(node) or isinstance(node, type):
        return node
    changes: dict[str, object] = {}
    for f in fields(node):
        value = getattr(node, f.name)
        if f.name == "span":
            changes[f.name] = ast.NOWHERE
        elif f.name in ("name_spans", "arg_spans", "flag_spans"):
            changes[f.name] = ()
        elif isinstance(value, tuple) or is_dataclass(value):
            changes[f.name] = _strip(value)
    return replace(node, **changes)


#: ``relocate(path, what, declaring_file)`` -> the path to write instead; ``what`` is ``mesh``, ``urdf``
#: or ``include``; ``declaring_file`` the file the path was written in (it is relative to its folder)
Relocate = Callable[[str, str, str], str]


def relocate_paths(node: object, relocate: Relocate, declaring_file: str) -> object:
    """``node`` with every file path it names (a ``:urdf`` string, a ``(mesh "file")`` shape, an
    ``(:include "file")``) replaced by ``relocate(path, what, declaring_file)``."""
    from dataclasses import fields, is_dataclass, replace

    if isinstance(node, tuple):
        return tuple(relocate_paths(n, relocate, declaring_file) for n in node)
    if isinstance(node, ast.Include):
        return replace(node, path=relocate(node.path, "include", declaring_file))
    if isinstance(node, ast.Property) and node.key == "urdf" and isinstance(node.value, ast.String):
        return replace(node, value=replace(node.value, value=relocate(node.value.value, "urdf", declaring_file)))
    if (
        isinstance(node, ast.ListValue)
        and len(node.items) >= 2
        and isinstance(node.items[0], ast.Symbol)
        and node.items[0].name == "mesh"
        and isinstance(node.items[1], ast.String)
    ):
        path = replace(node.items[1], value=relocate(node.items[1].value, "mesh", declaring_file))
        return replace(node, items=(node.items[0], path, *node.items[2:]))
    if not is_dataclass(node) or isinstance(node, type):
        return node
    changes = {
        f.name: relocate_paths(getattr(node, f.name), relocate, declaring_file)
        for f in fields(node)
        if isinstance(getattr(node, f.name), tuple) or is_dataclass(getattr(node, f.name))
    }
    return replace(node, **changes)


def facts_document(
    source: ast.SourceFile,
    problem_name: str,
    domain_name: str,
    domain_file: str,
    facts: Iterable[Fact],
    source_path: str,
    out_path: str | None,
    header: str,
    relocate: Relocate | None = None,
) -> str:
    """The text ``mrgc facts`` writes: ``problem_name`` with its ``:init`` completed by ``facts``.

    The domain comes along when the source file defines it, or when the output is written to another
    folder than the source (then a copy of the domain definition replaces the problem's includes, so the
    facts file stands on its own, and every file path it names is passed through ``relocate``).
    """
    import os

    from mrgc.language.parser import parse_text
    from mrgc.language.printer import format_source

    same_folder = out_path is None or os.path.dirname(os.path.abspath(out_path)) == os.path.dirname(
        os.path.abspath(source_path)
    )
    defs: list[ast.DomainDef | ast.ProblemDef] = []
    own = [d for d in source.definitions if isinstance(d, ast.DomainDef) and d.name == domain_name]
    if own:
        defs.extend(own)
    elif not same_folder:
        with open(domain_file, encoding="utf-8") as fh:
            tree = parse_text(fh.read(), domain_file)
        if isinstance(tree, ast.SourceFile):
            defs.extend(d for d in tree.definitions if isinstance(d, ast.DomainDef) and d.name == domain_name)
    problem = next(d for d in source.definitions if isinstance(d, ast.ProblemDef) and d.name == problem_name)
    problem = with_init(problem, facts)
    if defs and not same_folder:
        problem = ast.ProblemDef(problem.name, tuple(s for s in problem.sections if not isinstance(s, ast.Include)))
    if relocate is not None and not same_folder:
        defs = [relocate_paths(d, relocate, source_path if own else domain_file) for d in defs]  # type: ignore[misc]
        problem = relocate_paths(problem, relocate, source_path)  # type: ignore[assignment]
    tree = strip_spans(ast.SourceFile(tuple(defs) + (problem,)))
    return "".join(f"; {line}\n" for line in header.splitlines()) + format_source(tree)
