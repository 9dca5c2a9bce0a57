"""Where a missing ``)`` belongs: the ``(`` a syntax error most likely comes from leaving open.

A forgotten ``)`` shows up late: the parser reads on until something cannot be inside the open form (the
next section, the next ``define``, the end of the file).  Reporting that place sends the user to the wrong
line, so the syntax diagnostics of the parser ask :func:`unclosed_paren` for the opening parenthesis
instead, when the file has more ``(`` than ``)``.

Which ``(`` (of those still open where the parser stopped): the innermost one whose form is followed by a
line that starts at or left of the ``(`` itself (contents are indented deeper than their opening
parenthesis, so such a line was meant to come after the form's ``)``), else the innermost one.  Strings and
``;`` comments are skipped.
"""

from __future__ import annotations

from typing import NamedTuple


class OpenParen(NamedTuple):
    """An unclosed ``(``: its offset in the text, 1-based line and column, and the word after it."""

    offset: int
    line: int
    column: int
    word: str


def open_parens(text: str, end: int) -> list[OpenParen] | None:
    """The parentheses still open at offset ``end`` (outermost first), or None when the whole text has no
    more ``(`` than ``)`` (then no parenthesis is missing)."""
    stack: list[int] = []
    at_end: list[int] | None = None
    depth_total = 0
    i, n = 0, len(text)
    while i < n:
        if i >= end and at_end is None:
            at_end = list(stack)
        ch = text[i]
        if ch == ";":
            nl = text.find("\n", i)
            i = n if nl < 0 else nl
            continue
        if ch == '"':
            i += 1
            while i < n and text[i] != '"' and text[i] != "\n":
                i += 2 if text[i] == "\\" else 1
        elif ch == "(":
            stack.append(i)
            depth_total += 1
        elif ch == ")":
            if stack:
                stack.pop()
            depth_total -= 1
        i += 1
    if at_end is None:
        at_end = list(stack)
    if depth_total <= 0:
        return None
    return [paren_at(text, k) for k in at_end]


def unclosed_paren(text: str, end: int) -> OpenParen | None:
    """The ``(`` most likely left open by a syntax error found at offset ``end`` (see the module
    docstring); None when the text has no unclosed parenthesis."""
    opened = open_parens(text, end)
    if not opened:
        return None
    # a "(" right before the token the parser stopped at was opened by that token's form: not a candidate
    before = text[:end].rstrip()
    if before.endswith("(") and opened[-1].offset == len(before) - 1 and len(opened) > 1:
        opened = opened[:-1]
    starts = _line_starts(text, end)
    for paren in reversed(opened):
        if any(line > paren.line and column <= paren.column for line, column in starts):
            return paren
    return opened[-1]


def _line_starts(text: str, end: int) -> list[tuple[int, int]]:
    """(line, column) of the first character of every line with one before offset ``end`` (blank lines and
    comment lines left out)."""
    out = []
    offset = 0
    for number, line in enumerate(text.split("\n"), 1):
        stripped = line.lstrip(" \t")
        col = len(line) - len(stripped) + 1
        if offset + col - 1 > end:
            break
        if stripped and not stripped.startswith(";"):
            out.append((number, col))
        offset += len(line) + 1
    return out


def paren_at(text: str, offset: int) -> OpenParen:
    """The ``(`` at ``offset``: its line, column and the word after it."""
    line = text.count("\n", 0, offset) + 1
    column = offset - (text.rfind("\n", 0, offset) + 1) + 1
    j = offset + 1
    while j < len(text) and text[j] in " \t":
        j += 1
    k = j
    while k < len(text) and not text[k].isspace() and text[k] not in '()";' and k - j < 40:
        k += 1
    return OpenParen(offset, line, column, text[j:k])
