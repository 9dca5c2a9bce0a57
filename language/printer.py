"""The canonical printer behind ``mrgc fmt``: syntax tree (+ the file's comments) → canonical text.

Layout rules (docs/language.md, "Canonical format"): two-space indentation; one section per line; a
declaration section with properties puts one declaration per line; ``:init`` puts one atom per line; bare
name lists fill lines up to :data:`WIDTH` columns; numbers print in their shortest exact form (``0.5``,
``90``, ``1e-05``).  Comments are kept: a comment on its own line stays before the item that follows it, a
comment after code stays at the end of that item's line.  Printing is idempotent, and for any tree
``parse(print(tree)) == tree``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mrgc.errors import Span
from mrgc.language import ast

WIDTH = 100


@dataclass(frozen=True)
class Comment:
    """A ``;`` comment: where it starts, its text (with the ``;``), and whether code precedes it on its line."""

    line: int
    column: int
    text: str
    trailing: bool


def comments_of(text: str) -> list[Comment]:
    """Every comment of ``text`` in order (``;`` inside a string is not a comment)."""
    out: list[Comment] = []
    line, col, in_string, code_on_line = 1, 1, False, False
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if in_string:
            if ch == "\\":
                i += 2
                col += 2
                continue
            if ch == '"':
                in_string = False
            elif ch == "\n":  # unterminated string: the parser reports it
                in_string = False
        elif ch == '"':
            in_string, code_on_line = True, True
        elif ch == ";":
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append(Comment(line, col, text[i:end].rstrip(), code_on_line))
            col += end - i
            i = end
            continue
        elif not ch.isspace():
            code_on_line = True
        if ch == "\n":
            line, col, code_on_line = line + 1, 1, False
        else:
            col += 1
        i += 1
    return out


def number(x: float) -> str:
    """Shortest text that parses back to exactly ``x`` (overflowed literals print as ``1e999``)."""
    if math.isinf(x):
        return "1e999" if x > 0 else "-1e999"
    if x == 0:
        return "0"
    if x.is_integer() and abs(x) < 1e16:
        return str(int(x))
    return repr(x)


def string(s: str) -> str:
    """A string literal as the language writes it (escapes for ``\\``, ``"``, newlines and tabs)."""
    body = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    return f'"{body}"'


def value(v: ast.Value | ast.Number | ast.Symbol | ast.String) -> str:
    """A property value's canonical text."""
    if isinstance(v, ast.Number):
        return number(v.value)
    if isinstance(v, ast.Symbol):
        return v.name
    if isinstance(v, ast.String):
        return string(v.value)
    return "(" + " ".join(value(i) for i in v.items) + ")"


def prop(p: ast.Property) -> str:
    """A property's canonical text, ``:key value``."""
    return f":{p.key} {value(p.value)}"


def decl(d: ast.Decl) -> str:
    """A declaration's canonical text: its name, or ``(name :key value ...)``."""
    if d.bare and not d.props:
        return d.name
    return "(" + " ".join([d.name, *(prop(p) for p in d.props)]) + ")"


def atom(a: ast.Atom) -> str:
    """An atom's canonical text, ``(predicate arg ...)``."""
    return "(" + " ".join([a.predicate, *a.args]) + ")"


class _Out:
    """Accumulates output lines, placing pending comments before the items they precede.

    Each line is kept as [code, comment] so a closing parenthesis can be put after the code and before a
    trailing comment.  A blank line in the source before an item or an own-line comment is kept (runs of
    blank lines become one).
    """

    def __init__(self, comments: list[Comment], text: str) -> None:
        self.lines: list[list[str]] = []
        self.pending = list(comments)
        self.blank = {i for i, ln in enumerate(text.split("\n"), 1) if not ln.strip()} if text else set()
        self.last_line = 0  # source line of the last thing emitted

    def _gap(self, line: int) -> None:
        """Keep one blank line if the source has one between the last emitted thing and ``line``."""
        if self.lines and self.lines[-1] != ["", ""] and any(n in self.blank for n in range(self.last_line + 1, line)):
            self.lines.append(["", ""])

    def _comment(self, c: Comment, indent: str) -> None:
        if c.trailing and self.lines and self.lines[-1][0].strip() and not self.lines[-1][1]:
            self.lines[-1][1] = c.text
        else:
            self._gap(c.line)
            self.lines.append([indent, c.text])
        self.last_line = c.line

    def flush_before(self, span: Span | None, indent: str) -> None:
        if span is None or span.file == "<generated>":
            return
        while self.pending and (self.pending[0].line, self.pending[0].column) < (span.line, span.column):
            self._comment(self.pending.pop(0), indent)

    def flush_until(self, line: int, indent: str) -> None:
        """Emit comments that start before ``line`` (used at the end of a group)."""
        self.flush_before(Span("", line, 1, line, 1), indent)

    def emit(self, text: str, indent: str, span: Span | None = None, header: bool = False) -> None:
        """A line of code; ``header`` marks the opening line of a group whose items follow."""
        self.flush_before(span, indent)
        if span is not None and span.file != "<generated>":
            self._gap(span.line)
            self.last_line = span.line if header else span.end_line
        self.lines.append([indent + text, ""])

    def append(self, text: str) -> None:
        """Continue the last code line (filled name lists)."""
        self.lines[-1][0] += text

    def close(self, indent: str) -> None:
        """Close the innermost group: after the last code, or on its own line after an own-line comment."""
        last = self.lines[-1]
        if last[0].strip():
            last[0] += ")"
        else:
            self.lines.append([indent + ")", ""])

    def rest(self) -> None:
        for c in self.pending:
            self._comment(c, "")
        self.pending = []

    def text(self) -> str:
        return "\n".join((code + " " + com) if code.strip() and com else (code + com) for code, com in self.lines)


def format_source(tree: ast.SourceFile, text: str = "") -> str:
    """The canonical text of ``tree``; pass the original ``text`` to keep its comments."""
    out = _Out(comments_of(text) if text else [], text)
    for i, d in enumerate(tree.definitions):
        if i:
            out.lines.append(["", ""])
        head = "domain" if isinstance(d, ast.DomainDef) else "problem"
        out.emit(f"(define ({head} {d.name})", "", d.span, header=True)
        for sec in d.sections:
            _section(out, sec)
        if d.span.file != "<generated>":
            out.flush_until(d.span.end_line, "  ")  # comments inside, before the closing line
            out.flush_before(Span("", d.span.end_line, d.span.end_column - 1, 0, 0), "  ")
        out.close("")
        if d.span.file != "<generated>":
            out.flush_until(d.span.end_line + 1, "")  # comments after the closing parenthesis
    out.rest()
    return out.text() + "\n"


def _section(out: _Out, sec: ast.DomainSection | ast.ProblemSection) -> None:
    ind = "  "
    if isinstance(sec, ast.Requirements):
        out.emit("(" + " ".join([":requirements", *(":" + f for f in sec.flags)]) + ")", ind, sec.span)
    elif isinstance(sec, ast.Grasps):
        _decls(out, ":grasps", sec.decls, sec.span)
    elif isinstance(sec, ast.Include):
        out.emit(f"(:include {string(sec.path)})", ind, sec.span)
    elif isinstance(sec, ast.DomainRef):
        out.emit(f"(:domain {sec.name})", ind, sec.span)
    elif isinstance(sec, ast.RobotKindDecl):
        out.emit(f"(:robot-kind {sec.name}", ind, sec.span, header=True)
        for p in sec.props:
            out.emit(prop(p), ind * 2, p.span)
        _close_group(out, sec.span, ind * 2, ind)
    elif isinstance(sec, ast.DeclSection):
        _decls(out, ":" + sec.kind, sec.decls, sec.span)
    elif isinstance(sec, ast.Init):
        if not sec.atoms:
            out.emit("(:init)", ind, sec.span)
            return
        out.emit("(:init", ind, sec.span, header=True)
        for a in sec.atoms:
            out.emit(atom(a), ind * 2, a.span)
        _close_group(out, sec.span, ind * 2, ind)
    elif isinstance(sec, ast.Goal):
        _goal(out, sec)


def _decls(out: _Out, head: str, decls: tuple[ast.Decl, ...], span: Span) -> None:
    """A section of declarations: bare names filled to WIDTH, else one declaration per line."""
    ind = "  "
    if all(d.bare and not d.props for d in decls):
        _fill(out, head, [(d.name, d.span) for d in decls], span)
        return
    out.emit(f"({head}", ind, span, header=True)
    for d in decls:
        out.emit(decl(d), ind * 2, d.span)
    _close_group(out, span, ind * 2, ind)


def _goal(out: _Out, sec: ast.Goal) -> None:
    ind = "  "
    if not sec.conjunction:
        out.emit(f"(:goal {atom(sec.atoms[0])})", ind, sec.span)
        return
    one_line = "(:goal (and" + "".join(" " + atom(a) for a in sec.atoms) + "))"
    s, last = sec.span, sec.atoms[-1].span if sec.atoms else sec.span
    # a comment before the last atom keeps the goal on several lines; one inside or after the last atom does
    # not: it is printed after that atom, outside the goal, where the next formatting finds it (idempotence)
    commented = s.file != "<generated>" and any(
        (s.line, s.column) < (c.line, c.column) < (last.line, last.column) for c in out.pending
    )
    if len(ind + one_line) <= WIDTH and not commented:
        out.emit(one_line, ind, sec.span)
        return
    out.emit("(:goal (and", ind, sec.span, header=True)
    for a in sec.atoms:
        out.emit(atom(a), ind * 3, a.span)
    _close_group(out, sec.span, ind * 3, ind)
    out.close(ind)


def _fill(out: _Out, head: str, names: list[tuple[str, Span]], span: Span) -> None:
    """``(head a b c ...)`` filled to WIDTH; a comment before a name starts a new line."""
    ind, cont = "  ", "    "
    out.emit("(" + head, ind, span, header=True)
    for name, nspan in names:
        has_comment = (
            bool(out.pending)
            and nspan.file != "<generated>"
            and (out.pending[0].line, out.pending[0].column) < (nspan.line, nspan.column)
        )
        if has_comment or out.lines[-1][1] or len(out.lines[-1][0]) + 1 + len(name) > WIDTH:
            out.emit(name, cont, nspan)
        else:
            out.append(" " + name)
            if nspan.file != "<generated>":
                out.last_line = nspan.end_line
    _close_group(out, span, cont, ind)


def _close_group(out: _Out, span: Span, inner: str, indent: str) -> None:
    """Emit the comments before the group's closing parenthesis, then close it."""
    if span.file != "<generated>":
        out.flush_before(Span("", span.end_line, span.end_column - 1, 0, 0), inner)
    out.close(indent)
