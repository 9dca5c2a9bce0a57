"""Motion planning on OMPL: RRTConnect (the paper's BiRRT) in joint space and in SE(2).

Both planners take a validity test on plain numpy states, a time limit and a seed, and return a
:class:`MotionResult` whose ``status`` says what happened; not finding a path is an outcome, not an error.
The returned path is *dense*: consecutive states are at most ``resolution`` apart (joint space: Euclidean
distance in radians/metres; SE(2): ``resolution`` metres of translation and ``yaw_resolution`` radians of
turn), and every returned state is one that OMPL's motion validator checked with ``is_valid``.

Paths are not simplified unless asked (``simplify=True``): shortcutting costs 5–15× the solve (DESIGN §6).
The same seed gives the same path when the solve finishes within its time limit.  OMPL's console output is
silenced.
"""

from __future__ import annotations

import enum
import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

Validity = Callable[[np.ndarray], bool]


class MotionStatus(str, enum.Enum):
    SOLVED = "solved"
    NO_PATH = "no-path"              # no exact solution within the time limit
    INVALID_START = "invalid-start"  # the start is out of bounds or fails is_valid
    INVALID_GOAL = "invalid-goal"    # the goal is out of bounds or fails is_valid


@dataclass(frozen=True)
class MotionResult:
    """What a planner found: ``path`` (start first, goal last) is empty unless ``status`` is SOLVED."""

    status: MotionStatus
    path: list[np.ndarray] = field(default_factory=list)
    planning_time: float = 0.0

    @property
    def solved(self) -> bool:
        return self.status is MotionStatus.SOLVED


_quiet = False


def _ompl() -> tuple[Any, Any, Any]:
    global _quiet
    from ompl import base as ob, geometric as og, util as ou

    if not _quiet:
        ou.setLogLevel(ou.LogLevel.LOG_NONE)
        _quiet = True
    return ob, og, ou


def _seed(ou: Any, seed: int) -> None:
    # OMPL ignores a seed of 0 (and then samples nondeterministically), so shift every seed by one.
    ou.RNG.setSeed(int(seed) % (2**31 - 2) + 1)


def plan_joint_path(lower: Sequence[float], upper: Sequence[float], start: Sequence[float],
                    goal: Sequence[float], is_valid: Validity, time_limit: float = 1.0, seed: int = 0,
                    resolution: float = 0.05, simplify: bool = False) -> MotionResult:
    """A collision-free path in the box ``lower <= q <= upper`` from ``start`` to ``goal`` (RRTConnect).

    ``is_valid(q)`` gets a fresh float array of the joint values; ``resolution`` is the largest step
    between checked (and returned) states along a motion, in joint units.
    """
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    q0, q1 = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    n = len(lo)
    if n == 0 or lo.shape != (n,) or hi.shape != (n,) or q0.shape != (n,) or q1.shape != (n,):
        raise ValueError(f"bounds, start and goal must be 1-D of one length (got {lo.shape}, {hi.shape}, "
                         f"{q0.shape}, {q1.shape})")
    if np.any(hi < lo) or resolution <= 0 or time_limit <= 0:
        raise ValueError("need lower <= upper, resolution > 0 and time_limit > 0")
    if np.any(q0 < lo) or np.any(q0 > hi) or not is_valid(q0.copy()):
        return MotionResult(MotionStatus.INVALID_START)
    if np.any(q1 < lo) or np.any(q1 > hi) or not is_valid(q1.copy()):
        return MotionResult(MotionStatus.INVALID_GOAL)

    ob, og, ou = _ompl()
    _seed(ou, seed)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(lo[i]))
        bounds.setHigh(i, float(hi[i]))
    space.setBounds(bounds)
    index = range(n)

    def check(state: Any) -> bool:
        return bool(is_valid(np.fromiter((state[i] for i in index), float, n)))

    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(check)
    extent = space.getMaximumExtent()
    setup.getSpaceInformation().setStateValidityCheckingResolution(min(1.0, resolution / extent)
                                                                   if extent > 0 else 1.0)
    s, g = space.allocState(), space.allocState()
    for i in index:
        s[i], g[i] = float(q0[i]), float(q1[i])
    setup.setStartAndGoalStates(s, g)

    def read(state: Any) -> np.ndarray:
        return np.fromiter((state[i] for i in index), float, n)

    return _solve(og, setup, time_limit, simplify, read)


def plan_se2_path(bounds: Sequence[float], start: Sequence[float], goal: Sequence[float], is_valid: Validity,
                  time_limit: float = 1.0, seed: int = 0, resolution: float = 0.02,
                  yaw_resolution: float = 0.05, simplify: bool = False) -> MotionResult:
    """A collision-free path of a planar pose (x, y, yaw) within ``bounds`` = (xmin, xmax, ymin, ymax).

    ``is_valid`` gets ``np.array([x, y, yaw])``; yaw is in radians, in [-π, π) on the returned path, and
    turns the short way round.  ``resolution`` (metres) and ``yaw_resolution`` (radians) bound the step
    between checked (and returned) states.
    """
    xmin, xmax, ymin, ymax = (float(b) for b in bounds)
    p0, p1 = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    if p0.shape != (3,) or p1.shape != (3,):
        raise ValueError("start and goal are (x, y, yaw)")
    if not (xmin < xmax and ymin < ymax) or resolution <= 0 or yaw_resolution <= 0 or time_limit <= 0:
        raise ValueError("need xmin < xmax, ymin < ymax, resolutions > 0 and time_limit > 0")
    p0[2], p1[2] = _wrap(p0[2]), _wrap(p1[2])

    def inside(p: np.ndarray) -> bool:
        return xmin <= p[0] <= xmax and ymin <= p[1] <= ymax

    if not inside(p0) or not is_valid(p0.copy()):
        return MotionResult(MotionStatus.INVALID_START)
    if not inside(p1) or not is_valid(p1.copy()):
        return MotionResult(MotionStatus.INVALID_GOAL)

    ob, og, ou = _ompl()
    _seed(ou, seed)
    space = ob.SE2StateSpace()
    box = ob.RealVectorBounds(2)
    box.setLow(0, xmin)
    box.setHigh(0, xmax)
    box.setLow(1, ymin)
    box.setHigh(1, ymax)
    space.setBounds(box)

    def check(state: Any) -> bool:
        return bool(is_valid(np.array([state.getX(), state.getY(), state.getYaw()])))

    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(check)
    setup.getSpaceInformation().setStateValidityCheckingResolution(0.01)
    # per-component resolutions (they survive setup()): translation in metres, rotation in radians
    space.getSubspace(0).setLongestValidSegmentFraction(
        min(1.0, resolution / space.getSubspace(0).getMaximumExtent()))
    space.getSubspace(1).setLongestValidSegmentFraction(min(1.0, yaw_resolution / math.pi))
    s, g = space.allocState(), space.allocState()
    for state, p in ((s, p0), (g, p1)):
        state.setX(float(p[0]))
        state.setY(float(p[1]))
        state.setYaw(float(p[2]))
    setup.setStartAndGoalStates(s, g)

    def read(state: Any) -> np.ndarray:
        return np.array([state.getX(), state.getY(), state.getYaw()])

    return _solve(og, setup, time_limit, simplify, read)


def _solve(og: Any, setup: Any, time_limit: float, simplify: bool,
           read: Callable[[Any], np.ndarray]) -> MotionResult:
    setup.setPlanner(og.RRTConnect(setup.getSpaceInformation()))
    t0 = time.perf_counter()
    setup.solve(float(time_limit))
    if not setup.haveExactSolutionPath():
        return MotionResult(MotionStatus.NO_PATH, [], time.perf_counter() - t0)
    if simplify:
        setup.simplifySolution()
    path = setup.getSolutionPath()
    path.interpolate()  # exactly the states the discrete motion validator checked
    states = [read(path.getState(i)) for i in range(path.getStateCount())]
    return MotionResult(MotionStatus.SOLVED, states, time.perf_counter() - t0)


def _wrap(angle: float) -> float:
    """``angle`` in [-π, π)."""
    return (float(angle) + math.pi) % (2 * math.pi) - math.pi
