"""``mrgc facts --summary`` / ``mrgc.facts_summary`` and the reach map ``mrgc render FILE --reach`` (issue 24):
what each robot reaches, how each goal can be delivered, what nobody reaches with its nearest miss, and a
top-down picture of where each arm reaches, on the shipped problems."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from support import ROOT, run_cli

import mrgc
from mrgc.geometry.kinematics import RobotModel
from mrgc.geometry.reach import reach_map
from mrgc.geometry.scene import scene_from_problem
from mrgc.render.palette import ROBOT_COLOURS, byte_colour

PACKAGING = ROOT / "domains" / "packaging"


def test_a_symbolic_summary_names_partners_routes_and_misses() -> None:
    summary = mrgc.facts_summary(ROOT / "domains" / "symbolic" / "handover.mrg")
    r1, r2 = summary.robots
    assert (r1.picks, r1.places, r1.handover_partners) == (("o1", "o2"), ("start",), ("r2",))
    assert (r2.picks, r2.places, r2.handover_partners) == (("o3",), ("goal",), ("r1",))
    routes = {g.obj: (g.route, g.by) for g in summary.goals}
    assert routes == {"o1": ("handover", ("r1->r2",)), "o2": ("handover", ("r1->r2",)), "o3": ("direct", ("r2",))}
    assert [g.obj for g in summary.needs_help] == ["o1", "o2"] and summary.missed == []


def test_the_summary_of_a_shipped_geometric_problem(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "facts", PACKAGING / "pa3-handover.mrg", "--summary", "json")
    assert code == 0
    doc = json.loads(out)
    robots = {r["name"]: r for r in doc["robots"]}
    # only r1 reaches the start region's objects and only r2 the goal bin: o1 needs the handover
    assert robots["r1"]["picks"] == ["o1", "o2", "o3"] and robots["r2"]["picks"] == []
    assert "bin-b" in robots["r2"]["places"] and "bin-b" not in robots["r1"]["places"]
    assert robots["r1"]["handover_partners"] == ["r2"]
    assert doc["goals"] == [{"object": "o1", "region": "bin-b", "route": "handover", "by": ["r1->r2"]}]
    assert doc["unreachable"] == []


def test_what_nobody_reaches_comes_with_the_nearest_miss(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], panda: RobotModel
) -> None:
    """An object 2.5 m from the only arm, a goal bin 3 m away: both missed, by how far out of reach."""
    (tmp_path / "far.mrg").write_text(
        """(define (domain cell)
  (:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand")
  (:grasps top))
(define (problem far)
  (:domain cell)
  (:robots (r1 :kind panda :base (0 -0.6 0 90)))
  (:regions
    (start :shape (box 0.3 0.3 0.3) :pose (0 0 0.15 0))
    (away :shape (box 0.3 0.3 0.3) :pose (2.5 0 0.15 0))
    (far :shape (box 0.3 0.3 0.3) :pose (3 0 0.15 0)))
  (:movable
    (o1 :shape (box 0.04 0.04 0.1) :pose (0 0 0.05 0))
    (o2 :shape (box 0.04 0.04 0.1) :pose (2.5 0 0.05 0)))
  (:goal (in-region o1 far)))
"""
    )
    summary = mrgc.facts_summary(tmp_path / "far.mrg")
    assert summary.goals[0].route == "none"
    missed = {(m.obj, m.region): m for m in summary.missed}
    assert set(missed) == {("o2", None), ("o1", "far")}
    # beyond the reach bound (the Panda's, plus its derived tool centre point) from r1's shoulder: o2's
    # centre, and the nearest point of the goal bin (x = 2.85, y = -0.15, its top z = 0.3)
    bound = panda.reach + 0.105
    shoulder = np.array([0.0, -0.6, panda.shoulder[2]])
    assert missed[("o2", None)].nearest == "r1"
    assert missed[("o2", None)].distance == pytest.approx(np.linalg.norm([2.5, 0.0, 0.05] - shoulder) - bound, abs=1e-3)
    near = [2.85, -0.15, min(0.3, shoulder[2])]  # the corner of the bin nearest the shoulder
    assert missed[("o1", "far")].distance == pytest.approx(np.linalg.norm(near - shoulder) - bound, abs=1e-3)
    code, out, _ = run_cli(capsys, "facts", tmp_path / "far.mrg", "--summary")
    assert code == 0
    assert "object o2 (no pick): nearest r1, " in out and "goal o1 -> far (no place): nearest r1, " in out


@pytest.fixture(scope="module")
def pa3_reach() -> tuple[mrgc.Problem, object]:
    problem = mrgc.load_problem(PACKAGING / "pa3-handover.mrg")
    return problem, reach_map(scene_from_problem(problem))


def test_the_reach_map_covers_what_the_facts_say_each_arm_picks(pa3_reach: tuple[mrgc.Problem, object]) -> None:
    problem, found = pa3_reach
    facts = mrgc.facts_summary(problem)
    scene = scene_from_problem(problem)
    for robot in facts.robots:
        reached = found.reached[robot.name]  # type: ignore[attr-defined]
        for obj in robot.picks:  # a cell next to the object's centre is reached
            x, y = scene.body(obj).pose[:2, 3]
            i, j = np.abs(found.ys - y).argmin(), np.abs(found.xs - x).argmin()  # type: ignore[attr-defined]
            assert reached[max(0, i - 1) : i + 2, max(0, j - 1) : j + 2].any(), (robot.name, obj)
        assert 0.1 < reached.mean() < 0.9  # an arm reaches part of the scene, not all of it
        # the arm's base is inside its own reach area's bounding box
        ys, xs = np.nonzero(reached)
        bx, by = scene.robot(robot.name).base[:2, 3]
        assert found.xs[xs.min()] <= bx <= found.xs[xs.max()]  # type: ignore[attr-defined]


def test_render_reach_draws_each_arm_in_its_colour(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "reach.png"
    code, text, _ = run_cli(capsys, "render", PACKAGING / "pa3-handover.mrg", "--reach", "-o", out)
    assert code == 0 and "reach map (r1 reaches " in text and ", r2 reaches " in text
    pixels = np.asarray(Image.open(out).convert("RGB")).reshape(-1, 3).astype(int)
    assert Image.open(out).size == (900, 700)
    for colour in ROBOT_COLOURS[:2]:  # each arm's base dot and outline are drawn in its colour
        near = np.abs(pixels - np.array(byte_colour(colour))).sum(axis=1) < 30
        assert near.sum() > 200
    code, _, err = run_cli(capsys, "render", PACKAGING / "pa3-handover.mrg", "--reach", "-o", tmp_path / "r.gif")
    assert code == 2 and "error[E000]: --reach writes the reach map" in err
