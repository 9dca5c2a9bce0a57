"""Test-suite wiring: the helper modules beside the tests made importable, and the fixtures many tests share.

Tests run with ``--import-mode=importlib`` and no ``tests/__init__.py``, so sibling helper modules are not
on the import path; conftest runs first and registers them once for every test module: ``support`` (the
repository root ``ROOT``, the Panda model, ``mrgc`` run in this process), the validator's valid plans
(``validator_plans``), a headless Chromium driver (``headless_chromium``) and issue 21's doctored plans
(``doctor``).  (The independent skeleton oracle is installed with the package: ``mrgc.testing.oracle``.)

Fixture: ``panda``, the Franka Panda's model, loaded once.  The facts cache: see below (its own folder, off
unless a test turns it on).
"""

from __future__ import annotations

import atexit
import importlib.util
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

# numpy's OpenBLAS on one thread, as the mrgc command runs it (cli.py): the suite's two workers would
# otherwise each start a BLAS thread per core that spins beside the other worker.  Set before any module
# of the tests imports numpy (OpenBLAS reads it once, when numpy loads).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# The facts cache (planner/facts_cache.py) of the test session is its own, never the user's: a fresh
# XDG_CACHE_HOME, removed at exit, inherited by the mrgc processes tests start.  It is also off by default,
# so that no test's outcome depends on which tests ran before it (a deadline that cuts phase 1 short, the
# seconds phase 1 took); tests of the cache turn it on (monkeypatch.delenv("MRGC_NO_CACHE")).
_CACHE_HOME = tempfile.mkdtemp(prefix="mrgc-test-cache-")
atexit.register(shutil.rmtree, _CACHE_HOME, True)
os.environ["XDG_CACHE_HOME"] = _CACHE_HOME
os.environ["MRGC_NO_CACHE"] = "1"

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
