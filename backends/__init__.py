"""Solver backends: each module is the only importer of its solver library (see docs/architecture.md).

The package is also what ``mrgc.backends`` names in the public API, so calling it lists the registered
backends: ``mrgc.backends()`` is :func:`mrgc.backends.registry.records` (docs/api.md).  Importing it loads
no solver library.
"""

from __future__ import annotations

import sys
import types
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mrgc.backends.registry import BackendRecord


class _Package(types.ModuleType):
    """This package, callable: ``mrgc.backends()`` lists the registered backends."""

    def __call__(self) -> "list[BackendRecord]":
        from mrgc.backends.registry import records

        return records()


sys.modules[__name__].__class__ = _Package
