"""The box-moving domain: planar mobile robots and the path-mode predicates (geometry/planar.py,
geometry/path_predicates.py) on tiny scenes with known answers, and every shipped box-moving problem
compiled to its optimum skeleton from the facts they compute."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from support import ROOT

from mrgc import cli, parse_file, parse_string
from mrgc.geometry.path_predicates import PlanarEvaluator
from mrgc.geometry.planar import DiscGrid, PlanarRobot, placements, scene_bounds
from mrgc.geometry.planar_grasps import CLEARANCE
from mrgc.geometry.scene import SceneSpec, inside, scene_from_problem
from mrgc.language.model import Fact, Problem
from mrgc.planner.skeletons import compile_problem

BOX_MOVING = ROOT / "domains" / "box-moving"
PROBLEMS = sorted(p for p in BOX_MOVING.glob("*.mrg") if p.name != "domain.mrg")

# the shipped domain's mover, with `top` in the vocabulary (planar robots must ignore it)
DOMAIN = """
(define (domain movers)
  (:requirements :planar-base)
  (:robot-kind mover :base planar :footprint (box 0.5 0.4 0.3) :carry (0.45 0 0.2 0))
  (:grasps top side-x+ side-x- side-y+ side-y-))
"""

WALLS = """
    (wall-s :shape (box 4.2 0.1 0.5) :pose (0 -1.55 0.25 0))
    (wall-n :shape (box 4.2 0.1 0.5) :pose (0 1.55 0.25 0))
    (wall-w :shape (box 0.1 3.2 0.5) :pose (-2.05 0 0.25 0))
    (wall-e :shape (box 0.1 3.2 0.5) :pose (2.05 0 0.25 0))"""

# two rooms joined by a 0.8 m doorway at x = 0 that a box stands in; the robot is in the west room,
# `target` in the east room
DOORWAY = (
    DOMAIN
    + f"""
(define (problem doorway)
  (:domain movers)
  (:robots (r1 :kind mover :base (-1.2 0 0 0)))
  (:fixed {WALLS}
    (divider-s :shape (box 0.1 1.1 0.5) :pose (0 -0.95 0.25 0))
    (divider-n :shape (box 0.1 1.1 0.5) :pose (0 0.95 0.25 0)))
  (:regions
    (west :shape (box 2.2 3 0.5) :pose (-0.9 0 0.25 0))
    (east :shape (box 1.8 3 0.5) :pose (1 0 0.25 0)))
  (:movable
    (door :shape (box 0.3 0.3 0.3) :pose (0 0 0.15 0))
    (target :shape (box 0.3 0.3 0.3) :pose (1 0 0.15 0))
    (side :shape (box 0.3 0.3 0.3) :pose (-1.2 1 0.15 0) :grasps (top side-x+)))
  (:goal (in-region target west)))
"""
)

# the same rooms, with no gap in the divider
SEALED = (
    DOMAIN
    + f"""
(define (problem sealed)
  (:domain movers)
  (:robots (r1 :kind mover :base (-1.2 0 0 0)))
  (:fixed {WALLS}
    (divider :shape (box 0.1 3 0.5) :pose (0 0 0.25 0)))
  (:regions
    (west :shape (box 2 3 0.5) :pose (-1 0 0.25 0))
    (east :shape (box 1.8 3 0.5) :pose (1 0 0.25 0)))
  (:movable (box1 :shape (box 0.3 0.3 0.3) :pose (-0.8 0.8 0.15 0)))
  (:goal (in-region box1 east)))
"""
)


def problem_of(text: str) -> Problem:
    return parse_string(text, file="tiny.mrg").problem()


def robot_facts(scene: SceneSpec, seed: int = 0) -> set[Fact]:
    out: set[Fact] = set()
    for r in scene.robots:
        out.update(PlanarEvaluator(scene, r.name, seed).run().facts)
    return out


def all_facts(problem: Problem, seed: int = 0) -> set[Fact]:
    """What phase 1 computes for a box-moving problem: the robots' facts and ``in-region``."""
    scene = scene_from_problem(problem)
    facts = robot_facts(scene, seed)
    facts.update(
        Fact("in-region", (m.name, reg.name))
        for m in scene.movable
        for reg in scene.regions
        if inside(reg, m.shape, m.pose)
    )
    return facts


def of(facts: set[Fact], predicate: str) -> set[tuple[str, ...]]:
    return {f.args for f in facts if f.predicate == predicate}


@pytest.fixture(scope="module")
def doorway() -> tuple[SceneSpec, set[Fact]]:
    scene = scene_from_problem(problem_of(DOORWAY))
    return scene, robot_facts(scene)


# ----------------------------------------------------------------------------------------- the model
def test_pick_base_pose_faces_the_grasped_side_at_the_standoff(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    scene, _ = doorway
    robot = PlanarRobot(scene.robot("r1"))
    target = scene.body("target")  # at (1, 0), 0.3 m cube; footprint 0.5 × 0.4
    d = 0.25 + CLEARANCE + 0.15
    expect = {"side-x+": (1 + d, 0, 180), "side-x-": (1 - d, 0, 0), "side-y+": (1, d, -90), "side-y-": (1, -d, 90)}
    for g, (x, y, yaw) in expect.items():
        q = robot.grasp_base(target.pose, target.shape, g)
        assert np.allclose(q[:2], (x, y)), g
        assert math.isclose(math.cos(q[2] - math.radians(yaw)), 1.0), g
        # carried, the object sits at the kind's carry pose (0.45 0 0.2) with the grasped face to the robot
        carry = robot.carry_transform(target.shape, g)
        assert np.allclose(carry[:3, 3], (0.45, 0, 0.2))


def test_placements_lie_inside_the_region_centre_first(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    scene, _ = doorway
    region = scene.body("east")
    poses = placements(scene.body("target"), region)
    assert poses and all(inside(region, scene.body("target").shape, p) for p in poses)
    assert np.allclose(poses[0][:2, 3], region.pose[:2, 3])


def test_disc_grid_separates_blocked_rooms_only(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    scene, _ = doorway
    robot = PlanarRobot(scene.robot("r1"))
    grid = DiscGrid(robot, scene, scene_bounds(scene, robot.radius + 0.1))
    walls = frozenset(b.name for b in scene.fixed)
    west, east = np.array([-1.2, 0, 0]), np.array([1.0, 0.8, 0])
    assert grid.connected(west, east, walls)
    assert not grid.connected(west, east, walls | {"door"})
    assert grid.connected(west, np.array([-1.2, -1.0, 0]), walls | {"door"})


@pytest.mark.parametrize("door_y", [0.0, 0.08, 0.16, 0.22, 0.3])
def test_disc_grid_never_rules_out_a_path_the_planner_finds(door_y: float) -> None:
    moved = DOORWAY.replace(
        "(door :shape (box 0.3 0.3 0.3) :pose (0 0 0.15 0))",
        f"(door :shape (box 0.3 0.3 0.3) :pose (0 {door_y} 0.15 0))",
    )
    scene = scene_from_problem(problem_of(moved))
    ev = PlanarEvaluator(scene, "r1")
    ev.grid.enabled = False
    start, goal = ev.robot.start, np.array([1.0, 0.0, 0.0])
    found = ev._path(start, goal, None, (), frozenset({"door"}))
    ev.grid.enabled = True
    assert found is None or ev.grid.connected(start, goal, ev.fixed | {"door"})
    if door_y == 0.0:
        assert found is None and not ev.grid.connected(start, goal, ev.fixed | {"door"})
    if door_y == 0.3:
        assert found is not None


def test_disc_grid_changes_no_fact(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    scene, facts = doorway
    ev = PlanarEvaluator(scene, "r1")
    ev.grid.enabled = False
    assert set(ev.run().facts) == facts


# ------------------------------------------------------------------------------------- predicates
def test_box_in_the_doorway_occludes_the_pick_behind_it(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    _, facts = doorway
    picks = {g for (o, g, r) in of(facts, "reachable-pick") if o == "target"}
    assert picks == {"side-x+", "side-x-", "side-y+", "side-y-"}
    occluders = {(m1, g) for (m1, m, g, r) in of(facts, "occludes-pick") if m == "target"}
    assert occluders == {("door", g) for g in picks}
    # the door box itself is picked from the west room only (its side faces are against the divider)
    assert {g for (o, g, r) in of(facts, "reachable-pick") if o == "door"} == {"side-x-"}
    assert not {f for f in of(facts, "occludes-pick") if f[1] == "door"}
    # carrying target home to the west room also crosses the door
    assert {(m1, g) for (m1, m, _, g, _) in of(facts, "occludes-goal-place")} == {("door", g) for g in picks}
    assert {(re, g) for (o, re, g, r) in of(facts, "reachable-place") if o == "target"} == {
        (re, g) for re in ("west", "east") for g in picks
    }


def test_top_and_narrowed_grasps_give_no_facts(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    _, facts = doorway
    assert all("top" not in f.args for f in facts)
    assert {g for (o, g, r) in of(facts, "reachable-pick") if o == "side"} == {"side-x+"}


def test_goal_behind_a_wall_without_a_gap_is_not_reachable() -> None:
    facts = robot_facts(scene_from_problem(problem_of(SEALED)))
    assert of(facts, "reachable-pick")  # box1 can be picked ...
    assert {re for (_, re, _, _) in of(facts, "reachable-place")} == {"west"}  # ... but not taken east
    assert not of(facts, "occludes-pick") and not of(facts, "occludes-goal-place")


def test_same_seed_same_facts() -> None:
    scene = scene_from_problem(parse_file(BOX_MOVING / "bo-doorway.mrg").problem())
    assert robot_facts(scene, seed=3) == robot_facts(scene, seed=3)


def test_no_handovers_for_planar_robots(doorway: tuple[SceneSpec, set[Fact]]) -> None:
    scene, facts = doorway
    assert not of(facts, "enable-goal-handover")
    assert PlanarEvaluator(scene, "r1").run().handover == {}


# ------------------------------------------------------------------------------- shipped problems
@pytest.mark.parametrize("path", PROBLEMS, ids=lambda p: p.name)
def test_shipped_problem_compiles_to_its_expected_optimum(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    expect = re.search(r"^; expect: makespan=(\d+) moved=(\d+)$", text, re.M)
    assert expect, f"{path.name} states no '; expect: makespan=N moved=K' line"
    problem = parse_file(path).problem()
    facts = all_facts(problem)
    result = compile_problem(problem, facts=sorted(facts))
    assert result.status == "optimal", result.reasons
    best = result.skeletons[0]
    assert (best.makespan, len(best.moved)) == (int(expect.group(1)), int(expect.group(2)))


def test_a_cart_drives_around_an_arm_standing_on_the_floor(tmp_path: Path) -> None:
    """A Panda bolted in the middle of a 3 m wide room: the cart's base paths ignored the arms (at home and
    their mounts), drove straight through it, and every plan was refused by the referee ('exhausted')."""
    src, out = ROOT / "tests" / "data" / "mixed" / "arm-in-the-way.mrg", tmp_path / "plan.json"
    assert cli.main(["plan", str(src), "--time-limit", "120", "-o", str(out)]) == 0
    assert cli.main(["validate", str(src), str(out)]) == 0


def test_a_box_is_set_down_aligned_with_a_turned_region() -> None:
    """A 0.3 m box at yaw 0 into a 0.34 m region turned 45°: its own four yaws never fit, so the region's are
    tried too (it was "infeasible: no robot can reach goal region"); an aligned box gets no extra candidate."""
    from mrgc.geometry.scene import Body
    from mrgc.geometry.transforms import rot_z, translation
    from mrgc.language.model import Box

    box = Body("b", Box(0.3, 0.3, 0.3), translation(0, 0, 0.15))
    turned = Body("goal", Box(0.34, 0.34, 0.5), translation(2, 0, 0.25) @ rot_z(math.radians(45)))
    found = placements(box, turned)
    assert found and all(
        abs(math.remainder(math.atan2(p[1, 0], p[0, 0]) - math.radians(45), math.pi / 2)) < 1e-9 for p in found
    )
    square = Body("goal", Box(0.34, 0.34, 0.5), translation(2, 0, 0.25))
    assert len(placements(box, square)) == len(placements(Body("b", box.shape, box.pose @ rot_z(math.pi / 2)), square))
