"""The grounding API the planner uses: placements, approach configurations, handovers, paths, volumes."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from support import ROOT

import mrgc
from mrgc import parse_file, parse_string
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.answers import Answer, GroundStatus
from mrgc.geometry.arm_paths import joint_line
from mrgc.geometry.collision import CollisionShape, CollisionWorld, Packed, Posed
from mrgc.geometry.conventions import PATH_RESOLUTION, to_se2
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.kinematics import Link
from mrgc.geometry.scene import inside, scene_from_problem
from mrgc.geometry.stances import PHASES, Stance, stance
from mrgc.geometry.transforms import translation
from mrgc.planner.ground import EXCHANGE_TRIES, Outcome, ReverseGrounder


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


def _wall(g: Grounder, region: str) -> list[tuple[CollisionShape, np.ndarray]]:
    """A volume of o1's covering a 30 × 30 cm square around ``region``'s centre, near its floor."""
    pose = g.scene.body(region).pose
    return [
        (g.shape("o1"), pose @ translation(x, y, -0.09))
        for x in np.linspace(-0.15, 0.15, 7)
        for y in np.linspace(-0.15, 0.15, 7)
    ]


def test_placement_avoids_a_swept_volume(pa3: Grounder) -> None:
    # a wall of volume over the whole start region except nothing: no placement can be found
    volume = _wall(pa3, "start")
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


def _carry_to_the_exchange(pa3: Grounder) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """r1 picks o1 (avoiding o2 and o3) and carries it, lifted, to its configuration of the exchange at h1:
    the pick's configurations, the handover's and the transfer's path."""
    pick = pa3.pick("r1", "o1", "top", avoid=["o2", "o3"])
    hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
    assert pick.ok and pick.configs is not None and hand.ok and hand.configs is not None
    carry = pa3.transfer("r1", "o1", "top", pick.configs[-1], hand.configs[0], avoid=["o2", "o3"], lift=True)
    assert carry.ok
    return pick.configs, hand.configs, np.array(carry.path)


def test_transfer_lifts_then_carries_to_the_pre_place(pa3: Grounder) -> None:
    """The held object's transfer starts at the grasp, rises 8 cm straight up, ends at the pre-place, moves no
    joint more than 1 cm-rad between configurations, and (past its first centimetre, where the object
    leaves the table it rests on) keeps the arm and the object clear of the table."""
    picked, exchanged, path = _carry_to_the_exchange(pa3)
    assert np.allclose(path[0], picked[-1]) and np.allclose(path[-1], exchanged[0])
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
    assert g.robot(robot).parks and not g.robot(robot).approaches  # a cart
    start = to_se2(g.scene.robot(robot).base)
    goal = start + np.array([0.3, 0.0, 0.0])
    res = g.base_path(robot, start, goal)
    assert res.ok and np.allclose(res.path[-1], goal, atol=1e-6)
    assert g.hits([p for v in g.volumes(robot, np.array(res.path)) for p in v], among="fixed") == set()


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
    path = _carry_to_the_exchange(pa3)[2]
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


#: one Panda beside a 22 x 30 cm bin whose near corner is 30 cm from its base; three objects to put in it with
#: side grasps (the hand comes from +y, the arm's side): o2 (19 cm tall) first in the plan, so the reverse search
#: places o10 and o13 first, and the arm reaching across the bin to put one of them in a far corner sweeps
#: wherever o2 could stand (the situation of generated packaging i51, seed 1051, with its other objects gone)
PACKED_BIN = """
(define (domain packaging)
  (:requirements :handover)
  (:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand"
    :tcp (0 0 0.105 0) :home (0 -0.785 0 -2.356 0 1.571 0.785) :gripper-opening 0.08)
  (:grasps top top-x side-x+ side-x- side-y+ side-y-))
(define (problem packed-bin)
  (:domain packaging)
  (:robots (r2 :kind panda :base (0.31 0.542 0 -139)))
  (:fixed (table :shape (box 1.28 1.19 0.05) :pose (0 0 -0.025 0)))
  (:regions
    (start :shape (box 0.556 0.48 0.3) :pose (0.289 -0.185 0.15 0))
    (bin-a :shape (box 0.22 0.3 0.3) :pose (0.481 0.249 0.15 0)))
  (:movable
    (o2 :shape (cylinder 0.031 0.192) :pose (0.214 -0.016 0.096 0))
    (o10 :shape (box 0.049 0.044 0.155) :pose (0.259 -0.271 0.0775 3))
    (o13 :shape (box 0.054 0.074 0.104) :pose (0.113 -0.352 0.052 1)))
  (:goal (and (in-region o2 bin-a) (in-region o10 bin-a) (in-region o13 bin-a))))
"""


def test_crowded_out_names_an_object_left_no_free_pose(pa3: Grounder) -> None:
    wall = _wall(pa3, "bin-b")
    assert pa3.crowded_out(["o2", "o3"], "bin-b") is None
    assert pa3.crowded_out(["o2", "o3"], "bin-b", volume=wall) == "o2"
    assert pa3.placement("o2", "bin-b", volume=wall, packed=True).status is GroundStatus.NO_PLACEMENT


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_crowded_out_asks_extra_pieces_as_part_of_one_volume_and_keeps_its_rooms(seed: int) -> None:
    """``crowded_out`` with the placement's own motions given apart (``extra``) answers as with them joined
    to the volume, however the pieces are split between the two (part of a wall over the bin, some objects
    left no pose, some not); asked again with a volume of the same content (a new object), it answers from
    the free poses it kept, without a further collision query."""
    rng = np.random.default_rng(seed)
    problem = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()
    split, joined = Grounder(scene_from_problem(problem), seed=0), Grounder(scene_from_problem(problem), seed=0)
    wall = _wall(split, "bin-b")
    share = rng.uniform(0.05, 0.6) if rng.random() < 0.7 else 1.0  # about half the draws leave o2 no pose
    pieces = [p for p in wall if rng.random() < share]
    cut = int(rng.integers(0, len(pieces) + 1))
    for objs in (["o2", "o3"], ["o3", "o2"]):
        expected = joined.crowded_out(objs, "bin-b", volume=pieces or None)
        base = Posed.of(pieces[:cut]) if cut else None
        assert split.crowded_out(objs, "bin-b", volume=base, extra=pieces[cut:]) == expected
        before = split.queries
        again = Posed.of(pieces[:cut]) if cut else None
        assert split.crowded_out(objs, "bin-b", volume=again, extra=pieces[cut:]) == expected
        assert split.queries == before


def test_a_placement_that_leaves_no_room_for_an_earlier_object_is_passed_over(tmp_path: Path) -> None:
    """Grounding o2, o13, o10 into the bin in that order: before, the first placement of the last object swept
    the whole bin and o2 had no free pose ("placement: no free pose of o2 in bin-a" on every skeleton, the
    search exhausted); now a placement that leaves an object still to come no free pose is not taken, and
    the plan is found and valid.  (The order was o2, o10, o13 until the arm kept clear of itself: that
    grounding placed o13 with link6 24.5 mm inside link0 and carried o2 with link5 6.2 mm inside link2;
    free of that, o10 leaves o2 no room in that order, and the planner's own plan takes this one.)"""
    path = tmp_path / "packed-bin.mrg"
    path.write_text(PACKED_BIN, encoding="utf-8")
    problem = parse_file(path).problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    steps = tuple((Action(o, "bin-a", "r2", "r2", "side-y+", "side-y+"),) for o in ("o2", "o13", "o10"))
    grounding = ReverseGrounder(g, {"o2": "bin-a", "o10": "bin-a", "o13": "bin-a"}).ground(Skeleton(steps), [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    bin_a = g.scene.body("bin-a")
    for step in grounding.steps:
        assert inside(bin_a, g.scene.body(step.actions[0].object).shape, np.array(step.actions[0].place_pose))
    plan = mrgc.plan(str(path), seed=0, time_limit=300)
    assert plan.status is mrgc.PlanStatus.SOLVED, plan.summary()
    report = mrgc.validate(str(path), plan)
    assert report.ok, report.lines()


@pytest.mark.parametrize(("direction", "height"), [((0, 0, 1), 0.08), ((0.6, 0, 0.8), 0.12), ((0, 0, 1), 1.2)])
def test_a_straight_motion_puts_the_tool_on_its_line_every_centimetre(
    pa3: Grounder, direction: tuple[float, float, float], height: float
) -> None:
    """An arm's straight motion (the lift, a descent backwards): from the grasp of o1, the tool at the k-th
    configuration stands k cm along the direction, turned as at the start (to the solver's tolerances), and no
    joint moves more than 0.2 rad between two; asked for 1.2 m up, beyond its reach, it stops where the next
    centimetre, solved from the last configuration, is not followed."""
    pick = pa3.pick("r1", "o1", "top", avoid=["o2", "o3"])
    assert pick.ok and pick.configs is not None
    q, way = pick.configs[-1], np.array(direction, dtype=float)
    path = pa3._lift("r1", q, height, way)
    assert path is not None and np.allclose(path[0], q)
    arm = pa3.arm("r1")
    tools = arm.tool_world(path)
    for k, tool in enumerate(tools):
        assert np.linalg.norm(tool[:3, 3] - (tools[0][:3, 3] + 0.01 * k * way)) < 2e-4
        assert np.abs(tool[:3, :3] - tools[0][:3, :3]).max() < 2e-3
    assert np.abs(np.diff(path, axis=0)).max() <= 0.2
    full = round(height / 0.01) + 1
    if height < 0.3:
        assert len(path) == full  # within reach: every centimetre
    else:
        assert 10 < len(path) < full
        tool = arm.tool_world(path[-1:])[0]  # the next centimetre from the last is not followed either
        target = arm.ee_target(translation(*(0.01 * way)) @ tool)
        nxt = solve_ik_many(arm.model, target[None], 0, q_init=path[-1], restarts=0)[0]
        assert not nxt.solved or nxt.q is None or np.abs(nxt.q - path[-1]).max() > 0.2


@settings(max_examples=200, deadline=None)
@given(
    points=st.integers(1, 12),
    start=st.integers(0, 3),
    blocked=st.sets(st.integers(0, 200), max_size=4),
    seed=st.integers(0, 2**16),
)
def test_a_straight_motion_is_free_as_far_as_its_centimetres_one_by_one_say(
    points: int, start: int, blocked: set[int], seed: int
) -> None:
    """geometry/arm_paths.py ``_free_run`` (lifts and descents): asking the whole rest of a straight motion in one
    batch first, then centimetre by centimetre when something is in the way, ends where the centimetres one by
    one end, for any configurations and any states in the way (``hits`` finds a state blocked by its values)."""
    from mrgc.geometry.arm_paths import _free_run

    rng = np.random.default_rng(seed)
    up = np.cumsum(rng.uniform(-0.05, 0.05, (points, 3)), axis=0)
    line = joint_line(up, PATH_RESOLUTION)
    marks = {line[k].tobytes() for k in blocked if k < len(line)}

    def hits(configs: np.ndarray) -> set[str] | None:
        return {"x"} if any(c.tobytes() in marks for c in configs) else None

    top = min(start, points - 1)
    one_by_one = top
    while one_by_one + 1 < len(up) and hits(joint_line(up[one_by_one : one_by_one + 2], PATH_RESOLUTION)) is None:
        one_by_one += 1
    assert _free_run(up, hits, top) == one_by_one


def test_a_carry_crosses_the_table_above_what_may_stand_there() -> None:
    """pa18-4arms, r4 carrying o1 from its pick to a placement in start: between the lift and the descent, the
    plain joint-space line sags the held box to 7 cm above the table, below the top of the tallest object that
    may stand on it (12 cm: a bin the reverse search fills later would have no room under it); the carry's
    low points raised keep it above that top, and both lift and descent now reach it."""
    g = Grounder(scene_from_problem(parse_file(ROOT / "domains" / "packaging" / "pa18-4arms.mrg").problem()), seed=0)
    held = ("o1", "top")
    pick = g.pick("r4", *held)
    assert pick.ok and pick.configs is not None
    place = next(a for pose in g.placements("o1", "start", packed=True) if (a := g.place("r4", *held, pose)).ok)
    assert place.configs is not None
    top = g.standing_top
    assert top == pytest.approx(0.12)  # the tallest movable object, on the table
    up = g._lift("r4", pick.configs[-1], g.lift_height("o1", start=True))
    down = g._lift("r4", place.configs[0], g.lift_height("o1", goal=("r4", "top", place.configs[0])))
    assert up is not None and down is not None
    a, b = up[-1], down[-1]
    assert g._held_bottom("r4", held, np.stack([a, b])).min() >= top  # both ends above it
    line = joint_line(np.stack([a, b]), PATH_RESOLUTION)
    assert g._held_bottom("r4", held, line).min() < top - 0.04  # the plain line sags 5 cm under it
    over = g._over("r4", held, a, b)
    assert over is not None
    assert np.allclose(over[0], a) and np.allclose(over[-1], b)
    assert np.abs(np.diff(over, axis=0)).max() <= PATH_RESOLUTION + 1e-9
    assert g._held_bottom("r4", held, over).min() >= top  # raised: above whatever may stand there


def test_other_arms_bases_are_obstacles_home_or_not(pa3: Grounder) -> None:
    """An arm's base link (left out of its probes: its own links start on it) is an obstacle to every other
    arm, also while that arm is away from home in the step (generated i67/i69: the validator rejected
    grounded plans whose arm grazed another arm's base by 1.1-21.7 mm)."""
    hulls = pa3.arm("r2").base_hulls
    assert len(hulls) == 1
    probe = [(shape, pose) for _, shape, pose in hulls]
    for roles in ({}, {"r2": "pick-place"}):  # r2 at home, then r2 picking in the step (its home links gone)
        pa3.step(roles)
        assert pa3.world.probe_hits(probe, against=pa3._others("r1", phase="pick")) >= {"@r2:base"}
        assert "@r2:base" not in pa3.world.probe_hits(probe, against=pa3._others("r2", phase="pick"))
    pa3.step({})


def test_an_obstacle_with_no_reachable_place_in_its_region_is_parked_in_another() -> None:
    """Generated packaging i51 (seed 1051): r2 must clear obstacles from the crowded start region, and once
    the later steps' sweeps are kept clear no free place there is within its reach (~100 skeletons failed
    with "place by r2: no inverse kinematics" before).  Obstacles are parked in bin-b, a region nobody's
    goal that r2 reaches (then goal bins with room left for their goals); the plan is valid."""
    from mrgc.planfile.format import file_sha256
    from mrgc.planner.search import plan_problem
    from mrgc.validator.validate import validate

    path = ROOT / "tests" / "data" / "park-packaging.mrg"
    problem = parse_file(path).problem()
    # a ceiling, not a budget: the search (16 groundings, ~220 s of CPU) is the same whatever the load, and on a
    # 2-core machine running the suite's other tests beside it, it has needed up to 615 s of wall time
    plan = plan_problem(problem, str(path), file_sha256(str(path)), mrgc.__version__, seed=0, time_limit=1800)
    assert plan.status == "solved", plan.summary()
    parked = {a.region for step in plan.steps for a in step if a.object not in problem.goal_regions} - {"start"}
    assert "bin-b" in parked  # nobody's goal, tried first; goal bins after it, keeping room for their goals
    assert validate(problem, plan, str(path)).ok


def test_an_obstacle_with_no_room_in_any_region_is_set_aside_on_the_table() -> None:
    """tests/data/aside-table.mrg: o2 stands against o1, the goal object, in a start region that holds the two
    and no more, and the bin holds o1 only.  Before session 42 no skeleton could be grounded (``exhausted``:
    "placement: no free pose of o2 in start"); now r1 sets o2 aside on the table, clear of both regions'
    footprints and resting on the table's top, and the validator accepts the plan."""
    from mrgc.geometry.placements import ASIDE_GAP, off_regions
    from mrgc.planfile.format import file_sha256
    from mrgc.planner.search import plan_problem
    from mrgc.validator.validate import validate

    path = ROOT / "tests" / "data" / "aside-table.mrg"
    problem = parse_file(path).problem()
    plan = plan_problem(problem, str(path), file_sha256(str(path)), mrgc.__version__, seed=0, time_limit=600)
    assert plan.status == "solved", plan.summary()
    moves = {a.object: a for step in plan.steps for a in step}
    assert moves["o2"].region == "table" and moves["o1"].region == "bin"
    scene = scene_from_problem(problem)
    pose = np.array(moves["o2"].place_pose)
    assert off_regions(scene, "o2")(pose) and inside(scene.region("table"), scene.body("o2").shape, pose)
    for region in scene.regions:  # its centre well outside each region's footprint
        local = np.linalg.inv(region.pose) @ pose[:, 3]
        assert np.any(np.abs(local[:2]) > np.array([region.shape.sx, region.shape.sy]) / 2 + ASIDE_GAP)
    assert validate(problem, plan, str(path)).ok


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    x=st.floats(-0.6, 0.6),
    y=st.floats(-0.5, 0.5),
    yaw=st.floats(-np.pi, np.pi),
)
def test_a_pose_off_the_regions_leaves_every_corner_of_the_object_outside_them(x: float, y: float, yaw: float) -> None:
    """:func:`off_regions` is conservative: a pose it passes has every corner of the object's bounding box at
    least the gap outside each region's footprint on some axis of that region (no corner inside a footprint);
    and a pose whose centre lies inside a footprint never passes."""
    from mrgc.geometry.placements import ASIDE_GAP, off_regions
    from mrgc.geometry.scene import outline
    from mrgc.geometry.transforms import rot_z

    scene = _aside_scene()
    pose = translation(x, y, 0.1) @ rot_z(yaw)
    corners = outline(scene.body("o2").shape) @ pose[:3, :3].T + pose[:3, 3]
    for region in scene.regions:
        inv = np.linalg.inv(region.pose)
        local = corners @ inv[:3, :3].T + inv[:3, 3]
        half = np.array([region.shape.sx, region.shape.sy]) / 2
        centre_in = bool(np.all(np.abs((inv @ pose[:, 3])[:2]) <= half))
        if off_regions(scene, "o2")(pose):
            assert not centre_in
            assert not np.any(np.all(np.abs(local[:, :2]) <= half + ASIDE_GAP - 1e-9, axis=1))
    # and a pose whose object stays farther than both half diagonals and the gap from every region passes
    reach = float(np.linalg.norm(outline(scene.body("o2").shape)[0, :2]))
    if all(
        np.linalg.norm(pose[:2, 3] - r.pose[:2, 3]) > reach + np.hypot(r.shape.sx, r.shape.sy) / 2 + ASIDE_GAP
        for r in scene.regions
    ):
        assert off_regions(scene, "o2")(pose)


def test_the_doomed_probe_asks_the_table_an_obstacle_may_be_set_aside_on() -> None:
    """The doomed probe (planner/doomed.py) tries the places the grounding would: in aside-table, with o2's own
    spot in the suffix's volume (as o1's pick sweeps it), o2 has no free pose in start once o1 is avoided, but
    one on the table, so moving it is not doomed; asked about start alone, the probe says why it fails there."""
    from mrgc.planner.ground import ReverseGrounder

    scene = _aside_scene()
    g = Grounder(scene, seed=0)
    rg = ReverseGrounder(g, dict(scene.goal))
    rg.doomed._volume = [(g.shape("o2"), scene.body("o2").pose)]
    move = Action("o2", "start", "r1", "r1", "top", "top")
    assert [name for name, _ in rg._parking(move)][-1] == "table"
    assert rg.doomed._ask(move, ["o1"]) is None
    alone = rg.doomed._placeable(move, "start", ["o1"])
    assert alone is not None and "o2" in alone.check and "start" in alone.check


def test_only_a_fixed_box_top_of_a_table_s_size_takes_obstacles_set_aside() -> None:
    """:func:`aside_tops`: the table's top, not a wall's (thinner than :data:`ASIDE_SIDE`) nor a cylinder's."""
    from mrgc.geometry.placements import ASIDE_SIDE, aside_tops

    text = (ROOT / "tests" / "data" / "aside-table.mrg").read_text()
    text = text.replace(
        "(table :shape (box 1.2 1.0 0.05) :pose (0 0 -0.025 0)))",
        "(table :shape (box 1.2 1.0 0.05) :pose (0 0 -0.025 0))"
        f" (wall :shape (box 1.2 {ASIDE_SIDE - 0.01} 0.3) :pose (0 0.9 0.15 0))"
        " (post :shape (cylinder 0.3 0.5) :pose (0.9 0.9 0.25 0)))",
    )
    scene = scene_from_problem(parse_string(text, "aside").problems[0])
    tops = aside_tops(scene)
    assert [t.name for t in tops] == ["table"]
    assert tops[0].pose[2, 3] > 0  # standing on the table's top face (z = 0), not at its centre


@functools.lru_cache(maxsize=1)
def _aside_scene() -> Any:
    return scene_from_problem(parse_file(ROOT / "tests" / "data" / "aside-table.mrg").problem())


def test_failures_say_whether_only_what_never_moves_explains_them(pa3: Grounder) -> None:
    """A place that fails on the table or on IK fails again whatever moves (``static``: grounding passes over
    that placement later without spending a try; generated i20, a side grasp whose place hits the table at
    most placements of its bin, was a time limit with both seeds and is solved); one blocked by a movable
    object is not static."""
    sunk = pa3.poses["o1"] @ translation(0, 0, -0.03)  # 3 cm into the table: the held object hits it
    into_table = pa3.place("r1", "o1", "top", sunk)
    assert into_table.status is GroundStatus.COLLISION and into_table.static
    assert pa3.place("r2", "o1", "top", pa3.poses["o1"]).static  # out of r2's reach: no IK
    blocked = pa3.place("r1", "o1", "side-x+", pa3.poses["o1"], avoid=["o2"])
    assert blocked.status is GroundStatus.COLLISION and "o2" in blocked.blockers and not blocked.static


def test_the_grounder_knows_where_each_arm_of_the_step_is_in_each_phase(pa3: Grounder) -> None:
    """The execution model a plan means (docs/validator.md, validator/replay.py), as the grounding reads it:
    between its own motions an arm stands where its last motion left it; a missing transit (no path under
    the ``configurations`` model) is a jump at the end of its phase."""
    assert stance("pick-place", "to-handover") is stance("pick-place", "giver-home") is Stance.PICKED
    assert stance("taker", "to-handover") is Stance.HOME and stance("taker", "to-handover", full=True) is Stance.MOVES
    assert stance("taker", "giver-home") is Stance.RECEIVED and stance("giver", "giver-home") is Stance.EXCHANGE
    assert stance("giver", "giver-home", full=True) is Stance.MOVES
    assert [stance("giver", p) for p in PHASES[PHASES.index("to-place") :]] == [Stance.HOME] * 3
    pa3.step({"r1": "giver", "r2": "taker"})
    try:
        # the taker waits at home while the giver picks and carries the object to the exchange; the giver is
        # home again while the taker carries the object on and places it
        assert "home:r2" in pa3._others("r1", "pick") and "home:r2" in pa3._others("r1", "to-handover")
        assert "home:r1" in pa3._others("r2", "to-place") and "home:r1" in pa3._others("r2", "place")
        # the taker stands at its exchange holding the object while the giver withdraws: an obstacle to it
        # once the grounding knows that configuration, and not at home
        assert "home:r2" not in pa3._others("r1", "giver-home")
        hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
        assert hand.ok and hand.configs is not None
        taker = pa3.arm_volume("r2", hand.configs[1:], holding=("o1", "side-x+"))
        with pa3.standing("r2", {Stance.RECEIVED: taker}):
            assert "stand:r2:RECEIVED" in pa3._others("r1", "giver-home")
            assert "stand:r2:RECEIVED" not in pa3._others("r1", "handover")  # it moves there then (busy)
        assert "stand:r2:RECEIVED" not in pa3._others("r1", "giver-home")  # gone after the block
        pa3.step({"r1": "giver", "r2": "taker"}, full=True)
        assert "home:r2" not in pa3._others("r1", "to-handover")  # on its taker-to-handover path: busy
    finally:
        pa3.step({})
    assert "home:r1" in pa3._others("r2", "handover")  # no step: every other arm at home


@functools.lru_cache(maxsize=1)
def _six_arms_seed_8() -> Grounder:
    from mrgc.generate import packaging

    text = packaging(robots=6, goals=10, others=30, seed=8)
    return Grounder(scene_from_problem(mrgc.parse_string(text, "big-8.mrg").problem()), seed=0)


@pytest.mark.parametrize("full", [False, True])
def test_an_exchange_is_clear_of_its_partner_at_home_when_the_model_puts_it_there(full: bool) -> None:
    """6 arms, 40 objects, generated seed 8: handover point h1 lies 0.19 m from r2's base.  r3's first exchange
    holding o13 there (top-x) reaches into r2 at home, where the default motion model keeps the taker until
    the handover phase: the giver's carry to it then had no valid goal, and the search failed 51 of its 80
    groundings on ``carry to the handover by r3: no path`` (300 s, time limit).  Each arm's exchange is now
    drawn clear of its partner where the model has it at home then: the taker while the giver arrives (not
    under ``--motions full``: it moves to its exchange meanwhile), the giver when the taker leaves."""
    g = _six_arms_seed_8()
    g.step({"r3": "giver", "r2": "taker"}, full)
    try:
        for point in ("h1", "h2"):
            ans = g.handover("o13", point, "r3", "top-x", "r2", "side-y-")
            if not ans.ok:
                assert ans.status is GroundStatus.COLLISION and ans.detail.startswith("hits")
                continue
            assert ans.configs is not None
            giver = g.arm_volume("r3", ans.configs[:1], holding=("o13", "top-x"))
            taker = g.arm_volume("r2", ans.configs[1:], holding=("o13", "side-y-"))
            assert g.world.probe_collides(Posed.of(giver), against=("home:r2",)) is (full and point == "h1")
            assert not g.world.probe_collides(Posed.of(taker), against=("home:r3",))
        # no exchange at h1 is clear of both r2 and r1 at home; with --motions full the taker is on its way
        # meanwhile, and the first exchange drawn (reaching into r2's home) stands
        assert g.handover("o13", "h1", "r3", "top-x", "r2", "side-y-").ok is full
    finally:
        g.step({})


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), pair=st.integers(0, 11))
def test_every_exchange_found_is_clear_of_the_partner_waiting_at_home(seed: int, pair: int) -> None:
    """Generated 4-arm cells: whatever exchange the grounder finds for a goal object at any of its handover
    points (one of the twelve ordered pairs of arms; a top grasp against a side one, both ways), under the
    default motion model the giver holding the object is clear of the taker at home, and the taker holding it
    of the giver at home.  Before, 9 of the cells of generator seeds 0-9 had such an exchange (1-15 each)."""
    from mrgc.generate import packaging

    text = packaging(robots=4, goals=3, others=4, seed=seed)
    g = Grounder(scene_from_problem(mrgc.parse_string(text, "cell.mrg").problem()), seed=0)
    giver, taker = [(a, b) for a in ("r1", "r2", "r3", "r4") for b in ("r1", "r2", "r3", "r4") if a != b][pair]
    g.step({giver: "giver", taker: "taker"})
    try:
        for obj in sorted(g.scene.goal):
            for point in g.scene.handover_of.get(obj, ()):
                for g1, g2 in (("top", "side-y+"), ("side-x-", "top")):
                    ans = g.handover(obj, point, giver, g1, taker, g2)
                    if not ans.ok:
                        continue
                    assert ans.configs is not None
                    for arm, q, grasp, other in (
                        (giver, ans.configs[0], g1, taker),
                        (taker, ans.configs[1], g2, giver),
                    ):
                        held = Posed.of(g.arm_volume(arm, q[None], holding=(obj, grasp)))
                        assert not g.world.probe_collides(held, against=(f"home:{other}",))
    finally:
        g.step({})


def test_a_giver_lets_go_backing_its_fingers_off_the_object_the_taker_holds(pa3: Grounder) -> None:
    """The taker stands at its exchange holding the object while the giver withdraws home, the giver's
    fingers at the grasp's opening (the validator's giver-home phase): the giver's path first backs straight
    off along its approach axis, and clear of the taker standing there and the object it holds, with the
    fingers as the validator replays them (fully open fingers are another volume)."""
    pa3.step({"r1": "giver", "r2": "taker"}, full=True)
    try:
        hand = pa3.handover("o1", "h1", "r1", "top", "r2", "side-x+")
        assert hand.ok and hand.configs is not None
        taker = pa3.arm_volume("r2", hand.configs[1:], holding=("o1", "side-x+"))
        axis = pa3.arm("r1").tool_world(hand.configs[:1])[0][:3, 2]
        with pa3.standing("r2", {Stance.RECEIVED: taker}):
            home = pa3.transit(
                "r1",
                hand.configs[0],
                pa3.arm("r1").home,
                phase="giver-home",
                fingers=("o1", "top"),
                retreat=-axis,
            )
    finally:
        pa3.step({})
    assert home.ok
    path = np.array(home.path)
    assert np.allclose(path[0], hand.configs[0]) and np.allclose(path[-1], pa3.arm("r1").home)
    tools = pa3.arm("r1").tool_world(path)[:, :3, 3]
    back = (tools - tools[0]) @ -axis
    out = next(i for i, d in enumerate(back) if d >= 0.05 - 1e-4)  # 5 cm back along its approach axis
    sideways = (tools[: out + 1] - tools[0]) - back[: out + 1, None] * -axis
    assert np.linalg.norm(sideways, axis=1).max() < 2e-3  # straight back
    world = CollisionWorld()
    for i, (shape, t) in enumerate(taker):
        world.add(f"taker{i}", shape, t, "taker")
    assert not world.probe_collides(pa3.arm_volume("r1", path, grasp=("o1", "top")), against="taker")


def test_arm_volumes_are_the_volumes_of_each_configuration(pa3: Grounder) -> None:
    """One batched forward kinematics for a motion's samples gives each sample's volume, held object
    included, as :meth:`Grounder.arm_volume` does one by one."""
    arm = pa3.arm("r1")
    configs = arm.home[None] + np.linspace(0, 0.3, 4)[:, None]
    for holding in (None, ("o1", "top")):
        batched = pa3.volumes("r1", configs, holding=holding, fingers=("o1", "top"))
        for q, volume in zip(configs, batched):
            one = pa3.arm_volume("r1", q[None], holding=holding, grasp=("o1", "top"))
            assert [s for s, _ in volume] == [s for s, _ in one]
            assert np.allclose(np.array([t for _, t in volume]), np.array([t for _, t in one]))


# ------------------------------------------------------------------ robots of one step in each other's way
DOORWAY = ROOT / "domains" / "box-moving" / "bo-one-doorway.mrg"


def test_a_base_path_blocked_only_by_another_robot_of_the_step_says_so() -> None:
    """bo-one-doorway, the doorway cleared: r1's drive through the 1 m doorway fails while what r2 sweeps
    meanwhile stands in it, and the answer says so (before, "no path" with nothing named, and the step was
    never split); without r2's sweep the path exists, and a path the scene blocks says nothing of robots."""
    from mrgc.geometry.answers import BUSY
    from mrgc.geometry.transforms import rot_z

    g = Grounder(scene_from_problem(parse_file(DOORWAY).problem()), seed=0)
    aside = {"door": translation(-2.0, 0.0, 0.15), "front": translation(-2.0, -0.5, 0.15)}
    start, goal = to_se2(g.scene.robot("r1").base), np.array([1.5, 0.0, 0.0])
    (r2_in_doorway,) = g.volumes("r2", np.array([[0.0, 0.0, 0.0]]))
    with g.moved(aside):
        assert g.base_path("r1", start, goal).ok
        blocked = g.base_path("r1", start, goal, busy=r2_in_doorway)
        assert not blocked.ok and blocked.detail == BUSY
        wall = translation(0.0, 0.0, 0.15) @ rot_z(0.0)
        with g.moved({"door": wall}):  # the door box back in the doorway: the scene blocks it too
            assert g.base_path("r1", start, goal, avoid=["door"], busy=r2_in_doorway).detail == ""


def test_two_carts_through_one_doorway_pass_one_after_the_other_in_their_step() -> None:
    """The skeleton the compiler gives bo-one-doorway carries both goal boxes through the doorway in step 3;
    the carts' drives collide there (before: "carry to the placement: no path", no bodies, every makespan-3
    skeleton failed and the search took 217 groundings to reach makespan 4; then the step was split, one
    cart after the other).  Now one cart waits while the other passes, in the same step: its path repeats
    its first or last configuration, and nothing was split."""
    problem = parse_file(DOORWAY).problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    steps = (
        (Action("front", "start", "r2", "r2", "side-y-", "side-y-"),),
        (Action("door", "start", "r2", "r2", "side-x-", "side-x-"),),
        (
            Action("g1", "goal", "r1", "r1", "side-x+", "side-x+"),
            Action("g2", "goal", "r2", "r2", "side-y+", "side-y+"),
        ),
    )
    grounding = ReverseGrounder(g, dict(problem.goal_regions)).ground(Skeleton(steps), [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    assert [len(s.actions) for s in grounding.steps] == [1, 1, 2]
    waits = [(a.object, w) for a in grounding.steps[2].actions for w in a.waits()]
    assert waits and not grounding.resolved, (waits, grounding.resolved)


def _crossing(y0: float, n: int = 5) -> tuple[list[list[float]], list[Any]]:
    """A path of ``n`` configurations along y from ``y0`` to ``-y0`` at x = 0.5 (a 0.1 m box as its volume at
    each), and the volumes; beside ``_across``, which crosses it at (0.5, 0) half-way."""
    box = _box(0.1)
    ys = np.linspace(y0, -y0, n)
    return [[0.5, float(y), 0.0] for y in ys], [[(box, translation(0.5, float(y), 0.0))] for y in ys]


def _across(n: int = 5) -> list[Any]:
    box = _box(0.1)
    return [[(box, translation(float(x), 0.0, 0.0))] for x in np.linspace(0.0, 1.0, n)]


@functools.lru_cache(maxsize=None)
def _box(side: float) -> CollisionShape:
    from mrgc.geometry.collision import collision_shape
    from mrgc.language.model import Box

    return collision_shape(Box(side, side, side))


def test_a_robot_waits_while_another_of_its_step_passes() -> None:
    """Two robots of a step cross at the same moment of a phase: the one of the action being grounded waits
    (its path's first configuration repeated: half the phase standing still), which clears the comparison;
    the other robot's motion is untouched."""
    from mrgc.planfile.format import PlannedAction
    from mrgc.planner.ground import _robots_collide, _waiting

    path, volumes = _crossing(1.0)
    action = PlannedAction("b", "goal", "r2", "r2", "top", "top", paths={"to-place": [list(q) for q in path]})
    theirs = _across()
    mine, motions = {"r2": {"to-place": volumes}}, {"r1": {"to-place": theirs}}
    clash = _robots_collide(mine, motions)
    assert clash == ("to-place", ("r1", "r2"))
    left, waited = _waiting(action, mine, motions, clash)
    assert left is None and _robots_collide(waited, motions) is None
    assert action.waits() == [("to-place", 4, 0)] and action.paths["to-place"][4:] == path
    assert motions["r1"]["to-place"] is theirs and len(theirs) == 5


@pytest.mark.parametrize("case", ["standing", "approach", "both-move"])
def test_no_wait_where_waiting_cannot_help_or_would_desynchronise_a_handover(case: str) -> None:
    """No wait (the clash is returned, the paths untouched) when the other robot stands still in the phase
    (no moment is free of it), in an approach (its configurations are the motion model's) or where both
    robots of a handover move (a wait would change when they meet)."""
    from mrgc.planfile.format import PlannedAction
    from mrgc.planner.ground import _waiting

    path, volumes = _crossing(1.0)
    others: dict[str, dict[str, list[Any]]] = {"r1": {"to-place": _across()}}
    action = PlannedAction("b", "goal", "r2", "r2", "top", "top", paths={"to-place": [list(q) for q in path]})
    phase = "to-place"
    if case == "standing":
        others = {"r1": {"to-place": [[(_box(0.1), translation(0.5, 0.0, 0.0))]]}}
    elif case == "approach":
        phase, others = "place", {"r1": {"place": _across()}}
    else:
        action = PlannedAction(
            "b", "goal", "r2", "r3", "top", "top", paths={"to-handover": path, "taker-to-handover": path}
        )
        phase, others = "to-handover", {"r1": {"to-handover": _across()}}
    mine = {"r2": {phase: volumes}}
    before = {k: [list(q) for q in v] for k, v in action.paths.items()}
    left, _ = _waiting(action, mine, others, (phase, ("r1", "r2")))
    assert left == (phase, ("r1", "r2")) and action.paths == before and not action.waits()


def test_a_variation_of_the_doorway_is_solved_and_valid() -> None:
    """tests/data/bo-one-doorway-north.mrg: the doorway off-centre, other boxes; solved (one cart through
    the doorway after the other, in one step: one waits) and valid."""
    path = ROOT / "tests" / "data" / "bo-one-doorway-north.mrg"
    plan = mrgc.plan(str(path), seed=0, time_limit=600)
    assert plan.status is mrgc.PlanStatus.SOLVED, plan.summary()
    assert mrgc.validate(str(path), plan).ok
    assert plan.stats["skeleton_makespan"] == 3 and plan.stats["split_steps"] == 0 and len(plan.steps) == 3
    assert plan.stats["waits"] >= 1  # one cart waits in the doorway step while the other passes


def test_three_arms_keep_their_parallel_steps() -> None:
    """tests/data/kitting-3arms.mrg (generated packaging, 3 arms, 5 goals, 3 others, seed 1): an action kept
    clear of the whole of what another arm of its step sweeps failed, and the step was split; now the phases
    are compared as the arms pass and the plan keeps steps where two or three arms move objects; what a
    re-timing or a split got around is reported against the skeleton's makespan."""
    path = ROOT / "tests" / "data" / "kitting-3arms.mrg"
    plan = mrgc.plan(str(path), seed=0, time_limit=600)
    assert plan.status is mrgc.PlanStatus.SOLVED, plan.summary()
    assert mrgc.validate(str(path), plan).ok
    assert max(len({r for a in step for r in a.robots()}) for step in plan.steps) >= 2
    stats = plan.stats
    assert len(plan.steps) == stats["skeleton_makespan"] + stats["split_steps"]


def test_retiming_moves_an_action_to_the_latest_earlier_step_its_order_constraints_allow() -> None:
    """An action in another robot's way goes to an earlier step where its robots are free and its obstacles
    are moved before it (strictly for a pick obstacle); nowhere else; taken back on rollback."""
    from mrgc.planner.ground import _Retiming

    a = Action("a", "goal", "r1", "r1", "top", "top")
    b = Action("b", "start", "r2", "r2", "top", "top")
    c = Action("c", "goal", "r3", "r3", "top", "top")
    x = Action("x", "goal", "r3", "r3", "top", "top")  # x's pick waits for b (strict), its place for a
    obstacles = {x: [("b", True), ("a", False)]}
    y = Action("y", "goal", "r1", "r1", "top", "top")
    busy = _Retiming([[a], [b], [c], [x, y]], lambda s: obstacles.get(s, []))
    # step 3 holds r3 (c); step 2 moves b, which must move strictly before x; step 1 is before b
    assert not busy.retime(x, 4) and busy.steps[3] == [x, y] and not busy.pending
    free = _Retiming([[a], [b], [Action("z", "goal", "r1", "r1", "top", "top")], [x]], lambda s: obstacles.get(s, []))
    assert free.retime(x, 4) and free.pending == [(x, 4, 3)]
    mark = free.mark()
    free.rollback((0, 0))
    assert free.steps[3] == [x] and free.mark() == (0, 0) != mark
    assert not _Retiming([[a], [x]], None).retime(x, 2)  # no order constraints known: no re-timing


def _count_picks(grounder: Grounder) -> list[str]:
    """The objects of every pick query ``grounder`` answers from now on, in order (a wrapper around its own)."""
    picked: list[str] = []
    pick = grounder.pick

    def counted(robot: str, obj: str, *args: object, **kwargs: object) -> object:
        picked.append(obj)
        return pick(robot, obj, *args, **kwargs)  # type: ignore[arg-type]

    grounder.pick = counted  # type: ignore[method-assign]
    return picked


def test_an_action_doomed_by_what_never_moves_fails_before_the_later_steps(pa3: Grounder) -> None:
    """planner/doomed.py: r1 cannot reach bin-b.  The first grounding of a skeleton putting o1 there in step 1
    grounds step 2 first and then fails at step 1; once that part has failed, a skeleton holding it is probed
    before its later steps are grounded, and fails at the same step with the same check without grounding them."""
    reverse = ReverseGrounder(pa3, {"o1": "bin-b"})
    skel = Skeleton(
        (
            (Action("o1", "bin-b", "r1", "r1", "top", "top"),),
            (Action("o2", "bin-a", "r1", "r1", "top", "top"),),
        )
    )
    picked = _count_picks(pa3)
    first = reverse.ground(skel, [], key="1")
    assert "o2" in picked  # step 2 was grounded first
    picked.clear()
    assert first.outcome is Outcome.FAIL and first.failures, first.reason
    assert (first.failures[0].step, first.failures[0].check) == (1, "place by r1: no inverse kinematics")
    assert first.failures[0].static  # every placement tried is out of reach: what never moves
    # another skeleton with that step (its step 2 places o2 with another grasp: not a repeated failure)
    other = Skeleton((skel.steps[0], (Action("o2", "bin-a", "r1", "r1", "top", "top-x"),)))
    second = reverse.ground(other, [], key="2")
    assert second.outcome is Outcome.FAIL and second.failures
    assert (second.failures[0].step, second.failures[0].check) == (1, "place by r1: no inverse kinematics")
    assert second.failures[0].detail == "probed before the later steps" and not second.repeats
    assert "o2" not in picked  # step 2 was not grounded
    assert reverse.doomed.doomed == 1  # the search's statistics count it (``doomed_skeletons``)
    # an action the probe finds placeable is grounded as before: o2 into bin-a alone succeeds
    alone = reverse.ground(Skeleton(((Action("o2", "bin-a", "r1", "r1", "top", "top"),),)), [], key="3")
    assert alone.outcome is Outcome.SUCCESS, alone.reason


def test_a_failure_is_not_grounded_again_under_the_same_steps(pa3: Grounder) -> None:
    """planner/ground.py ``ReverseGrounder._repeated``: a skeleton whose steps from the one that failed on are
    those of a failed grounding (the same suffix, the same objects moved) fails as that one did without a
    geometric query: here r1 cannot reach bin-b (step 2), and a second skeleton differs only in step 1 (o3
    into bin-a with another grasp).  One whose failing step differs is grounded as before."""
    reverse = ReverseGrounder(pa3, {"o1": "bin-b", "o3": "bin-a"})
    o1 = (Action("o1", "bin-b", "r1", "r1", "top", "top"),)
    first = reverse.ground(Skeleton(((Action("o3", "bin-a", "r1", "r1", "top", "top"),), o1)), [], key="1")
    assert first.outcome is Outcome.FAIL and first.failures and first.failures[0].step == 2, first.reason
    queries = pa3.queries
    picked = _count_picks(pa3)
    again = reverse.ground(Skeleton(((Action("o3", "bin-a", "r1", "r1", "top-x", "top-x"),), o1)), [], key="2")
    assert again.outcome is Outcome.FAIL and again.repeats == "1" and reverse.repeated == 1
    assert [f.line() for f in again.failures] == [f.line() for f in first.failures]
    assert picked == [] and pa3.queries == queries  # nothing was asked
    handed = (Action("o1", "bin-b", "r1", "r2", "top", "top"),)  # another step 2: grounded
    third = reverse.ground(Skeleton(((Action("o3", "bin-a", "r1", "r1", "top", "top"),), handed)), [], key="3")
    assert not third.repeats and pa3.queries > queries


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    actions=st.integers(2, 7),
    pairs=st.sets(st.tuples(st.integers(0, 6), st.integers(0, 6)), max_size=12),
    alone=st.sets(st.integers(0, 6), max_size=3),
    latest=st.sets(st.integers(0, 6), max_size=2),
)
@example(actions=2, pairs={(0, 1)}, alone={0}, latest=set())  # packed twice: the other action in the latest
@example(actions=2, pairs={(0, 1)}, alone=set(), latest={1})  # the failing action fails first in the latest: last
@example(actions=3, pairs={(0, 2)}, alone={0, 2}, latest=set())  # the two that must be in the latest meet: fails
@example(actions=4, pairs={(0, 3), (1, 3)}, alone={0, 1}, latest=set())  # 0 then 1 put first
@example(actions=6, pairs={(i, j) for i in range(6) for j in range(i)}, alone=set(), latest=set())  # one per step
def test_a_step_whose_robots_meet_is_packed_into_plan_steps_whose_robots_do_not(
    pa3: Grounder, actions: int, pairs: set[tuple[int, int]], alone: set[int], latest: set[int]
) -> None:
    """planner/ground.py ``ReverseGrounder._packed``: a joint action here fails at its first action that fails given
    the ones grounded before it, as the real one grounds them one after another: one that meets one of them
    (robots of the step colliding: any pair of ``pairs``), an action of ``alone`` in an earlier plan step (what
    the later ones sweep in its way: it grounds in the latest only), an action of ``latest`` first in the latest
    (grounded before the others there, it fails on its own).  Unless the step's first failure is not robots
    colliding (then nothing is packed, as before), the step is packed exactly when the actions of ``alone`` meet
    none of each other: every action in exactly one plan step, none meeting another of its plan step, ``alone``
    in the latest and no action of ``latest`` first there, each action of an earlier plan step meeting one of
    the next (it was dropped from there); the earlier plan steps keep clear of the later ones' objects, which
    the grounding counts as grounded meanwhile; no skeleton step's packings run out.  Otherwise the step's own
    failure."""
    from mrgc.geometry.collision import Packed, Posed
    from mrgc.planner import ground
    from mrgc.planner.outcome import Failure

    step = tuple(Action(f"o{i}", "bin-a", f"r{i}", f"r{i}", "top", "top") for i in range(actions))
    meets = {frozenset((i, j)) for i, j in pairs if i != j and max(i, j) < actions}
    alone, latest = {i for i in alone if i < actions}, {i for i in latest if i < actions} - alone
    number = {a: i for i, a in enumerate(step)}
    tried: list[tuple[Action, ...]] = []

    def joint(self: ReverseGrounder, part: tuple[Action, ...], avoid: set[str], *args: Any, **kwargs: Any) -> Any:
        tried.append(part)
        earlier = bool(self.grounded)  # a later plan step of the step grounded: this one is earlier
        assert self.grounded <= avoid and not self.grounded & {a.obj for a in part}
        for k, a in enumerate(part):
            if number[a] in alone and earlier or number[a] in latest and not earlier and k == 0:
                return Failure(1, ground.label(a), "carry to the placement by r0: no path")
            met = [b for b in part[:k] if frozenset((number[a], number[b])) in meets]
            if met:
                robots = tuple(sorted({a.pick_robot, met[0].pick_robot}))
                return Failure(1, ground.label(a), "pick: robots of the step collide", robots)
        return ground.GroundedStep([], Packed.of(Posed.of([])), tuple(a.obj for a in part))

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(ReverseGrounder, "_step", joint)
        reverse = ReverseGrounder(pa3, {})
        out = reverse._steps(step, set(), ground.swept([]), "k", 1)
    assert not reverse.grounded
    first = tried[0]  # the step in the skeleton's order, in the latest plan step
    failed = next(
        (
            a
            for k, a in enumerate(first)
            if number[a] in latest and k == 0 or any(frozenset((number[a], number[b])) in meets for b in first[:k])
        ),
        None,
    )
    clash = failed is not None and failed is not first[0]
    packable = not any(frozenset((i, j)) in meets for i in alone for j in alone)
    assert isinstance(out, Failure) == (failed is not None and not (clash and packable)), (out, failed, clash)
    assert reverse.packings_spent == 0 and reverse.repacked <= 2 * actions
    if isinstance(out, Failure):  # the step's own failure
        assert failed is not None and out.action == ground.label(failed)
        return
    parts = [[int(o[1:]) for o in s.moved] for s in out]
    assert sorted(i for part in parts for i in part) == list(range(actions))
    assert (len(parts) > 1) == (failed is not None)
    assert alone <= set(parts[-1]) and parts[-1][0] not in latest
    for part in parts:
        assert not any(frozenset((i, j)) in meets for i in part for j in part if i < j)
    for earlier, later in zip(parts, parts[1:]):
        assert all(any(frozenset((i, j)) in meets for j in later) for i in earlier)


def test_a_pick_failing_on_what_never_moves_fails_every_skeleton_holding_it_at_once(pa3: Grounder) -> None:
    """planner/doomed.py: r1 reaches o2 with no side-y+ grasp (every attempt fails on its inverse kinematics:
    a static answer).  Once one grounding has failed on that pick, another skeleton holding the same pick (with
    another place grasp, in another step) fails at that step before any geometric query, with the same check;
    a pick of o2 by r1 with another grasp is grounded as before."""
    pa3.step({"r1": Stance.PICKED})
    answer = pa3.pick("r1", "o2", "side-y+")
    pa3.step({})
    assert answer.status is GroundStatus.NO_IK and answer.static  # the premise, measured
    reverse = ReverseGrounder(pa3, {"o1": "bin-a", "o2": "bin-a"})
    first = reverse.ground(Skeleton(((Action("o2", "bin-a", "r1", "r1", "side-y+", "top"),),)), [], key="1")
    assert first.outcome is Outcome.FAIL and first.failures[0].static, first.reason
    assert first.failures[0].check == "pick by r1: no inverse kinematics"
    queries = pa3.queries
    picked = _count_picks(pa3)
    later = Skeleton(
        (
            (Action("o2", "bin-a", "r1", "r1", "side-y+", "side-y+"),),
            (Action("o1", "bin-a", "r1", "r1", "top", "top"),),
        )
    )
    second = reverse.ground(later, [], key="2")
    assert second.outcome is Outcome.FAIL and second.failures
    f = second.failures[0]
    assert (f.step, f.check, f.static) == (1, "pick by r1: no inverse kinematics", True)
    assert f.detail.endswith("(known)") and picked == [] and pa3.queries == queries  # nothing was asked
    other = reverse.ground(Skeleton(((Action("o2", "bin-a", "r1", "r1", "top", "top"),),)), [], key="3")
    assert picked and picked[0] == "o2"  # asked again: another grasp is another query
    assert other.outcome is Outcome.SUCCESS, other.reason


def test_a_pick_whose_hand_hits_a_neighbour_stops_after_one_attempt(
    pa3: Grounder, monkeypatch: pytest.MonkeyPatch
) -> None:
    """geometry/approaches.py: o1 stands 2 cm from o2 and o3; its top-x grasp closes the fingers across them.
    The hand (the end-effector link and the fingers: :attr:`Arm.hand`) stands where the grasp puts it in every
    IK attempt, so the first attempt's hit ends the query with the same answer (collision, those blockers)
    instead of trying every IK branch; without the neighbours to avoid the pick is found."""
    import mrgc.geometry.approaches as approaches

    arm = pa3.arm("r1")
    links = arm.model.links
    below = {k for k in range(len(links)) if _below(links, k, arm.model.ee_link)}
    assert arm.hand and {arm.probes[1][i] for i in arm.hand} == below & set(arm.probes[1])
    solves: list[int] = []
    real = approaches.solve_ik_many

    def counted(*args: object, **kwargs: object) -> object:
        solves.append(1)
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(approaches, "solve_ik_many", counted)
    pa3.step({"r1": Stance.PICKED})
    blocked = pa3.pick("r1", "o1", "top-x", avoid=["o2", "o3"])
    assert blocked.status is GroundStatus.COLLISION and blocked.blockers == {"o2", "o3"}
    assert len(solves) == 2  # one attempt: the grasp and its pre-grasp
    assert pa3.pick("r1", "o1", "top-x").ok


def _below(links: tuple[Link, ...], k: int, ancestor: int) -> bool:
    """Whether link ``k`` is link ``ancestor`` or lies below it in the tree."""
    while k != ancestor and links[k].parent is not None and links[k].parent >= 0:
        k = links[k].parent
    return k == ancestor


def test_a_static_pick_failure_away_from_the_start_is_not_remembered(pa3: Grounder) -> None:
    """planner/doomed.py: a relay's onward half picks its object up at the relay's spot; a pick failing there on
    what never moves says nothing of the pick from the object's initial pose, so it is not remembered."""
    from mrgc.planner.outcome import Failure

    reverse = ReverseGrounder(pa3, {"o1": "bin-a"})
    a = Action("o2", "bin-a", "r1", "r1", "side-y+", "top")
    failure = Failure(1, "r1 moves o2", "pick by r1: no inverse kinematics", static=True)
    elsewhere = pa3.poses["o2"] @ translation(0.0, 0.05, 0.0)
    with pa3.moved({"o2": elsewhere}):
        reverse.doomed.failed(a, failure)
    assert reverse.doomed.static_picks == {}
    reverse.doomed.failed(a, failure)  # at its initial pose: remembered
    assert list(reverse.doomed.static_picks) == [("r1", "o2", "side-y+")]


def test_a_suffix_leaving_a_goal_object_no_room_in_its_goal_region_is_a_dead_end(pa3: Grounder) -> None:
    """planner/ground.py: a skeleton under a suffix failed on "no free pose of o1 in bin-b", o1's goal region;
    when the suffix's volume alone (nothing else avoided) leaves o1 no free pose in bin-b, no skeleton can come
    before that suffix (``dead_end``); a suffix leaving room, a failure of another kind or a region that is not
    the object's goal say nothing of the kind."""
    from mrgc.planner.ground import GroundedStep
    from mrgc.planner.outcome import Failure

    reverse = ReverseGrounder(pa3, {"o1": "bin-b"})
    skeleton = Skeleton(((Action("o1", "bin-b", "r1", "r2", "top", "top"),),))
    full = Failure(1, "r1->r2 moves o1", "placement: no free pose of o1 in bin-b")
    walled = [GroundedStep([], Packed.of(Posed.of(_wall(pa3, "bin-b"))), ("o2",))]
    why = reverse.dead_end(full, skeleton, walled)
    assert "no free pose of o1 in bin-b" in why and "1 step(s)" in why
    one = [GroundedStep([], Packed.of(Posed.of(_wall(pa3, "bin-b")[:1])), ("o2",))]
    assert reverse.dead_end(full, skeleton, one) == ""
    assert reverse.dead_end(Failure(1, "r1->r2 moves o1", "place by r2: no inverse kinematics"), skeleton, walled) == ""
    assert ReverseGrounder(pa3, {"o1": "bin-a"}).dead_end(full, skeleton, walled) == ""


def test_a_place_the_analytic_solver_has_no_branch_for_gives_up_after_one_attempt(
    pa3: Grounder, monkeypatch: pytest.MonkeyPatch
) -> None:
    """geometry/approaches.py: a place of o1 with the top grasp 0.87 m from r1's shoulder (inside its reach
    bound, but no Panda configuration holds the tool there pointing down).  The first numeric attempt fails,
    the analytic solver (every branch over the q7 grid) has none either, so the place is out of reach at once
    -- the same answer (no inverse kinematics, static) as after the :data:`IK_GIVE_UP` numeric attempts."""
    import mrgc.geometry.approaches as approaches
    from mrgc.geometry.arm import Arm

    far = translation(-0.75, -1.05, 0.06)
    solves: list[bool] = []
    real, oracle = approaches.solve_ik_many, Arm.no_branch

    def counted(*args: object, **kwargs: object) -> object:
        solves.append(False)
        return real(*args, **kwargs)  # type: ignore[arg-type]

    def asked(arm: Arm, tool: np.ndarray) -> bool:
        solves.append(True)
        return oracle(arm, tool)

    monkeypatch.setattr(approaches, "solve_ik_many", counted)
    monkeypatch.setattr(Arm, "no_branch", asked)
    pa3.step({"r1": Stance.PLACED})
    quick = pa3.place("r1", "o1", "top", far)
    assert solves == [False, True]  # one numeric attempt, then the analytic check
    solves.clear()
    monkeypatch.setattr(Arm, "no_branch", lambda arm, tool: False)
    slow = pa3.place("r1", "o1", "top", far)
    pa3.step({})
    assert solves == [False] * approaches.IK_GIVE_UP
    assert (quick.status, quick.static) == (slow.status, slow.static) == (GroundStatus.NO_IK, True)
    assert not oracle(pa3.arm("r1"), pa3.arm("r1").tool_world(pa3.arm("r1").home))  # home: a branch


def test_a_place_whose_pre_grasp_no_branch_reaches_gives_up_at_its_first_attempt(
    pa3: Grounder, monkeypatch: pytest.MonkeyPatch
) -> None:
    """geometry/approaches.py: o1 placed with the side-x+ grasp 0.5 m from r1's base, toward the table's edge:
    the grasp has an IK answer, its pre-grasp (backed off outward, the same tool pose for every branch) none,
    and the analytic solver has no branch for the pre-grasp either: no inverse kinematics (static) after the
    first attempt, where without the check all eight attempts solve the grasp and fail at the pre-grasp."""
    import mrgc.geometry.approaches as approaches
    from mrgc.geometry.arm import Arm

    pose = translation(0.433, -0.45, 0.06)
    solves: list[str] = []
    real = approaches.solve_ik_many

    def counted(*args: object, **kwargs: object) -> object:
        solves.append("numeric")
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(approaches, "solve_ik_many", counted)
    pa3.step({"r1": Stance.PLACED})
    quick = pa3.place("r1", "o1", "side-x+", pose)
    assert len(solves) == 3  # the grasp, its pre-grasp, the pre-grasp again (the cache answers), then the oracle
    asked = 2
    solves.clear()
    monkeypatch.setattr(Arm, "no_branch", lambda arm, tool: False)
    slow = pa3.place("r1", "o1", "side-x+", pose)
    pa3.step({})
    assert len(solves) > 4 * asked  # every attempt: a grasp and its pre-grasp
    assert (quick.status, quick.static) == (slow.status, slow.static) == (GroundStatus.NO_IK, True)


@functools.lru_cache(maxsize=1)
def _pa3() -> Grounder:
    """One grounder of pa3-handover for a property test's examples (a fixture is made once per test, not
    per example)."""
    return Grounder(
        scene_from_problem(parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()), seed=0
    )


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    u=st.lists(st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7), min_size=1, max_size=6),
    holding=st.sampled_from([None, ("o1", "top"), ("o2", "side-x+")]),
    grasp=st.sampled_from([None, ("o3", "top")]),
)
def test_a_volume_made_from_the_arrays_is_the_volume_made_from_its_pieces(u, holding, grasp) -> None:
    """geometry/volumes.py ``free_posed`` (the motion checks' form, :meth:`Arm.posed`): at any configurations,
    holding an object or not, the same pieces (shapes, transforms, boxes, in order) as :meth:`free_volume`'s
    list converted by :meth:`Posed.of`, and None exactly where that is None."""
    g = _pa3()
    arm = g.arm("r1")
    qs = arm.model.lower + np.array(u) * (arm.model.upper - arm.model.lower)
    listed = g.free_volume("r1", qs, holding=holding, grasp=grasp)
    direct = g.free_posed("r1", qs, holding=holding, grasp=grasp)
    assert (listed is None) == (direct is None)
    whole = g.arm_volume("r1", qs, holding=holding, grasp=grasp)
    made, _, _ = arm.posed(
        qs, g._held("r1", holding), None if not (holding or grasp) else g._grip("r1", *(holding or grasp))[0]
    )
    of = Posed.of(whole)
    assert len(made) == len(of) == len(whole)
    assert [made.shape(i) for i in range(len(made))] == [of.shape(i) for i in range(len(of))]
    assert np.array_equal(made.transforms, of.transforms)
    assert np.allclose(made.lo, of.lo, atol=1e-12) and np.allclose(made.hi, of.hi, atol=1e-12)


def test_a_held_object_swung_into_its_own_arm_is_not_free(pa3: Grounder) -> None:
    """geometry/arm.py ``held_collides_at``: r1 holding o1 with the top grasp at a configuration whose links are
    free of each other and of everything, but which folds the object into the arm's own links (the validator's
    ``collision-self-held``; the 6-arm 40-object instance's first plan was rejected for 1 mm of it between two
    samples of a carry): not a free configuration; at home, holding o1, it is."""
    q = np.array([1.499, -0.016, 2.04, -3.13, 0.985, 2.913, -1.029])
    assert pa3.free_volume("r1", q[None], grasp=("o1", "top")) is not None  # the arm alone, fingers as holding
    assert pa3.free_volume("r1", q[None], holding=("o1", "top")) is None
    arm = pa3.arm("r1")
    assert pa3.free_volume("r1", arm.home[None], holding=("o1", "top")) is not None


@pytest.mark.parametrize(
    "q",
    [
        [0.2, 0.3, 0.1, -1.8, 0.0, 2.1, 0.8],
        [-0.6, 0.5, 0.3, -2.0, 0.2, 2.5, -0.4],
        [1.0, -0.2, -0.5, -1.5, -0.3, 1.6, 1.9],
    ],
)
def test_a_contact_segment_off_the_approach_line_is_refused(pa3: Grounder, q: list[float]) -> None:
    """geometry/approaches.py ``on_the_line``: a contact segment from the grasp backed off 2 cm along the
    tool's z axis (IK from the grasp configuration) keeps the tool on the approach line; one whose start has
    the first joint turned 0.05 rad (the tool some 2-4 cm off sideways) does not, and the approach is refused
    before the validator would reject its plan (10 mm, 0.05 rad)."""
    from mrgc.geometry.approaches import on_the_line
    from mrgc.geometry.ik import solve_ik_many

    arm = pa3.arm("r1")
    grasp = np.array(q)
    tool = arm.tool_world(grasp[None])[0]
    back = solve_ik_many(arm.model, arm.ee_target(tool @ translation(0, 0, -0.02))[None], 0, q_init=grasp[None])[0]
    assert back.solved and back.q is not None
    assert on_the_line(arm, tool, np.asarray(back.q), grasp)
    turned = np.asarray(back.q).copy()
    turned[0] += 0.05
    assert not on_the_line(arm, tool, turned, grasp)


def test_a_handover_failing_at_every_point_tells_the_failure_that_can_be_acted_on() -> None:
    """An action's handover fails at each of its points: the failure reported is the one another robot of the
    step caused (the step's passes are compared, or the step is split), else one with bodies in the way
    (objects to move), else the carry to a point whose exchange was found, else any but a point out of
    reach, else the last; never merely the last point's, which for a point out of the arms' reach hid why
    the reachable one failed, nor an exchange's collision at one point over the carry to the point where the
    exchange exists."""
    from mrgc.geometry.answers import BUSY
    from mrgc.planner.ground import _telling
    from mrgc.planner.outcome import Failure

    def at(
        point: str, status: GroundStatus, bodies: tuple[str, ...] = (), detail: str = ""
    ) -> tuple[Failure, GroundStatus, bool]:
        return Failure(0, "", f"handover at {point}: {status.value}", bodies, detail), status, False

    far = at("h5", GroundStatus.NO_IK)
    busy = at("h1", GroundStatus.COLLISION, detail=BUSY)
    blocked = at("h2", GroundStatus.COLLISION, ("o3",))
    fixed = at("h3", GroundStatus.COLLISION, detail="hits table")
    assert _telling([blocked, busy, far]) is busy[0]
    assert _telling([fixed, blocked, far]) is blocked[0]
    assert _telling([fixed, far]) is fixed[0] and _telling([far, fixed]) is fixed[0]
    nearer = at("h1", GroundStatus.NO_IK)
    assert _telling([nearer, far]) is far[0] and _telling([far]) is far[0]
    carry = (Failure(0, "", "carry to the handover by r5: no path"), GroundStatus.NO_PATH, True)
    assert _telling([nearer, fixed, far, carry]) is carry[0] and _telling([fixed, carry, busy]) is busy[0]
    assert _telling([carry, blocked]) is blocked[0]


def test_a_handover_whose_carry_to_one_point_fails_is_tried_at_the_next(tmp_path: Path) -> None:
    """planner/ground.py ``ReverseGrounder._hand_over``: an object with two handover points whose giver can
    exchange it at the first but not carry it there (a carry refused here for every goal at that point's
    exchange, as RRTConnect refuses one near the edge of the arm's reach) is handed over at the second; when
    the carries to both fail, the action fails with the carry's line.  Before, the first point with a free
    exchange was the only one tried: on the 6-arm, 40-object instance of seed 8 one handover failed 40 times
    as "carry to the handover by r3: no path" at h1 and was never tried at h2."""
    text = (ROOT / "domains" / "packaging" / "pa3-handover.mrg").read_text(encoding="utf-8")
    text = text.replace("(h1 :position (0 0 0.4))", "(h0 :position (0.05 0 0.42)) (h1 :position (0 0 0.4))")
    path = tmp_path / "two-points.mrg"
    path.write_text(text, encoding="utf-8")
    domain = ROOT / "domains" / "packaging" / "domain.mrg"
    (tmp_path / "domain.mrg").write_text(domain.read_text(encoding="utf-8"), encoding="utf-8")
    g = Grounder(scene_from_problem(parse_file(path).problem()), seed=0)
    assert g.scene.handover_of["o1"] == ("h0", "h1")
    refused: set[str] = set()
    exchanges: dict[str, list[np.ndarray]] = {}  # every giver configuration of a free exchange pair at each point
    for point in ("h0", "h1"):
        for k in range(EXCHANGE_TRIES):
            hand = g.handover("o1", point, "r1", "top", "r2", "side-x+", skip=k)
            assert hand.ok and hand.configs is not None or k > 0, point
            if hand.configs is not None:
                exchanges.setdefault(point, []).append(hand.configs[0])
    transfer = g.transfer

    def carry(robot: str, obj: str, grasp: str, start: np.ndarray, goal: np.ndarray, *args: Any, **kw: Any) -> Answer:
        if any(np.allclose(goal, q) for p in refused for q in exchanges[p]):
            return Answer(GroundStatus.NO_PATH)
        return transfer(robot, obj, grasp, start, goal, *args, **kw)

    g.transfer = carry  # type: ignore[method-assign]
    skeleton = Skeleton(((Action("o1", "bin-b", "r1", "r2", "top", "side-x+"),),))
    grounded = ReverseGrounder(g, {"o1": "bin-b"}).ground(skeleton, [], key="both")
    assert grounded.outcome is Outcome.SUCCESS and grounded.steps[0].actions[0].handover_point == "h0"
    refused.add("h0")
    second = ReverseGrounder(g, {"o1": "bin-b"}).ground(skeleton, [], key="h1")
    assert second.outcome is Outcome.SUCCESS, second.reason
    assert second.steps[0].actions[0].handover_point == "h1"
    refused.add("h1")
    neither = ReverseGrounder(g, {"o1": "bin-b"}).ground(skeleton, [], key="neither")
    assert neither.outcome is Outcome.FAIL and neither.failures
    assert neither.failures[0].check == "carry to the handover by r1: no path"


def test_a_handover_whose_carry_to_one_exchange_fails_tries_another_at_the_same_point(tmp_path: Path) -> None:
    """planner/ground.py ``ReverseGrounder._hand_over``: when the giver's carry to the first free exchange at a
    point fails, the next free exchange pairs there (other branches of the arms, ``Grounder.handover(skip=k)``)
    are tried before the next point, each giver configuration once.  6-arm seed 0: no RRTConnect path of
    64,000 checks reaches r5's first exchange at h5; its second is reached in 0.03 s."""
    text = (ROOT / "domains" / "packaging" / "pa3-handover.mrg").read_text(encoding="utf-8")
    path = tmp_path / "one-point.mrg"
    path.write_text(text, encoding="utf-8")
    domain = ROOT / "domains" / "packaging" / "domain.mrg"
    (tmp_path / "domain.mrg").write_text(domain.read_text(encoding="utf-8"), encoding="utf-8")
    g = Grounder(scene_from_problem(parse_file(path).problem()), seed=0)
    point = g.scene.handover_of["o1"][0]
    pairs = [g.handover("o1", point, "r1", "top", "r2", "side-x+", skip=k) for k in range(EXCHANGE_TRIES + 2)]
    free = [p.configs for p in pairs if p.ok and p.configs is not None]
    assert len(free) >= 2 and not np.array_equal(free[0], free[1])
    assert pairs[0].ok and np.array_equal(
        pairs[0].configs, g.handover("o1", point, "r1", "top", "r2", "side-x+").configs
    )
    givers = {tuple(np.round(f[0], 9)) for f in free}
    transfer = g.transfer
    asked: list[np.ndarray] = []

    def carry(robot: str, obj: str, grasp: str, start: np.ndarray, goal: np.ndarray, *args: Any, **kw: Any) -> Answer:
        asked.append(goal)
        if np.array_equal(goal, free[0][0]):  # only the first exchange is out of the carry's way
            return Answer(GroundStatus.NO_PATH)
        return transfer(robot, obj, grasp, start, goal, *args, **kw)

    g.transfer = carry  # type: ignore[method-assign]
    skeleton = Skeleton(((Action("o1", "bin-b", "r1", "r2", "top", "side-x+"),),))
    grounded = ReverseGrounder(g, {"o1": "bin-b"}).ground(skeleton, [], key="second")
    assert grounded.outcome is Outcome.SUCCESS, grounded.reason
    (planned,) = grounded.steps[0].actions
    assert planned.handover_point == point
    giver = np.array(planned.configs["handover"][0])
    assert not np.allclose(giver, free[0][0]) and tuple(np.round(giver, 9)) in givers
    assert np.array_equal(asked[0], free[0][0]) and len(asked) == len({tuple(q) for q in map(tuple, asked)})


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(st.tuples(st.integers(0, 4), st.integers(0, 2)), min_size=1, max_size=9),
    st.lists(st.tuples(st.integers(0, 4), st.integers(0, 2)), min_size=1, max_size=9),
    st.integers(0, 6),
    st.booleans(),
)
def test_paired_motions_collide_as_their_samples_pair_by_pair(
    xs_a: list[tuple[int, int]], xs_b: list[tuple[int, int]], wait: int, late: bool
) -> None:
    """The comparison of two motions (one kernel query, a repeated volume once) says what testing each
    sample pair ``i * len // n`` on its own says, also when one motion waits (its first or last volume
    repeated) or stands still."""
    from mrgc.geometry.collision import pieces_collide
    from mrgc.planner.ground import _paired

    def volumes(xs: list[tuple[int, int]]) -> list[Any]:
        return [[(_box(0.1), translation(0.08 * x, 0.3 * y, 0.0))] if y < 2 else [] for x, y in xs]

    a, b = volumes(xs_a), volumes(xs_b)
    a = [a[0]] * wait + a if late else a + [a[-1]] * wait  # the same volume object repeated: a wait
    n = max(len(a), len(b))
    expected = any(pieces_collide(a[i * len(a) // n], b[i * len(b) // n]) for i in range(n))
    assert _paired(a, b) is expected
    assert _paired(b, a) is expected


def test_a_clash_re_times_the_failing_action_first_then_the_other_robots_action() -> None:
    """Two robots of a step in each other's way: the failing action is re-timed first, then the actions of
    the robot it met (not the step's uninvolved ones); a failure that names no robot re-times the failing
    action only."""
    from mrgc.compiler.task_graph import Action
    from mrgc.planner.ground import _retimable
    from mrgc.planner.outcome import Failure

    o2 = Action("o2", "bin-a", "r1", "r1", "top", "top")
    o3 = Action("o3", "bin-b", "r2", "r2", "side-y+", "side-y+")
    o4 = Action("o4", "bin-c", "r3", "r4", "top", "top")  # a handover of two robots not in the clash
    clash = Failure(2, "r2 moves o3 to bin-b (side-y+)", "to-place: robots of the step collide", ("r1", "r2"))
    assert _retimable(o3, (o2, o3, o4), clash) == [o3, o2]
    assert _retimable(o3, (o2, o3, o4), Failure(2, "", "carry: no path", ("o7",))) == [o3]


def test_a_clash_settled_by_re_timing_the_other_robots_action_keeps_the_skeletons_makespan() -> None:
    """PA5-s15 (the preset, seed 15): a skeleton whose step 2 has r1 place o2 while r2 picks o3, which
    collide at r2's pick.  r2 is busy in step 1 (o1), so o3 cannot go earlier; r1 is free there, so o2 is
    re-timed into step 1 and the plan keeps the skeleton's two steps (the step was split into three
    before, one robot after the other)."""
    from mrgc import parse_string
    from mrgc.generate import preset

    problem = parse_string(preset("pa5", 15), "pa5-s15.mrg", str(ROOT / "domains" / "packaging")).problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    steps = (
        (Action("o1", "bin-c", "r2", "r2", "side-y+", "side-y+"),),
        (Action("o2", "bin-a", "r1", "r1", "top", "top"), Action("o3", "bin-b", "r2", "r2", "side-y+", "side-y+")),
    )
    grounding = ReverseGrounder(g, dict(problem.goal_regions)).ground(Skeleton(steps), [], order=lambda a: [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    assert [sorted(a.object for a in s.actions) for s in grounding.steps] == [["o1", "o2"], ["o3"]]
    assert grounding.retimed == [("r1 moves o2 to bin-a (top)", 2, 1)]
    assert [f.bodies for f in grounding.resolved] == [("r1", "r2")]


def test_two_robots_of_a_step_take_a_phase_in_turn_when_no_wait_of_one_clears_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """No wait of the action's robot alone clearing the phase (none allowed here), the two robots take it in
    turn: the earlier action's robot hurries through the first half and stands at its path's end while the
    other stands at its start, or the other way round; both paths carry their waits, the step's motions
    the other's, and every robot of the step was compared with both.  A third robot standing in the way of
    both orders leaves the clash."""
    import mrgc.planner.ground as ground_module
    from mrgc.planfile.format import PlannedAction
    from mrgc.planner.ground import _robots_collide, _waiting

    monkeypatch.setattr(ground_module, "WAITS", ())
    path, volumes = _crossing(1.0)
    across = [[float(x), 0.0, 0.0] for x in np.linspace(0.0, 1.0, 5)]
    earlier = PlannedAction("a", "goal", "r1", "r1", "top", "top", paths={"to-place": [list(q) for q in across]})
    action = PlannedAction("b", "goal", "r2", "r2", "top", "top", paths={"to-place": [list(q) for q in path]})
    motions = {"r1": {"to-place": _across()}}
    owners = {("r1", "to-place"): (earlier, "to-place")}
    mine = {"r2": {"to-place": volumes}}
    clash = _robots_collide(mine, motions)
    assert clash is not None
    assert _waiting(action, mine, motions, clash)[0] == clash  # without owners: nothing to take in turn
    left, waited = _waiting(action, mine, motions, clash, owners)
    assert left is None and _robots_collide(waited, motions) is None
    (mine_wait,), (their_wait,) = action.waits(), earlier.waits()
    assert {mine_wait[1:], their_wait[1:]} == {(4, 0), (0, 4)}  # one sets out late, the other arrives early
    assert len(motions["r1"]["to-place"]) == 9 and len(action.paths["to-place"]) == 9

    # a third robot standing where both orders put one of them: no turn clears it, nothing changes
    action = PlannedAction("b", "goal", "r2", "r2", "top", "top", paths={"to-place": [list(q) for q in path]})
    earlier = PlannedAction("a", "goal", "r1", "r1", "top", "top", paths={"to-place": [list(q) for q in across]})
    motions = {"r1": {"to-place": _across()}, "r3": {"to-place": [[(_box(0.1), translation(0.5, 1.0, 0.0))]]}}
    owners = {("r1", "to-place"): (earlier, "to-place")}
    mine = {"r2": {"to-place": volumes}}
    clash = _robots_collide(mine, motions)
    assert clash is not None
    left, _ = _waiting(action, mine, motions, clash, owners)
    assert left is not None and not action.waits() and not earlier.waits() and len(motions["r1"]["to-place"]) == 5


def _pa7_s1_first_steps() -> tuple[Any, Grounder, Skeleton]:
    """PA7-s1 (the preset, seed 1) and its first skeleton: step 1 has r1 clear o7 aside in the start region
    while r2 clears o4 there too."""
    from mrgc import parse_string
    from mrgc.generate import preset

    problem = parse_string(preset("pa7", 1), "pa7-s1.mrg", str(ROOT / "domains" / "packaging")).problem()
    steps = (
        (Action("o7", "start", "r1", "r1", "top", "top"), Action("o4", "start", "r2", "r2", "side-y+", "side-y+")),
        (Action("o6", "bin-c", "r1", "r2", "side-x+", "top"),),
        (Action("o5", "bin-b", "r1", "r2", "side-x-", "top"),),
        (Action("o3", "bin-a", "r1", "r1", "side-y-", "side-y-"),),
    )
    return problem, Grounder(scene_from_problem(problem), seed=0), Skeleton(steps)


def test_a_clash_settled_by_grounding_the_failing_action_first_keeps_the_step() -> None:
    """PA7-s1's step 1: grounded in the skeleton's order, r2's carry of o4 meets r1's of o7 and no placement
    of o4 clear of what r1 sweeps is reached; neither action can go to another step (both robots are busy in
    step 2).  Grounded with o4 first, r1 plans around it (one waits for the other), and the plan keeps the
    skeleton's four steps (it had five: the step split, one robot after the other)."""
    problem, g, skeleton = _pa7_s1_first_steps()
    grounding = ReverseGrounder(g, dict(problem.goal_regions)).ground(skeleton, [], order=lambda a: [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    assert [sorted(a.object for a in s.actions) for s in grounding.steps] == [["o4", "o7"], ["o6"], ["o5"], ["o3"]]
    assert [a.object for a in grounding.steps[0].actions] == ["o4", "o7"]
    assert grounding.retimed == []
    assert [(f.action, f.bodies) for f in grounding.resolved] == [("r2 moves o4 to start (side-y+)", ("r1", "r2"))]


def test_a_place_kept_clear_of_the_other_robots_gives_up_after_a_few_carries_they_block(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """PA7-s1's step 1 again: while o4's place keeps clear of what r1 sweeps, at most BUSY_CARRIES carries are
    blocked by it per try and no other region is tried (parking is for a crowded region, not for robots in
    each other's way); it tried 17 placements in three regions before (1.5 s of carries)."""
    from mrgc.geometry.answers import BUSY
    from mrgc.planner.ground import BUSY_CARRIES

    problem, g, skeleton = _pa7_s1_first_steps()
    carries: list[tuple[str, bool]] = []
    transfer = Grounder.transfer

    def counted(self: Grounder, robot: str, obj: str, *args: Any, **kw: Any) -> Answer:
        answer = transfer(self, robot, obj, *args, **kw)
        if obj == "o4" and kw.get("busy"):
            carries.append((kw.get("phase", ""), answer.detail == BUSY))
        return answer

    monkeypatch.setattr(Grounder, "transfer", counted)
    grounding = ReverseGrounder(g, dict(problem.goal_regions)).ground(skeleton, [], order=lambda a: [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    blocked = [c for c in carries if c[1]]
    assert 0 < len(blocked) <= BUSY_CARRIES, carries


@pytest.mark.parametrize("busy", [False, True])
def test_a_place_approach_blocked_by_an_object_costs_a_look_and_by_the_step_s_robots_a_try(
    pa3: Grounder, busy: bool
) -> None:
    """A crowded start region: the first free poses lie next to other objects, and the fingers touch one.  Such
    an approach costs a look (up to PLACEMENT_TRIES + OUT_OF_REACH_TRIES), so the place goes on to a pose with
    room (6-arm instances: 1 in 10 obstacles with a reachable free pose was given up after 6 such touches); an
    approach the step's other robots block still costs a try, so that step is split or re-timed soon."""
    from mrgc.geometry.answers import BUSY
    from mrgc.planner.ground import OUT_OF_REACH_TRIES, PLACEMENT_TRIES

    blocked = 10**6 if busy else PLACEMENT_TRIES + 2
    calls: list[int] = []
    place = pa3.place

    def crowded(robot: str, obj: str, *args: Any, **kw: Any) -> Answer:
        calls.append(1)
        if len(calls) <= blocked:
            if busy:
                return Answer(GroundStatus.COLLISION, detail=BUSY)
            return Answer(GroundStatus.COLLISION, blockers={"o2"})
        return place(robot, obj, *args, **kw)

    pa3.place = crowded  # type: ignore[method-assign]
    skel = Skeleton(((Action("o1", "bin-a", "r1", "r1", "top", "top"),),))
    grounding = ReverseGrounder(pa3, {"o1": "bin-a"}).ground(skel, [], key="looks")
    if busy:
        # the strict attempt and the relaxed one (M_out ignored) each give up after PLACEMENT_TRIES approaches
        assert grounding.outcome is Outcome.FAIL and len(calls) == 2 * PLACEMENT_TRIES, (len(calls), grounding.reason)
    else:
        assert grounding.outcome is Outcome.SUCCESS, grounding.reason
        assert blocked < len(calls) <= PLACEMENT_TRIES + OUT_OF_REACH_TRIES


def test_placements_past_the_arm_s_reach_bound_are_never_asked_and_fail_as_out_of_reach(pa3: Grounder) -> None:
    """r1 cannot reach bin-b: every free pose there lies past its reach bound (an upper bound of where its
    end effector can be), so no place query is made for them and none costs a look; the step fails as one
    whose every placement has no inverse kinematics (static: on what never moves), naming why."""
    asked: list[np.ndarray] = []
    place = pa3.place

    def recorded(robot: str, obj: str, grasp: str, pose: np.ndarray, *args: Any, **kw: Any) -> Answer:
        asked.append(pose)
        return place(robot, obj, grasp, pose, *args, **kw)

    pa3.place = recorded  # type: ignore[method-assign]
    far_off = pa3.out_of_reach("r1", "o1", "top")
    skel = Skeleton(((Action("o1", "bin-b", "r1", "r1", "top", "top"),),))
    grounding = ReverseGrounder(pa3, {"o1": "bin-b"}).ground(skel, [], key="far")
    assert grounding.outcome is Outcome.FAIL, grounding.reason
    failure = grounding.failures[0]
    assert (failure.check, failure.static) == ("place by r1: no inverse kinematics", True)
    assert "beyond its reach" in failure.detail
    assert all(far_off(p) for p in pa3.placements("o1", "bin-b", key="far", packed=True))
    assert not asked  # every free pose lies past the bound: none was asked
