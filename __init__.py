"""mrgc: a declarative domain compiler and solver for multi-robot geometric task-and-motion planning.

Public API (everything the ``mrgc`` command does is a thin layer over these):

- :func:`parse_file`, :func:`parse_string`: read and check a ``.mrg`` file → :class:`MrgFile`
  holding checked :class:`Problem` objects (raises :class:`InputError` listing every diagnostic).
- :func:`format_source`: canonical text of a parsed file (what ``mrgc fmt`` prints).
"""

from mrgc.errors import Diagnostic, InputError, MrgcError, Span
from mrgc.language.loader import MrgFile, parse_file, parse_string
from mrgc.language.model import Domain, Fact, Problem
from mrgc.language.printer import format_source

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "Diagnostic",
    "Domain",
    "Fact",
    "InputError",
    "MrgFile",
    "MrgcError",
    "Problem",
    "Span",
    "format_source",
    "parse_file",
    "parse_string",
]
