"""Cheap infeasibility reasons found on the task graph before any solver runs.

An object with no action can never move; an action obstructed by an object that can never move is dead;
objects whose every action is dead can never move either (to a fixpoint).  If an object of M* ends up
unmovable, no skeleton exists at any horizon, and the reasons name the culprits.

Blocking cycles: when *every* live action of object A is obstructed at its pick by B, B must move strictly
before A (and, for an obstruction at the place, no later than A).  Such forced orders among the objects
that must move (M* and, transitively, what they force) that close a cycle through a strict edge admit no
schedule at all: :func:`blocking_cycles` names them (two boxes that each block every pick of the other).

Waits with alternatives: an object may have several actions, each obstructed by a different object (a cart
can leave a room through either of two doorways, each blocked by a box), so no single blocker is forced and
there is no blocking cycle, yet no order exists: every way out waits for an object that itself waits.
:func:`orderable` computes, to a fixpoint, the objects some order of moves can move (each moved once, to its
target region: a goal object only into its goal region); :func:`explain_waits` names the objects of M*
left out and, per object, what each of its actions waits for.  The fixpoint relaxes the skeleton model
(no robot capacity, no horizon; a non-strict place obstacle may move in the same step), so an object it
leaves out cannot be moved by any skeleton: the reason is sound.
"""

from __future__ import annotations

from typing import Iterable

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
    if not reasons:
        reasons = explain_waits(graph)
    return reasons


def orderable(graph: TaskGraph) -> set[str]:
    """The objects some order of moves can move, layer by layer: an object joins a layer when one of its
    actions has every strict obstacle in earlier layers and every other obstacle in earlier layers or this
    one (the layer is the largest such set).  A relaxation of the skeleton model (module docstring)."""
    done: set[str] = set()
    while True:
        layer = {o for o in graph.objects if o not in done and graph.actions_of(o)}
        changed = True
        while changed:
            ready = {o for o in layer if any(_ready(graph, i, done, layer) for i in graph.actions_of(o))}
            changed = ready != layer
            layer = ready
        if not layer:
            return done
        done |= layer


def _ready(graph: TaskGraph, i: int, done: set[str], layer: set[str]) -> bool:
    return all(b in done or (not strict and b in layer) for b, strict in graph.obstacles(i))


def explain_waits(graph: TaskGraph) -> list[str]:
    """One sentence when objects of M* wait for each other with alternatives (module docstring): the
    objects that no order of moves reaches, and per object what each group of its actions waits for;
    empty when every object of M* is :func:`orderable`."""
    ok = orderable(graph)
    stuck = [o for o in graph.must_move if o not in ok]
    if not stuck:
        return []
    told: list[str] = []
    todo = list(stuck)
    parts = []
    while todo:
        obj = todo.pop(0)
        if obj in told:
            continue
        told.append(obj)
        groups: dict[tuple[tuple[str, ...], str], list[Action]] = {}
        for i in graph.actions_of(obj):
            waits = tuple(dict.fromkeys(b for b, _ in graph.obstacles(i) if b not in ok))
            where = " and ".join(
                w
                for w, blocks in (("pick", graph.block_pick[i]), ("place", graph.block_place[i]))
                if any(b in blocks for b in waits)
            )
            groups.setdefault((waits, where), []).append(graph.actions[i])
            todo.extend(b for b in waits if b not in told)
        parts.append(f"{obj} waits for " + " or ".join(_wait(w, where, acts) for (w, where), acts in groups.items()))
    return [
        f"no order of moves exists for {', '.join(stuck)} (each object moves once, a goal object only into its "
        f"goal region; every action waits for an object that itself waits): " + "; ".join(parts)
    ]


def _wait(waits: tuple[str, ...], where: str, actions: list[Action], shown: int = 2) -> str:
    listed = ", ".join(_short(a) for a in actions[:shown]) + (
        f", +{len(actions) - shown} more" if len(actions) > shown else ""
    )
    return f"{' and '.join(waits)} (the {where} of {listed})"


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
    if a.via is not None:
        return f"{a.pick_grasp}->{a.place_grasp} by {a.pick_robot}->{a.place_robot} via {a.via}"
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
    return (
        f"no robot that can pick {obj} can also place it in {region}"
        + (", and no handover or relay of it is enabled" if is_goal else "")
        + _pick_and_place(facts, obj, region, is_goal)
    )


def _pick_and_place(facts: FactBase, obj: str, region: str, is_goal: bool) -> str:
    """Who picks ``obj`` with which grasps, who places it in ``region``, and (a goal object) the handovers of
    it that are enabled, none of which links the two: `` (picked by r1 with top/top-x; ...)``."""

    def by(entries: Iterable[tuple[str, str]]) -> str:
        grasps: dict[str, list[str]] = {}
        for g, r in sorted(entries, key=lambda e: (facts.robots.index(e[1]), e[0])):
            grasps.setdefault(r, []).append(g)
        return ", ".join(f"{r} with {'/'.join(gs)}" for r, gs in grasps.items())

    picks = by((g, r) for o, g, r in facts.reachable_pick if o == obj)
    places = by((g, r) for o, re, g, r in facts.reachable_place if o == obj and re == region)
    text = f" (picked by {picks}; placed in {region} by {places}"
    if is_goal:
        pairs = sorted({(g1, g2) for o, g1, g2, _, _ in facts.handover if o == obj})
        text += (
            f"; handovers of it only between grasps {', '.join(f'{a}->{b}' for a, b in pairs)}"
            if pairs
            else "; no handover of it between any grasps"
        )
    return text + ")"


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
