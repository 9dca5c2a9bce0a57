"""What many test modules share: the repository root, the Panda arm's model, and ``mrgc`` run in this
process with its output captured.  (Registered by conftest.py, which also offers them as fixtures.)"""

from __future__ import annotations

import functools
from pathlib import Path

import pytest

from mrgc import cli
from mrgc.geometry.kinematics import RobotModel, load_robot_model

ROOT = Path(__file__).resolve().parent.parent
#: the Panda of the packaging domain, from pybullet_data
PANDA_URDF = "franka_panda/panda.urdf"


@functools.cache
def panda_model() -> RobotModel:
    """The Franka Panda (tool link ``panda_hand``), loaded once."""
    return load_robot_model(PANDA_URDF, str(ROOT / "domains" / "packaging"), "panda_hand")


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str | Path) -> tuple[int, str, str]:
    """``mrgc ARGV`` in this process (``cli.main``): exit code, standard output, standard error; never a
    traceback or an internal error."""
    capsys.readouterr()
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    bad = [ln for ln in err.splitlines() if ln.startswith(("mrgc: internal error", "Traceback"))]
    assert not bad, err[-2000:]
    return code, out, err
