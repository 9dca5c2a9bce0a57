"""What a cart carries rides above the floor and outside the cart (session 40).  A 0.6 m tall box at the
shipped box-moving kind's carry height (its centre 0.2 m up) was dragged 10 cm through the floor, a 0.6 m deep
one rode 10 cm inside its own cart, and the validator accepted both plans.  Now phase 1 gives such an object
no fact (``PlanarRobot.load_fits``), ``mrgc check`` warns (W278), and the validator rejects such a carry
(``carry``): shown here on the plans the planner made before, rebuilt by letting every load fit."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from support import ROOT

from mrgc import cli, parse_file
from mrgc.geometry.planar import PlanarRobot
from mrgc.geometry.scene import RobotSpec
from mrgc.geometry.transforms import from_pose
from mrgc.language.model import Box
from mrgc.validator.replay import _Replayer

PROBLEM = """(define (problem load)
  (:domain box-moving)
  (:robots (r1 :kind mover :base (-1.5 0 0 0)))
  (:regions
    (start :shape (box 3 4 0.8) :pose (-1.5 0 0.4 0))
    (goal :shape (box 2 3 0.8) :pose (1.7 0 0.4 0)))
  (:movable (g1 :shape (box {sx} {sy} {sz}) :pose (-0.5 0 {z} 0)))
  (:goal (in-region g1 goal)))
"""
CASES = {"tall": (0.3, 0.3, 0.6), "deep": (0.6, 0.6, 0.3), "fits": (0.4, 0.4, 0.4)}


def _write(folder: Path, name: str) -> Path:
    sx, sy, sz = CASES[name]
    (folder / "domain.mrg").write_text((ROOT / "domains" / "box-moving" / "domain.mrg").read_text(encoding="utf-8"))
    path = folder / f"{name}.mrg"
    path.write_text(PROBLEM.format(sx=sx, sy=sy, sz=sz, z=sz / 2), encoding="utf-8")
    return path


def test_which_loads_fit_the_shipped_cart(tmp_path: Path) -> None:
    spec = parse_file(_write(tmp_path, "fits")).problem()
    robot = spec.robots[0]
    kind = next(k for k in spec.domain.robot_kinds if k.name == robot.kind)
    cart = PlanarRobot(RobotSpec(robot.name, kind, from_pose(robot.base)))
    assert cart.load_fits(Box(0.4, 0.4, 0.4), "side-x-")  # touching the cart's front, its bottom on the floor
    assert not cart.load_fits(Box(0.3, 0.3, 0.6), "side-x-")  # 10 cm into the floor
    assert not cart.load_fits(Box(0.6, 0.6, 0.3), "side-x-")  # 10 cm into the cart


@pytest.mark.parametrize(
    ("name", "message"), [("tall", "mm below the floor it drives on"), ("deep", "mm into its own footprint")]
)
def test_a_carry_into_the_floor_or_the_cart_is_rejected(
    name: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    src, out = _write(tmp_path, name), tmp_path / "plan.json"
    assert cli.main(["check", str(src)]) == 0 and "warning[W278]" in capsys.readouterr().err
    monkeypatch.setenv("MRGC_NO_CACHE", "1")
    assert cli.main(["plan", str(src), "--time-limit", "60"]) == 1  # infeasible: no fact carries it
    capsys.readouterr()
    # the planner and the validator before: every load fits, no carry is checked
    monkeypatch.setattr(PlanarRobot, "load_fits", lambda self, shape, grasp: True)
    monkeypatch.setattr(_Replayer, "_cart_load", lambda self, t, a: None)
    assert cli.main(["plan", str(src), "-o", str(out), "--time-limit", "60"]) == 0
    capsys.readouterr()
    monkeypatch.undo()
    assert cli.main(["validate", str(src), str(out), "--format", "json"]) == 1
    found = [v for v in json.loads(capsys.readouterr().out)["violations"] if v["code"] == "carry"]
    assert found and found[0]["message"].startswith("r1 carries g1 ") and f"100.0 {message}" in found[0]["message"]
