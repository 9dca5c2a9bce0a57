"""Inverse kinematics in numpy: batched Levenberg–Marquardt with random restarts, a reach pre-filter and a
cache.  Outcomes are values (:class:`IKStatus`), never exceptions.

The solver is Sugihara's Levenberg–Marquardt (damping ``E(q) + w̄``, where ``E`` is half the squared pose
error), with the result clamped into the joint limits at every step.  All restarts of a target — and all
targets of :func:`solve_ik_many` — iterate as one numpy batch; a target stops as soon as one of its
restarts meets the tolerances, and the lowest-numbered restart among those that met them first is the
answer, so a target's result does not depend on the other targets of a batch.  Restarts come from
``numpy.random.default_rng(seed)``: the same (model, target, seed) always gives the same configuration.

Arms with a Franka Panda's kinematics (recognised from their URDF chain, :func:`~mrgc.geometry.ik_analytic.
panda_chain`) are solved analytically instead when the caller asks for it (``analytic=True``: phase 1, which
asks whether a pose is reachable at all; :mod:`mrgc.geometry.ik_analytic`): the branch nearest
``q_init`` (the middle of the limits when None), verified by forward kinematics to the same tolerances; it
does not depend on ``seed``, ``restarts`` or ``max_iters``.  When no branch qualifies the result is
NO_CONVERGENCE, without the numeric solver (docs/geometry.md, "Analytic IK", measures why), except for
solves from ``q_init`` alone (``restarts`` 0), which also try it when the analytic answer jumps
(:data:`LOCAL_JUMP`).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from mrgc.geometry.conventions import rotation_log
from mrgc.geometry.fk import chain_frames, jacobian_t
from mrgc.geometry.ik_analytic import PandaChain, panda_chain, solve_many
from mrgc.geometry.kinematics import RobotModel

#: weight of the orientation error (radians) against the position error (metres) in the least squares
ROT_WEIGHT = 0.5
#: a solve's tolerances unless its caller says otherwise: metres, and radians of the rotation's angle
TOL_POS, TOL_ROT = 1e-4, 1e-3
#: Sugihara's bias damping w̄
DAMPING = 1e-3
#: a restart whose error has not dropped by STALL_RATIO over STALL_WINDOW iterations is drawn afresh ...
STALL_WINDOW = 4
STALL_RATIO = 0.9
#: ... at most this many times per restart (so a target gets restarts × (1 + this) starts in all); a target
#: whose restarts are all stalled with no redraws left is NO_CONVERGENCE before ``max_iters``
REDRAWS_PER_RESTART = 2
#: targets per batch in :func:`solve_ik_many` (larger batches fall out of the CPU caches)
CHUNK = 128
#: solve Panda-kinematics arms analytically (:mod:`mrgc.geometry.ik_analytic`) when a call does not say
#: (``analytic=None``); phase 1 says so (``analytic=True``), grounding does not (benchmarks and tests switch it)
ANALYTIC = False
#: a solve from ``q_init`` alone (``restarts`` 0: tracking a Cartesian line) whose analytic answer moves a joint
#: farther than this (rad), or has none, also runs the numeric solver from ``q_init`` and keeps the nearer
#: answer: near a wrist or shoulder singularity the analytic branches, q7 held near its start, jump
LOCAL_JUMP = 0.1


class IKStatus(str, enum.Enum):
    """How an inverse kinematics solve ended."""

    SOLVED = "solved"
    #: the target is provably out of reach (beyond the arm's reach bound); no iteration ran
    UNREACHABLE = "unreachable"
    #: no restart met the tolerances within the iteration budget (maybe unreachable, maybe unlucky)
    NO_CONVERGENCE = "no-convergence"


@dataclass(frozen=True, eq=False)
class IKResult:
    """``q`` (within limits, read-only) when SOLVED, else None.  ``pos_error`` and ``rot_error`` (metres,
    radians) are those of ``q``, or of the closest configuration of the last iteration; for UNREACHABLE,
    ``pos_error`` is how far the target lies beyond the reach bound (a lower bound on any position error).
    ``iterations``: solver iterations run (restarts tried, for pybullet's IK; q7 values tried, for the
    analytic solver)."""

    status: IKStatus
    q: np.ndarray | None
    pos_error: float
    rot_error: float
    iterations: int

    @property
    def solved(self) -> bool:
        """Whether ``q`` holds a solution."""
        return self.status is IKStatus.SOLVED


def restart_configurations(model: RobotModel, seed: int, restarts: int, q_init: np.ndarray | None = None) -> np.ndarray:
    """The ``restarts`` start configurations of a solve, ``(restarts, dof)``: ``q_init`` (clamped into the
    limits; the middle of the limits when None), then uniform draws within the limits from
    ``default_rng(seed)``."""
    first = (model.lower + model.upper) / 2 if q_init is None else model.clamp(np.asarray(q_init, dtype=float))
    if restarts <= 1:  # the start alone (a generator made for no draw costs more than the rest of a 1 cm lift)
        return first[None].copy()
    rng = np.random.default_rng(seed)
    rest = rng.uniform(model.lower, model.upper, size=(restarts - 1, model.dof))
    return np.concatenate([first[None], rest])


# ------------------------------------------------------------------------------------------ the cache

_CACHE: dict[tuple[object, ...], IKResult] = {}
CACHE_SIZE = 200_000


def clear_ik_cache() -> None:
    """Forget every cached solve (for measurements and tests)."""
    _CACHE.clear()


def _key(
    model: RobotModel, target: np.ndarray, seed: int, q_init: np.ndarray | None, params: tuple[object, ...]
) -> tuple[object, ...]:
    init = None if q_init is None else np.round(np.asarray(q_init, dtype=float), 9).tobytes()
    return (model.key, np.round(target[:3], 9).tobytes(), seed, init, params)


def _remember(key: tuple[object, ...], result: IKResult) -> None:
    if len(_CACHE) >= CACHE_SIZE:
        _CACHE.clear()
    _CACHE[key] = result


# ---------------------------------------------------------------------------------------- public API


def solve_ik(
    model: RobotModel,
    target: np.ndarray,
    seed: int,
    q_init: np.ndarray | None = None,
    restarts: int = 8,
    tol_pos: float = TOL_POS,
    tol_rot: float = TOL_ROT,
    max_iters: int = 100,
    analytic: bool | None = None,
) -> IKResult:
    """A configuration putting the end-effector link at ``target`` (4×4 in the robot's base frame).

    ``restarts`` start configurations (see :func:`restart_configurations`) run as one batch for at most
    ``max_iters`` iterations; the first to reach ``tol_pos`` metres and ``tol_rot`` radians wins.  Targets
    farther from the shoulder than the arm's reach are UNREACHABLE without iterating.  Cached per (model,
    target rounded to 1e-9, seed, q_init, parameters).
    """
    return solve_ik_many(
        model, np.asarray(target, dtype=float)[None], seed, q_init, restarts, tol_pos, tol_rot, max_iters, analytic
    )[0]


def solve_ik_many(
    model: RobotModel,
    targets: np.ndarray,
    seed: int,
    q_init: np.ndarray | None = None,
    restarts: int = 8,
    tol_pos: float = TOL_POS,
    tol_rot: float = TOL_ROT,
    max_iters: int = 100,
    analytic: bool | None = None,
) -> list[IKResult]:
    """:func:`solve_ik` for each of ``targets`` (M, 4, 4), solved together in one batch: the same results
    as M separate calls, at a fraction of the cost when M is large.  ``q_init`` may be one configuration for
    all targets or an (M, dof) array giving each target its own first start.  ``analytic``: solve arms with
    a Panda's kinematics analytically (module docstring; None: :data:`ANALYTIC`).  Grounding leaves it off:
    its motions are joint-space lines from the configurations it solves, and the numeric solver's answers,
    found from the start, keep those lines on their Cartesian paths where the analytic branch nearest the
    start (q7 locked) did not (docs/geometry.md, "Analytic IK": pa10 seed 0, pa3-handover, the carry and
    self-collision tests)."""
    targets = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
    chain = panda_chain(model) if (ANALYTIC if analytic is None else analytic) else None
    params: tuple[object, ...]
    if chain is not None:  # the analytic answer depends on neither the seed nor the numeric solver's budget
        seed, params = 0, ("analytic", tol_pos, tol_rot, restarts <= 0 and max_iters)
    else:
        params = (restarts, tol_pos, tol_rot, max_iters)
    results: list[IKResult | None] = [None] * len(targets)
    per_target = q_init is not None and np.ndim(q_init) == 2  # one first start per target
    inits = np.asarray(q_init, dtype=float) if per_target else None
    keys = [_key(model, t, seed, inits[i] if inits is not None else q_init, params) for i, t in enumerate(targets)]
    todo, twins = _answered(model, targets, keys, results)
    if todo and chain is not None:
        if inits is not None:
            refs = model.clamp(inits[todo])
        else:
            refs = np.tile(restart_configurations(model, seed, 1, q_init)[0], (len(todo), 1))
        local = (tol_pos, tol_rot, max_iters) if restarts <= 0 else None
        for i, res in zip(todo, _analytic(model, chain, targets[todo], refs, tol_pos, tol_rot, local)):
            results[i] = res
            _remember(keys[i], res)
    elif todo:
        starts = restart_configurations(model, seed, restarts, None if per_target else q_init)
        for lo in range(0, len(todo), CHUNK):
            part = todo[lo : lo + CHUNK]
            if inits is not None:
                batch = np.repeat(starts[None], len(part), axis=0)
                batch[:, 0] = model.clamp(inits[part])
            else:
                batch = starts
            for i, res in zip(part, _lm(model, targets[part], batch, seed, tol_pos, tol_rot, max_iters)):
                results[i] = res
                _remember(keys[i], res)
    for i, j in twins.items():
        results[i] = results[j]
    return results  # type: ignore[return-value]


def _answered(
    model: RobotModel, targets: np.ndarray, keys: list[tuple[object, ...]], results: list[IKResult | None]
) -> tuple[list[int], dict[int, int]]:
    """Fill ``results`` with what needs no solve (the cache's answers; targets beyond the reach bound are
    UNREACHABLE); the targets left to solve, and those asked again in the batch (the same key), each with the
    one solved for it (its rows would run exactly as that one's)."""
    todo: list[int] = []
    twins: dict[int, int] = {}
    first: dict[tuple[object, ...], int] = {}
    gap = np.linalg.norm(targets[:, :3, 3] - model.shoulder, axis=-1) - model.reach  # > 0: out of reach
    for i, key in enumerate(keys):
        hit = _CACHE.get(key)
        if hit is not None:
            results[i] = hit
        elif gap[i] > 1e-9:
            results[i] = miss = IKResult(IKStatus.UNREACHABLE, None, float(gap[i]), float("inf"), 0)
            _remember(key, miss)
        elif key in first:
            twins[i] = first[key]
        else:
            first[key] = i
            todo.append(i)
    return todo, twins


def _analytic(
    model: RobotModel,
    chain: PandaChain,
    targets: np.ndarray,
    refs: np.ndarray,
    tol_pos: float,
    tol_rot: float,
    local: tuple[float, float, int] | None,
) -> list[IKResult]:
    """The analytic results of ``targets`` from starts ``refs``; with ``local`` (the numeric solver's
    tolerances and iterations), an answer that is missing or jumps (:data:`LOCAL_JUMP`) is compared with the
    numeric solver's from the start alone."""
    out = []
    for target, ref, ans in zip(targets, refs, solve_many(model, chain, targets, refs, tol_pos, tol_rot)):
        status = IKStatus.SOLVED if ans.q is not None else IKStatus.NO_CONVERGENCE
        res = IKResult(status, ans.q, ans.pos_error, ans.rot_error, ans.calls)
        if local is not None and (ans.q is None or float(np.abs(ans.q - ref).max()) > LOCAL_JUMP):
            res = _nearer(res, _lm(model, target[None], ref[None], 0, *local)[0], ref)
        out.append(res)
    return out


def _nearer(analytic: IKResult, local: IKResult, ref: np.ndarray) -> IKResult:
    """Of an analytic answer and the numeric solver's from ``ref`` alone, the solved one nearer ``ref``."""
    if not local.solved or local.q is None:
        return analytic
    if analytic.q is not None and np.linalg.norm(analytic.q - ref) <= np.linalg.norm(local.q - ref):
        return analytic
    return local


# ------------------------------------------------------------------------------------------- the solver


def _lm(
    model: RobotModel,
    targets: np.ndarray,
    starts: np.ndarray,
    seed: int,
    tol_pos: float,
    tol_rot: float,
    max_iters: int,
) -> list[IKResult]:
    # Written for few numpy calls per iteration: a single solve is bound by call overhead, not arithmetic.
    m, r, n = len(targets), starts.shape[-2], model.dof
    w = np.array([1.0, 1.0, 1.0, ROT_WEIGHT, ROT_WEIGHT, ROT_WEIGHT])
    out: list[IKResult | None] = [None] * m
    ids = np.arange(m)  # which targets are still being solved
    t_pos = np.repeat(targets[:, :3, 3], r, axis=0)  # rows: target-major, restart-minor
    t_rot = np.repeat(targets[:, :3, :3], r, axis=0)
    q = starts.reshape(m * r, n).copy() if starts.ndim == 3 else np.tile(starts, (m, 1))
    checked = np.full(m * r, np.inf)  # energy at the last stall check
    dead = np.zeros(m * r, dtype=bool)  # stalled rows whose target has no redraws left
    redraws = np.full(m, REDRAWS_PER_RESTART * r)  # redraws left per target
    rngs: dict[int, np.random.Generator] = {}  # redraws for stalled restarts, one stream per target
    lower, upper = model.lower, model.upper
    damp = DAMPING * np.eye(n)
    eye = np.eye(n)
    tol_pos2, tol_rot2 = tol_pos * tol_pos, tol_rot * tol_rot
    for it in range(max_iters + 1):
        frames, ee = chain_frames(model, q)
        e_pos = t_pos - ee[:, :3, 3]
        e_rot = rotation_log(t_rot @ np.swapaxes(ee[:, :3, :3], -1, -2))
        pe2 = np.einsum("ij,ij->i", e_pos, e_pos)
        re2 = np.einsum("ij,ij->i", e_rot, e_rot)
        conv = (pe2 <= tol_pos2) & (re2 <= tol_rot2)
        energy = 0.5 * (pe2 + ROT_WEIGHT * re2)
        if it == max_iters or conv.any() or (it % STALL_WINDOW == 0 and dead.any()):
            conv = (conv & ~dead).reshape(-1, r)
            done = conv.any(axis=1)
            finished = done | dead.reshape(-1, r).all(axis=1) | (it == max_iters)
            first = np.argmax(conv, axis=1)
            low = np.argmin(np.where(dead, np.inf, energy).reshape(-1, r), axis=1)
            for k in np.flatnonzero(finished):
                if done[k]:
                    row = k * r + first[k]
                    qs = q[row].copy()
                    qs.setflags(write=False)
                    out[ids[k]] = IKResult(IKStatus.SOLVED, qs, float(np.sqrt(pe2[row])), float(np.sqrt(re2[row])), it)
                else:
                    row = k * r + (low[k] if not dead[k * r + low[k]] else int(np.argmin(energy[k * r : (k + 1) * r])))
                    out[ids[k]] = IKResult(
                        IKStatus.NO_CONVERGENCE, None, float(np.sqrt(pe2[row])), float(np.sqrt(re2[row])), it
                    )
            if finished.all():
                break
            if finished.any():
                ids, redraws = ids[~finished], redraws[~finished]
                keep = np.repeat(~finished, r)
                q, t_pos, t_rot, frames, ee, e_pos, e_rot, energy, dead, checked = (
                    q[keep],
                    t_pos[keep],
                    t_rot[keep],
                    frames[keep],
                    ee[keep],
                    e_pos[keep],
                    e_rot[keep],
                    energy[keep],
                    dead[keep],
                    checked[keep],
                )
        # one Levenberg-Marquardt step: (Jᵀ W J + (E + w̄) I) dq = Jᵀ W e
        jt = jacobian_t(model, frames, ee)  # (B, n, 6)
        jtw = jt * w
        h = jtw @ np.swapaxes(jt, -1, -2) + (energy[:, None, None] * eye + damp)
        dq = np.linalg.solve(h, jtw @ np.concatenate([e_pos, e_rot], axis=-1)[:, :, None])
        q = np.minimum(np.maximum(q + dq[..., 0], lower), upper)
        if it % STALL_WINDOW == 0:
            # restarts stuck in a local minimum start again from a fresh random draw, while redraws last
            stalled = energy > STALL_RATIO * checked
            checked = energy
            if stalled.any():
                checked = checked.copy()
                for row in np.flatnonzero(stalled & ~dead):
                    k = row // r
                    if redraws[k] <= 0:
                        dead[row] = True
                        continue
                    redraws[k] -= 1
                    tid = int(ids[k])
                    if tid not in rngs:
                        rngs[tid] = np.random.default_rng([seed, 1])
                    q[row] = rngs[tid].uniform(lower, upper)
                    checked[row] = np.inf
    return out  # type: ignore[return-value]
