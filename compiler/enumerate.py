"""Skeleton enumeration: distinct skeletons in (makespan, moved objects) order, resumable.

"Distinct" means a different *set of actions*: after each skeleton a cut excludes its action set at every
horizon (a cut on the schedule would only exclude one ordering of the same plan).  For horizon-loop
encodings the horizon grows T = T0, T0+1, ... up to the limit, carrying the cuts into each new model; a
model of horizon T yields skeletons with exactly T non-empty steps, cheapest first.  A time-of-move model
covers every makespan up to its horizon; it too is solved one horizon at a time unless its solver says
otherwise (``grow_horizon``): since its objective ranks makespan first, the model of horizon T yields the
skeletons of makespan T once those of smaller makespans are used up (its infeasibility moves T on), the same
keys in the same order as one model up to the limit, from a model whose bounds are tight (6-arm, 40-object
packaging: 0.16 s per skeleton instead of 5 s with CP-SAT, docs/compiler.md).  ``next(k)`` returns the next
k skeletons and keeps the solver, the horizon and the cuts, so asking again continues where it stopped.
Each solution is given first in its preferred form (grasps in declared order among interchangeable actions,
compiler/grasp_order.py) and, when that differs, in the solver's own form when the solver returns it again.

Beyond the paper, actions may be *deferred* (:meth:`SkeletonGenerator.defer`; the planner defers an action
whose grounding keeps failing): the skeletons that hold none of them come first, and when those are used
up the deferral is lifted and enumeration goes on from the first horizon with every cut kept, so no
skeleton is lost, only later (the (makespan, moved) order then holds within each part).  A lifted action is
*released*: it is not deferred again, but actions deferred after the lift are kept back as before (until
session 29 one lift ended deferral for good: on the 6-arm instance of seed 2 the root's source lifted its
first deferral at once, an action every skeleton holds, and the actions deferred later kept coming, one of
them in 11 of 52 failed groundings).  Each lift releases at least one action, so enumeration still ends.
"""

from __future__ import annotations

import enum
import math
import time
from dataclasses import dataclass, field
from typing import Callable, Iterable

from mrgc.compiler.diagnose import prune
from mrgc.compiler.encodings.base import Encoded, Encoding
from mrgc.compiler.grasp_order import preferred
from mrgc.compiler.ir import Row, Solver, SolveStatus
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action, TaskGraph


class BatchOutcome(enum.StrEnum):
    """Why :meth:`SkeletonGenerator.next` stopped: outcomes are values, not exceptions."""

    #: the skeletons asked for were found (more may exist)
    ENOUGH = "enough"
    #: every skeleton within the horizon limit has been returned
    EXHAUSTED = "exhausted"
    TIME_LIMIT = "time limit"
    #: the solver failed (its message says how)
    ERROR = "error"


@dataclass
class Batch:
    """What one call of :meth:`SkeletonGenerator.next` produced."""

    skeletons: list[Skeleton]
    outcome: BatchOutcome
    message: str = ""
    stats: dict[str, float] = field(default_factory=dict)


class SkeletonGenerator:
    """Enumerates the skeletons of ``graph`` with ``encoding``, solving with solvers from ``make_solver``;
    ``grow_horizon``: an encoding without a horizon loop is solved one horizon at a time all the same
    (module docstring), else in one model up to the limit."""

    def __init__(
        self,
        graph: TaskGraph,
        encoding: Encoding,
        make_solver: Callable[[], Solver],
        max_makespan: int | None = None,
        grow_horizon: bool = True,
    ) -> None:
        self.graph = prune(graph)
        self.encoding = encoding
        #: one model per horizon T0, T0 + 1, ... (else one model of horizon ``limit``)
        self.loop = encoding.horizon_loop or grow_horizon
        self.make_solver = make_solver
        # a skeleton moves each object at most once and at least one per step: no makespan exceeds the
        # number of objects, so a larger limit changes nothing but the size of time-indexed models
        complete = max(1, len(graph.objects))
        self.limit = min(max_makespan, complete) if max_makespan is not None else complete
        self.horizon = first_horizon(self.graph)
        self.first_horizon = self.horizon
        self.found: list[frozenset[int]] = []
        self.given: set[frozenset[int]] = set()  # the same action sets, to look up
        #: actions (indices) kept out of the skeletons until the others are used up; then ``released``
        self.deferred: set[int] = set()
        #: actions (indices) whose deferral was lifted: never deferred again
        self.released: set[int] = set()
        self.solver: Solver | None = None
        self.encoded: Encoded | None = None
        self.done = False
        self.trivial = not graph.must_move  # nothing to move: the empty skeleton is the one plan
        self.stats: dict[str, float] = {"solves": 0, "solve_seconds": 0.0, "build_seconds": 0.0, "models": 0}

    def _cuts(self, enc: Encoded) -> list[Row]:
        cuts = [enc.cut(s, name=f"cut{i}") for i, s in enumerate(self.found)]
        return cuts + _out(enc, self.deferred)

    def defer(self, actions: Iterable[Action]) -> None:
        """Keep ``actions`` (those of this graph; others are ignored) out of the skeletons given next, until
        no other skeleton is left; no effect on an action released before (its deferral lifted) or once
        enumeration is over."""
        if self.done:  # between calls ``done`` means enumeration is over: nothing to reorder
            return
        index = {a: i for i, a in enumerate(self.graph.actions)}
        new = {index[a] for a in actions if a in index} - self.deferred - self.released
        if not new:
            return
        self.deferred |= new
        if self.solver is not None and self.encoded is not None:
            self.solver.add_rows(_out(self.encoded, new))

    def _used_up(self) -> bool:
        """Whether enumeration is over; when only the deferred actions' skeletons are left, the deferral
        is lifted (its actions released) and enumeration starts again at the first horizon, with the cuts."""
        if not self.deferred:
            return True
        self.released |= self.deferred
        self.deferred = set()
        self.horizon, self.solver, self.done = self.first_horizon, None, False
        return False

    def _preferred(self, skel: Skeleton, chosen: frozenset[int]) -> tuple[Skeleton, frozenset[int]]:
        """The solution's preferred form (its actions' grasps in declared order, compiler/grasp_order.py)
        when that action set has not been given yet, else the solution as it is.  Only the action set given
        is cut: the solver's own form, when it differs, comes again later and is given then, so enumeration
        still gives every action set once, in the same (makespan, moved) order."""
        swap = preferred(self.graph, chosen, self.deferred)
        best = frozenset(swap.values())
        if best == chosen or best in self.given:
            return skel, chosen
        actions = self.graph.actions
        by = {actions[i]: actions[j] for i, j in swap.items()}
        return Skeleton(tuple(tuple(by[a] for a in step) for step in skel.steps)), best

    def _load(self) -> None:
        t0 = time.perf_counter()
        self.encoded = self.encoding.build(self.graph, self.horizon if self.loop else self.limit)
        self.solver = self.make_solver()
        self.solver.load(self.encoded.model)
        cuts = self._cuts(self.encoded)
        if cuts:
            self.solver.add_rows(cuts)
        self.stats["build_seconds"] += time.perf_counter() - t0
        self.stats["models"] += 1

    def next(self, k: int, deadline: float | None = None) -> Batch:
        """Up to ``k`` further skeletons, in (makespan, moved) order (after a :meth:`defer`, within the
        skeletons without the deferred actions, then within the others).  ``deadline``: a
        ``time.perf_counter()`` instant (None: none), the one deadline type the planner passes down; each
        solve is given the seconds left, the unit of the solvers' own time limits."""
        out: list[Skeleton] = []
        if self.trivial and not self.done:
            self.done = True
            return Batch([Skeleton(())] if k > 0 else [], BatchOutcome.EXHAUSTED, stats=dict(self.stats))
        while len(out) < k:
            if (self.done or self.horizon > self.limit) and self._used_up():
                self.done = True
                return Batch(out, BatchOutcome.EXHAUSTED, stats=dict(self.stats))
            if self.solver is None:
                self._load()
            assert self.solver is not None and self.encoded is not None
            left = None if deadline is None else deadline - time.perf_counter()
            if left is not None and left <= 0:
                return Batch(out, BatchOutcome.TIME_LIMIT, stats=dict(self.stats))
            sol = self.solver.solve(left)
            self.stats["solves"] += 1
            self.stats["solve_seconds"] += sol.seconds
            if sol.status == SolveStatus.OPTIMAL:
                skel = self.encoded.decode(sol.values)
                chosen = frozenset(i for i, v in enumerate(self.encoded.select) if sol.values[v])
                skel, chosen = self._preferred(skel, chosen)
                self.found.append(chosen)
                self.given.add(chosen)
                self.solver.add_rows([self.encoded.cut(chosen, name=f"cut{len(self.found) - 1}")])
                out.append(skel)
            elif sol.status == SolveStatus.INFEASIBLE:
                if not self.loop:
                    self.done = True
                    continue
                self.horizon += 1
                self.solver = None
            elif sol.status in (SolveStatus.TIME_LIMIT, SolveStatus.FEASIBLE):
                return Batch(out, BatchOutcome.TIME_LIMIT, sol.message, stats=dict(self.stats))
            else:
                return Batch(out, BatchOutcome.ERROR, sol.message, stats=dict(self.stats))
        return Batch(out, BatchOutcome.ENOUGH, stats=dict(self.stats))


def first_horizon(graph: TaskGraph) -> int:
    """A lower bound on the makespan of every skeleton of ``graph`` (at least 1), where the horizon loop
    starts: each step moves at most one object per robot, so at least ``|M*| / |R|`` steps; and a robot does
    one action per step, so at least as many steps as M* has objects that only actions of that robot move
    (on the PA presets the arm that reaches the start region takes part in every move: the bound is 3
    instead of 2 on most PA10 instances, a model load and an infeasible solve fewer)."""
    robots = max(1, len(graph.robots))
    bound = math.ceil(len(graph.must_move) / robots)
    movable = [graph.actions_of(o) for o in graph.must_move if graph.actions_of(o)]
    for r in graph.robots:
        bound = max(bound, sum(all(r in graph.actions[i].robots for i in acts) for acts in movable))
    return max(1, bound)


def _out(enc: Encoded, actions: Iterable[int]) -> list[Row]:
    """Rows keeping each of ``actions`` out of the skeleton (its selection literal 0)."""
    return [Row(((enc.select[i], 1),), hi=0, name=f"defer{i}") for i in sorted(actions)]
