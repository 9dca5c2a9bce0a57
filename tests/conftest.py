"""Test-suite wiring: the helper modules beside the tests made importable, and the fixtures many tests share.

Tests run with ``--import-mode=importlib`` and no ``tests/__init__.py``, so sibling helper modules are not
on the import path; conftest runs first and registers them once for every test module: ``support`` (the
repository root ``ROOT``, the Panda model, ``mrgc`` run in this process), the validator's valid plans
(``validator_plans``), a headless Chromium driver (``headless_chromium``) and issue 21's doctored plans
(``doctor``).  (The independent skeleton oracle is installed with the package: ``mrgc.testing.oracle``.)

Fixture: ``panda``, the Franka Panda's model, loaded once.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

for _name in ("support", "validator_plans", "headless_chromium", "doctor", "adversarial_round2"):
    if _name not in sys.modules:
        _spec = importlib.util.spec_from_file_location(_name, Path(__file__).with_name(f"{_name}.py"))
        assert _spec is not None and _spec.loader is not None
        _module = importlib.util.module_from_spec(_spec)
        sys.modules[_name] = _module
        _spec.loader.exec_module(_module)

from support import panda_model  # noqa: E402 - registered just above

from mrgc.geometry.kinematics import RobotModel  # noqa: E402


@pytest.fixture(scope="session")
def panda() -> RobotModel:
    """The Franka Panda of the packaging domain (tool link ``panda_hand``)."""
    return panda_model()
