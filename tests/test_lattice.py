"""The SE(2) lattice planner of planar robots (geometry/lattice.py): exact occupancy at lattice states,
paths valid state by state, doorways found whatever their width as long as the robot fits, "no path" when it
does not, determinism."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import event, given, settings
from hypothesis import strategies as st

from mrgc.geometry.collision import CollisionWorld, collision_shape
from mrgc.geometry.conventions import se2, wrap_angle
from mrgc.geometry.lattice import SLACK, LatticePlanner, interpolate, segment_clear
from mrgc.geometry.motion import MotionStatus
from mrgc.geometry.planar import grown
from mrgc.geometry.scene import hull2d
from mrgc.geometry.transforms import rot_z, translation
from mrgc.language.model import Box

ROBOT = Box(0.5, 0.4, 0.3)
LIFT = translation(0, 0, 0.151)
BOUNDS = (0.0, 4.0, 0.0, 3.0)


def wall_with_door(door_y: float, width: float) -> list[tuple[str, Box, np.ndarray]]:
    """A wall at x = 2 from y = 0 to 3 with a door of ``width`` centred at ``door_y``."""
    lo, hi = door_y - width / 2, door_y + width / 2
    return [
        ("south", Box(0.1, lo, 0.5), translation(2.0, lo / 2, 0.25)),
        ("north", Box(0.1, 3.0 - hi, 0.5), translation(2.0, (3.0 + hi) / 2, 0.25)),
    ]


def validity(obstacles: list[tuple[str, Box, np.ndarray]], parts: list[tuple[Box, np.ndarray]]):
    world = CollisionWorld()
    for name, shape, t in obstacles:
        world.add(name, collision_shape(shape), t, "fixed")

    def valid(q: np.ndarray) -> bool:
        if not (BOUNDS[0] <= q[0] <= BOUNDS[1] and BOUNDS[2] <= q[1] <= BOUNDS[3]):
            return False
        base = se2(*q)
        return not world.probe_collides([(collision_shape(s), base @ t) for s, t in parts], against="fixed")

    return valid


def plan(obstacles, start, goal, parts=((ROBOT, LIFT),)):
    lattice = LatticePlanner(BOUNDS)
    parts = list(parts)
    occupied = lattice.occupancy(parts, obstacles)
    valid = validity(obstacles, parts)
    return lattice.plan(occupied, np.array(start, float), np.array(goal, float), valid, 0.01, 0.01), valid


def assert_valid_path(res, start, goal, valid) -> None:
    assert res.status is MotionStatus.SOLVED
    assert np.allclose(res.path[0], start) and np.allclose(res.path[-1][:2], goal[:2])
    assert abs(wrap_angle(res.path[-1][2] - goal[2])) < 1e-9
    for a, b in zip(res.path, res.path[1:]):  # dense: no step longer than the resolution
        assert math.hypot(b[0] - a[0], b[1] - a[1]) <= 0.01 + 1e-9 and abs(wrap_angle(b[2] - a[2])) <= 0.01 + 1e-9
    assert all(valid(q) for q in res.path)


@settings(max_examples=30, deadline=None)
@given(
    ox=st.floats(1.0, 3.0),
    oy=st.floats(0.8, 2.2),
    oyaw=st.floats(-math.pi, math.pi),
    sx=st.floats(0.05, 0.8),
    sy=st.floats(0.05, 0.8),
    seed=st.integers(0, 2**16),
)
def test_occupancy_is_exact_at_lattice_states(ox, oy, oyaw, sx, sy, seed) -> None:
    """At lattice states near a box the rasterised occupancy says what coal says of the footprint and the
    box (both standing on the floor: the floor projection loses nothing), away from touching."""
    lattice = LatticePlanner(BOUNDS)
    obstacle = ("box", Box(sx, sy, 0.4), translation(ox, oy, 0.2) @ rot_z(oyaw))
    occupied = lattice.occupancy([(ROBOT, LIFT)], [obstacle])
    world = CollisionWorld()
    world.add("box", collision_shape(obstacle[1]), obstacle[2], "fixed")
    world.add("robot", collision_shape(ROBOT), np.eye(4), "robot")
    rng = np.random.default_rng(seed)
    for _ in range(60):
        k = int(rng.integers(lattice.yaws))
        i = int(np.clip((ox + rng.uniform(-0.9, 0.9) - BOUNDS[0]) / lattice.cell, 0, lattice.nx - 1))
        j = int(np.clip((oy + rng.uniform(-0.9, 0.9) - BOUNDS[2]) / lattice.cell, 0, lattice.ny - 1))
        world.set_transform("robot", se2(*lattice.state(k, i, j)) @ LIFT)
        gap = world.distance("box", "robot")
        if abs(gap) > 1e-5:
            assert bool(occupied[k, i, j]) == (gap < 0), (k, i, j, gap)
    assert occupied.any()


def test_hull2d() -> None:
    pts = np.random.default_rng(3).uniform(-1, 1, (200, 2))
    hull = hull2d(pts)
    e = np.roll(hull, -1, axis=0) - hull
    # counter-clockwise, and every point on the inner side of every edge
    cross = e[:, 0, None] * (pts[None, :, 1] - hull[:, 1, None]) - e[:, 1, None] * (pts[None, :, 0] - hull[:, 0, None])
    assert (cross >= -1e-12).all()
    assert {tuple(v) for v in hull} <= {tuple(p) for p in np.round(pts, 12)}


def test_interpolate_turns_the_short_way_and_keeps_steps_small() -> None:
    a, b = np.array([0.0, 0.0, 3.0]), np.array([0.05, 0.0, -3.0])
    states = interpolate(a, b, 0.01, 0.01)
    assert np.allclose(states[-1], [0.05, 0.0, -3.0])
    yaws = [a[2]] + [q[2] for q in states]
    assert max(abs(wrap_angle(v - u)) for u, v in zip(yaws, yaws[1:])) <= 0.01 + 1e-9
    assert len(states) == math.ceil((2 * math.pi - 6.0) / 0.01 - 1e-9)


def test_through_the_door_when_the_robot_fits() -> None:
    # the robot is 0.4 wide: a 0.46 m door leaves 3 cm each side
    start, goal = (1.0, 0.5, 0.0), (3.0, 2.5, 0.0)
    obstacles = wall_with_door(1.5, 0.46)
    res, valid = plan(obstacles, start, goal)
    assert_valid_path(res, np.array(start), np.array(goal), valid)
    assert any(abs(q[0] - 2.0) < 0.05 and 1.27 < q[1] < 1.73 for q in res.path)  # through the door
    again, _ = plan(obstacles, start, goal)
    assert len(again.path) == len(res.path) and all(np.array_equal(p, q) for p, q in zip(again.path, res.path))


def test_no_path_when_the_door_is_too_narrow() -> None:
    res, _ = plan(wall_with_door(1.5, 0.36), (1.0, 0.5, 0.0), (3.0, 2.5, 0.0))
    assert res.status is MotionStatus.NO_PATH


def test_turns_to_pass_a_door_narrower_than_its_length() -> None:
    """Carrying a box in front makes the robot 1 m long: it must face the door to pass it."""
    carried = (Box(0.3, 0.3, 0.2), translation(0.45, 0, 0.2))
    parts = [(ROBOT, LIFT), carried]
    start, goal = (1.0, 1.5, math.pi / 2), (3.0, 1.5, -math.pi / 2)  # facing along the wall at both ends
    res, valid = plan(wall_with_door(1.5, 0.6), start, goal, parts)
    assert_valid_path(res, np.array(start), np.array(goal), valid)


def test_start_and_goal_states_are_reported() -> None:
    obstacles = wall_with_door(1.5, 0.6)
    assert plan(obstacles, (2.0, 0.5, 0.0), (3.0, 1.5, 0.0))[0].status is MotionStatus.INVALID_START
    assert plan(obstacles, (1.0, 1.5, 0.0), (2.0, 2.5, 0.0))[0].status is MotionStatus.INVALID_GOAL


# ------------------------------------------------------------------ between the checked states
CARRIED = (Box(0.3, 0.3, 0.2), translation(0.45, 0, 0.2))


def clearance(obstacles: list[tuple[str, Box, np.ndarray]], parts: list[tuple[Box, np.ndarray]]):
    """``clear(q, margin)`` as grounding builds it (planar.grown parts), and the deepest overlap (m, >= 0)
    of the robot at q with an obstacle by coal's signed distance."""
    world = CollisionWorld()
    for name, shape, t in obstacles:
        world.add(name, collision_shape(shape), t, "fixed")
    for i, (shape, t) in enumerate(parts):
        world.add(f"part{i}", collision_shape(shape), t, "robot")

    def clear(q: np.ndarray, margin: float) -> bool:
        probe = [(grown(collision_shape(s), margin), se2(*q) @ t) for s, t in parts]
        return not world.probe_collides(probe, against="fixed")

    def overlap(q: np.ndarray) -> float:
        for i, (_, t) in enumerate(parts):
            world.set_transform(f"part{i}", se2(*q) @ t)
        return max(0.0, -min(world.distance(f"part{i}", name) for i in range(len(parts)) for name, _, _ in obstacles))

    return clear, overlap


def deepest_between(a: np.ndarray, b: np.ndarray, overlap, samples: int = 41) -> float:
    d = np.array([b[0] - a[0], b[1] - a[1], wrap_angle(b[2] - a[2])])
    return max(overlap(a + s * d) for s in np.linspace(0.0, 1.0, samples))


CORNER = [("wall", Box(0.1, 1.0, 0.5), translation(2.0, 0.5, 0.25))]  # its corner at (1.95, 1.0)


def test_two_free_states_can_hide_an_overlap_that_the_segment_test_finds() -> None:
    """The footprint slides past a wall corner: free at both states 1 cm apart (what a state-by-state test
    accepts), 3.9 mm deep in the wall between them (found by a search over random steps near the corner)."""
    clear, overlap = clearance(CORNER, [(ROBOT, LIFT)])
    a, b = np.array([1.692229, 1.181759, 0.037857]), np.array([1.701503, 1.191633, 0.044935])
    assert clear(a, 0.0) and clear(b, 0.0)
    assert deepest_between(a, b, overlap) > 3e-3
    assert not segment_clear(a, b, 0.33, clear)


@settings(max_examples=300, deadline=None)
@given(
    dx=st.floats(-0.012, 0.004),
    dy=st.floats(-0.012, 0.004),
    yaw=st.floats(-0.05, 0.05),
    step=st.tuples(st.floats(-0.003, 0.01), st.floats(-0.003, 0.01), st.floats(-0.01, 0.01)),
    carrying=st.booleans(),
)
def test_an_accepted_segment_overlaps_nothing_deeper_than_the_slack(dx, dy, yaw, step, carrying) -> None:
    """Random steps of the validator's size (1 cm, 0.01 rad) that take the robot's corner (or its load's)
    round a wall's corner, often cutting it between two free states: what segment_clear accepts overlaps
    the wall by at most SLACK anywhere between."""
    parts = [(ROBOT, LIFT), CARRIED] if carrying else [(ROBOT, LIFT)]
    reach = math.hypot(0.6, 0.15) if carrying else math.hypot(0.25, 0.2)
    corner = (1.95 - 0.6, 1.0 + 0.15) if carrying else (1.95 - 0.25, 1.0 + 0.2)
    clear, overlap = clearance(CORNER, parts)
    a = np.array([corner[0] + dx, corner[1] + dy, yaw])
    b = a + np.array(step)
    accepted, deepest = segment_clear(a, b, reach, clear), deepest_between(a, b, overlap)
    ends_free = clear(a, 0.0) and clear(b, 0.0)
    event(f"accepted {accepted}, ends free {ends_free}, overlap between {deepest > SLACK}")
    if accepted:
        assert deepest <= SLACK + 1e-6


def test_a_path_planned_with_a_clearance_test_keeps_clear_between_its_states() -> None:
    """Carrying a box through a door 0.6 m wide: the dense path's every motion, sampled 20 times finer,
    overlaps nothing deeper than SLACK."""
    parts = [(ROBOT, LIFT), CARRIED]
    obstacles = wall_with_door(1.5, 0.6)
    clear, overlap = clearance(obstacles, parts)
    lattice = LatticePlanner(BOUNDS)
    start, goal = np.array([1.0, 1.5, math.pi / 2]), np.array([3.0, 1.5, -math.pi / 2])
    res = lattice.plan(
        lattice.occupancy(parts, obstacles),
        start,
        goal,
        lambda q: clear(q, 0.0),
        0.01,
        0.01,
        clear,
        math.hypot(0.6, 0.15),
    )
    assert res.status is MotionStatus.SOLVED
    assert max(deepest_between(a, b, overlap, 21) for a, b in zip(res.path, res.path[1:])) <= SLACK + 1e-6


def _bfs_distance(free: np.ndarray, goals: list[tuple[int, int, int]], start: tuple[int, int, int]) -> int | None:
    """Moves from ``start`` to the nearest goal over free states, by a plain breadth-first search (the
    reference the packed search of ``LatticePlanner._wavefront`` is checked against)."""
    from collections import deque

    from mrgc.geometry.lattice import _MOVES

    yaws, nx, ny = free.shape
    dist = dict.fromkeys(goals, 0)
    queue = deque(goals)
    while queue:
        k, i, j = queue.popleft()
        for dk, di, dj in _MOVES:
            n = ((k + dk) % yaws, i + di, j + dj)
            if 0 <= n[1] < nx and 0 <= n[2] < ny and free[n] and n not in dist:
                dist[n] = dist[(k, i, j)] + 1
                queue.append(n)
    return dist.get(start)


@settings(max_examples=60, deadline=None)
@given(
    yaws=st.sampled_from([1, 3, 8, 13, 32, 64]),
    nx=st.integers(1, 14),
    ny=st.integers(1, 14),
    density=st.floats(0.0, 0.6),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_wavefront_finds_a_fewest_moves_path_over_free_states(
    yaws: int, nx: int, ny: int, density: float, seed: int
) -> None:
    """The lattice search (headings packed into the bits of a word) answers a path of lattice moves over
    free states from a start to a goal with as few moves as a plain breadth-first search finds, and None
    exactly when none connects; with 1 to 64 headings."""
    from mrgc.geometry.lattice import _MOVES

    rng = np.random.default_rng(seed)
    free = rng.random((yaws, nx, ny)) >= density
    cells = [tuple(int(v) for v in c) for c in np.argwhere(free)]
    if not cells:
        return
    goals = [cells[i] for i in rng.choice(len(cells), size=min(2, len(cells)), replace=False)]
    starts = [cells[i] for i in rng.choice(len(cells), size=min(2, len(cells)), replace=False)]
    lattice = LatticePlanner((0.0, float(nx), 0.0, float(ny)), cell=1.0, yaws=yaws)
    assert (lattice.yaws, lattice.nx, lattice.ny) == (yaws, nx, ny)
    path = lattice._wavefront(free, goals, starts)
    best = [d for d in (_bfs_distance(free, goals, s) for s in starts) if d is not None]
    event("connected" if best else "not connected")
    if not best:
        assert path is None
        return
    assert path is not None and path[0] in starts and path[-1] in goals
    assert len(path) - 1 == min(best)
    moves = {((dk % yaws), di, dj) for dk, di, dj in _MOVES}
    for a, b in zip(path, path[1:]):
        assert free[b] and ((b[0] - a[0]) % yaws, b[1] - a[1], b[2] - a[2]) in moves


def test_a_lattice_has_at_most_64_headings() -> None:
    """The search packs a cell's headings into one 64-bit word: more is a usage error."""
    import pytest

    with pytest.raises(ValueError, match="1 to 64 headings"):
        LatticePlanner(BOUNDS, yaws=65)
