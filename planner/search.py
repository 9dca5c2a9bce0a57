"""``mrgc plan``: phase 1, then the MCTS over skeletons with reverse-search grounding, then a Plan.

Symbolic problems have no geometry to ground: their plan is the best skeleton (documented in
docs/planner.md).  The outcome is a status on the plan (``solved``, ``no plan``, ``time limit``) with
statistics: time per phase, skeletons generated and grounded, tree size, geometric queries.
"""

from __future__ import annotations

import time
from typing import Any, Callable

from mrgc.compiler.facts import FactBase
from mrgc.compiler.skeleton import Skeleton
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.model import Problem
from mrgc.planner.ground import GroundedStep, ReverseGrounder
from mrgc.planner.mcts import MCTS
from mrgc.planner.plan import Plan, PlannedAction
from mrgc.planner.skeletons import DEFAULT_BACKEND, DEFAULT_ENCODING, SkeletonSource, must_move, problem_facts


def plan_problem(problem: Problem, problem_file: str, sha256: str, version: str, backend: str = DEFAULT_BACKEND,
                 encoding: str = DEFAULT_ENCODING, seed: int = 0, time_limit: float = 60.0, c: float = 1.0,
                 alpha: float = 1.0, skeletons: int = 5, max_makespan: int | None = None) -> Plan:
    """Plan ``problem`` (see the module docstring)."""
    t0 = time.perf_counter()
    deadline = t0 + time_limit
    facts, facts_seconds = problem_facts(problem, seed=seed)
    base = FactBase.from_problem(problem, facts)
    plan = Plan(problem.name, problem_file, sha256, version, backend, encoding, seed, "no plan",
                symbolic=problem.symbolic)
    stats: dict[str, Any] = {"robots": [r.name for r in problem.robots], "facts": len(facts),
                             "facts_seconds": round(facts_seconds, 4)}
    start = must_move(problem, facts)

    def sources(need: set[str], moved: set[str]) -> Callable[[int], list[Skeleton]]:
        src = SkeletonSource(base, sorted(need, key=_order(problem)), sorted(moved), backend, encoding,
                             max_makespan, seed)

        def more(k: int) -> list[Skeleton]:
            left = max(0.01, deadline - time.perf_counter())
            return src.next(k, time_limit=left).skeletons

        return more

    if problem.symbolic:
        first = sources(set(start), set())(1)
        if first:
            plan.status = "solved"
            plan.steps = [[_planned(a) for a in step] for step in first[0].steps]
        stats["skeleton_seconds"] = round(time.perf_counter() - t0 - facts_seconds, 4)
    else:
        scene = scene_from_problem(problem)
        grounder = Grounder(scene, seed=seed)
        reverse = ReverseGrounder(grounder, problem.goal_regions)
        count = [0]

        def ground(skel: Skeleton, suffix: list[GroundedStep]):  # type: ignore[no-untyped-def]
            count[0] += 1
            return reverse.ground(skel, suffix, key=str(count[0]))

        search = MCTS(ground, sources, set(start), c=c, alpha=alpha, k=skeletons)
        result = search.run(deadline)
        if result.steps is not None:
            plan.status = "solved"
            plan.steps = [s.actions for s in result.steps]
        elif time.perf_counter() >= deadline:
            plan.status = "time limit"
        stats.update({k: (round(v, 4) if isinstance(v, float) else v) for k, v in result.stats.items()})
        stats["iterations"] = result.iterations
        stats["geometric_queries"] = grounder.queries
    stats["seconds"] = round(time.perf_counter() - t0, 4)
    plan.stats = stats
    return plan


def _planned(a: Any) -> PlannedAction:
    return PlannedAction(a.obj, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp)


def _order(problem: Problem) -> Callable[[str], int]:
    index = {m.name: i for i, m in enumerate(problem.movable)}
    return lambda o: index.get(o, len(index))
