"""RRTConnect through OMPL: a point through a gap in a wall, SE(2) around a wall, outcomes, determinism."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from mrgc.geometry.motion import MAX_CHECKS, MotionResult, MotionStatus, plan_joint_path

LOWER, UPPER = [0.0, 0.0], [1.0, 1.0]


def wall_with_gap(q: np.ndarray) -> bool:
    """The unit square with a wall at 0.45 <= x <= 0.55, open only for 0.45 < y < 0.55."""
    x, y = q
    return not (0.45 <= x <= 0.55 and not 0.45 < y < 0.55)


def check_path(result: MotionResult, start, goal, is_valid, step: float, yaw: bool = False) -> None:
    assert result.status is MotionStatus.SOLVED and result.solved
    path = np.array(result.path)
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    assert all(is_valid(q) for q in path)
    d = np.diff(path, axis=0)
    if yaw:
        d[:, 2] = (d[:, 2] + math.pi) % (2 * math.pi) - math.pi
        assert np.max(np.linalg.norm(d[:, :2], axis=1)) <= step + 1e-9
    else:
        assert np.max(np.linalg.norm(d, axis=1)) <= step + 1e-9


def test_point_through_the_gap() -> None:
    result = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], wall_with_gap, seed=1, resolution=0.01)
    check_path(result, [0.1, 0.1], [0.9, 0.9], wall_with_gap, 0.01)
    # it really went through the gap
    crossing = [q for q in result.path if 0.45 <= q[0] <= 0.55]
    assert crossing and all(0.45 < q[1] < 0.55 for q in crossing)


def test_every_checked_state_is_returned() -> None:
    calls: list[np.ndarray] = []

    def valid(q: np.ndarray) -> bool:
        calls.append(q)
        return wall_with_gap(q)

    result = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], valid, seed=3, resolution=0.02)
    assert result.solved
    assert all(isinstance(q, np.ndarray) and q.shape == (2,) for q in calls)
    checked = {tuple(np.round(q, 12)) for q in calls}
    assert all(tuple(np.round(q, 12)) in checked for q in result.path)


def test_invalid_start_and_goal() -> None:
    r = plan_joint_path(LOWER, UPPER, [0.5, 0.1], [0.9, 0.9], wall_with_gap)
    assert r.status is MotionStatus.INVALID_START and r.path == []
    r = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.5, 0.9], wall_with_gap)
    assert r.status is MotionStatus.INVALID_GOAL
    r = plan_joint_path(LOWER, UPPER, [1.5, 0.1], [0.9, 0.9], wall_with_gap)
    assert r.status is MotionStatus.INVALID_START


def test_enclosed_goal_is_no_path_after_the_budget() -> None:
    def boxed_in(q: np.ndarray) -> bool:  # a closed ring 0.1 thick around the goal at (0.8, 0.8)
        d = np.max(np.abs(q - 0.8))
        return not 0.1 <= d <= 0.2

    r = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.8, 0.8], boxed_in, max_checks=3000, seed=0)
    assert r.status is MotionStatus.NO_PATH and r.path == [] and not r.solved
    # it stopped because the budget was spent (overrunning it by at most one planner iteration)
    assert 3000 <= r.checks < 3000 + 500


def test_misuse_raises() -> None:
    with pytest.raises(ValueError):
        plan_joint_path([0, 0], [1, 1], [0.1], [0.9, 0.9], wall_with_gap)
    with pytest.raises(ValueError):
        plan_joint_path([0, 0], [1, 1], [0.1, 0.1], [0.9, 0.9], wall_with_gap, resolution=0)
    with pytest.raises(ValueError):
        plan_joint_path([0, 0], [1, 1], [0.1, 0.1], [0.9, 0.9], wall_with_gap, max_checks=0)


def test_exceptions_in_the_validity_test_propagate() -> None:
    def broken(q: np.ndarray) -> bool:
        if 0.4 < q[0] < 0.6:  # start and goal are fine: it raises inside OMPL's solve
            raise RuntimeError("bug in the checker")
        return True

    with pytest.raises(RuntimeError, match="bug in the checker"):
        plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], broken)


def test_same_seed_same_path_and_other_seed_other_path() -> None:
    def run(seed: int) -> list[np.ndarray]:
        r = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], wall_with_gap, seed=seed)
        assert r.solved
        return r.path

    a, b, c = run(7), run(7), run(8)
    assert len(a) == len(b) and all(np.array_equal(p, q) for p, q in zip(a, b))
    assert len(a) != len(c) or not all(np.array_equal(p, q) for p, q in zip(a, c))
    # seed 0 is deterministic too (OMPL itself ignores a zero seed)
    z1, z2 = run(0), run(0)
    assert len(z1) == len(z2) and all(np.array_equal(p, q) for p, q in zip(z1, z2))


def slowed(is_valid, pause: float):  # type: ignore[no-untyped-def]
    """``is_valid``, taking ``pause`` seconds longer per call (as on a machine busy with other work)."""

    def valid(q: np.ndarray) -> bool:
        end = time.perf_counter() + pause
        while time.perf_counter() < end:
            pass
        return is_valid(q)

    return valid


def same_result(a: MotionResult, b: MotionResult) -> bool:
    return (
        a.status is b.status
        and a.checks == b.checks
        and len(a.path) == len(b.path)
        and all(np.array_equal(p, q) for p, q in zip(a.path, b.path))
    )


def test_no_clock_decides_a_result() -> None:
    """A validity test 50 times slower (as on a loaded machine) changes no result: the budget counts checks,
    and a wall-clock limit between the two solves' durations (15 ms and 0.5 s) would have decided differently."""

    def maze(q: np.ndarray) -> bool:  # three walls with gaps at alternating ends
        x, y = q
        return not any(
            abs(x - w) < 0.02 and (y < 0.9 if k % 2 == 0 else y > 0.1) for k, w in enumerate((0.25, 0.5, 0.75))
        )

    for budget in (400, 5000):
        fast = plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], maze, max_checks=budget, seed=5, resolution=0.01)
        slow = plan_joint_path(
            LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], slowed(maze, 2e-4), max_checks=budget, seed=5, resolution=0.01
        )
        assert same_result(fast, slow), (budget, fast.status, slow.status, fast.checks, slow.checks)
    assert not plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], maze, max_checks=400, seed=5).solved
    assert fast.solved and same_result(
        fast, plan_joint_path(LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], maze, seed=5, resolution=0.01)
    )  # the default budget MAX_CHECKS
    assert fast.checks < MAX_CHECKS


def test_seven_joints() -> None:
    lo, hi = -np.pi * np.ones(7), np.pi * np.ones(7)

    def valid(q: np.ndarray) -> bool:  # a slab in joint 0 with a window where joint 1 is near 0
        return not (abs(q[0]) < 0.2 and abs(q[1]) > 0.3)

    start, goal = np.full(7, -2.0), np.full(7, 2.0)
    r = plan_joint_path(lo, hi, start, goal, valid, seed=2, resolution=0.05)
    check_path(r, start, goal, valid, 0.05)
    simple = plan_joint_path(lo, hi, start, goal, valid, seed=2, resolution=0.05, simplify=True)
    check_path(simple, start, goal, valid, 0.05)


@pytest.mark.parametrize("budget", [150, 400, 5000, MAX_CHECKS])
@pytest.mark.parametrize("seed", [0, 5, 11])
def test_motions_checked_in_batches_give_the_same_results(budget: int, seed: int) -> None:
    """geometry/motion.py: with ``all_valid`` the states inside a motion are checked in one batch; the status,
    the path (bit for bit) and the count of checks are those of OMPL's own motion validator, with budgets that
    stop the search and budgets that do not, and the batch is asked of a whole motion at a time."""

    def maze(q: np.ndarray) -> bool:
        x, y = q
        return not any(
            abs(x - w) < 0.02 and (y < 0.9 if k % 2 == 0 else y > 0.1) for k, w in enumerate((0.25, 0.5, 0.75))
        )

    batches: list[int] = []

    def all_valid(states: np.ndarray) -> bool:
        batches.append(len(states))
        return all(maze(q) for q in states)

    args = (LOWER, UPPER, [0.1, 0.1], [0.9, 0.9], maze)
    one = plan_joint_path(*args, max_checks=budget, seed=seed, resolution=0.01)
    batched = plan_joint_path(*args, max_checks=budget, seed=seed, resolution=0.01, all_valid=all_valid)
    assert same_result(one, batched), (one.status, batched.status, one.checks, batched.checks)
    assert batches and max(batches) > 1
