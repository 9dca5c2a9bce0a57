"""Test-suite wiring: make the sibling helper modules importable: the validator's valid plans
(``validator_plans``) and a headless Chromium driver (``headless_chromium``).  (The independent skeleton
oracle is installed with the package: ``mrgc.testing.oracle``.)

Tests run with ``--import-mode=importlib`` and no ``tests/__init__.py``, so sibling helper modules are not
on the import path; conftest runs first and registers them once for every test module.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

for _name in ("validator_plans", "headless_chromium"):
    if _name not in sys.modules:
        _spec = importlib.util.spec_from_file_location(_name, Path(__file__).with_name(f"{_name}.py"))
        assert _spec is not None and _spec.loader is not None
        _module = importlib.util.module_from_spec(_spec)
        sys.modules[_name] = _module
        _spec.loader.exec_module(_module)
