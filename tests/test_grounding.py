"""The grounding API the planner uses: placements, approach configurations, handovers, paths, volumes."""

from __future__ import annotations

import numpy as np
import pytest
from support import ROOT

from mrgc import parse_file
from mrgc.geometry.conventions import to_se2
from mrgc.geometry.grounding import Grounder, GroundStatus
from mrgc.geometry.scene import inside, scene_from_problem
from mrgc.geometry.transforms import translation


@pytest.fixture()
def pa3() -> Grounder:
    problem = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()
    return Grounder(scene_from_problem(problem), seed=0)


def test_placement_lies_inside_the_region_and_avoids_objects(pa3: Grounder) -> None:
    ans = pa3.placement("o2", "start", avoid=["o1", "o3"])
    assert ans.ok and ans.pose is not None
    assert inside(pa3.scene.body("start"), pa3.scene.body("o2").shape, ans.pose)
    volume = [(pa3.shape("o2"), ans.pose)]
    assert pa3.hits(volume, among=["o1", "o3"]) == set()


def test_placement_avoids_a_swept_volume(pa3: Grounder) -> None:
    # a wall of volume over the whole start region except nothing: no placement can be found
    region = pa3.scene.body("start")
    volume = [
        (pa3.shape("o1"), region.pose @ translation(x, y, -0.09))
        for x in np.linspace(-0.15, 0.15, 7)
        for y in np.linspace(-0.15, 0.15, 7)
    ]
    assert pa3.placement("o2", "start", volume=volume, samples=40).status is GroundStatus.NO_PLACEMENT
    assert pa3.placement("o2", "start", volume=volume[:1], samples=40).ok


def test_pick_reports_the_objects_in_the_way(pa3: Grounder) -> None:
    blocked = pa3.pick("r1", "o1", "side-x+", avoid=["o2", "o3"])
    assert blocked.status is GroundStatus.COLLISION and "o2" in blocked.blockers
    free = pa3.pick("r1", "o1", "top", avoid=["o2", "o3"])
    assert free.ok and free.configs is not None and free.configs.shape == (5, 7)
    assert pa3.arm("r1").model.within_limits(free.configs).all()
    # the last configuration puts the tool at the grasp
    tool = pa3.arm("r1").tool_world(free.configs[-1])
    assert np.linalg.norm(tool[:3, 3] - (pa3.poses["o1"][:3, 3] + [0, 0, 0.04])) < 1e-3
    assert pa3.pick("r2", "o1", "top").status is GroundStatus.NO_IK  # out of r2's reach


def test_moving_an_object_clears_the_way(pa3: Grounder) -> None:
    assert not pa3.pick("r1", "o1", "side-x+", avoid=["o2"]).ok
    pa3.move("o2", pa3.poses["o2"] @ translation(0, 0.45, 0))  # far to the other side of the table
    assert pa3.pick("r1", "o1", "side-x+", avoid=["o2"]).ok


def test_handover_and_place(pa3: Grounder) -> None:
    hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
    assert hand.ok and hand.configs is not None and hand.configs.shape == (2, 7)
    target = pa3.placement("o1", "bin-b")
    assert target.ok and target.pose is not None
    assert pa3.place("r2", "o1", "top", target.pose).ok
    assert pa3.place("r1", "o1", "top", target.pose).status is GroundStatus.NO_IK


def test_transfer_lifts_then_carries_to_the_pre_place(pa3: Grounder) -> None:
    """The held object's transfer starts at the grasp, rises 8 cm straight up, ends at the pre-place, moves no
    joint more than 1 cm-rad between configurations, and (past its first centimetre, where the object
    leaves the table it rests on) keeps the arm and the object clear of the table."""
    pick = pa3.pick("r1", "o1", "top", avoid=["o2", "o3"])
    hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
    assert pick.ok and pick.configs is not None and hand.ok and hand.configs is not None
    carry = pa3.transfer("r1", "o1", "top", pick.configs[-1], hand.configs[0], avoid=["o2", "o3"], lift=True)
    assert carry.ok
    path = np.array(carry.path)
    assert np.allclose(path[0], pick.configs[-1]) and np.allclose(path[-1], hand.configs[0])
    assert np.abs(np.diff(path, axis=0)).max() <= 0.01 + 1e-9
    arm = pa3.arm("r1")
    z = arm.tool_world(path)[:, 2, 3]
    rise = next(i for i, h in enumerate(z) if h >= z[0] + 0.08 - 1e-4)
    tools = arm.tool_world(path[: rise + 1])[:, :2, 3]
    assert np.abs(tools - tools[0]).max() < 2e-3  # straight up
    start = next(i for i, h in enumerate(z) if h >= z[0] + 0.01 - 1e-4)
    volume = pa3.arm_volume("r1", path[start:], holding=("o1", "top"))
    assert pa3.hits(volume, among="fixed", ignore=["o1"]) == set()
    assert pa3.hits(volume, among=["o2", "o3"]) == set()


def test_transfer_names_what_blocks_it(pa3: Grounder) -> None:
    pick = pa3.pick("r1", "o1", "top")
    assert pick.ok and pick.configs is not None
    # an object put right above o1 is in the way of the lift
    pa3.move("o2", pa3.poses["o1"] @ translation(0, 0, 0.15))
    blocked = pa3.transfer("r1", "o1", "top", pick.configs[-1], pick.configs[0], avoid=["o2"], lift=True)
    assert blocked.status is GroundStatus.COLLISION and blocked.blockers == {"o2"}


def test_packed_placements_fill_a_bin_from_its_corners(pa3: Grounder) -> None:
    bin_b = pa3.scene.body("bin-b")
    first = pa3.placement("o1", "bin-b", packed=True)
    assert first.ok and first.pose is not None
    local = np.linalg.inv(bin_b.pose) @ first.pose
    centre = pa3.placement("o1", "bin-b")
    assert centre.ok and centre.pose is not None
    assert np.allclose(centre.pose[:2, 3], bin_b.pose[:2, 3])  # the default starts in the middle
    assert abs(local[0, 3]) > 0.01 and abs(local[1, 3]) > 0.01  # packed starts in a corner
    assert inside(bin_b, pa3.scene.body("o1").shape, first.pose)


def test_arm_path_and_its_volume(pa3: Grounder) -> None:
    arm = pa3.arm("r1")
    pick = pa3.pick("r1", "o1", "top")
    assert pick.ok and pick.configs is not None
    path = pa3.arm_path("r1", arm.home, pick.configs[0])
    assert path.ok and np.allclose(path.path[0], arm.home) and np.allclose(path.path[-1], pick.configs[0])
    volume = pa3.arm_volume("r1", np.array(path.path))
    assert pa3.hits(volume, among="fixed") == set()
    held = pa3.arm_volume("r1", pick.configs[-1:], holding=("o1", "top"))
    assert len(held) == len(pa3.arm("r1").probes[0]) + 1


def test_base_path_for_a_planar_robot() -> None:
    problem = parse_file(ROOT / "domains" / "box-moving" / "bo-doorway.mrg").problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    robot = problem.robots[0].name
    assert g.is_planar(robot)
    start = to_se2(g.scene.robot(robot).base)
    goal = start + np.array([0.3, 0.0, 0.0])
    res = g.base_path(robot, start, goal)
    assert res.ok and np.allclose(res.path[-1], goal, atol=1e-6)
    assert g.hits(g.base_volume(robot, res.path), among="fixed") == set()


def test_same_queries_same_answers() -> None:
    problem = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()
    a = Grounder(scene_from_problem(problem), seed=4).placement("o2", "start", avoid=["o1", "o3"])
    b = Grounder(scene_from_problem(problem), seed=4).placement("o2", "start", avoid=["o1", "o3"])
    assert a.pose is not None and b.pose is not None and np.array_equal(a.pose, b.pose)


def test_a_transfer_lifts_the_object_clear_of_taller_neighbours(pa3: Grounder) -> None:
    """o1 (12 cm) between o2 and o3: a lift of 8 cm does not clear them when o2 stands 10 cm higher; the
    lift then rises until o1's bottom is 1 cm above o2's top, straight up, and the whole carry keeps clear
    of both neighbours."""
    assert pa3.lift_height("o1") == pytest.approx(0.13)  # neighbours as tall as o1: 12 cm + 1 cm
    pa3.move("o2", pa3.poses["o2"] @ translation(0, 0, 0.10))  # (floating: the lift only reads heights)
    assert pa3.lift_height("o1") == pytest.approx(0.23)
    pa3.move("o3", pa3.poses["o3"] @ translation(0, 0, 0.50))
    assert pa3.lift_height("o1") == pytest.approx(0.30)  # at most MAX_LIFT
    pa3.move("o3", pa3.scene.body("o3").pose)
    pick = pa3.pick("r1", "o1", "top", avoid=["o2", "o3"])
    hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
    assert pick.ok and pick.configs is not None and hand.ok and hand.configs is not None
    carry = pa3.transfer("r1", "o1", "top", pick.configs[-1], hand.configs[0], avoid=["o2", "o3"], lift=True)
    assert carry.ok
    path = np.array(carry.path)
    arm = pa3.arm("r1")
    z = arm.tool_world(path)[:, 2, 3]
    rise = next(i for i, h in enumerate(z) if h >= z[0] + 0.23 - 1e-4)
    tools = arm.tool_world(path[: rise + 1])[:, :2, 3]
    assert np.abs(tools - tools[0]).max() < 2e-3  # straight up all the way
    volume = pa3.arm_volume("r1", path[1:], holding=("o1", "top"))
    assert pa3.hits(volume, among=["o2", "o3"]) == set()


def test_a_transfer_with_lower_comes_straight_down_onto_its_goal(pa3: Grounder) -> None:
    """The taker carries o1 from the exchange to above the pre-place and comes straight down onto it: the
    path ends at the pre-place, and over its last centimetres the tool only descends."""
    hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
    target = pa3.placement("o1", "bin-b")
    assert hand.ok and hand.configs is not None and target.ok and target.pose is not None
    place = pa3.place("r2", "o1", "side-x+", target.pose)
    assert place.ok and place.configs is not None
    carry = pa3.transfer("r2", "o1", "side-x+", hand.configs[1], place.configs[0], lower=True)
    assert carry.ok
    path = np.array(carry.path)
    assert np.allclose(path[0], hand.configs[1]) and np.allclose(path[-1], place.configs[0])
    assert np.abs(np.diff(path, axis=0)).max() <= 0.01 + 1e-9
    tools = pa3.arm("r2").tool_world(path)[:, :3, 3]
    z = tools[:, 2]
    above = next(i for i in range(len(z) - 1, -1, -1) if z[i] >= z[-1] + 0.05 - 1e-4)  # 5 cm above the end
    assert np.abs(tools[above:, :2] - tools[-1, :2]).max() < 2e-3  # straight down from there
    assert np.all(np.diff(z[above:]) <= 1e-4)
