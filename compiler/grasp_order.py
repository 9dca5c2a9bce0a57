"""Which grasps a skeleton's actions use when the solver had a free choice: the ones declared first.

The skeleton model ranks skeletons by (makespan, moved objects) only, so among actions that differ in
their grasps alone the solver returns whichever its search meets first.  Two actions are *interchangeable*
when they move the same object to the same region with the same robots (and the same relay region) and
have the same obstacles, the same pick obstacles and the same place obstacles: every constraint of the
model reads only those, so one stands in for the other in any skeleton and schedule, and the skeleton
stays valid with the same makespan and moved objects.  Among interchangeable actions the preferred one is
the first in the task graph's order, which is the order the grasps are declared in (``:grasps`` of the
domain, or an object's own list; Alg. 1 goes through them in that order, pick grasp first, then the place
grasp of a handover).

Why it matters: the grasps decide the geometry.  On the PA presets a side grasp of an obstacle cleared
aside lands the arm among the crowded start region's neighbours and often finds no placement there, where
the top grasp (declared first) places it at once; Ap1 tries the actions in declared order too.  Measured:
docs/benchmarks.md, "Session 31".  The preference never removes a skeleton: the generator gives the
preferred form of a solution first and the solver's own form later, when it comes again (compiler/
enumerate.py).
"""

from __future__ import annotations

from typing import Collection

from mrgc.compiler.task_graph import TaskGraph


def interchangeable(graph: TaskGraph, i: int) -> list[int]:
    """The actions of ``graph`` interchangeable with action ``i`` (``i`` among them), in the graph's order."""
    a = graph.actions[i]
    same = (a.region, a.pick_robot, a.place_robot, a.via)
    pick, place = set(graph.block_pick[i]), set(graph.block_place[i])
    return [
        j
        for j in graph.actions_of(a.obj)
        if (graph.actions[j].region, graph.actions[j].pick_robot, graph.actions[j].place_robot, graph.actions[j].via)
        == same
        and set(graph.block_pick[j]) == pick
        and set(graph.block_place[j]) == place
    ]


def preferred(graph: TaskGraph, chosen: Collection[int], kept_out: Collection[int] = ()) -> dict[int, int]:
    """Each action of ``chosen`` (indices of ``graph``'s actions) -> the first action interchangeable with
    it that is not ``kept_out`` (deferred: the model has them out); itself when none comes before it."""
    return {i: next(j for j in interchangeable(graph, i) if j == i or j not in kept_out) for i in chosen}
