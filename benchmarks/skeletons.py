"""Skeleton generation speed: generated task graphs × backends × encodings.

    python benchmarks/skeletons.py                                   # the default grid (takes a while)
    python benchmarks/skeletons.py --objects 20 --robots 4 --backends cpsat --encodings time-of-move --repeat 5

For each generated instance (objects, robots, seed) and each backend × encoding it measures, in one fresh
generator, the time to the first skeleton, to K = 10 and to K = 50 (cumulative), with a time limit per
stage.  It prints one line per run and a Markdown table of medians over the instance seeds (``-`` = the
stage hit its time limit in some repeat, ``n/a`` = fewer skeletons exist).
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import build_task_graph
from mrgc.language.model import Fact
from mrgc.planner.skeletons import SkeletonSource

BACKENDS = ["cpsat", "mip", "smt", "pysmt"]
ENCODINGS = ["time-of-move", "disaggregated", "paper"]


def instance(n_objects: int, n_robots: int, seed: int) -> tuple[FactBase, list[str]]:
    """A PA-like fact base whose task graph holds all ``n_objects`` objects.

    Robots stand around a table; each object can be picked by one or two robots with one or two grasps;
    a quarter of the objects (at least 2) are goals in three bins that different robots reach, with
    handovers between robot pairs (always one into the bin when no picking robot reaches it, so every
    instance is feasible); every non-goal object blocks the pick of one earlier object (so Alg. 1
    pulls them all in, acyclically: a random tree below the goals), some objects have a second pick
    obstacle, and half of the goals get a place obstacle.
    """
    rng = random.Random(seed)
    robots = [f"r{i + 1}" for i in range(n_robots)]
    objs = [f"o{i + 1}" for i in range(n_objects)]
    grasps = ["top", "side"]
    bins = ["bin-a", "bin-b", "bin-c"]
    n_goals = max(2, n_objects // 4)
    goal = {o: rng.choice(bins) for o in objs[:n_goals]}
    reach = {b: set(rng.sample(robots, max(1, n_robots // 2))) for b in bins}
    facts = [Fact("in-region", (o, "start")) for o in objs]
    pickers_of = {o: rng.sample(robots, min(len(robots), rng.choice([1, 2]))) for o in objs}
    for i in range(len(objs)):
        facts += _object_facts(rng, i, objs, robots, grasps, n_goals, goal, reach, pickers_of)
    base = FactBase.from_facts(robots, objs, {o: tuple(grasps) for o in objs}, goal, facts)
    return base, list(goal)


def _object_facts(
    rng: random.Random,
    i: int,
    objs: list[str],
    robots: list[str],
    grasps: list[str],
    n_goals: int,
    goal: dict[str, str],
    reach: dict[str, set[str]],
    pickers_of: dict[str, list[str]],
) -> list[Fact]:
    """The facts of the i-th object (see :func:`instance`), drawn from ``rng`` in a fixed order."""
    o = objs[i]
    facts: list[Fact] = []
    if i >= n_goals:  # o blocks the pick of an earlier object, whatever robot and grasp picks it
        parent = objs[rng.randrange(i)]
        facts += [Fact("occludes-pick", (o, parent, g, r)) for r in pickers_of[parent] for g in grasps]
    pickers = pickers_of[o]
    pick_grasps = {}
    for r in pickers:
        pick_grasps[r] = rng.sample(grasps, rng.choice([1, 2]))
        for g in pick_grasps[r]:
            facts.append(Fact("reachable-pick", (o, g, r)))
            facts.append(Fact("reachable-place", (o, "start", g, r)))
    if o in goal:
        facts += _goal_facts(rng, o, goal[o], robots, grasps, reach[goal[o]], pickers, pick_grasps)
    later = objs[max(i + 1, n_goals) :]
    if later and rng.random() < 0.3:
        blocker = rng.choice(later)
        for r in pickers:
            facts.append(Fact("occludes-pick", (blocker, o, rng.choice(grasps), r)))
    if o in goal and later and rng.random() < 0.5:
        b = rng.choice(later)
        facts += [Fact("occludes-goal-place", (b, o, goal[o], g, r)) for r in robots for g in grasps]
    return facts


def _goal_facts(
    rng: random.Random,
    o: str,
    bin_: str,
    robots: list[str],
    grasps: list[str],
    reach: set[str],
    pickers: list[str],
    pick_grasps: dict[str, list[str]],
) -> list[Fact]:
    """A goal object's places into its bin and handovers (always one into the bin when no picking robot
    reaches it)."""
    facts = [Fact("reachable-place", (o, bin_, g, r)) for r in robots if r in reach for g in grasps]
    for r1 in pickers:
        for r2 in robots:
            if r2 != r1 and rng.random() < 0.5:
                facts.append(Fact("enable-goal-handover", (o, pick_grasps[r1][0], "side", r1, r2)))
    if not reach & set(pickers):  # keep the instance feasible: a handover into the bin
        r1, r2 = pickers[0], sorted(reach)[0]
        facts.append(Fact("enable-goal-handover", (o, pick_grasps[r1][0], "top", r1, r2)))
    return facts


def run(base: FactBase, must: list[str], backend: str, encoding: str, limit: float) -> dict[str, float | None]:
    """Cumulative seconds to the 1st, 10th and 50th skeleton (None: time limit; nan: fewer exist)."""
    t0 = time.perf_counter()
    src = SkeletonSource(base, must, backend=backend, encoding=encoding)
    out: dict[str, float | None] = {}
    have = 0
    for label, k in (("first", 1), ("k10", 10), ("k50", 50)):
        batch = src.next(k - have, deadline=time.perf_counter() + limit)
        have += len(batch.skeletons)
        if batch.outcome == "time limit":
            out[label] = None
            for rest in ("first", "k10", "k50"):
                out.setdefault(rest, None)
            break
        out[label] = time.perf_counter() - t0 if have >= k else float("nan")
    return out


def fmt(values: list[float | None]) -> str:
    if any(v is None for v in values):
        return "-"
    nums = [v for v in values if v is not None]
    if all(v != v for v in nums):
        return "n/a"
    return f"{statistics.median([v for v in nums if v == v]):.3f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--objects", type=int, nargs="+", default=[5, 10, 20, 40])
    ap.add_argument("--robots", type=int, nargs="+", default=[2, 4, 6])
    ap.add_argument("--backends", nargs="+", default=BACKENDS)
    ap.add_argument("--encodings", nargs="+", default=ENCODINGS)
    ap.add_argument("--repeat", type=int, default=3, help="instance seeds per size")
    ap.add_argument("--time-limit", type=float, default=20.0, help="seconds per stage")
    args = ap.parse_args()
    warm, must = instance(5, 2, 0)
    for b in args.backends:  # import every solver library before timing anything
        SkeletonSource(warm, must, backend=b, encoding=args.encodings[0]).next(1)
    rows = []
    for n in args.objects:
        for r in args.robots:
            insts = [instance(n, r, seed) for seed in range(args.repeat)]
            graphs = [build_task_graph(base, must) for base, must in insts]
            objects = statistics.median(len(g.objects) for g in graphs)
            size = f"{objects:g}/{statistics.median(len(g.actions) for g in graphs):g}"
            for b in args.backends:
                for e in args.encodings:
                    res = [run(base, must, b, e, args.time_limit) for base, must in insts]
                    row = [
                        f"{n}",
                        f"{r}",
                        size,
                        b,
                        e,
                        fmt([x["first"] for x in res]),
                        fmt([x["k10"] for x in res]),
                        fmt([x["k50"] for x in res]),
                    ]
                    print(" ".join(row), flush=True)
                    rows.append(row)
    print()
    print("| objects | robots | graph objects/actions | backend | encoding | first (s) | K=10 (s) | K=50 (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
