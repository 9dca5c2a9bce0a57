"""The ``.mrg`` language: grammar, syntax tree, checks, checked model and canonical printer."""

from mrgc.language.loader import MAX_BYTES, MrgFile, parse_file, parse_string
from mrgc.language.model import PREDICATES, Domain, Fact, Problem

__all__ = ["MAX_BYTES", "MrgFile", "parse_file", "parse_string", "PREDICATES", "Domain", "Fact", "Problem"]
