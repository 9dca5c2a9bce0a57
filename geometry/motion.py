"""Motion planning on OMPL: RRTConnect (the paper's BiRRT) in joint space (planar robots' base paths are
searched on a lattice instead: :mod:`mrgc.geometry.lattice`).

The planner takes a validity test on plain numpy states, a budget of validity checks and a seed, and
return a :class:`MotionResult` whose ``status`` says what happened; not finding a path is an outcome, not
an error.
The returned path is *dense*: consecutive states are at most ``resolution`` apart (joint space: Euclidean
distance in radians/metres), and every returned state is one that OMPL's motion validator checked with ``is_valid``.

Paths are not simplified unless asked (``simplify=True``): shortcutting costs 5–15× the solve (DESIGN §6).

Determinism: no clock is read to decide anything, except the run's ``deadline`` (a ``time.perf_counter()``
value): past it a solve stops with status ``TIME_LIMIT`` (the planner then ends its search; an answer the
deadline cut is never used as a result).  A solve stops when RRTConnect connects its trees or
when it has made ``max_checks`` calls to ``is_valid`` (an OMPL ``PlannerTerminationCondition`` on a
counter, evaluated by the planner between iterations, so a solve may overrun the budget by the checks of
one iteration); OMPL's random generator is seeded per call.  The same inputs and seed therefore give the
same result and the same path on an idle or a loaded machine.  ``planning_time`` is for statistics only.
OMPL's console output is silenced.
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

Validity = Callable[[np.ndarray], bool]
#: a validity test of many states at once ((k, n) array): True when every one of them is valid
BatchValidity = Callable[[np.ndarray], bool]
#: joint values (bounds, configurations): a sequence of floats or a 1-D array
Vector = Sequence[float] | np.ndarray

#: default budget of one solve: calls to the validity test before RRTConnect gives up (no path)
#: (docs/geometry.md, "Motion planning").
MAX_CHECKS = 20_000


class MotionStatus(str, enum.Enum):
    """How a motion-planning query ended."""

    SOLVED = "solved"
    NO_PATH = "no-path"  # no exact solution within the budget of validity checks
    INVALID_START = "invalid-start"  # the start is out of bounds or fails is_valid
    INVALID_GOAL = "invalid-goal"  # the goal is out of bounds or fails is_valid
    TIME_LIMIT = "time-limit"  # the run's deadline passed during the solve


@dataclass(frozen=True)
class MotionResult:
    """What a planner found: ``path`` (start first, goal last) is empty unless ``status`` is SOLVED;
    ``checks``: calls the solve made to the validity test; ``planning_time``: seconds (statistics only)."""

    status: MotionStatus
    path: list[np.ndarray] = field(default_factory=list)
    planning_time: float = 0.0
    checks: int = 0

    @property
    def solved(self) -> bool:
        """Whether ``path`` holds a path."""
        return self.status is MotionStatus.SOLVED


_quiet = False


def _ompl() -> tuple[Any, Any, Any]:
    global _quiet
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    if not _quiet:
        ou.setLogLevel(ou.LogLevel.LOG_NONE)
        _quiet = True
    return ob, og, ou


def _seed(ou: Any, seed: int) -> None:
    # OMPL ignores a seed of 0 (and then samples nondeterministically), so shift every seed by one.
    ou.RNG.setSeed(int(seed) % (2**31 - 2) + 1)


def plan_joint_path(
    lower: Vector,
    upper: Vector,
    start: Vector,
    goal: Vector,
    is_valid: Validity,
    max_checks: int = MAX_CHECKS,
    seed: int = 0,
    resolution: float = 0.05,
    simplify: bool = False,
    deadline: float | None = None,
    all_valid: BatchValidity | None = None,
) -> MotionResult:
    """A collision-free path in the box ``lower <= q <= upper`` from ``start`` to ``goal`` (RRTConnect).

    ``is_valid(q)`` gets a fresh float array of the joint values; ``resolution`` is the largest step
    between checked (and returned) states along a motion, in joint units.  ``deadline`` (a
    ``time.perf_counter()`` value): the solve stops there with status ``TIME_LIMIT``.  ``all_valid`` (the
    same test of many states in one call, when cheaper per state): the states between a motion's ends are
    then checked in one batch (:class:`_EdgeBatches`), with the same answers, paths and check counts.
    """
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    q0, q1 = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    n = len(lo)
    if n == 0 or lo.shape != (n,) or hi.shape != (n,) or q0.shape != (n,) or q1.shape != (n,):
        raise ValueError(
            f"bounds, start and goal must be 1-D of one length (got {lo.shape}, {hi.shape}, {q0.shape}, {q1.shape})"
        )
    if np.any(hi < lo) or resolution <= 0 or max_checks < 1:
        raise ValueError("need lower <= upper, resolution > 0 and max_checks >= 1")
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
    budget = _Budget(max_checks, deadline)

    def check(state: Any) -> bool:
        budget.used += 1
        return bool(is_valid(np.fromiter((state[i] for i in index), float, n)))

    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(check)
    extent = space.getMaximumExtent()
    setup.getSpaceInformation().setStateValidityCheckingResolution(min(1.0, resolution / extent) if extent > 0 else 1.0)
    if all_valid is not None and not simplify:  # (the simplifier asks motions for their last valid state)
        si = setup.getSpaceInformation()
        si.setMotionValidator(_edge_batches(ob, si, space, n, is_valid, all_valid, budget))
    s, g = space.allocState(), space.allocState()
    for i in index:
        s[i], g[i] = float(q0[i]), float(q1[i])
    setup.setStartAndGoalStates(s, g)

    def read(state: Any) -> np.ndarray:
        return np.fromiter((state[i] for i in index), float, n)

    return _solve(ob, og, setup, budget, simplify, read)


def _edge_batches(
    ob: Any, si: Any, space: Any, n: int, is_valid: Validity, all_valid: BatchValidity, budget: _Budget
) -> Any:
    """An OMPL motion validator that answers as OMPL's ``DiscreteMotionValidator`` does, with the states
    between a motion's ends checked in one batch (see :class:`_EdgeBatches`)."""

    class _EdgeBatches(ob.MotionValidator):  # type: ignore[misc]
        """``checkMotion(s1, s2)`` as OMPL's discrete validator: ``s2`` first, then the states at ``k / nd``
        of the way (``nd`` = the space's valid segment count), middles first, breadth first, stopping at the
        first invalid one; ``s1`` is valid (the tree's).  Here the middle states are checked in one
        ``all_valid`` call; only when one of them is invalid are they checked again one by one in OMPL's
        order, so that the budget counts exactly the checks OMPL would have made (and the same solve ends
        at the same iteration).  The states are interpolated with OMPL's formula (``a + (b - a) * t``)."""

        def checkMotion(self, s1: Any, s2: Any) -> bool:  # noqa: N802 (OMPL's name)
            q1 = np.fromiter((s1[i] for i in range(n)), float, n)
            q2 = np.fromiter((s2[i] for i in range(n)), float, n)
            budget.used += 1
            if not is_valid(q2.copy()):
                return False
            nd = int(space.validSegmentCount(s1, s2))
            if nd < 2:
                return True
            ts = np.array([k / nd for k in _bisection_order(nd)])
            states = q1[None] + (q2 - q1)[None] * ts[:, None]
            if all_valid(states):
                budget.used += len(states)
                return True
            for q in states:
                budget.used += 1
                if not is_valid(q.copy()):
                    return False
            return False  # (the batch found a collision the single checks did not: kept invalid)

    return _EdgeBatches(si)


def _bisection_order(nd: int) -> list[int]:
    """The order OMPL's discrete motion validator checks the states ``1 .. nd - 1`` of a motion in: the
    middle of each interval first, intervals breadth first (a queue)."""
    out: list[int] = []
    queue = [(1, nd - 1)]
    while queue:
        lo, hi = queue.pop(0)
        mid = (lo + hi) // 2
        out.append(mid)
        if lo < mid:
            queue.append((lo, mid - 1))
        if hi > mid:
            queue.append((mid + 1, hi))
    return out


class _Budget:
    """Validity checks allowed (``limit``) and made so far (``used``) by one solve, and the run's deadline
    (``late`` once it has passed)."""

    __slots__ = ("limit", "used", "deadline", "late")

    def __init__(self, limit: int, deadline: float | None = None) -> None:
        self.limit, self.used = int(limit), 0
        self.deadline, self.late = deadline, False

    def spent(self) -> bool:
        if self.deadline is not None and not self.late and time.perf_counter() > self.deadline:
            self.late = True
        return self.late or self.used >= self.limit


def _solve(
    ob: Any, og: Any, setup: Any, budget: _Budget, simplify: bool, read: Callable[[Any], np.ndarray]
) -> MotionResult:
    setup.setPlanner(og.RRTConnect(setup.getSpaceInformation()))
    t0 = time.perf_counter()  # statistics only: the budget is counted in validity checks
    # evaluated by the planner itself, between iterations (no watcher thread: no period argument)
    setup.solve(ob.PlannerTerminationCondition(budget.spent))
    if budget.late:
        return MotionResult(MotionStatus.TIME_LIMIT, [], time.perf_counter() - t0, budget.used)
    if not setup.haveExactSolutionPath():
        return MotionResult(MotionStatus.NO_PATH, [], time.perf_counter() - t0, budget.used)
    if simplify:
        setup.simplifySolution()  # shortcuts until no improvement: no time limit
    path = setup.getSolutionPath()
    path.interpolate()  # exactly the states the discrete motion validator checked
    states = [read(path.getState(i)) for i in range(path.getStateCount())]
    return MotionResult(MotionStatus.SOLVED, states, time.perf_counter() - t0, budget.used)
