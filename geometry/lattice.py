"""Base paths of planar robots on an SE(2) lattice: deterministic and complete at the lattice's resolution.

A sampling planner with a budget of validity checks (RRTConnect, :func:`~mrgc.geometry.motion.plan_se2_path`)
answers "no path" for a cart carrying a box through a doorway it fits through whenever the budget runs out
first; the answer then depends on the budget, not on the scene.  This module answers the same queries by
search on a lattice of base poses, which finds a path whenever one exists among the lattice's states:

- **States.**  Cell centres of a grid of side :data:`CELL` over the bounds × :data:`YAWS` headings
  (multiples of 2π / YAWS).  Moves: to the 8 neighbouring cells at the same heading, or one heading step
  (either way, wrapping).
- **Occupancy (the approximation).**  The robot is its parts (the footprint and, when carrying, the carried
  object), each projected on the floor to the convex hull of its outline; an obstacle likewise.  A state is
  occupied when some part's hull, turned to the state's heading and put at the cell centre, overlaps an
  obstacle whose height range meets the part's: the Minkowski difference of the two hulls, rasterised at
  cell centres (numpy; per obstacle and heading, cached).  Projecting to the floor over-approximates; sampling
  at cell centres under-approximates between centres.
- **Search.**  A breadth-first wavefront from the goal (vectorised over the whole lattice, stopped as soon as
  it reaches the start or stops growing), then descent from the start.  The start and goal poses join the
  lattice through their nearest free states, each join checked.
- **The exact check decides.**  Every motion of the returned path (joins, lattice moves) is checked with
  the caller's exact validity test at the caller's resolution; a move that fails removes its end state and
  the search is repeated (at most :data:`REPAIRS` times).  Then the path is shortened greedily (straight
  shortcuts, each checked the same way).  So a returned path is valid by the exact test at every state of
  the dense path returned; "no path" means no path through the lattice's states (up to the repairs).
- **Between the checked states** (when the caller gives a clearance test, as grounding does).  The robot
  moves on a straight line in (x, y, yaw) from state a to state b; a point of it at distance at most
  ``reach`` from the base origin then travels at most ``L = |Δxy| + reach·|Δyaw|`` (the translation plus
  the arc of the turn), so at every moment each of its points lies within ``L/2`` of where it was at a or
  at b: the robot between a and b lies inside the union of the robot at a and at b, each grown
  horizontally by ``L/2``.  With the validator's 1 cm / 0.01 rad steps and a cart reaching 0.7 m (its
  load in front) that is 8.5 mm, and a state-by-state test let a drive home graze a wall corner by
  2.4 mm between two states that were both free.  So a motion is accepted segment by segment (consecutive
  states of the dense path): a segment whose two ends are clear by ``L/2`` (the caller's ``clear(q,
  margin)``: the robot's parts grown horizontally by the margin collide with nothing) is free throughout;
  otherwise it is halved (``L`` halves) until the ends are clear by the half's ``L/2``, or until
  ``L/2`` ≤ :data:`SLACK`, where ends free by the exact test bound any overlap between them by SLACK
  (0.25 mm, below the validator's 1 mm contact tolerance).  Only segments that pass within ``L/2`` of an
  obstacle cost more than one test per state.

Everything is deterministic: no random numbers, and no clock but the run's ``deadline`` (a
``time.perf_counter()`` value, :meth:`LatticePlanner.plan`): past it every test fails and the answer is
``TIME_LIMIT``, never used as a result.  The count of exact checks is reported in
:class:`~mrgc.geometry.motion.MotionResult` like the sampling planner's.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable, Hashable, Sequence, Union

import numpy as np

from mrgc.geometry.collision import CollisionShape
from mrgc.geometry.conventions import wrap_angle
from mrgc.geometry.motion import MotionResult, MotionStatus
from mrgc.geometry.scene import hull2d, outline
from mrgc.language.model import Shape

#: lattice cell side (m) and number of headings (at most :data:`MAX_YAWS`)
CELL = 0.05
YAWS = 32
#: the search packs a cell's headings into the bits of one 64-bit word (:meth:`LatticePlanner._wavefront`)
MAX_YAWS = 64
#: searches repeated after an exact check rejected a lattice move
REPAIRS = 12
#: lattice states tried to join the start (and the goal) to the lattice
JOINS = 12
#: the deepest overlap (m) with an obstacle that a motion accepted with a clearance test may hide between
#: its tested states (module docstring, "Between the checked states"); margins are rounded up to multiples
SLACK = 2.5e-4

Validity = Callable[[np.ndarray], bool]
#: ``clear(q, margin)``: the robot at base pose q, its parts grown horizontally by ``margin`` (m), is free
Clearance = Callable[[np.ndarray, float], bool]
#: a body for the lattice: a shape (or an (N, 3) array of points whose hull it is) at a transform (world for
#: obstacles, base frame for robot parts)
Body = Union[Shape, CollisionShape, np.ndarray]
Placed = tuple[Body, np.ndarray]
# 8 moves in the plane and the two turns, as (dk, di, dj)
_MOVES = [(0, di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0)] + [(1, 0, 0), (-1, 0, 0)]


_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)


def box_corners(shape: CollisionShape, grow: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The 8 corners of a collision shape's bounding box, in the shape's frame (the box grown by ``grow``
    along x, y, z)."""
    corners: np.ndarray = shape.center + _SIGNS * (shape.half + np.asarray(grow, dtype=float))
    return corners


def _footprint(body: Placed) -> tuple[np.ndarray, float, float]:
    """A body's floor hull and height range (a collision shape by the corners of its bounding box, an array
    as the points it holds)."""
    shape, t = body
    if isinstance(shape, np.ndarray):  # points in the body's frame
        local = shape
    elif isinstance(shape, CollisionShape):
        local = box_corners(shape)
    else:
        local = outline(shape)
    pts = local @ t[:3, :3].T + t[:3, 3]
    return hull2d(pts[:, :2]), float(pts[:, 2].min()), float(pts[:, 2].max())


def _normals(poly: np.ndarray) -> np.ndarray:
    """Edge normals of a convex polygon (any orientation; for a degenerate one, the coordinate axes)."""
    if len(poly) < 3:
        return np.eye(2)
    e = np.roll(poly, -1, axis=0) - poly
    return np.stack([-e[:, 1], e[:, 0]], axis=1)


def interpolate(a: np.ndarray, b: np.ndarray, resolution: float, yaw_resolution: float) -> list[np.ndarray]:
    """The states of the straight motion from ``a`` to ``b`` (yaw the short way round), ``a`` excluded, ``b``
    included, no step longer than the resolutions."""
    d = np.array([b[0] - a[0], b[1] - a[1], wrap_angle(b[2] - a[2])])
    n = max(1, math.ceil(math.hypot(d[0], d[1]) / resolution - 1e-9), math.ceil(abs(d[2]) / yaw_resolution - 1e-9))
    return [np.array([a[0] + d[0] * s, a[1] + d[1] * s, wrap_angle(a[2] + d[2] * s)]) for s in np.arange(1, n + 1) / n]


def travel(a: np.ndarray, b: np.ndarray, reach: float) -> float:
    """The farthest (m) a point within ``reach`` of the base origin moves on the straight motion from base
    pose ``a`` to ``b`` (yaw the short way round), bounded by the translation plus the arc of the turn."""
    return math.hypot(float(b[0] - a[0]), float(b[1] - a[1])) + reach * abs(wrap_angle(float(b[2] - a[2])))


def segment_clear(a: np.ndarray, b: np.ndarray, reach: float, clear: Clearance, slack: float = SLACK) -> bool:
    """Whether the straight motion from ``a`` to ``b`` is free throughout, up to overlaps of ``slack``:
    both ends clear by half the :func:`travel`, else the halves, recursively (module docstring)."""
    todo = [(a, b)]
    while todo:
        p, q = todo.pop()
        margin = math.ceil(travel(p, q, reach) / 2 / slack - 1e-9) * slack
        if margin <= slack:
            if clear(p, 0.0) and clear(q, 0.0):
                continue
            return False
        if clear(p, margin) and clear(q, margin):
            continue
        if not (clear(p, 0.0) and clear(q, 0.0)):
            return False
        d = np.array([q[0] - p[0], q[1] - p[1], wrap_angle(q[2] - p[2])])
        mid = p + d / 2
        mid[2] = wrap_angle(mid[2])
        todo += [(mid, q), (p, mid)]
    return True


class _Checks:
    """The exact tests of one :meth:`LatticePlanner.plan`: states by ``valid``, motions state by state at
    the resolutions, or segment by segment when a clearance test is given (:func:`segment_clear`, its
    answers remembered); ``count`` counts the tests made."""

    def __init__(
        self,
        valid: Validity,
        clear: Clearance | None,
        reach: float,
        resolution: float,
        yaw_resolution: float,
        deadline: float | None = None,
    ) -> None:
        self.valid, self.clear, self.reach = valid, clear, reach
        self.resolution, self.yaw_resolution = resolution, yaw_resolution
        self.count = 0
        self._clear: dict[tuple[bytes, float], bool] = {}
        self.deadline, self.late = deadline, False

    def past(self) -> bool:
        """Whether the run's deadline has passed (then every test fails: the answer is TIME_LIMIT)."""
        if self.deadline is not None and not self.late and time.perf_counter() > self.deadline:
            self.late = True
        return self.late

    def state(self, q: np.ndarray) -> bool:
        """``valid(q)``, counted."""
        self.count += 1
        return not self.past() and bool(self.valid(q.copy()))

    def _free(self, q: np.ndarray, margin: float) -> bool:
        assert self.clear is not None
        if self.past():
            return False
        key = (q.tobytes(), margin)
        if key not in self._clear:
            self.count += 1
            self._clear[key] = bool(self.clear(q.copy(), margin))
        return self._clear[key]

    def motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight motion from ``a`` (already tested) to ``b`` passes."""
        states = interpolate(a, b, self.resolution, self.yaw_resolution)
        if self.clear is None:
            return all(self.state(q) for q in states)
        return all(segment_clear(p, q, self.reach, self._free) for p, q in zip([a, *states], states))


class LatticePlanner:
    """Base paths of one planar robot within ``bounds`` = (xmin, xmax, ymin, ymax) (see the module docstring).

    Occupancy is cached per (robot parts key, obstacle key): callers pass keys that change when the parts
    (what is carried, how) or an obstacle's pose change.
    """

    def __init__(self, bounds: Sequence[float], cell: float = CELL, yaws: int = YAWS) -> None:
        self.xmin, xmax, self.ymin, ymax = (float(b) for b in bounds)
        if not 1 <= int(yaws) <= MAX_YAWS:
            raise ValueError(f"a lattice has 1 to {MAX_YAWS} headings, not {yaws}")
        self.cell, self.yaws = float(cell), int(yaws)
        self.nx = max(1, int(math.floor((xmax - self.xmin) / cell)))
        self.ny = max(1, int(math.floor((ymax - self.ymin) / cell)))
        self.headings = np.arange(self.yaws) * (2 * math.pi / self.yaws)
        self._blocks: dict[tuple[Hashable, Hashable], list[tuple[int, int, np.ndarray]]] = {}

    # ------------------------------------------------------------------------------------ lattice states
    def state(self, k: int, i: int, j: int) -> np.ndarray:
        """The base pose ``(x, y, yaw)`` of lattice state ``(k, i, j)``: heading ``k``, cell ``(i, j)``."""
        return np.array(
            [self.xmin + (i + 0.5) * self.cell, self.ymin + (j + 0.5) * self.cell, wrap_angle(self.headings[k])]
        )

    def _near(self, q: np.ndarray) -> list[tuple[int, int, int]]:
        """Lattice states near ``q``, nearest first (position, then heading)."""
        fi, fj = (q[0] - self.xmin) / self.cell - 0.5, (q[1] - self.ymin) / self.cell - 0.5
        fk = (q[2] % (2 * math.pi)) / (2 * math.pi / self.yaws)
        out = []
        for i in range(math.floor(fi) - 1, math.floor(fi) + 3):
            for j in range(math.floor(fj) - 1, math.floor(fj) + 3):
                if not (0 <= i < self.nx and 0 <= j < self.ny):
                    continue
                for k in (math.floor(fk), math.floor(fk) + 1):
                    dk = min(abs(fk - k), self.yaws - abs(fk - k))
                    out.append((math.hypot(fi - i, fj - j) + dk, k % self.yaws, i, j))
        return [(k, i, j) for _, k, i, j in sorted(out)]

    # ------------------------------------------------------------------------------------ occupancy
    def _c_obstacle(
        self, parts: Sequence[tuple[np.ndarray, float, float]], obstacle: Placed
    ) -> list[tuple[int, int, np.ndarray]]:
        """(i0, j0, mask over headings × cells) blocks of the states where a part (floor hull and height
        range) overlaps ``obstacle``."""
        o_hull, o_lo, o_hi = _footprint(obstacle)
        out = []
        for p_hull, p_lo, p_hi in parts:
            if p_hi < o_lo or o_hi < p_lo or len(o_hull) == 0 or len(p_hull) == 0:
                continue
            block = self._overlaps(p_hull, o_hull)
            if block is not None:
                out.append(block)
        return out

    def _overlaps(self, part: np.ndarray, obstacle: np.ndarray) -> tuple[int, int, np.ndarray] | None:
        """Where the convex polygon ``part`` (base frame), turned to each heading and put at a cell centre,
        meets the convex polygon ``obstacle`` (touching counts).

        Separating axes: the two meet iff on every edge normal n of either polygon their projections
        overlap, i.e. n·c lies in an interval [L, U] for the cell centre c.  Each interval is a slab of
        the plane, so for a column of cells (x fixed) the centres that meet the obstacle are those whose y
        lies in one interval: vectorised over headings, axes and columns, then compared with the rows.
        """
        reach = float(np.max(np.hypot(part[:, 0], part[:, 1])))
        lo, hi = obstacle.min(axis=0) - reach, obstacle.max(axis=0) + reach
        i0 = max(0, math.ceil((lo[0] - self.xmin) / self.cell - 0.5))
        i1 = min(self.nx - 1, math.floor((hi[0] - self.xmin) / self.cell - 0.5))
        j0 = max(0, math.ceil((lo[1] - self.ymin) / self.cell - 0.5))
        j1 = min(self.ny - 1, math.floor((hi[1] - self.ymin) / self.cell - 0.5))
        if i1 < i0 or j1 < j0:
            return None
        xs = self.xmin + (np.arange(i0, i1 + 1) + 0.5) * self.cell
        ys = self.ymin + (np.arange(j0, j1 + 1) + 0.5) * self.cell
        c, s = np.cos(self.headings), np.sin(self.headings)
        rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (H, 2, 2)
        turned = np.einsum("hab,kb->hka", rot, part)  # (H, K, 2): the part's vertices at each heading
        axes = np.concatenate(
            [
                np.broadcast_to(_normals(obstacle), (self.yaws, *_normals(obstacle).shape)),
                np.einsum("hab,kb->hka", rot, _normals(part)),
            ],
            axis=1,
        )  # (H, A, 2)
        p_proj = np.einsum("hka,hna->hnk", turned, axes)
        o_proj = np.einsum("ka,hna->hnk", obstacle, axes)
        eps = 1e-9
        low = (o_proj.min(-1) - p_proj.max(-1) - eps)[..., None]  # (H, A, 1): bounds on n·c
        high = (o_proj.max(-1) - p_proj.min(-1) + eps)[..., None]
        nx, ny = axes[..., 0, None], axes[..., 1, None]
        t = nx * xs  # (H, A, columns)
        vertical = np.abs(ny) < 1e-12
        safe = np.where(vertical, 1.0, ny)
        y1, y2 = (low - t) / safe, (high - t) / safe
        inside = (t >= low) & (t <= high)  # for an axis along x: the whole column or none of it
        y_lo = np.where(vertical, np.where(inside, -np.inf, np.inf), np.minimum(y1, y2)).max(axis=1)
        y_hi = np.where(vertical, np.where(inside, np.inf, -np.inf), np.maximum(y1, y2)).min(axis=1)
        mask = (ys >= y_lo[..., None]) & (ys <= y_hi[..., None])  # (H, columns, rows)
        return (i0, j0, mask) if mask.any() else None

    def occupancy(self, parts: Sequence[Placed], obstacles: Sequence[tuple[Hashable, Body, np.ndarray]]) -> np.ndarray:
        """(headings, nx, ny) booleans: states where the robot's parts overlap an obstacle (see the module
        docstring); ``obstacles`` are (key, shape, world transform), the key naming the obstacle at its pose
        (the occupancy of each is cached per key and the parts' floor hulls)."""
        footprints = [_footprint(p) for p in parts]
        parts_key = tuple((h.round(9).tobytes(), round(lo, 9), round(hi, 9)) for h, lo, hi in footprints)
        occ = np.zeros((self.yaws, self.nx, self.ny), dtype=bool)
        for key, shape, t in obstacles:
            blocks = self._blocks.get((parts_key, key))
            if blocks is None:
                blocks = self._blocks[(parts_key, key)] = self._c_obstacle(footprints, (shape, t))
            for i0, j0, m in blocks:
                occ[:, i0 : i0 + m.shape[1], j0 : j0 + m.shape[2]] |= m
        return occ

    # ------------------------------------------------------------------------------------ search
    def plan(
        self,
        occupied: np.ndarray,
        start: Sequence[float] | np.ndarray,
        goal: Sequence[float] | np.ndarray,
        valid: Validity,
        resolution: float,
        yaw_resolution: float,
        clear: Clearance | None = None,
        reach: float = 0.0,
        deadline: float | None = None,
    ) -> MotionResult:
        """A path from ``start`` to ``goal`` through free lattice states, every state of it (at the
        resolutions) accepted by ``valid``; the first state is ``start``, the last ``goal``.  With ``clear``
        (and the robot's ``reach``, m), every motion between two states of the path is checked too
        (:func:`segment_clear`).  ``deadline`` (a ``time.perf_counter()`` value): past it the search stops
        with status TIME_LIMIT."""
        t0 = time.perf_counter()
        check = _Checks(valid, clear, reach, resolution, yaw_resolution, deadline)
        ok, motion_ok = check.state, check.motion

        def result(status: MotionStatus, path: list[np.ndarray] | None = None) -> MotionResult:
            if check.past():  # a test the deadline failed may have decided this answer
                return MotionResult(MotionStatus.TIME_LIMIT, [], time.perf_counter() - t0, check.count)
            return MotionResult(status, path or [], time.perf_counter() - t0, check.count)

        p0 = np.array([start[0], start[1], wrap_angle(start[2])], dtype=float)
        p1 = np.array([goal[0], goal[1], wrap_angle(goal[2])], dtype=float)
        if not ok(p0):
            return result(MotionStatus.INVALID_START)
        if not ok(p1):
            return result(MotionStatus.INVALID_GOAL)
        if motion_ok(p0, p1):
            return result(MotionStatus.SOLVED, [p0, *interpolate(p0, p1, resolution, yaw_resolution)])
        free = ~occupied
        starts = self._joins(p0, free, lambda s: motion_ok(p0, self.state(*s)))
        goals = self._joins(p1, free, lambda s: motion_ok(self.state(*s), p1))
        if not starts or not goals:
            return result(MotionStatus.NO_PATH)
        for _ in range(REPAIRS + 1):
            if check.past():
                break
            nodes = self._wavefront(free, goals, starts)
            if nodes is None:
                return result(MotionStatus.NO_PATH)
            waypoints = [p0] + [self.state(*n) for n in nodes] + [p1]
            bad = next((m for m in range(1, len(nodes)) if not motion_ok(waypoints[m], waypoints[m + 1])), None)
            if bad is None:
                return result(MotionStatus.SOLVED, self._shortcut(waypoints, motion_ok, resolution, yaw_resolution))
            free = free.copy()
            free[nodes[bad]] = False
            goals = [g for g in goals if g != nodes[bad]]
            starts = [s for s in starts if s != nodes[bad]]
            if not starts or not goals:
                return result(MotionStatus.NO_PATH)
        return result(MotionStatus.NO_PATH)

    def _joins(
        self, q: np.ndarray, free: np.ndarray, check: Callable[[tuple[int, int, int]], bool]
    ) -> list[tuple[int, int, int]]:
        """Free lattice states near ``q`` whose join to ``q`` passes ``check``; stops at the first few."""
        out = []
        for s in self._near(q)[:JOINS]:
            if free[s] and check(s):
                out.append(s)
                if len(out) >= 2:
                    break
        return out

    def _wavefront(
        self, free: np.ndarray, goals: list[tuple[int, int, int]], starts: list[tuple[int, int, int]]
    ) -> list[tuple[int, int, int]] | None:
        """Lattice states from a start to a goal (inclusive), fewest moves, or None when none connect.

        A breadth-first search from the goals over :data:`_MOVES` (8 neighbours in the plane, one heading
        either way, cyclic), layer by layer until a start is reached, then back from the nearest start
        (the first of equally near ones) through the first move of :data:`_MOVES` one layer closer.  A
        cell's headings are the bits of one 64-bit word (:func:`_pack`): a layer is a few operations on an
        ``nx`` × ``ny`` array, a heading move a rotation of the bits."""
        yaws, nx, ny = free.shape
        word = _word(yaws)
        bit = [word(1) << word(k) for k in range(yaws)]
        reached = np.zeros((nx, ny), dtype=word)
        for k, i, j in goals:
            reached[i, j] |= bit[k]
        open_ = _pack(free, word) & ~reached
        # the states reached lie in a window that grows by one cell a layer: work on it only
        i0, i1 = min(g[1] for g in goals), max(g[1] for g in goals)
        j0, j1 = min(g[2] for g in goals), max(g[2] for g in goals)
        # layers[d]: the states d moves from a goal, as the corner of a window and the window's words
        layers = [(i0, j0, reached[i0 : i1 + 1, j0 : j1 + 1].copy())]

        def found() -> bool:
            return any(reached[i, j] & bit[k] for k, i, j in starts)

        while not found():
            i0, i1, j0, j1 = max(i0 - 1, 0), min(i1 + 1, nx - 1), max(j0 - 1, 0), min(j1 + 1, ny - 1)
            win = (slice(i0, i1 + 1), slice(j0, j1 + 1))
            li, lj, last = layers[-1]
            front = np.zeros((i1 - i0 + 1, j1 - j0 + 1), dtype=word)
            front[li - i0 : li - i0 + last.shape[0], lj - j0 : lj - j0 + last.shape[1]] = last
            grown = _grow(front, yaws) & open_[win]
            if not grown.any():
                return None
            layers.append((i0, j0, grown))
            reached[win] |= grown
            open_[win] &= ~grown

        def at(state: tuple[int, int, int], d: int) -> bool:
            k, i, j = state
            li, lj, words = layers[d]
            i, j = i - li, j - lj
            return 0 <= i < words.shape[0] and 0 <= j < words.shape[1] and bool(words[i, j] & bit[k])

        d = next(d for d in range(len(layers)) if any(at(s, d) for s in starts))
        here = next(s for s in starts if at(s, d))
        path = [here]
        while d > 0:
            k, i, j = here
            d -= 1
            for dk, di, dj in _MOVES:
                n = ((k + dk) % self.yaws, i + di, j + dj)
                if 0 <= n[1] < self.nx and 0 <= n[2] < self.ny and at(n, d):
                    here = n
                    break
            path.append(here)
        return path

    @staticmethod
    def _shortcut(
        waypoints: list[np.ndarray],
        motion_ok: Callable[[np.ndarray, np.ndarray], bool],
        resolution: float,
        yaw_resolution: float,
    ) -> list[np.ndarray]:
        """Greedy straight shortcuts over ``waypoints`` (each checked), then the dense path."""
        kept = [0]
        i, n = 0, len(waypoints)
        while i < n - 1:
            nxt = i + 1
            for j in sorted({min(i + span, n - 1) for span in (64, 32, 16, 8, 4, 2)}, reverse=True):
                if j > i + 1 and motion_ok(waypoints[i], waypoints[j]):
                    nxt = j
                    break
            kept.append(nxt)
            i = nxt
        dense = [waypoints[0]]
        for a, b in zip(kept, kept[1:]):
            dense.extend(interpolate(waypoints[a], waypoints[b], resolution, yaw_resolution))
        return dense


def _word(yaws: int) -> type[np.unsignedinteger[Any]]:
    """The smallest unsigned integer type with a bit for each of ``yaws`` headings."""
    return next(t for t in (np.uint8, np.uint16, np.uint32, np.uint64) if np.dtype(t).itemsize * 8 >= yaws)


def _pack(states: np.ndarray, word: type[np.unsignedinteger[Any]]) -> np.ndarray:
    """Lattice states (yaws, nx, ny) as one ``word`` per cell (nx, ny): bit k is heading k."""
    weights = word(1) << np.arange(states.shape[0], dtype=word)
    packed: np.ndarray = np.bitwise_or.reduce(np.where(states, weights[:, None, None], word(0)), axis=0)
    return packed


def _grow(front: np.ndarray, yaws: int) -> np.ndarray:
    """The states one move of :data:`_MOVES` from ``front`` (packed, :func:`_pack`): the 8 neighbouring
    cells with the same heading, and the same cell one heading either way (cyclic over ``yaws``)."""
    plane = front.copy()
    plane[1:, :] |= front[:-1, :]
    plane[:-1, :] |= front[1:, :]
    out = plane.copy()
    out[:, 1:] |= plane[:, :-1]
    out[:, :-1] |= plane[:, 1:]
    word = front.dtype.type
    one, top = word(1), word(yaws - 1)
    up, down = (front << one) | (front >> top), (front >> one) | (front << top)  # k -> k + 1 and k -> k - 1
    if yaws < 8 * front.dtype.itemsize:  # bits above the headings: keep them clear
        mask = (one << word(yaws)) - one
        up &= mask
        down &= mask
    out |= up
    out |= down
    return out
