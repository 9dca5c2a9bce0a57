"""Continuous collision checking of one phase of a replay: nothing passes between two checked samples.

A phase is a set of motions that share the time ``s`` in [0, 1], each linear between its configurations
(:mod:`mrgc.validator.sampling`).  The bodies it moves are checked pairwise; each *pair* (a robot against an
object, a robot against itself at two links, a held object against another robot ...) is made of
*sub-pairs*, one for each two links whose distance pybullet reports.  Between two breakpoints (where some
motion passes one of its configurations) every joint moves at a constant speed, so every point of a link
moves at most at a constant *rate* (:mod:`mrgc.validator.bounds`): the rate of a sub-pair is the sum
of its two sides' rates (for two links of one arm, only the joints that move one of them and not the
other count).

**Conservative advancement.**  When a sub-pair is checked at time ``s`` and found ``d`` apart, it cannot
overlap by more than the collision tolerance ``tol`` before its two sides together may have moved
``d + tol``: its *budget*.  The sweep checks every pair at ``s = 0``, then moves time on to the first
moment a budget runs out, checks the pairs whose budget ran out there (and only them) at that time, and so
on to ``s = 1``.  So every sub-pair's distance is known, with a bound, at every time of the phase, and an
overlap deeper than ``tol`` between two checked samples is impossible: the check is continuous, not
sampled.  A pair farther apart than :data:`CAP` is checked as if it were :data:`CAP` away (pybullet is not
asked about more distant points).  A pair already overlapping, or within :data:`MIN_BUDGET` of the
tolerance, is given a budget of :data:`MIN_BUDGET`, and one deeper than ``tol`` one of :data:`FLOOR`
(to find how deep it goes): there, and only there, an overlap between samples may exceed the tolerance
by at most that budget.

Everything the sweep needs from the world comes through callables: ``set_state(s)`` (put every moving body
where it is at time ``s``), ``query(p, s)`` (the distances of pair ``p``'s links now) and ``report(p, sub, d,
s)`` (a sub-pair of ``p`` that is checked then overlaps by more than the tolerance: ``d`` < -tol; links the
pair does not list are never reported; from its ``until`` on, a sub-pair may overlap ``slack`` more).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

CAP = 0.5  # m: pybullet is asked for distances up to this; a pair farther away counts as this far
BATCH = 1.0  # when the world is set for a pair that is due, the pairs due within this share of the last step join it
MIN_BUDGET = 1e-4  # m: the smallest budget of a pair at or near the tolerance
FLOOR = 5e-4  # m: the budget of a pair overlapping deeper than the tolerance (its deepest point is sought)
FAR = 0.02  # m: a due pair whose lower bounds give every sub-pair this much budget is not asked of pybullet


@dataclass
class Pair:
    """One pair of bodies to keep apart during a phase.  ``subs``: the (link of a, link of b) keys of its
    sub-pairs as the query reports them; ``coeffs`` (len(subs), columns): each sub-pair's rate is
    ``coeffs @ speeds`` (the phase's joint speeds, see :class:`Sweep`); ``until`` (len(subs),): the time
    from which a sub-pair may overlap ``slack`` (len(subs),, m) more than the tolerance (a gripper in its
    pick's contact segment may reach as deep into the object as it stands at the grasp; inf: not checked
    then at all)."""

    subs: list[tuple[int, int]]
    coeffs: np.ndarray
    until: np.ndarray = field(default_factory=lambda: np.zeros(0))
    slack: np.ndarray = field(default_factory=lambda: np.zeros(0))


class Sweep:
    """The conservative-advancement sweep of one phase (module docstring).

    ``breakpoints``: sorted times from 0 to 1 between which speeds are constant (every configuration of
    every motion, and every ``until``); ``speeds(k)``: the absolute speeds (columns of the pairs'
    ``coeffs``) on ``[breakpoints[k], breakpoints[k + 1]]``; ``tol``: the collision tolerance (m);
    ``max_events``: a sweep needing more checked times stops (``exhausted``)."""

    def __init__(
        self,
        breakpoints: np.ndarray,
        speeds: Callable[[int], np.ndarray],
        pairs: Sequence[Pair],
        set_state: Callable[[float], None],
        query: Callable[[int, float], dict[tuple[int, int], float]],
        report: Callable[[int, tuple[int, int], float, float], None],
        tol: float,
        max_events: int,
    ) -> None:
        self.breakpoints = breakpoints
        self.speeds = speeds
        self.pairs = pairs
        self.set_state = set_state
        self.query = query
        self.report = report
        self.tol = tol
        self.max_events = max_events
        #: times at which the world was set and pairs were asked
        self.events = 0
        #: pybullet queries made (pairs asked)
        self.queries = 0
        #: whether the sweep stopped at max_events before s = 1
        self.exhausted = False
        self.stop: Callable[[], bool] = lambda: False
        #: optional: lower bounds on every sub-pair's distance (in the order of ``pairs``) at the state the world
        #: was last set to, computed without pybullet's distance queries (see :meth:`_bounded`)
        self.bound: Callable[[], np.ndarray] | None = None

    def run(self) -> None:
        """Sweep the phase from s = 0 to 1.  Each sub-pair keeps the time its budget runs out at the
        current rates (``due``), each pair the earliest of its sub-pairs'; at a breakpoint the budgets left
        are carried over to the next interval's rates."""
        if not self.pairs:
            return
        sizes = [len(p.subs) for p in self.pairs]
        self._start = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        self._local = [{sub: int(self._start[i]) + k for k, sub in enumerate(p.subs)} for i, p in enumerate(self.pairs)]
        self._subs = [sub for p in self.pairs for sub in p.subs]
        coeffs = np.concatenate([p.coeffs for p in self.pairs], axis=0)
        until = np.concatenate([p.until if len(p.until) else np.full(len(p.subs), np.inf) for p in self.pairs])
        slack = np.concatenate([p.slack if len(p.slack) else np.zeros(len(p.subs)) for p in self.pairs])
        self._pair_of = pair_of = np.repeat(np.arange(len(self.pairs)), sizes)
        n = len(pair_of)
        self._due = np.zeros(n)  # when each sub-pair's budget runs out
        self._budget = np.zeros(n)  # its budget when it was last checked or carried over
        self._since = np.zeros(n)  # ... and the time of that
        self._pdue = np.zeros(len(self.pairs))
        self._far = np.ones(len(self.pairs), dtype=bool)  # pairs the lower bounds kept far when last computed
        self._asked = np.zeros(n)  # each sub-pair's budget from pybullet's distance when it was last asked
        bp = self.breakpoints
        need: np.ndarray = np.arange(len(self.pairs))
        s = 0.0
        for k in range(len(bp) - 1):
            a, b = float(bp[k]), float(bp[k + 1])
            self._rate = coeffs @ self.speeds(k)
            self._extra = np.where(until <= a + 1e-12, slack, 0.0)  # overlap allowed beyond the tolerance
            self._off = np.isinf(self._extra)
            self._rate[self._off] = 0.0
            self._fresh = np.where(self._off, np.inf, CAP + self.tol)  # the budget of a sub-pair not reported
            if k:  # carry the budgets left over into this interval's rates
                self._budget = np.where(self._off, np.inf, self._left(a))
                self._since[:] = a
                self._renew()
            s, last = a, a
            while True:
                if len(need):
                    if self.events >= self.max_events:
                        self.exhausted = True
                        return
                    self._check(s, need)
                    if self.stop():
                        return
                nxt = float(self._pdue.min())
                if nxt >= b:
                    break
                nxt = max(nxt, s + 1e-12)
                window = nxt + BATCH * (nxt - last)
                last, s = nxt, nxt
                need = np.flatnonzero(self._pdue <= window)
            need = need[:0]
            self._budget = self._left(b)
            self._since[:] = b
        done = self._budget <= 1e-12
        if done.any():
            self._check(1.0, np.unique(pair_of[done]))

    def _left(self, at: float) -> np.ndarray:
        """Each sub-pair's budget left at time ``at`` of the current interval."""
        left: np.ndarray = np.maximum(self._budget - self._rate * (at - self._since), 0.0)
        return left

    def _renew(self, subs: np.ndarray | slice = slice(None)) -> None:
        """Recompute the due times of sub-pairs ``subs`` (all by default) and every pair's."""
        rate = self._rate[subs]
        with np.errstate(divide="ignore", invalid="ignore"):
            self._due[subs] = np.where(rate > 0, self._since[subs] + self._budget[subs] / rate, np.inf)
        self._pdue = np.minimum.reduceat(self._due, self._start[:-1])

    def _check(self, s: float, need: np.ndarray) -> None:
        """Set the world at time ``s``, ask the pairs ``need`` and renew their sub-pairs' budgets."""
        self.set_state(s)
        self.events += 1
        bounded = self.bound is not None and bool(self._far[need].any())
        if bounded:
            need = self._bounded(s, need)
        budget, since, fresh, start = self._budget, self._since, self._fresh, self._start
        found: dict[int, float] = {}
        for i in need.tolist():
            lo, hi = int(start[i]), int(start[i + 1])
            budget[lo:hi] = fresh[lo:hi]
            since[lo:hi] = s
            local = self._local[i]
            for sub, d in self.query(i, s).items():
                j = local.get(sub)
                if j is not None:
                    found[j] = d
        self.queries += len(need)
        off, extra, tol = self._off, self._extra, self.tol
        bad = []
        for j, d in found.items():
            if off[j]:
                continue
            allowed = tol + float(extra[j])
            if d < -allowed:
                budget[j] = FLOOR
                bad.append(j)
            else:
                budget[j] = max(min(d, CAP) + allowed, MIN_BUDGET)
        for j in sorted(bad):
            self.report(int(self._pair_of[j]), self._subs[j], found[j], s)
        if self.bound is not None and len(need):
            asked = self._subs_of(need)
            self._asked[asked] = budget[asked]
        if bounded or len(need) > 8:
            self._renew()
        else:
            for i in need.tolist():
                lo, hi = int(start[i]), int(start[i + 1])
                rate = self._rate[lo:hi]
                with np.errstate(divide="ignore", invalid="ignore"):
                    due = np.where(rate > 0, s + budget[lo:hi] / rate, np.inf)
                self._due[lo:hi] = due
                self._pdue[i] = due.min()

    def _subs_of(self, pairs: np.ndarray) -> np.ndarray:
        """The sub-pairs of ``pairs``."""
        asked = np.zeros(len(self.pairs), dtype=bool)
        asked[pairs] = True
        out: np.ndarray = np.flatnonzero(asked[self._pair_of])
        return out

    def _bounded(self, s: float, need: np.ndarray) -> np.ndarray:
        """Renew every sub-pair's budget from the lower bounds at time ``s`` where they give more than is
        left of it (a lower bound ``lb`` on a distance is as good a start as the distance: the sub-pair cannot
        overlap by more than the tolerance before its sides have moved ``lb`` + tolerance); the pairs of
        ``need`` that are still to be asked: those with a sub-pair whose budget is now less than :data:`FAR`
        or less than half what pybullet's distance gave it when the pair was last asked (the bound is loose
        there; asking gives it a longer step)."""
        assert self.bound is not None
        lb = np.minimum(self.bound(), CAP)
        self._budget = np.maximum(self._left(s), np.where(self._off, np.inf, lb + self.tol + self._extra))
        self._since[:] = s
        near = self._budget < FAR
        self._far = np.maximum.reduceat(near.astype(np.int8), self._start[:-1]) == 0
        short = near | (self._budget < 0.5 * self._asked)
        ask = np.maximum.reduceat(short.astype(np.int8), self._start[:-1]) > 0
        out: np.ndarray = need[ask[need]]
        return out
