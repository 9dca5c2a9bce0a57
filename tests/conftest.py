"""Test-suite wiring: make the independent skeleton oracle importable as ``skeleton_oracle``.

Tests run with ``--import-mode=importlib`` and no ``tests/__init__.py``, so sibling helper modules are not
on the import path; conftest runs first and registers the oracle once for every test module.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

if "skeleton_oracle" not in sys.modules:
    _spec = importlib.util.spec_from_file_location("skeleton_oracle", Path(__file__).with_name("skeleton_oracle.py"))
    assert _spec is not None and _spec.loader is not None
    _module = importlib.util.module_from_spec(_spec)
    sys.modules["skeleton_oracle"] = _module
    _spec.loader.exec_module(_module)
