"""Analytic inverse kinematics for arms with a Franka Panda's kinematics: GeoFIK (``geofikpy``, MIT), the only
importer of that package, imported lazily.

A model qualifies when its URDF chain *is* a Panda's, whatever its names (:func:`panda_chain`): seven
revolute joints about their +z axes whose fixed transforms between consecutive joints (``Joint.pre``) equal
a Panda's to :data:`DETECT_TOL`, the first joint anywhere on the base (a pedestal is a rigid offset), and the
end-effector link rigidly attached after the seventh joint (``panda_hand``, ``panda_link8``, a tool point).
Everything else keeps the numeric solver (:mod:`mrgc.geometry.ik`).

GeoFIK solves the arm with the seventh joint locked: up to 8 branches per value of q7, in its frame "E"
(the Panda's flange ``panda_link8`` turned −45° about z and moved 0.1034 m along z; its base frame "O" is
``panda_link0``).  :func:`solve_many` maps each end-effector target (4×4 in the model's base frame) into
that frame and locks q7 first at the start configuration's value (``q_init``, or the middle of the limits),
then, for targets that gives no solution, at each of :data:`Q7_GRID` values evenly spread over q7's
limits.  Every branch of a stage is kept if it lies within the model's joint limits and the project's own
forward kinematics (:func:`mrgc.geometry.fk.ee_pose`) puts the end effector on the target to the solver's
tolerances; the answer is the one nearest ``q_init`` (Euclidean in joint space; the first in branch order on
a tie).  :func:`reaches` asks only whether some branch exists (the start's q7, then the grid), without the
search for the nearest.  Deterministic: no randomness, no clock, and a target's answer depends on nothing else
of its batch.

GeoFIK's own joint limits (:data:`GEOFIK_LOWER`, :data:`GEOFIK_UPPER`, Franka's datasheet) are inside the
URDF's of pybullet_data's Panda by 0.07 rad: GeoFIK computes each branch in full, then blanks (NaN) every
joint beyond them.  :func:`solve_many`'s answers keep to GeoFIK's limits (a configuration so close to a joint's
limit is a poor one to plan from, and phase 1's facts stay those they were).  :func:`reaches`, the question
whether any branch exists, fills a joint blanked alone back in from the target (:func:`recover`) and counts
the branch if it is within the model's limits, so "no branch" means none within the URDF's limits; q7 stays
locked within GeoFIK's range (docs/geometry.md, "Analytic IK", measures what is still missed).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from mrgc.geometry.fk import chain_frames, ee_pose
from mrgc.geometry.kinematics import RobotModel
from mrgc.geometry.transforms import from_xyz_rpy, inverse, rot_z, translation

Array = NDArray[np.float64]

_H = np.pi / 2
#: a Panda's chain: the fixed transform from each joint's frame to the next one's (``Joint.pre`` of joints 2-7,
#: as (xyz, rpy)), the published Panda kinematics (Franka's Denavit-Hartenberg table, pybullet_data's URDF)
PANDA_PRE: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...] = (
    ((0.0, 0.0, 0.0), (-_H, 0.0, 0.0)),
    ((0.0, -0.316, 0.0), (_H, 0.0, 0.0)),
    ((0.0825, 0.0, 0.0), (_H, 0.0, 0.0)),
    ((-0.0825, 0.384, 0.0), (-_H, 0.0, 0.0)),
    ((0.0, 0.0, 0.0), (_H, 0.0, 0.0)),
    ((0.088, 0.0, 0.0), (_H, 0.0, 0.0)),
)
#: the height of joint 2 above GeoFIK's base frame O (``panda_link0``): joint 1's frame is O moved up this much
PANDA_D1 = 0.333
#: GeoFIK's frame E in the frame of the seventh joint (``panda_link7``): the flange 0.107 m up z, then the hand's
#: −45° about z and 0.1034 m along z
JOINT7_TO_E = translation(0.0, 0.0, 0.107) @ rot_z(-np.pi / 4) @ translation(0.0, 0.0, 0.1034)
#: how closely (metres, and rotation-matrix entries) a chain must match a Panda's
DETECT_TOL = 1e-6
#: the joint limits GeoFIK applies inside (a branch with a joint beyond them comes back as NaN)
GEOFIK_LOWER = np.array([-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973])
GEOFIK_UPPER = np.array([2.8973, 1.762, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973])
#: the q7 values tried when the start's q7 gives no solution: of this many, at the centres of equal cells of q7's
#: range, those where the elbow triangle closes (a cheap test), at most :data:`Q7_CALLS` of them evenly spread
Q7_GRID = 128
Q7_CALLS = 32
#: a branch at the start's q7 this close to the start on every joint (rad) is taken without searching q7 nearby
NEAR = 0.05
#: the steps (rad) of the search for the q7 whose branch is nearest the start
NEAR_STEPS = (0.05, 0.01)
#: GeoFIK's wrist geometry (its geofik.cpp): distance of frame E from the wrist centre along E's z axis, the
#: elbow's two link lengths; used to skip q7 values where the chain cannot close (GeoFIK prints an error then)
_DE, _A7, _B1, _B2 = 0.2104, 0.088, float(np.hypot(0.316, 0.0825)), float(np.hypot(0.384, 0.0825))


@dataclass(frozen=True, eq=False)
class PandaChain:
    """A model recognised as a Panda.  ``base_inv`` maps the model's base frame into GeoFIK's base frame O;
    ``to_e`` maps the end-effector link's frame to GeoFIK's frame E (target_E = base_inv · target · to_e);
    ``lower`` and ``upper`` are the limits a solution must respect (the model's); ``q7_lo`` and ``q7_hi`` the
    range q7 is locked in (the model's limits within GeoFIK's); ``grid`` the :data:`Q7_GRID` values of q7."""

    base_inv: Array
    to_e: Array
    lower: Array
    upper: Array
    q7_lo: float
    q7_hi: float
    grid: Array


@dataclass(frozen=True, eq=False)
class Answer:
    """One target's analytic answer: ``q`` (within limits, read-only) or None when no branch qualified;
    ``pos_error`` and ``rot_error`` (metres, radians) of ``q``, or of the nearest-to-target branch that was
    rejected (inf when GeoFIK returned none); ``calls``: q7 values GeoFIK was asked."""

    q: Array | None
    pos_error: float
    rot_error: float
    calls: int


def panda_chain(model: RobotModel) -> PandaChain | None:
    """The Panda reading of ``model``, or None when its chain is not a Panda's (cached per model)."""
    return _chain(model.key, model)


@functools.lru_cache(maxsize=64)
def _chain(key: str, model: RobotModel) -> PandaChain | None:
    joints = model.joints
    if len(joints) != 7 or any(j.kind != "revolute" or j.continuous for j in joints):
        return None
    if any(not np.allclose(j.axis, (0.0, 0.0, 1.0), atol=DETECT_TOL, rtol=0.0) for j in joints):
        return None
    for joint, (xyz, rpy) in zip(joints[1:], PANDA_PRE):
        if not np.allclose(joint.pre, from_xyz_rpy(xyz, rpy), atol=DETECT_TOL, rtol=0.0):
            return None
    base = joints[0].pre @ translation(0.0, 0.0, -PANDA_D1)  # GeoFIK's O in the model's base frame
    q7_lo = max(float(model.lower[6]), float(GEOFIK_LOWER[6]))
    q7_hi = min(float(model.upper[6]), float(GEOFIK_UPPER[6]))
    if q7_lo > q7_hi:
        return None
    grid = q7_lo + (np.arange(Q7_GRID) + 0.5) * (q7_hi - q7_lo) / Q7_GRID
    return PandaChain(
        base_inv=inverse(base),
        to_e=inverse(model.ee_offset) @ JOINT7_TO_E,
        lower=np.asarray(model.lower, dtype=float),
        upper=np.asarray(model.upper, dtype=float),
        q7_lo=q7_lo,
        q7_hi=q7_hi,
        grid=grid,
    )


def load_solver() -> None:
    """Load GeoFIK's module now: a process about to fork workers that will solve shares it with them
    instead of each loading its own."""
    import geofikpy  # noqa: F401


def solve_many(
    model: RobotModel, chain: PandaChain, targets: Array, refs: Array, tol_pos: float, tol_rot: float
) -> list[Answer]:
    """The analytic answer for each of ``targets`` (M, 4, 4; end-effector poses in the model's base frame):
    the qualifying branch nearest ``refs[i]`` (M, 7; the start configurations), q7 locked near ``refs[i]``'s
    value first (:func:`_near_rows`), then over the grid for the targets that gave none (module docstring)."""
    from geofikpy import franka_ik_q7

    targets = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
    refs = np.asarray(refs, dtype=float).reshape(-1, 7)
    e = chain.base_inv @ targets @ chain.to_e  # the targets in GeoFIK's frames
    calls = np.zeros(len(targets), dtype=int)
    misses = np.full((len(targets), 2), np.inf)  # errors of the nearest rejected branch, per target
    owner: list[int] = []
    rows: list[Array] = []
    for i in range(len(targets)):
        r, rot = e[i, :3, 3].tolist(), e[i, :3, :3].ravel().tolist()
        q1_sing = float(refs[i, 0])

        def solve(q7: float, r: list[float] = r, rot: list[float] = rot, q1_sing: float = q1_sing) -> Array:
            sols, n = franka_ik_q7(r, rot, q7, q1_sing)
            return np.array(sols[:n], dtype=float).reshape(-1, 7)

        found, calls[i] = _near_rows(solve, e[i], refs[i], chain, model)
        owner += [i] * len(found)
        rows += found
    answers = _pick(model, targets, refs, owner, rows, tol_pos, tol_rot, misses)
    todo = np.array([i for i in range(len(targets)) if i not in answers], dtype=int)
    if len(todo):
        on_grid, grid_rows = _grid_rows(franka_ik_q7, e, refs, todo, chain, calls)
        answers.update(_pick(model, targets, refs, on_grid, grid_rows, tol_pos, tol_rot, misses))
    out = []
    for i in range(len(targets)):
        if i in answers:
            q, p, r = answers[i]
            q.setflags(write=False)
            out.append(Answer(q, p, r, int(calls[i])))
        else:
            out.append(Answer(None, float(misses[i, 0]), float(misses[i, 1]), int(calls[i])))
    return out


def reaches(
    model: RobotModel, chain: PandaChain, targets: Array, refs: Array, tol_pos: float, tol_rot: float
) -> list[bool]:
    """Whether some branch within the model's limits reaches each of ``targets`` (M, 4, 4; model's base
    frame), a joint GeoFIK blanked filled in (:func:`recover`): the branches with q7 locked at ``refs[i]``'s
    value first, then the grid for the targets those do not reach: the search of :func:`solve_many` without
    the part that looks for the branch nearest the start, so a target near its start costs one call of the
    solver."""
    from geofikpy import franka_ik_q7

    targets = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
    refs = np.asarray(refs, dtype=float).reshape(-1, 7)
    e = chain.base_inv @ targets @ chain.to_e
    calls = np.zeros(len(targets), dtype=int)
    misses = np.full((len(targets), 2), np.inf)
    owner: list[int] = []
    rows: list[Array] = []
    for i in range(len(targets)):
        q7 = min(max(float(refs[i, 6]), chain.q7_lo), chain.q7_hi)
        if _closes_one(e[i], q7):
            sols, n = franka_ik_q7(e[i, :3, 3].tolist(), e[i, :3, :3].ravel().tolist(), q7, float(refs[i, 0]))
            owner += [i] * n
            rows += [np.asarray(row, dtype=float) for row in sols[:n]]
    found = set(_pick(model, targets, refs, owner, rows, tol_pos, tol_rot, misses, fill=True))
    todo = np.array([i for i in range(len(targets)) if i not in found], dtype=int)
    if len(todo):
        on_grid, grid_rows = _grid_rows(franka_ik_q7, e, refs, todo, chain, calls)
        found |= set(_pick(model, targets, refs, on_grid, grid_rows, tol_pos, tol_rot, misses, fill=True))
    return [i in found for i in range(len(targets))]


def _near_rows(
    solve: Callable[[float], Array], e: Array, ref: Array, chain: PandaChain, model: RobotModel
) -> tuple[list[Array], int]:
    """The branches within limits found with q7 locked at ``ref``'s q7 and, unless one of those is within
    :data:`NEAR` of ``ref`` on every joint, at the q7 values a short search for the branch nearest ``ref``
    visits (a parabola through three values, twice: steps :data:`NEAR_STEPS`); and the number of GeoFIK
    calls.  Only values where the elbow triangle closes are asked."""
    seen: dict[float, float] = {}  # q7 -> squared distance of its nearest branch to ref (inf: none)
    found: list[Array] = []

    def near(q7: float) -> float:
        q7 = min(max(q7, chain.q7_lo), chain.q7_hi)
        if q7 not in seen:
            seen[q7] = np.inf
            if _closes_one(e, q7):
                sols = solve(q7)
                sols = sols[~np.isnan(sols).any(axis=1) & model.within_limits(sols)]
                if len(sols):
                    found.append(sols)
                    seen[q7] = float(np.min(np.sum((sols - ref) ** 2, axis=1)))
        return seen[q7]

    x0 = float(ref[6])
    f0 = near(x0)
    if f0 < np.inf and float(np.abs(found[0] - ref).max(axis=1).min()) <= NEAR:
        return list(found[0]), len(seen)
    for h in NEAR_STEPS:
        fm, fp = near(x0 - h), near(x0 + h)
        if fm < np.inf and fp < np.inf and f0 < np.inf and fp - 2 * f0 + fm > 0:
            x1 = x0 - h * (fp - fm) / (2 * (fp - 2 * f0 + fm))
            near(min(max(x1, x0 - 4 * h), x0 + 4 * h))
        x0 = min(seen, key=lambda q7: (seen[q7], q7))
        f0 = seen[x0]
    return [row for sols in found for row in sols], len(seen)


def _grid_rows(
    franka_ik_q7: Callable[..., tuple[list[list[float]], int]],
    e: Array,
    refs: Array,
    todo: NDArray[np.int_],
    chain: PandaChain,
    calls: NDArray[np.int_],
) -> tuple[list[int], Array]:
    """The branches of targets ``todo`` with q7 locked at the grid's values where the elbow triangle closes,
    at most :data:`Q7_CALLS` of them evenly spread (ends included); with the target each belongs to
    (``calls`` counted up in place).  The branches come as one (N, 7) array, in the order GeoFIK gave them,
    but for those with two joints or more blanked, which no caller can use (:func:`_pick`, :func:`recover`)."""
    closes = _closes(e[todo], np.broadcast_to(chain.grid, (len(todo), len(chain.grid))))
    owner: list[int] = []
    flat: list[list[float]] = []
    for k, i in enumerate(todo.tolist()):
        r, rot, q1 = e[i, :3, 3].tolist(), e[i, :3, :3].ravel().tolist(), float(refs[i, 0])
        where = np.flatnonzero(closes[k])
        if len(where) > Q7_CALLS:
            where = where[np.linspace(0, len(where) - 1, Q7_CALLS).round().astype(int)]
        calls[i] += len(where)
        for q7 in chain.grid[where].tolist():
            sols, n = franka_ik_q7(r, rot, q7, q1)
            owner += [i] * n
            flat += sols[:n]
    rows = np.array(flat, dtype=float).reshape(-1, 7)
    usable = np.isnan(rows).sum(axis=1) <= 1
    return np.asarray(owner, dtype=int)[usable].tolist(), rows[usable]


def _pick(
    model: RobotModel,
    targets: Array,
    refs: Array,
    owner: list[int],
    rows: list[Array] | Array,
    tol_pos: float,
    tol_rot: float,
    misses: Array,
    fill: bool = False,
) -> dict[int, tuple[Array, float, float]]:
    """Of branches ``rows`` (of targets ``owner``), those within the limits that forward kinematics puts on
    their target to the tolerances; the nearest to its ``refs`` row per target (the first of equally near
    ones), with its position and rotation errors.  ``misses`` keeps the errors of the nearest rejected
    branch per target.  ``fill``: a joint GeoFIK blanked is filled in first (:func:`recover`)."""
    if not len(rows):
        return {}
    cand = np.array(rows, dtype=float).reshape(-1, 7)
    who = np.array(owner, dtype=int)
    if fill:
        cand = recover(model, cand, targets[who])
    keep = ~np.isnan(cand).any(axis=1) & model.within_limits(cand)
    cand, who = cand[keep], who[keep]
    if not len(cand):
        return {}
    p, r = _errors(ee_pose(model, cand), targets[who])
    good = (p <= tol_pos) & (r <= tol_rot)
    for j in np.flatnonzero(~good):
        if p[j] + r[j] < misses[who[j]].sum():
            misses[who[j]] = (p[j], r[j])
    best: dict[int, int] = {}  # target -> index of its nearest qualifying branch
    dist = np.einsum("ij,ij->i", cand - refs[who], cand - refs[who])
    for idx in np.flatnonzero(good):
        i = int(who[idx])
        if i not in best or dist[idx] < dist[best[i]]:
            best[i] = int(idx)
    return {i: (cand[idx].copy(), float(p[idx]), float(r[idx])) for i, idx in best.items()}


def recover(model: RobotModel, rows: Array, targets: Array) -> Array:
    """``rows`` (N, 7; GeoFIK's branches, for end-effector ``targets`` (N, 4, 4) in the model's base frame)
    with each joint GeoFIK blanked alone filled in: GeoFIK computes a branch in full, then replaces every
    joint beyond Franka's datasheet limits by NaN, and those lie inside the URDF's (:data:`GEOFIK_LOWER`).
    With the other six joints known, the blanked joint ``j`` follows from the target: with ``F`` the frame of
    joint ``j`` at angle 0 and ``E0`` the end effector's there, ``Rz(q_j) = F⁻¹ · target · E0⁻¹ · F``; the
    angle is shifted by 2π into the model's limits where one shift fits, else left blank.  A row with two or
    more blanks is returned as it is.  What comes back is still only a candidate: the caller checks its
    limits and its forward kinematics (:func:`_pick`)."""
    blank = np.isnan(rows)
    one = np.flatnonzero(blank.sum(axis=1) == 1)
    if not len(one):
        return rows
    rows = rows.copy()
    joint = np.argmax(blank[one], axis=1)
    frames, ee = chain_frames(model, np.nan_to_num(rows[one]))
    f = frames[np.arange(len(one)), joint, :3, :3]
    ft = np.swapaxes(f, -1, -2)
    m = ft @ targets[one][:, :3, :3] @ np.swapaxes(ee[:, :3, :3], -1, -2) @ f
    angle = np.arctan2(m[:, 1, 0], m[:, 0, 0])
    lo, hi = model.lower[joint] - 1e-9, model.upper[joint] + 1e-9
    for shift in (0.0, 2 * np.pi, -2 * np.pi):
        fits = np.isnan(rows[one, joint]) & (angle + shift >= lo) & (angle + shift <= hi)
        rows[one[fits], joint[fits]] = angle[fits] + shift
    return rows


def _errors(poses: Array, targets: Array) -> tuple[Array, Array]:
    """Position distance (m) and rotation angle (rad) between ``poses`` and ``targets`` (N, 4, 4): the angle
    from the trace of the relative rotation, accurate to about 1e-8 rad, far below the tolerances."""
    d = poses[:, :3, 3] - targets[:, :3, 3]
    c = 0.5 * (np.einsum("nij,nij->n", poses[:, :3, :3], targets[:, :3, :3]) - 1.0)
    return np.sqrt(np.einsum("ni,ni->n", d, d)), np.arccos(np.clip(c, -1.0, 1.0))


def _closes_one(e: Array, q7: float) -> bool:
    """:func:`_closes` for one target and one value of q7, in plain floats (a solve's first test)."""
    (ix, jx, kx, px), (iy, jy, ky, py), (iz, jz, kz, pz) = e[:3].tolist()
    c, s = math.cos(math.pi / 4 - q7), math.sin(math.pi / 4 - q7)
    x = px - _DE * kx - _A7 * (c * ix + s * jx)
    y = py - _DE * ky - _A7 * (c * iy + s * jy)
    z = pz - _DE * kz - _A7 * (c * iz + s * jz) - PANDA_D1
    length = max(math.sqrt(x * x + y * y + z * z), 1e-12)
    cos = (_B1 * _B1 - length * length - _B2 * _B2) / (-2.0 * length * _B2)
    return -1.0 <= cos <= 1.0 - 1e-9


def _closes(e: Array, q7s: Array) -> NDArray[np.bool_]:
    """Whether GeoFIK's elbow triangle closes for targets ``e`` (K, 4, 4, frame E in O) with q7 at each of
    ``q7s`` (K, S): the wrist centre within the elbow's reach (geofik.cpp's first test, slightly inside)."""
    i_e, j_e, k_e = e[:, :3, 0], e[:, :3, 1], e[:, :3, 2]
    th = -(q7s - np.pi / 4)  # GeoFIK turns E's x axis by this about E's z axis to get the sixth frame's
    i_6 = np.cos(th)[..., None] * i_e[:, None] + np.sin(th)[..., None] * j_e[:, None]
    r6 = (e[:, :3, 3] - _DE * k_e)[:, None] - _A7 * i_6
    r6[..., 2] -= PANDA_D1
    length = np.maximum(np.linalg.norm(r6, axis=-1), 1e-12)
    c = (_B1 * _B1 - length * length - _B2 * _B2) / (-2.0 * length * _B2)
    closes: NDArray[np.bool_] = (c <= 1.0 - 1e-9) & (c >= -1.0)
    return closes
