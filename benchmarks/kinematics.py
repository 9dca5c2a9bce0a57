"""Kinematics speed: numpy FK and IK (mrgc.geometry.fk / ik) against pybullet's.

    python benchmarks/kinematics.py
    python benchmarks/kinematics.py --urdf franka_panda/panda.urdf --ee panda_hand --poses 200 --restarts 8

FK: time per configuration of one batched call with N = 1 and N = 1000 configurations (all links), and of
pybullet's ``getLinkStates(computeForwardKinematics=True)``.  IK: the median and mean time per solve over
``--poses`` reachable poses (FK of uniform random configurations within the limits) with the cache cleared,
the fraction solved to 1e-4 m / 1e-3 rad within the limits, the same through the batch API
(``solve_ik_many``, time per target), the cost of a failing solve (targets inside the reach bound with
random orientations, mostly infeasible), and pybullet's ``calculateInverseKinematics`` with the same
restarts (plain damped least squares, and the null-space variant with limits on a subset).
Issue 22 adds, for a Panda chain: one GeoFIK call, and the analytic solve against the numeric one on the
same targets (single solves and one batch, CPU µs by ``time.process_time``).  Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

from mrgc.geometry import fk as F
from mrgc.geometry import ik as I
from mrgc.geometry import transforms as tf
from mrgc.geometry.kinematics import load_robot_model
from mrgc.testing.pybullet_reference import pybullet_fk, pybullet_ik


def per_call(fn, repeat: int) -> float:
    """Median seconds per call over 5 rounds of ``repeat`` calls."""
    rounds = []
    for _ in range(5):
        t = time.perf_counter()
        for _ in range(repeat):
            fn()
        rounds.append((time.perf_counter() - t) / repeat)
    return statistics.median(rounds)


def timed_solves(solve, targets) -> tuple[list[float], list]:
    times, results = [], []
    for i, t in enumerate(targets):
        start = time.perf_counter()
        results.append(solve(i, t))
        times.append(time.perf_counter() - start)
    return times, results


def cpu_per_call(fn, items) -> float:
    """Median CPU seconds per call over 5 rounds of calling ``fn`` on each of ``items``."""
    rounds = []
    for _ in range(5):
        t = time.process_time()
        for item in items:
            fn(item)
        rounds.append((time.process_time() - t) / len(items))
    return statistics.median(rounds)


def analytic_rows(model, qs, targets, restarts: int) -> list[tuple[str, str, str]]:
    """Issue 22: GeoFIK's call alone, a verified analytic solve (single and batched, from home and from the
    configuration itself) and the numeric solver on the same targets, in CPU µs (time.process_time)."""
    from mrgc.geometry import ik_analytic as A

    chain = A.panda_chain(model)
    if chain is None:
        return [("analytic IK", "not a Panda chain: numeric solver only", "")]
    from geofikpy import franka_ik_q7

    e = chain.base_inv @ targets @ chain.to_e
    # q7 locked at the configuration's own value (the chain closes there; GeoFIK prints where it does not)
    calls = [(t[:3, 3].tolist(), t[:3, :3].ravel().tolist(), float(q7)) for t, q7 in zip(e, qs[:, 6])]
    rows = [
        (
            "GeoFIK franka_ik_q7, one call (q7 locked)",
            f"{cpu_per_call(lambda c: franka_ik_q7(*c), calls) * 1e6:.1f} µs",
            "",
        )
    ]
    home = (model.lower + model.upper) / 2
    for label, flag in (("analytic", True), ("numeric LM", False)):
        I.ANALYTIC = flag
        out = []

        def one(t, out=out):
            I.clear_ik_cache()
            out.append(I.solve_ik(model, t, seed=0, q_init=home, restarts=restarts))

        per = cpu_per_call(one, targets[: 100 if flag else 40])
        ok = sum(r.solved for r in out[: 100 if flag else 40])
        rows.append(
            (f"solve_ik, {label}, from the middle of the limits", f"{per * 1e6:.0f} µs CPU", f"{ok}/{len(out) // 5}")
        )
        I.clear_ik_cache()
        t = time.process_time()
        res = I.solve_ik_many(model, targets, seed=0, q_init=home, restarts=restarts)
        per = (time.process_time() - t) / len(targets)
        rows.append(
            (
                f"solve_ik_many, {label}, batch of {len(targets)}",
                f"{per * 1e6:.0f} µs CPU/target",
                f"{sum(r.solved for r in res)}/{len(targets)}",
            )
        )
    I.ANALYTIC = True
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--urdf", default="franka_panda/panda.urdf")
    ap.add_argument("--ee", default="panda_hand")
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--restarts", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--null-space-poses", type=int, default=50, help="poses for pybullet's null-space IK")
    args = ap.parse_args()

    model = load_robot_model(args.urdf, ".", args.ee)
    rng = np.random.default_rng(args.seed)
    rows: list[tuple[str, str, str]] = []

    q1 = rng.uniform(model.lower, model.upper, size=(1, model.dof))
    q1000 = rng.uniform(model.lower, model.upper, size=(1000, model.dof))
    F.fk(model, q1)  # warm the plan cache
    rows.append(("FK all links, N=1", f"{per_call(lambda: F.fk(model, q1), 2000) * 1e6:.1f} µs/config", ""))
    rows.append(("FK all links, N=1000", f"{per_call(lambda: F.fk(model, q1000), 20) / 1000 * 1e6:.2f} µs/config", ""))
    rows.append(
        ("FK end effector, N=1000", f"{per_call(lambda: F.ee_pose(model, q1000), 20) / 1000 * 1e6:.2f} µs/config", "")
    )
    rows.append(
        (
            "pybullet FK (getLinkStates), N=1",
            f"{per_call(lambda: pybullet_fk(model, q1[0]), 500) * 1e6:.1f} µs/config",
            "",
        )
    )

    qs = rng.uniform(model.lower, model.upper, size=(args.poses, model.dof))
    targets = F.ee_pose(model, qs)
    n = len(targets)

    rows += analytic_rows(model, qs, targets, args.restarts)
    I.ANALYTIC = False  # the rows below are the numeric solver's (Levenberg-Marquardt), for every arm
    I.clear_ik_cache()
    times, res = timed_solves(lambda i, t: I.solve_ik(model, t, seed=i, restarts=args.restarts), targets)
    ok = sum(r.solved for r in res)
    rows.append(
        (
            f"mrgc solve_ik ({args.restarts} restarts)",
            f"median {statistics.median(times) * 1e3:.2f} ms, mean {statistics.mean(times) * 1e3:.2f} ms",
            f"{ok}/{n}",
        )
    )

    I.clear_ik_cache()
    start = time.perf_counter()
    res = I.solve_ik_many(model, targets, seed=args.seed, restarts=args.restarts)
    per = (time.perf_counter() - start) / n
    rows.append(("mrgc solve_ik_many (batch)", f"{per * 1e3:.2f} ms/target", f"{sum(r.solved for r in res)}/{n}"))

    centre = model.shoulder
    dirs = rng.normal(size=(50, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hard = np.array(
        [tf.from_xyz_rpy(centre + d * rng.uniform(0.8, 0.98) * model.reach, rng.uniform(-3, 3, 3)) for d in dirs]
    )
    I.clear_ik_cache()
    times, res = timed_solves(lambda i, t: I.solve_ik(model, t, seed=i, restarts=args.restarts), hard)
    fails = [t for t, r in zip(times, res) if not r.solved]
    if fails:
        rows.append(
            (
                "mrgc solve_ik, failing (hard targets)",
                f"median {statistics.median(fails) * 1e3:.2f} ms",
                f"{len(fails)}/{len(hard)} failed",
            )
        )

    times, res = timed_solves(lambda i, t: pybullet_ik(model, t, seed=i, restarts=args.restarts), targets)
    ok = sum(r.solved for r in res)
    rows.append(
        (
            f"pybullet IK, DLS ({args.restarts} restarts, 200 it.)",
            f"median {statistics.median(times) * 1e3:.2f} ms, mean {statistics.mean(times) * 1e3:.2f} ms",
            f"{ok}/{n}",
        )
    )
    m = min(args.null_space_poses, n)
    if m:
        times, res = timed_solves(
            lambda i, t: pybullet_ik(model, t, seed=i, restarts=args.restarts, null_space=True), targets[:m]
        )
        rows.append(
            (
                f"pybullet IK, null space + limits ({args.restarts} restarts)",
                f"median {statistics.median(times) * 1e3:.2f} ms",
                f"{sum(r.solved for r in res)}/{m}",
            )
        )

    print("command: python " + " ".join(sys.argv))
    print(f"robot: {model!r}, tolerance 1e-4 m / 1e-3 rad, joint limits enforced")
    print()
    print("| measure | time | solved |")
    print("| --- | --- | --- |")
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
