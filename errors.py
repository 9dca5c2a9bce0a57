"""The one exception root of mrgc, and located diagnostics.

Every problem a user can cause (a bad ``.mrg`` file, a bad command line, a missing solver) is reported as a
:class:`Diagnostic`: an error code from :mod:`mrgc.language.codes`, a one-line message, and where known a
:class:`Span` in a source file.  Diagnostics render as ``file:line:col: error[E###]: message`` followed by the
source line and a caret under the span.  Outcomes of solving (no plan, time limit) are *not* exceptions: they
are status values on result objects.
"""

from __future__ import annotations

import stat
from dataclasses import dataclass, field
from typing import Iterable, NamedTuple, Sequence

from mrgc.exits import ExitCode


class Span(NamedTuple):
    """A half-open region of a source file: 1-based line and column of its first and one-past-last char.

    A named tuple (not a dataclass) because the parser makes tens of thousands of them per large file.
    """

    file: str
    line: int
    column: int
    end_line: int
    end_column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


@dataclass(frozen=True)
class Diagnostic:
    """One located complaint about the user's input.

    ``code`` is a stable identifier (``E###`` for errors, ``W###`` for warnings) documented in docs/errors.md;
    ``message`` is a single line; ``span`` says where, when the complaint is about a file.
    """

    code: str
    message: str
    span: Span | None = None
    severity: str = "error"
    notes: tuple[str, ...] = field(default=())

    def headline(self) -> str:
        """The single ``file:line:col: error[E###]: message`` line."""
        where = f"{self.span}: " if self.span is not None else ""
        return f"{where}{self.severity}[{self.code}]: {self.message}"

    def render(self, source: str | Sequence[str] | None = None) -> str:
        """The headline, then (when ``source`` holds the file's text or lines) the source line with a caret."""
        lines = [self.headline()]
        if self.span is not None and source is not None:
            lines.extend(_snippet(source.split("\n") if isinstance(source, str) else source, self.span))
        lines.extend(f"  = note: {n}" for n in self.notes)
        return "\n".join(lines)


def _snippet(text_lines: Sequence[str], span: Span) -> list[str]:
    if not 1 <= span.line <= len(text_lines):
        return []
    text = text_lines[span.line - 1]
    if len(text) > 200:  # keep the caret line readable on generated one-line files
        start = max(0, span.column - 80)
        text = ("..." if start else "") + text[start : start + 160].rstrip("\r").replace("\t", " ")
        col = span.column - start + (3 if start else 0)
    else:
        text = text.rstrip("\r").replace("\t", " ")
        col = span.column
    width = span.end_column - span.column if span.end_line == span.line else len(text) - col + 1
    width = max(1, min(width, len(text) - col + 2))
    gutter = str(span.line)
    pad = " " * len(gutter)
    return [f" {gutter} | {text}", f" {pad} | {' ' * (col - 1)}{'^' * width}"]


class MrgcError(Exception):
    """Root of every exception mrgc raises on purpose.  ``exit_code`` is what the CLI exits with."""

    exit_code: ExitCode = ExitCode.INTERNAL

    def __init__(self, message: str, diagnostics: Sequence[Diagnostic] = ()) -> None:
        super().__init__(message)
        self.diagnostics: tuple[Diagnostic, ...] = tuple(diagnostics)

    def __reduce__(self) -> tuple[object, ...]:
        # picklable across processes (worker pools) whatever the subclass's constructor takes
        return (_rebuild, (type(self), self.args, self.__dict__))


def _rebuild(cls: type, args: tuple[object, ...], state: dict[str, object]) -> "MrgcError":
    err: MrgcError = Exception.__new__(cls)
    err.args = args
    err.__dict__.update(state)
    return err


class InputError(MrgcError):
    """The user's input (a file or the command line) is wrong; carries every diagnostic found."""

    exit_code = ExitCode.INPUT

    def __init__(self, diagnostics: Iterable[Diagnostic], sources: dict[str, str] | None = None) -> None:
        diags = tuple(diagnostics)
        first = diags[0].headline() if diags else "invalid input"
        more = f" (and {len(diags) - 1} more)" if len(diags) > 1 else ""
        super().__init__(first + more, diags)
        #: text of the files the spans point into, so the CLI can draw carets
        self.sources: dict[str, str] = dict(sources or {})

    def render(self) -> str:
        """Every diagnostic with its snippet, in file order (each file is split into lines once)."""
        split: dict[str, list[str]] = {}
        out = []
        for d in self.diagnostics:
            lines = None
            if d.span is not None and d.span.file in self.sources:
                if d.span.file not in split:
                    split[d.span.file] = self.sources[d.span.file].split("\n")
                lines = split[d.span.file]
            out.append(d.render(lines))
        return "\n".join(out)


class MissingBackendError(MrgcError):
    """A solver or geometry library needed for the request is not installed."""

    exit_code = ExitCode.MISSING_BACKEND


class InternalError(MrgcError):
    """A bug in mrgc; reported without a traceback and exit code 70."""

    exit_code = ExitCode.INTERNAL


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` that is not a regular file is ("a folder", "a FIFO", ...), for the
    messages that refuse it: an input (:mod:`mrgc.language.files`) or an output (:mod:`mrgc.outputs`)."""
    for test, name in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "a special file"  # pragma: no cover
