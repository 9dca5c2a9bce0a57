"""A region's floor holds objects up only where something is under it (session 40): on the ground, or over a
fixed box's top.  A goal region drawn wider than the pedestal it stands on, or a few cm above its table, or
over a table's edge, used to pass the validator with objects released in the air (pybullet: they fall).  The
planner places over the pedestal only (``geometry/scene.py``, ``floor_support``), the validator rejects a
placement off it (``floating``), ``mrgc check`` warns of a floor that holds nothing up (W277)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from support import ROOT

from mrgc import cli, parse_file
from mrgc.geometry.scene import Body, floor_support, ground_height
from mrgc.geometry.transforms import translation
from mrgc.language.model import Box

PEDESTAL = """(define (problem pedestal)
  (:domain packaging)
  (:robots (r1 :kind panda :base (0 -0.55 0 90)))
  (:fixed
    (table :shape (box 1.2 1.2 0.05) :pose (0 0 -0.025 0))
    (pedestal :shape (box 0.16 0.16 0.12) :pose (0.3 0 0.06 0)))
  (:regions
    (start :shape (box 0.3 0.2 0.3) :pose (-0.2 0 0.15 0))
    (top :shape (box 0.26 0.26 0.3) :pose (0.3 0 0.27 0)))
  (:movable
    (o1 :shape (box 0.05 0.05 0.1) :pose (-0.2 0 0.05 0)))
  (:goal (in-region o1 top)))
"""


def _problem(folder: Path, text: str) -> Path:
    (folder / "domain.mrg").write_text((ROOT / "domains" / "packaging" / "domain.mrg").read_text(encoding="utf-8"))
    path = folder / "p.mrg"
    path.write_text(text, encoding="utf-8")
    return path


def test_placements_stand_on_the_pedestal_and_one_beside_it_is_floating(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, out = _problem(tmp_path, PEDESTAL), tmp_path / "plan.json"
    assert cli.main(["plan", str(src), "-o", str(out)]) == 0
    plan = json.loads(out.read_text(encoding="utf-8"))
    (action,) = [a for s in plan["steps"] for a in s["actions"]]
    x, y = np.array(action["place_pose"])[:2, 3]
    assert abs(x - 0.3) <= 0.075 and abs(y) <= 0.075  # over the pedestal's top, 5 mm inside it
    moved = copy.deepcopy(plan)
    moved["steps"][0]["actions"][0]["place_pose"][0][3] = 0.41  # inside the region, beside the pedestal
    bad = tmp_path / "beside.json"
    bad.write_text(json.dumps(moved), encoding="utf-8")
    capsys.readouterr()
    assert cli.main(["validate", str(src), str(bad), "--format", "json"]) == 1
    floating = [v for v in json.loads(capsys.readouterr().out)["violations"] if v["code"] == "floating"]
    assert floating and "floor of top, which holds nothing up there" in floating[0]["message"]


@pytest.mark.parametrize(("z", "warned"), [(0.27, False), (0.31, True)])
def test_a_floor_off_its_table_is_warned_of(
    tmp_path: Path, z: float, warned: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    text = PEDESTAL.replace(
        "(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 0.27 0))", f"(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 {z} 0))"
    )
    assert cli.main(["check", str(_problem(tmp_path, text))]) == 0
    assert ("warning[W277]: the floor of region 'top'" in capsys.readouterr().err) == warned


def test_a_round_pedestal_holds_its_region_up(tmp_path: Path) -> None:
    """A cylinder's top holds up too (only boxes did: 'infeasible', and a false W277)."""
    text = PEDESTAL.replace(
        "(pedestal :shape (box 0.16 0.16 0.12) :pose (0.3 0 0.06 0))",
        "(pedestal :shape (cylinder 0.09 0.12) :pose (0.3 0 0.06 0))",
    )
    src, out = _problem(tmp_path, text), tmp_path / "plan.json"
    assert cli.main(["plan", str(src), "-o", str(out)]) == 0
    assert cli.main(["validate", str(src), str(out)]) == 0


@pytest.mark.parametrize(("z", "holds"), [(0.272, True), (0.278, False)])
def test_a_floor_a_few_mm_above_its_top(
    tmp_path: Path, z: float, holds: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    """Set down 6 mm above a floor 8 mm above the pedestal, the object would be released 14 mm up: floating
    for the validator (10 mm), so the planner takes a top at most 3 mm below the floor (it took 10 mm, and the
    plans it made were refused: 'exhausted')."""
    text = PEDESTAL.replace(
        "(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 0.27 0))", f"(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 {z} 0))"
    )
    src, out = _problem(tmp_path, text), tmp_path / "plan.json"
    assert cli.main(["check", str(src)]) == 0
    assert ("W277" in capsys.readouterr().err) != holds
    assert (cli.main(["plan", str(src), "-o", str(out)]) == 0) == holds
    if holds:
        assert cli.main(["validate", str(src), str(out)]) == 0


def test_the_ground_and_what_holds_a_floor_up() -> None:
    table = Body("table", Box(1.0, 1.0, 0.05), translation(0, 0, -0.025))
    wall = Body("wall", Box(0.1, 2.0, 0.5), translation(1, 0, 0.25))
    sunk = Body("wall", Box(0.1, 2.0, 0.54), translation(1, 0, 0.23))  # 4 cm below z = 0: not the ground's
    assert ground_height([table]) == pytest.approx(-0.05) and ground_height([wall]) == 0.0 and ground_height([]) == 0.0
    assert ground_height([sunk]) == 0.0 and ground_height([sunk, table]) == pytest.approx(-0.05)

    on_table = Body("bin", Box(0.2, 0.2, 0.3), translation(0.45, 0, 0.15))  # half of it over the table's edge
    held = floor_support([table], on_table)
    assert held is not None and held(translation(0.49, 0, 0.05)) and not held(translation(0.5, 0, 0.05))
    assert floor_support([wall], Body("room", Box(2, 2, 0.3), translation(0, 0, 0.15))) is None  # on the ground
    assert floor_support([table], Body("air", Box(0.2, 0.2, 0.3), translation(0, 0, 0.25))) is not None


def test_a_mesh_pedestal_holds_its_top_up(tmp_path: Path) -> None:
    """A mesh's top is the hull of its highest vertices, 5 mm inside it (only boxes held up before)."""
    from mrgc.language.model import Mesh

    v = [(x, y, z) for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.06, 0.06)]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    lines = [f"v {a} {b} {c}" for a, b, c in v] + ["f " + " ".join(map(str, q)) for q in faces]
    (tmp_path / "p.obj").write_text("\n".join(lines) + "\n", encoding="utf-8")
    pedestal = Body("p", Mesh(str(tmp_path / "p.obj")), translation(0.3, 0, 0.06))
    held = floor_support([pedestal], Body("top", Box(0.3, 0.3, 0.3), translation(0.3, 0, 0.27)))
    assert held is not None
    assert held(translation(0.3, 0, 0.2)) and held(translation(0.394, 0, 0.2)) and not held(translation(0.396, 0, 0.2))


def test_shipped_problems_have_no_floor_that_holds_nothing_up(capsys: pytest.CaptureFixture[str]) -> None:
    files = sorted((ROOT / "domains").rglob("*.mrg"))
    problems = [p for f in files for p in parse_file(f).problems if not p.symbolic]
    assert len(problems) >= 10
    for f in files:
        cli.main(["check", str(f)])
    assert "W277" not in capsys.readouterr().err


def test_a_plan_not_found_names_the_floor_first(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The layout's W277 leads the reasons (the plan said only "no robot can reach goal region top")."""
    text = PEDESTAL.replace(
        "(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 0.27 0))", "(top :shape (box 0.26 0.26 0.3) :pose (0.3 0 0.31 0))"
    )
    src = _problem(tmp_path, text)
    assert cli.main(["plan", str(src), "-o", str(tmp_path / "plan.json")]) == 1
    why = capsys.readouterr().out.splitlines()
    assert why[1].startswith("why: infeasible") and "W277 the floor of region 'top'" in why[2]
