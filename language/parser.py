"""Text → syntax tree.  The grammar lives in grammar.lark; one transformer method per rule builds the AST.

Syntax errors become :class:`~mrgc.errors.Diagnostic` values with readable "expected ..." lists (never lark's
terminal names).  The parser is built once per process from a cached LALR table.
"""

from __future__ import annotations

import threading
from functools import lru_cache
from pathlib import Path
from typing import Any

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from mrgc.errors import Diagnostic, Span
from mrgc.language import ast
from mrgc.language.parens import paren_at, unclosed_paren
from mrgc.language.suggest import did_you_mean

GRAMMAR = Path(__file__).with_name("grammar.lark")

#: how a terminal is named in "expected ..." messages
_READABLE = {
    "NAME": "a name",
    "KEYWORD": "a :keyword",
    "NUMBER": "a number",
    "STRING": "a string",
    "AXIS": "an axis like -z",
    "$END": "end of file",
}


@lru_cache(maxsize=1)
def _lark() -> Lark:
    return Lark(
        GRAMMAR.read_text(encoding="utf-8"),
        parser="lalr",
        keep_all_tokens=True,
        maybe_placeholders=False,
        transformer=_TRANSFORMER,
        start="file",
        cache=True,
    )


@lru_cache(maxsize=1)
def _terminal_text() -> dict[str, str]:
    """Terminal name → how to show it: the literal in quotes, else a phrase."""
    out: dict[str, str] = {}
    for term in _lark().terminals:
        if term.pattern.type == "str":
            out[term.name] = f"'{term.pattern.value}'"
        else:
            out[term.name] = _READABLE.get(term.name, term.name.lower())
    out.update({k: v for k, v in _READABLE.items() if k not in out})
    return out


def _tok_span(file: str, tok: Token) -> Span:
    line, col = tok.line or 1, tok.column or 1
    end_line = tok.end_line or line
    end_col = tok.end_column or col + max(1, len(str(tok)))
    return Span(file, line, col, end_line, end_col)


_NAMED = frozenset({"NAME", "KEYWORD", "NUMBER", "STRING", "AXIS"})
#: tokens that are values: unexpected, they are a mistake of their own, not a sign of a missing ")"
_VALUES = _NAMED - {"KEYWORD"}


class _ToAst(Transformer[Token, Any]):
    """One method per grammar rule; each returns the AST node of that rule.

    It runs inside the LALR parser (no parse tree is built).  Rules keep all their tokens, so a node's
    span runs from its opening to its closing parenthesis; the punctuation is then dropped.
    """

    def __init__(self) -> None:
        super().__init__(visit_tokens=False)
        self.path = "<string>"

    def _parts(self, children: list[Any]) -> tuple[Span, list[Any]]:
        first, last = children[0], children[-1]
        span = Span(self.path, first.line, first.column, last.end_line, last.end_column)
        keep = [c for c in children if not isinstance(c, Token) or c.type in _NAMED]
        return span, keep

    def _tspan(self, tok: Token) -> Span:
        return _tok_span(self.path, tok)

    # ------------------------------------------------------------ file and definitions
    def file(self, children: list[Any]) -> ast.SourceFile:
        return ast.SourceFile(tuple(children), path=self.path)

    def domain_def(self, children: list[Any]) -> ast.DomainDef:
        span, (name, *sections) = self._parts(children)
        return ast.DomainDef(str(name), tuple(sections), span)

    def problem_def(self, children: list[Any]) -> ast.ProblemDef:
        span, (name, *sections) = self._parts(children)
        return ast.ProblemDef(str(name), tuple(sections), span)

    # ------------------------------------------------------------ domain sections
    def requirements(self, children: list[Any]) -> ast.Requirements:
        span, flags = self._parts(children)
        return ast.Requirements(tuple(str(t)[1:] for t in flags), tuple(self._tspan(t) for t in flags), span)

    def robot_kind(self, children: list[Any]) -> ast.RobotKindDecl:
        span, (name, *props) = self._parts(children)
        return ast.RobotKindDecl(str(name), tuple(props), span)

    def grasps(self, children: list[Any]) -> ast.Grasps:
        span, decls = self._parts(children)
        return ast.Grasps(tuple(decls), span)

    def include(self, children: list[Any]) -> ast.Include:
        span, (path,) = self._parts(children)
        return ast.Include(_unquote(str(path)), span)

    # ------------------------------------------------------------ problem sections
    def domain_ref(self, children: list[Any]) -> ast.DomainRef:
        span, (name,) = self._parts(children)
        return ast.DomainRef(str(name), span)

    def _decls(self, kind: str, children: list[Any]) -> ast.DeclSection:
        span, decls = self._parts(children)
        return ast.DeclSection(kind, tuple(decls), span)

    def robots(self, children: list[Any]) -> ast.DeclSection:
        return self._decls("robots", children)

    def fixed(self, children: list[Any]) -> ast.DeclSection:
        return self._decls("fixed", children)

    def regions(self, children: list[Any]) -> ast.DeclSection:
        return self._decls("regions", children)

    def movable(self, children: list[Any]) -> ast.DeclSection:
        return self._decls("movable", children)

    def handover_points(self, children: list[Any]) -> ast.DeclSection:
        return self._decls("handover-points", children)

    def init(self, children: list[Any]) -> ast.Init:
        span, atoms = self._parts(children)
        return ast.Init(tuple(atoms), span)

    def goal(self, children: list[Any]) -> ast.Goal:
        span, (expr,) = self._parts(children)
        if isinstance(expr, ast.Atom):
            return ast.Goal((expr,), conjunction=False, span=span)
        return ast.Goal(expr, conjunction=True, span=span)

    def conjunction(self, children: list[Any]) -> tuple[ast.Atom, ...]:
        return tuple(c for c in children if isinstance(c, ast.Atom))

    # ------------------------------------------------------------ declarations and values
    def bare_decl(self, children: list[Token]) -> ast.Decl:
        return ast.Decl(str(children[0]), (), True, self._tspan(children[0]))

    def full_decl(self, children: list[Any]) -> ast.Decl:
        _, (name, *props) = self._parts(children)
        return ast.Decl(str(name), tuple(props), False, self._tspan(name))

    def prop(self, children: list[Any]) -> ast.Property:
        key, value = children
        return ast.Property(
            str(key)[1:], value, Span(self.path, key.line, key.column, value.span.end_line, value.span.end_column)
        )

    def number(self, children: list[Token]) -> ast.Number:
        tok = children[0]
        return ast.Number(float(tok), self._tspan(tok))

    def symbol(self, children: list[Token]) -> ast.Symbol:
        return ast.Symbol(str(children[0]), self._tspan(children[0]))

    def string(self, children: list[Token]) -> ast.String:
        return ast.String(_unquote(str(children[0])), self._tspan(children[0]))

    def list_value(self, children: list[Any]) -> ast.ListValue:
        span, items = self._parts(children)
        return ast.ListValue(tuple(items), span)

    def atom(self, children: list[Any]) -> ast.Atom:
        # hot path (a large problem is mostly atoms): children are exactly '(' NAME NAME* ')'
        first, head, *args, last = children
        path = self.path
        return ast.Atom(
            str(head),
            tuple(str(a) for a in args),
            tuple(Span(path, a.line, a.column, a.end_line, a.end_column) for a in args),
            Span(path, first.line, first.column, last.end_line, last.end_column),
        )


_TRANSFORMER = _ToAst()
_LOCK = threading.Lock()


def _unquote(text: str) -> str:
    body = text[1:-1]
    if "\\" not in body:
        return body
    out, i = [], 0
    while i < len(body):
        ch = body[i]
        if ch == "\\" and i + 1 < len(body):
            nxt = body[i + 1]
            out.append({"n": "\n", "t": "\t"}.get(nxt, nxt))
            i += 2
        else:
            out.append(ch)
            i += 1
    return "".join(out)


def parse_text(text: str, file: str = "<string>") -> ast.SourceFile | Diagnostic:
    """Parse ``text``; return its syntax tree, or the diagnostic of the first syntax error."""
    parser = _lark()
    with _LOCK:  # the transformer runs inside the parser and holds the current file name
        _TRANSFORMER.path = file
        try:
            result = parser.parse(text)
        except UnexpectedInput as exc:
            return _syntax_diagnostic(exc, text, file)
    assert isinstance(result, ast.SourceFile)
    return result


def _expected(names: set[str] | frozenset[str]) -> list[str]:
    table = _terminal_text()
    shown = sorted({table.get(n, n) for n in names if not n.startswith("__IGNORE")})
    return shown


def _phrase(items: list[str]) -> str:
    if not items:
        return "nothing"
    if len(items) == 1:
        return items[0]
    if len(items) > 8:
        items = items[:8] + ["..."]
    return ", ".join(items[:-1]) + " or " + items[-1]


def _section_literals(names: set[str] | frozenset[str]) -> list[str]:
    table = _terminal_text()
    return sorted(table[n].strip("'") for n in names if table.get(n, "").startswith("':"))


def _syntax_diagnostic(exc: UnexpectedInput, text: str, file: str) -> Diagnostic:
    """The diagnostic of a syntax error; one a missing ``)`` explains is reported at the ``(`` left open
    (E102 at the end of the file, E104 before the next form: :mod:`mrgc.language.parens`)."""
    found = _first_syntax_diagnostic(exc, text, file)
    if isinstance(exc, UnexpectedToken) and (
        found.code == "E102" or (found.code == "E101" and exc.token.type not in _VALUES and str(exc.token) != ")")
    ):
        end = len(text) if exc.token.type == "$END" else (exc.token.start_pos or 0)
        paren = unclosed_paren(text, end)
        if paren is not None:
            span = Span(file, paren.line, paren.column, paren.line, paren.column + 1 + len(paren.word))
            what = f"'({paren.word}'" if paren.word else "'('"
            if found.code == "E102":
                return Diagnostic(
                    "E102",
                    f"{what} is never closed: the file ends inside it",
                    span,
                    notes=(f"the file ends at {found.span}",),
                )
            assert found.span is not None
            return Diagnostic(
                "E104",
                f"{what} is not closed before {_form_at(text, end)} on line {found.span.line}",
                span,
                notes=(f"at {found.span}: {found.message}",),
            )
    return found


def _form_at(text: str, offset: int) -> str:
    """How to name what starts at ``offset``: ``'(:goal'`` for a form whose ``(`` is there or just before."""
    before = text[:offset].rstrip()
    start = len(before) - 1 if before.endswith("(") else offset
    if text.startswith("(", start):
        return f"'({paren_at(text, start).word}'"
    return f"'{text[start:].split(None, 1)[0][:40]}'" if text[start:].strip() else "the end"


def _first_syntax_diagnostic(exc: UnexpectedInput, text: str, file: str) -> Diagnostic:
    line = getattr(exc, "line", 1) or 1
    col = getattr(exc, "column", 1) or 1
    if isinstance(exc, UnexpectedToken):
        tok = exc.token
        expected = set(exc.expected)
        if tok.type == "$END":
            span = _end_span(text, file)
            return Diagnostic("E102", f"unexpected end of file; expected {_phrase(_expected(expected))}", span)
        span = _tok_span(file, tok)
        sections = _section_literals(expected)
        if tok.type == "KEYWORD" and sections:
            return _unknown_section(str(tok), sections, span)
        what = _describe_token(tok)
        return Diagnostic("E101", f"unexpected {what}; expected {_phrase(_expected(expected))}", span)
    if isinstance(exc, UnexpectedCharacters):
        allowed = set(exc.allowed or ())
        sections = _section_literals(allowed)
        word = _word_at(text, exc.pos_in_stream or 0)
        span = Span(file, line, col, line, col + max(1, len(word)))
        if word.startswith(":") and sections:
            return _unknown_section(word, sections, span)
        if exc.char == '"':
            return Diagnostic("E100", "unterminated string", span)
        shown = word if len(word) > 1 else exc.char
        return Diagnostic("E100", f"unexpected {shown!r}; expected {_phrase(_expected(allowed))}", span)
    if isinstance(exc, UnexpectedEOF):  # pragma: no cover - LALR reports end of input as UnexpectedToken
        return Diagnostic("E102", "unexpected end of file", _end_span(text, file))
    return Diagnostic("E101", str(exc).splitlines()[0], Span(file, line, col, line, col + 1))  # pragma: no cover


def _unknown_section(word: str, sections: list[str], span: Span) -> Diagnostic:
    return Diagnostic("E103", f"unknown section '{word}'{did_you_mean(word, sections)}", span)


def _describe_token(tok: Token) -> str:
    if tok.type in ("NAME", "AXIS"):
        return f"name '{tok}'"
    if tok.type == "NUMBER":
        return f"number {tok}"
    if tok.type == "STRING":
        return f"string {tok}"
    if tok.type == "KEYWORD":
        return f"keyword '{tok}'"
    return f"'{tok}'"


def _word_at(text: str, pos: int) -> str:
    end = pos
    while end < len(text) and end - pos < 40 and not text[end].isspace() and text[end] not in "()":
        end += 1
    return text[pos:end] or text[pos : pos + 1]


def _end_span(text: str, file: str) -> Span:
    lines = text.split("\n")
    # point at the last non-blank line, where the missing ')' belongs
    idx = len(lines) - 1
    while idx > 0 and not lines[idx].strip():
        idx -= 1
    col = len(lines[idx].rstrip()) + 1
    return Span(file, idx + 1, col, idx + 1, col + 1)
