"""Certifying a phase free of collisions, fast: bounds at many times at once, pybullet only where they fail.

The sweep of :mod:`mrgc.validator.sweep` walks a phase's time forward one checked time after another, setting
the pybullet world at each.  Most phases of a valid plan have nothing to report, and this module proves
that for a whole phase with far fewer pybullet calls; a phase it cannot prove clear (an overlap, or a pair
within :data:`~mrgc.validator.sweep.MIN_BUDGET` of the tolerance, or too many times needed) is then swept by
:mod:`mrgc.validator.sweep`, which finds and reports what is there.  So violations still come from the sweep
and pybullet's distances alone; this module only decides that there is none.

**Certifying an interval.**  For a sub-pair (two links, a link and an object, ...) and an interval
``[t0, t1]`` of the phase's time inside one stretch of constant joint speeds, let ``v0`` and ``v1`` be lower
bounds of its distance at ``t0`` and ``t1`` and ``D`` a bound on how far its two sides together can move
over the interval (each side's points, each chain joint's turn times the largest distance of those points
from the joint's axis over the interval; a motion of ``x`` of it over ``[t0, s]`` and ``D - x`` over
``[s, t1]``).  At every time between, the distance is at least ``max(v0 - x, v1 - (D - x))``, so at least
``m = max((v0 + v1 - D) / 2, max(v0, v1) - D)``; the interval is *certified* when ``m >= -allowed`` (the
collision tolerance, plus the pair's slack there).  Two-sided, an interval may be about twice as long as a
conservative-advancement step from one end.

**Where the bounds come from** (the phase's ``bounds``, :class:`~mrgc.validator.phase_bounds.PhaseBounds`):
at any times, the validator's numpy kinematics (:mod:`mrgc.validator.fk`) give lower bounds on every
sub-pair's distance (spheres about links, boxes about objects that stand still) and, per link, its largest
distance from each joint's axis (motion spheres); over an interval the latter grows at most by what the
joints beyond that joint move it, so ``D`` is bounded from the interval's ends, never above the global bound
of :mod:`mrgc.validator.bounds`.  Where a lower bound is weak (under :data:`FAR` of budget, or the
interval would need many pieces), pybullet is asked for the pair's distances at that time (the world set
there once for every pair asked then); an interval still not certified is cut in 2^k equal pieces (times
on a dyadic grid of its stretch, so that pairs share them) and the pieces are certified in turn.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from mrgc.validator.sweep import CAP, MIN_BUDGET, Pair

FAR = 0.02  # m: an end whose lower bound leaves less budget than this is asked of pybullet
MANY = 32  # an interval that lower bounds alone would cut in more pieces than this asks pybullet at its ends
SHARE = 0.6  # an interval is cut in the power of 2 next above this share of the pieces its ends' budgets need
MOST = 64  # pieces an interval is cut in at once, at most
GRID = 1 << 36  # dyadic steps of a stretch of constant speeds: times are stretch start + width * m / GRID


@dataclass
class Phase:
    """What the certifier knows of a phase.  ``breakpoints`` (K + 1,) and ``speeds`` (K, C): constant
    absolute speeds per stretch; ``pairs``: the sweep's pairs (sub-pairs, until, slack);
    ``ends`` (S, 2): each sub-pair's two *elements* (rows of ``rows``); ``sides`` (S, 2, C): which columns
    count for each side (0 or 1: for two links of one arm only the joints that move one and not the other);
    ``rows`` (E, C): each element's global rate per unit of each column's speed; ``bounds(times)``: lower
    bounds of every sub-pair's distance (T, S) and each element's rate at those times (T, E, C), at most
    ``rows``; ``set_state(s)``, ``query(p)``: the world at time ``s`` and pair ``p``'s distances there."""

    breakpoints: np.ndarray
    speeds: np.ndarray
    pairs: Sequence[Pair]
    ends: np.ndarray
    sides: np.ndarray
    rows: np.ndarray
    bounds: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    set_state: Callable[[float], None]
    query: Callable[[int], dict[tuple[int, int], float]]
    #: two links of one arm: the first joint between them (column; -1: none or not such a pair) and the
    #: upstream link's largest distance from that joint's axis, which is fixed in its frame (see _reach)
    first: np.ndarray | None = None
    first_rate: np.ndarray | None = None


def interval_rate(rows: np.ndarray, start: np.ndarray, end: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Rates (N, C) of elements over intervals: ``rows`` their global rates, ``start`` and ``end`` their rates
    at the interval's ends (a link's points' largest distance from each joint's axis), ``dq`` each column's
    motion over the interval (columns in chain order, an arm's joints from its base).  A point's distance
    from joint ``c``'s axis changes only as the joints beyond ``c`` move it in ``c``'s frame, at most by
    ``sum_{c' > c} rows[c'] dq[c']`` over the interval, so the rate at either end grown by that bounds it
    throughout; never above the global rate."""
    moved = rows * dq
    beyond = np.cumsum(moved[:, ::-1], axis=1)[:, ::-1] - moved
    out: np.ndarray = np.minimum(rows, np.minimum(start, end) + beyond)
    return out


class _Unsure(Exception):
    """The phase cannot be certified: the sweep decides."""


class Certifier:
    """Certify a :class:`Phase` (module docstring): :meth:`run` is True when no sub-pair overlaps by more
    than its allowance anywhere in the phase, False when that could not be shown (then sweep it).
    ``max_times``: the times asked of pybullet at most (then False)."""

    def __init__(self, phase: Phase, tol: float, max_times: int) -> None:
        self.ph, self.tol, self.max_times = phase, tol, max_times
        pairs = phase.pairs
        sizes = [len(p.subs) for p in pairs]
        self.start = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        self.local = [{sub: int(self.start[i]) + k for k, sub in enumerate(p.subs)} for i, p in enumerate(pairs)]
        self.pair_of = np.repeat(np.arange(len(pairs)), sizes)
        self.until = np.concatenate([p.until if len(p.until) else np.full(len(p.subs), np.inf) for p in pairs])
        self.slack = np.concatenate([p.slack if len(p.slack) else np.zeros(len(p.subs)) for p in pairs])
        self.n = len(self.pair_of)
        bp = phase.breakpoints
        inner = self.until[(self.until > bp[0]) & (self.until < bp[-1])]
        cuts = np.unique(np.concatenate([bp[:1], inner, bp[-1:]]))  # sections: the slack changes only at their ends
        self.a, self.w = cuts[:-1], np.diff(cuts)
        k = len(self.a)
        extra = np.where(self.until[None, :] <= self.a[:, None] + 1e-12, self.slack[None, :], 0.0)
        self.allowed = tol + extra  # (sections, S); inf: not checked in that section
        # each column's motion from the phase's start to each breakpoint (its total variation)
        steps = phase.speeds * np.diff(bp)[:, None]
        self.moved = np.concatenate([np.zeros((1, steps.shape[1])), np.cumsum(steps, axis=0)])
        self.known = np.zeros(0, dtype=np.int64)  # keys of the times evaluated (stretch * (GRID + 1) + step), sorted
        self.known_rows = np.zeros(0, dtype=np.int64)  # ... and their rows
        self.times = np.zeros(0)
        self.value = np.zeros((0, self.n))  # best lower bound of each sub-pair's distance at each time
        self.exact = np.zeros((0, self.n), dtype=bool)  # ... and whether it is pybullet's distance
        self.rate = np.zeros((0,) + phase.rows.shape)
        self.asked = 0  # times the world was set and pybullet asked
        self.k = k

    # ------------------------------------------------------------------ times
    def _rows(self, ks: np.ndarray, ms: np.ndarray) -> np.ndarray:
        """The rows of times (stretch ``ks``, grid steps ``ms``), evaluating the bounds at new ones (a
        stretch's end is the next one's start)."""
        end = (ms == GRID) & (ks + 1 < self.k)
        keys = np.where(end, (ks + 1) * (GRID + 1), ks * (GRID + 1) + ms)
        where = np.searchsorted(self.known, keys)
        hit = where < len(self.known)
        hit[hit] = self.known[where[hit]] == keys[hit]
        if not hit.all():
            new = np.unique(keys[~hit])
            k, m = new // (GRID + 1), new % (GRID + 1)
            t = np.minimum(self.a[k] + self.w[k] * (m / GRID), self.ph.breakpoints[-1])
            lb, rate = self.ph.bounds(t)
            base = len(self.times)
            self.times = np.concatenate([self.times, t])
            self.value = np.concatenate([self.value, lb])
            self.exact = np.concatenate([self.exact, np.zeros(lb.shape, dtype=bool)])
            self.rate = np.concatenate([self.rate, rate])
            known = np.concatenate([self.known, new])
            rows = np.concatenate([self.known_rows, base + np.arange(len(new))])
            order = np.argsort(known, kind="stable")
            self.known, self.known_rows = known[order], rows[order]
            where = np.searchsorted(self.known, keys)
        out: np.ndarray = self.known_rows[where]
        return out

    # ------------------------------------------------------------------ the run
    def run(self) -> bool:
        """Certify the phase (class docstring)."""
        ks, js = np.nonzero(np.isfinite(self.allowed))
        if not len(ks):
            return True
        m0, m1 = np.zeros(len(ks), dtype=np.int64), np.full(len(ks), GRID, dtype=np.int64)
        try:
            while len(ks):
                ks, js, m0, m1 = self._round(ks, js, m0, m1)
        except _Unsure:
            return False
        return True

    def _round(
        self, ks: np.ndarray, js: np.ndarray, m0: np.ndarray, m1: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One round over the open intervals (stretch, sub-pair, grid steps): drop the certified, ask pybullet
        at the ends of those whose bounds are weak, cut the others; the intervals left open."""
        i0, i1 = self._rows(ks, m0), self._rows(ks, m1)
        dq = self._moved(self.times[i1]) - self._moved(self.times[i0])
        allowed = self.allowed[ks, js]
        v0, v1 = self.value[i0, js], self.value[i1, js]
        reach = self._reach(js, i0, i1, dq)
        low = np.maximum(0.5 * (v0 + v1 - reach), np.maximum(v0, v1) - reach)
        open_ = low < -allowed
        if not open_.any():
            return ks[:0], js[:0], m0[:0], m1[:0]
        ks, js, m0, m1, i0, i1 = ks[open_], js[open_], m0[open_], m1[open_], i0[open_], i1[open_]
        v0, v1, allowed, reach = v0[open_], v1[open_], allowed[open_], reach[open_]
        e0, e1 = v0 + allowed, v1 + allowed
        x0, x1 = self.exact[i0, js], self.exact[i1, js]
        if ((x0 & (e0 < MIN_BUDGET)) | (x1 & (e1 < MIN_BUDGET))).any():
            raise _Unsure  # an overlap, or a pair at the tolerance: the sweep follows it
        least = np.maximum(np.minimum(e0, e1), 1e-9)
        pieces = reach / (2 * least)
        many = pieces > MANY
        ask0, ask1 = ~x0 & (many | (e0 < FAR)), ~x1 & (many | (e1 < FAR))
        if ask0.any() or ask1.any():
            self._ask(np.concatenate([i0[ask0], i1[ask1]]), np.concatenate([js[ask0], js[ask1]]))
            keep = ask0 | ask1  # asked now: judged again next round
        else:
            keep = np.zeros(len(ks), dtype=bool)
        cut = ~keep
        parts = [(ks[keep], js[keep], m0[keep], m1[keep])]
        if cut.any():
            parts.append(self._cut(ks[cut], js[cut], m0[cut], m1[cut], pieces[cut]))
        return tuple(np.concatenate(x) for x in zip(*parts))  # type: ignore[return-value]

    def _moved(self, t: np.ndarray) -> np.ndarray:
        """Each column's motion (T, C) from the phase's start to times ``t``."""
        bp = self.ph.breakpoints
        k = np.clip(np.searchsorted(bp, t, side="right") - 1, 0, len(bp) - 2)
        out: np.ndarray = self.moved[k] + self.ph.speeds[k] * (t - bp[k])[:, None]
        return out

    def _reach(self, js: np.ndarray, i0: np.ndarray, i1: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """How far the two sides of sub-pairs ``js`` can move together over their intervals (rows ``i0`` to
        ``i1``, joint motions ``dq``): each side's rate at the ends (its points' largest distance from each
        joint's axis), grown by what the joints beyond each joint can move it over the interval, never above
        its global rate.  Two links A (upstream) and B of one arm, with the chain joints c1 < c2 < ... between
        them: seen from the link that joint c1 turns, A turns about c1's axis, fixed in A's frame, and B moves
        by c2, ...; so c1's rate may be A's points' largest distance from that axis instead of B's, whichever
        is less (:attr:`Phase.first_rate`)."""
        ends, sides, rows = self.ph.ends[js], self.ph.sides[js], self.ph.rows
        combined = np.zeros(dq.shape)
        for side in (0, 1):
            e = ends[:, side]
            combined += sides[:, side] * interval_rate(rows[e], self.rate[i0, e], self.rate[i1, e], dq)
        if self.ph.first is not None and self.ph.first_rate is not None:
            first = self.ph.first[js]
            k = np.flatnonzero(first >= 0)
            combined[k, first[k]] = np.minimum(combined[k, first[k]], self.ph.first_rate[js[k]])
        out: np.ndarray = (combined * dq).sum(axis=1)
        return out

    def _ask(self, rows: np.ndarray, subs: np.ndarray) -> None:
        """Ask pybullet for the pairs of sub-pairs ``subs`` at time rows ``rows`` (each time set once)."""
        many = len(self.ph.pairs)  # (time row, pair) pairs as one key each: np.unique(axis=0) loads numpy.ma
        key = np.unique(rows.astype(np.int64) * many + self.pair_of[subs])
        want = np.stack([key // many, key % many], axis=1)
        times = np.unique(want[:, 0])
        if self.asked + len(times) > self.max_times:
            raise _Unsure
        self.asked += len(times)
        start, value, exact, local = self.start, self.value, self.exact, self.local
        cuts = np.flatnonzero(np.diff(want[:, 0])) + 1
        for group in np.split(want, cuts):
            row = int(group[0, 0])
            self.ph.set_state(float(self.times[row]))
            for p in group[:, 1].tolist():
                lo, hi = int(start[p]), int(start[p + 1])
                np.maximum(value[row, lo:hi], CAP, out=value[row, lo:hi])
                exact[row, lo:hi] = True
                lookup = local[p]
                for sub, d in self.ph.query(p).items():
                    j = lookup.get(sub)
                    if j is not None:
                        value[row, j] = d

    def _cut(
        self, ks: np.ndarray, js: np.ndarray, m0: np.ndarray, m1: np.ndarray, pieces: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Intervals cut in 2^k equal pieces, for ``pieces`` times :data:`SHARE` (at least 2, at most
        :data:`MOST`)."""
        n = 2 ** np.clip(np.ceil(np.log2(np.maximum(pieces * SHARE, 2.0))), 1, np.log2(MOST)).astype(np.int64)
        span = m1 - m0
        if (span < n).any():
            raise _Unsure  # the grid is exhausted (2^-36 of a stretch): the sweep decides
        idx = np.repeat(np.arange(len(ks)), n)
        within = np.arange(len(idx)) - np.repeat(np.cumsum(n) - n, n)
        lo = m0[idx] + (span[idx] * within) // n[idx]
        hi = m0[idx] + (span[idx] * (within + 1)) // n[idx]
        return ks[idx], js[idx], lo, hi
