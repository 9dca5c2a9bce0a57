"""Cheap infeasibility reasons found on the task graph before any solver runs.

An object with no action can never move; an action obstructed by an object that can never move is dead;
objects whose every action is dead can never move either (to a fixpoint).  If an object of M* ends up
unmovable, no skeleton exists at any horizon, and the reasons name the culprits.

Blocking cycles: when *every* live action of object A is obstructed at its pick by B, B must move strictly
before A (and, for an obstruction at the place, no later than A).  Such forced orders among the objects
that must move (M* and, transitively, what they force) that close a cycle through a strict edge admit no
schedule at all: :func:`blocking_cycles` names them (two boxes that each block every pick of the other).
"""

from __future__ import annotations

from mrgc.compiler.facts import FactBase
from mrgc.compiler.task_graph import Action, TaskGraph

#: a forced order: (object, blocker, strict, the object's live actions) -- the blocker moves before the
#: object (strictly when ``strict``: it obstructs every pick; else it obstructs every action somewhere)
Forced = tuple[str, str, bool, tuple[Action, ...]]


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
            culprits = sorted({b for i in own for b in graph.blockers(i) if b in unmovable}, key=graph.objects.index)
            reasons.append(
                f"every action moving {obj} is obstructed by an object no robot can move: "
                + ", ".join(culprits)
                + _why_stuck(graph, facts, culprits)
            )
        else:
            reasons.append(_no_action(facts, obj))
    if not reasons:
        reasons = [describe_cycle(c) for c in blocking_cycles(graph)]
    return reasons


def blocking_cycles(graph: TaskGraph) -> list[list[Forced]]:
    """Cycles of forced move orders (see the module docstring) among the objects that must move; each cycle
    is its edges in order (object, blocker, strict, actions), at least one of them strict.  Empty when none."""
    dead, _ = dead_actions(graph)
    live = {o: [i for i in graph.actions_of(o) if i not in dead] for o in graph.objects}
    forced: dict[str, list[Forced]] = {}
    for o, acts in live.items():
        if not acts:
            continue
        picks = set.intersection(*(set(graph.block_pick[i]) for i in acts))
        anywhere = set.intersection(*(set(graph.blockers(i)) for i in acts))
        actions = tuple(graph.actions[i] for i in acts)
        forced[o] = [(o, b, b in picks, actions) for b in sorted(anywhere, key=graph.objects.index) if b != o]
    # the objects that must move: M* and whatever they force, transitively
    need, todo = set(graph.must_move), list(graph.must_move)
    while todo:
        for _, b, _, _ in forced.get(todo.pop(), []):
            if b not in need:
                need.add(b)
                todo.append(b)
    cycles: list[list[Forced]] = []
    seen: set[frozenset[str]] = set()
    for start in sorted(need, key=graph.objects.index):
        cycle = _cycle_from(start, forced, need)
        if cycle and any(strict for _, _, strict, _ in cycle):
            key = frozenset(o for o, _, _, _ in cycle)
            if key not in seen:
                seen.add(key)
                cycles.append(cycle)
    return cycles


def _cycle_from(start: str, forced: dict[str, list[Forced]], need: set[str]) -> list[Forced]:
    """The first cycle through ``start`` (depth first, edges in a fixed order), preferring strict edges."""
    stack: list[tuple[str, list[Forced]]] = [(start, [])]
    visited: set[str] = set()
    while stack:
        node, path = stack.pop()
        for edge in sorted(forced.get(node, []), key=lambda e: (e[2], e[1]))[::-1]:
            _, b, _, _ = edge
            if b == start:
                return path + [edge]
            if b in need and b not in visited:
                visited.add(b)
                stack.append((b, path + [edge]))
    return []


def describe_cycle(cycle: list[Forced]) -> str:
    """One line naming a blocking cycle: its objects and, per edge, the actions obstructed."""
    ring = " -> ".join([o for o, _, _, _ in cycle] + [cycle[0][0]])
    parts = []
    for o, b, strict, actions in cycle:
        where = "pick" if strict else "action"
        parts.append(f"every {where} of {o} ({', '.join(_short(a) for a in actions)}) is obstructed by {b}")
    return f"blocking cycle {ring}: " + "; ".join(parts)


def _short(a: Action) -> str:
    return (
        f"{a.pick_grasp} by {a.pick_robot}"
        if not a.handover
        else f"{a.pick_grasp}->{a.place_grasp} by {a.pick_robot}->{a.place_robot}"
    )


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
    return f"no robot that can pick {obj} can also place it in {region}" + (
        ", and no handover of it is enabled" if is_goal else ""
    )


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
        strict_place=graph.strict_place,
    )
