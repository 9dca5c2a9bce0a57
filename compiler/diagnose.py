"""Cheap infeasibility reasons found on the task graph before any solver runs.

An object with no action can never move; an action obstructed by an object that can never move is dead;
objects whose every action is dead can never move either (to a fixpoint).  If an object of M* ends up
unmovable, no skeleton exists at any horizon, and the reasons name the culprits.
"""

from __future__ import annotations

from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import TaskGraph


def dead_actions(graph: TaskGraph) -> tuple[set[int], set[str]]:
    """(indices of actions that can never be executed, objects that can never be moved)."""
    unmovable = {o for o in graph.objects if not graph.actions_of(o)}
    dead: set[int] = set()
    changed = True
    while changed:
        changed = False
        for i in range(len(graph.actions)):
            if i not in dead and any(b in unmovable for b in graph.blockers(i)):
                dead.add(i)
                changed = True
        for o in graph.objects:
            if o not in unmovable and all(i in dead for i in graph.actions_of(o)):
                unmovable.add(o)
                changed = True
    return dead, unmovable


def explain_infeasible(graph: TaskGraph, facts: FactBase) -> list[str]:
    """One sentence per object of M* that can never be moved; empty when none is found this way."""
    dead, unmovable = dead_actions(graph)
    reasons = []
    for obj in graph.must_move:
        if obj not in unmovable:
            continue
        own = graph.actions_of(obj)
        if own:
            culprits = sorted({b for i in own for b in graph.blockers(i) if b in unmovable},
                              key=graph.objects.index)
            reasons.append(f"every action moving {obj} is obstructed by an object no robot can move: "
                           + ", ".join(culprits) + _why_stuck(graph, facts, culprits))
        else:
            reasons.append(_no_action(facts, obj))
    return reasons


def _why_stuck(graph: TaskGraph, facts: FactBase, objs: list[str]) -> str:
    stuck = [o for o in objs if not graph.actions_of(o)]
    return f" ({'; '.join(_no_action(facts, o) for o in stuck)})" if stuck else ""


def _no_action(facts: FactBase, obj: str) -> str:
    is_goal = obj in facts.goal
    region = facts.goal[obj] if is_goal else facts.region.get(obj)
    if region is None:
        return f"{obj} has no known region to be put back in"
    if not any(p[0] == obj for p in facts.reachable_pick):
        return f"no robot can pick {obj}"
    where = "goal region" if is_goal else "region"
    if not any(p[1] == region for p in facts.reachable_place):
        return f"no robot can reach {where} {region}"
    if not any(p[0] == obj and p[1] == region for p in facts.reachable_place):
        return f"no robot can place {obj} in {where} {region}"
    return (f"no robot that can pick {obj} can also place it in {region}"
            + (", and no handover of it is enabled" if is_goal else ""))


def prune(graph: TaskGraph) -> TaskGraph:
    """The graph without dead actions (they can never be selected); objects and M* stay as they are."""
    dead, _ = dead_actions(graph)
    if not dead:
        return graph
    keep = [i for i in range(len(graph.actions)) if i not in dead]
    return TaskGraph(
        robots=graph.robots,
        objects=graph.objects,
        must_move=graph.must_move,
        goal=graph.goal,
        actions=tuple(graph.actions[i] for i in keep),
        block_pick=tuple(graph.block_pick[i] for i in keep),
        block_place=tuple(graph.block_place[i] for i in keep),
        single_handover_point=graph.single_handover_point,
    )
