"""An independent reference for task skeletons, written only from the model's definitions.

It shares no code with ``mrgc.compiler``: ``Action`` and ``TaskGraph`` are used as plain input data (their
fields), nothing else; ``tests/test_layout.py`` keeps it so.  Use it to check a skeleton generator (the
project's own tests do, for every backend and encoding) or a domain of your own (docs/testing.md).

The definitions (DESIGN.md section 5, the paper's "Key Component 1"):

- each action moves exactly one object; every object moves at most once; every object of M* moves;
- a pick obstacle of a selected action moves at a strictly earlier step, a place obstacle at the same step
  or earlier (strictly earlier when the placing robot is in ``strict_place``: it drives through it);
  every obstacle of a selected action moves;
- an object outside M* moves only if it obstructs a selected action;
- a robot does at most one action per step, and a handover occupies both of its robots;
- no step is empty;
- skeletons are ranked by (makespan, number of moved objects); two skeletons are distinct when their sets
  of actions differ, and an action set's makespan is the smallest one any valid schedule of it has.

Contents: :func:`check_skeleton` (violations of one skeleton), :func:`min_makespan` and
:func:`feasible_action_sets` / :func:`oracle_keys` (brute force over action sets: exponential, for small
problems), :func:`reference_task_graph` (Alg. 1 of the paper on raw fact tuples, returned as a
``TaskGraph``) and :func:`problem_graph` (the same from a checked symbolic problem).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence

from mrgc.compiler.task_graph import Action, TaskGraph

if TYPE_CHECKING:
    from mrgc.language.model import Problem


# ------------------------------------------------------------------ helpers on the graph's data
def _obstacles(graph: TaskGraph) -> dict[Action, tuple[frozenset[str], frozenset[str]]]:
    """action -> (strictly-earlier obstacles, same-step-or-earlier obstacles), from the graph's edge lists:
    pick obstacles, and place obstacles of robots in ``graph.strict_place`` (robots that drive through
    them), are strict; other place obstacles are not."""
    out: dict[Action, tuple[frozenset[str], frozenset[str]]] = {}
    for i, a in enumerate(graph.actions):
        pick, place = out.get(a, (frozenset(), frozenset()))
        if a.place_robot in graph.strict_place:
            out[a] = (pick | frozenset(graph.block_pick[i]) | frozenset(graph.block_place[i]), place)
        else:
            out[a] = (pick | frozenset(graph.block_pick[i]), place | frozenset(graph.block_place[i]))
    return out


def _robots(a: Action) -> set[str]:
    return {a.pick_robot, a.place_robot}


def _steps(skeleton: Any) -> list[tuple[Action, ...]]:
    steps = skeleton.steps if hasattr(skeleton, "steps") else skeleton
    return [tuple(s) for s in steps]


# ------------------------------------------------------------------ (a) checking one skeleton
def check_skeleton(graph: TaskGraph, skeleton: Any) -> list[str]:
    """Every way ``skeleton`` (an object with ``.steps``, or a list of steps) breaks the definitions."""
    obstacles = _obstacles(graph)
    bad, step_of, placed = _step_faults(obstacles, _steps(skeleton))
    bad += [f"{o} is in M* but is not moved" for o in graph.must_move if o not in step_of]
    obstructing = _obstacle_faults(obstacles, placed, step_of, bad)
    must = set(graph.must_move)
    for o, t in step_of.items():
        if o not in must and o not in obstructing:
            bad.append(f"{o} is not in M* and obstructs no selected action, but is moved (step {t})")
    return bad


def _step_faults(
    obstacles: dict[Action, tuple[frozenset[str], frozenset[str]]], steps: list[tuple[Action, ...]]
) -> tuple[list[str], dict[str, int], list[tuple[int, Action]]]:
    """Faults of the steps themselves (empty steps, unknown actions, objects moved twice, busy robots), the
    step each object moves at, and every (step, action)."""
    bad: list[str] = []
    step_of: dict[str, int] = {}
    placed: list[tuple[int, Action]] = []
    for t, step in enumerate(steps, 1):
        if not step:
            bad.append(f"step {t} is empty")
        busy: dict[str, Action] = {}
        for a in step:
            placed.append((t, a))
            if a not in obstacles:
                bad.append(f"step {t}: '{a}' is not an action of the task graph")
            if a.obj in step_of:
                bad.append(f"{a.obj} is moved twice (steps {step_of[a.obj]} and {t})")
            else:
                step_of[a.obj] = t
            for r in sorted(_robots(a)):
                if r in busy:
                    bad.append(f"step {t}: robot {r} does two actions ('{busy[r]}' and '{a}')")
                else:
                    busy[r] = a
    return bad, step_of, placed


def _obstacle_faults(
    obstacles: dict[Action, tuple[frozenset[str], frozenset[str]]],
    placed: list[tuple[int, Action]],
    step_of: dict[str, int],
    bad: list[str],
) -> set[str]:
    """Add to ``bad`` the obstacles that do not move in time (pick: strictly earlier, place: no later); the
    objects that obstruct a selected action."""
    obstructing: set[str] = set()
    for t, a in placed:
        pick, place = obstacles.get(a, (frozenset(), frozenset()))
        obstructing |= pick | place
        for o in sorted(pick):
            if o not in step_of:
                bad.append(f"pick obstacle {o} of '{a}' (step {t}) is never moved")
            elif not step_of[o] < t:
                bad.append(f"pick obstacle {o} of '{a}' (step {t}) moves at step {step_of[o]}, not strictly earlier")
        for o in sorted(place):
            if o not in step_of:
                bad.append(f"place obstacle {o} of '{a}' (step {t}) is never moved")
            elif not step_of[o] <= t:
                bad.append(f"place obstacle {o} of '{a}' (step {t}) moves later, at step {step_of[o]}")
    return obstructing


# ------------------------------------------------------------------ (b) brute force
def _valid_selection(
    graph: TaskGraph, actions: Iterable[Action], obstacles: Mapping[Action, tuple[frozenset[str], frozenset[str]]]
) -> bool:
    """The schedule-free rules: one action per object, M* moved, obstacles moved, no needless move."""
    acts = list(actions)
    moved = [a.obj for a in acts]
    if len(moved) != len(set(moved)) or any(a not in obstacles for a in acts):
        return False
    moved_set = set(moved)
    needed: set[str] = set()
    for a in acts:
        needed |= obstacles[a][0] | obstacles[a][1]
    if not set(graph.must_move) <= moved_set or not needed <= moved_set:
        return False
    return moved_set <= needed | set(graph.must_move)


def min_makespan(graph: TaskGraph, actions: Iterable[Action]) -> int | None:
    """The smallest number of steps of a valid schedule of exactly ``actions`` (None: no schedule).

    Tries makespan m = 1, 2, ... and assigns every action a step in 1..m by backtracking; the first m
    that works leaves no step empty (an empty step could be squeezed out, giving a smaller m).
    """
    obstacles = _obstacles(graph)
    acts = sorted(set(actions), key=lambda a: (a.obj, str(a)))
    if not _valid_selection(graph, acts, obstacles):
        return None
    if not acts:
        return 0
    by_obj = {a.obj: a for a in acts}
    # pairwise relations: (i, j, kind) meaning step[i] < step[j] ('<'), step[i] <= step[j] ('<='),
    # or step[i] != step[j] ('!=', a shared robot)
    rel: list[list[tuple[int, str]]] = [[] for _ in acts]  # rel[j]: constraints against earlier i < j
    index = {a: k for k, a in enumerate(acts)}
    for a in acts:
        pick, place = obstacles[a]
        for o in pick:
            b = by_obj[o]
            _relate(rel, index[b], index[a], "<")
        for o in place - pick:
            b = by_obj[o]
            _relate(rel, index[b], index[a], "<=")
    for i, a in enumerate(acts):
        for j in range(i + 1, len(acts)):
            if _robots(a) & _robots(acts[j]):
                _relate(rel, i, j, "!=")
    for m in range(1, len(acts) + 1):
        if _assign(rel, [0] * len(acts), 0, m):
            return m
    return None


def _relate(rel: list[list[tuple[int, str]]], i: int, j: int, kind: str) -> None:
    """Record ``step[i] kind step[j]`` under the later of the two indices."""
    if i < j:
        rel[j].append((i, kind))
    elif i > j:
        flipped = {"<": ">", "<=": ">=", "!=": "!="}[kind]
        rel[i].append((j, flipped))
    else:  # an action obstructed by its own object: impossible for "<", trivial for "<="
        rel[i].append((i, kind))


def _assign(rel: list[list[tuple[int, str]]], step: list[int], k: int, m: int) -> bool:
    if k == len(step):
        return True
    for s in range(1, m + 1):
        step[k] = s
        ok = True
        for i, kind in rel[k]:
            # constraint "step[i] kind step[k]" (i < k) or, for i == k, "step[k] kind step[k]"
            x, y = step[i], s
            if (
                (kind == "<" and not x < y)
                or (kind == "<=" and not x <= y)
                or (kind == ">" and not x > y)
                or (kind == ">=" and not x >= y)
                or (kind == "!=" and not x != y)
            ):
                ok = False
                break
        if ok and _assign(rel, step, k + 1, m):
            return True
    step[k] = 0
    return False


def feasible_action_sets(graph: TaskGraph) -> dict[frozenset[Action], int]:
    """Every action set that has a valid schedule, with its minimum makespan.

    Search over subsets: each object of the graph is either not moved or moved by one of its actions
    (objects of M* must move).  Partial selections are cut as soon as an obstacle of a chosen action is
    decided "not moved"; the remaining rules are checked on the complete selection.
    """
    obstacles = _obstacles(graph)
    objects = list(dict.fromkeys(list(graph.objects) + [a.obj for a in graph.actions]))
    options: dict[str, list[Action]] = {o: [] for o in objects}
    for a in obstacles:
        options[a.obj].append(a)
    must = set(graph.must_move)
    out: dict[frozenset[Action], int] = {}
    choice: dict[str, Action | None] = {}

    def dfs(k: int) -> None:
        if k == len(objects):
            selected = frozenset(a for a in choice.values() if a is not None)
            m = min_makespan(graph, selected)
            if m is not None:
                out[selected] = m
            return
        o = objects[k]
        alternatives: list[Action | None] = list(options[o])
        if o not in must:
            alternatives.insert(0, None)
        for a in alternatives:
            choice[o] = a
            if _consistent(o, choice, obstacles, options):
                dfs(k + 1)
            del choice[o]

    dfs(0)
    return out


def _consistent(
    o: str,
    choice: dict[str, Action | None],
    obstacles: dict[Action, tuple[frozenset[str], frozenset[str]]],
    options: dict[str, list[Action]],
) -> bool:
    """Whether the choice just made for ``o`` keeps the partial selection consistent: a chosen action's
    obstacles are objects that may still move; an object left unmoved obstructs no chosen action."""

    def blockers(a: Action) -> frozenset[str]:
        return obstacles[a][0] | obstacles[a][1]

    a = choice[o]
    if a is not None:
        return all(b in options and not (b in choice and choice[b] is None) for b in blockers(a))
    return not any(c is not None and o in blockers(c) for c in choice.values())


def oracle_keys(graph: TaskGraph) -> list[tuple[int, int]]:
    """The sorted (makespan, moved objects) keys of every feasible action set: the exact key sequence a
    correct enumeration of distinct skeletons produces."""
    return sorted((m, len(s)) for s, m in feasible_action_sets(graph).items())


# ------------------------------------------------------------------ Alg. 1 on raw facts
def reference_task_graph(
    robots: Sequence[str],
    grasps: Mapping[str, Sequence[str]],
    goal: Mapping[str, str],
    region: Mapping[str, str],
    facts: Iterable[tuple[str, ...]],
    must_move: Sequence[str],
    moved: Iterable[str] = (),
) -> TaskGraph:
    """Alg. 1 (AddObject for every object of M*) on fact tuples ``(predicate, arg, ...)``.

    ``moved`` are the objects of the already grounded suffix S' (they move later, once): they get no node
    and are not in M*, and an action one of them obstructs is left out, since that object is still in
    place when the action would run (the project's reading of the paper's "M excludes S'").

    Target region: the goal region of a goal object, else the object's current region.  Direct actions need
    ReachablePick and ReachablePlace(target) with the same robot and grasp; handovers (goal objects only)
    need ReachablePick(g1, R1), EnableGoalHandover(g1, g2, R1, R2) with R1 != R2 and
    ReachablePlace(target, g2, R2); relays (goal objects only, beyond the paper) need ReachablePick(g1, R1),
    EnableRelay(Re, g1, g2, R1, R2) with Re not the target and ReachablePlace(target, g2, R2).  Pick
    obstacles: OccludesPick(Mj, M, g_pick, R_pick), and for a handover OccludesHandover(Mj, M, g_pick, g_place,
    R_pick, R_place), for a relay OccludesRelay(Mj, M, Re, g_pick, g_place, R_pick, R_place); place obstacles
    (goal objects only):
    OccludesGoalPlace(Mj, M, target, g_place, R_place).  Obstacles join the graph recursively.  Edges and
    actions are compared as sets by the tests, so order is not meaningful here.
    """
    facts = {tuple(f) for f in facts}
    pick = {f[1:] for f in facts if f[0] == "reachable-pick"}
    place = {f[1:] for f in facts if f[0] == "reachable-place"}
    hand = {f[1:] for f in facts if f[0] == "enable-goal-handover"}
    relay = {f[1:] for f in facts if f[0] == "enable-relay"}
    occ_pick = {f[1:] for f in facts if f[0] == "occludes-pick" and f[1] != f[2]}
    occ_place = {f[1:] for f in facts if f[0] == "occludes-goal-place" and f[1] != f[2]}
    occ_hand = {f[1:] for f in facts if f[0] == "occludes-handover" and f[1] != f[2]}
    occ_relay = {f[1:] for f in facts if f[0] == "occludes-relay" and f[1] != f[2]}
    done = set(moved)
    must_move = [m for m in dict.fromkeys(must_move) if m not in done]
    movable = sorted({f[1] for f in facts if f[0] == "in-region"} | set(goal) | set(must_move) | done)
    nodes: list[str] = []
    actions: list[Action] = []
    bp: list[tuple[str, ...]] = []
    bl: list[tuple[str, ...]] = []

    def add_object(m: str) -> None:
        if m in nodes or m in done:
            return
        nodes.append(m)
        target = goal.get(m, region.get(m))
        if target is None:
            return
        acts = _actions_of(m, target, m in goal, robots, grasps.get(m, ()), pick, place, hand)
        if m in goal:
            acts += [
                Action(m, target, r1, r2, g1, g2, via)
                for (o, via, g1, g2, r1, r2) in sorted(relay)
                if o == m and via != target and (m, g1, r1) in pick and (m, target, g2, r2) in place
            ]
        for a in acts:
            p = tuple(
                mj
                for mj in movable
                if (mj, m, a.pick_grasp, a.pick_robot) in occ_pick
                or (a.handover and (mj, m, a.pick_grasp, a.place_grasp, a.pick_robot, a.place_robot) in occ_hand)
                or (
                    a.via is not None
                    and (mj, m, a.via, a.pick_grasp, a.place_grasp, a.pick_robot, a.place_robot) in occ_relay
                )
            )
            q = tuple(mj for mj in movable if m in goal and (mj, m, target, a.place_grasp, a.place_robot) in occ_place)
            if done & set(p + q):
                continue
            actions.append(a)
            bp.append(p)
            bl.append(q)
            for mj in p + q:
                add_object(mj)

    for m in must_move:
        add_object(m)
    return TaskGraph(
        robots=tuple(robots),
        objects=tuple(nodes),
        must_move=tuple(must_move),
        goal={o: r for o, r in goal.items() if o in nodes},
        actions=tuple(actions),
        block_pick=tuple(bp),
        block_place=tuple(bl),
    )


def _actions_of(
    m: str,
    target: str,
    is_goal: bool,
    robots: Sequence[str],
    grasps: Sequence[str],
    pick: set[tuple[str, ...]],
    place: set[tuple[str, ...]],
    hand: set[tuple[str, ...]],
) -> list[Action]:
    """Object ``m``'s actions into ``target``, by picking robot and grasp: the direct one (same robot and
    grasp), then the handovers (goal objects only)."""
    out = []
    for r1 in robots:
        for g1 in grasps:
            if (m, g1, r1) not in pick:
                continue
            if (m, target, g1, r1) in place:
                out.append(Action(m, target, r1, r1, g1, g1))
            if is_goal:
                out += [
                    Action(m, target, r1, r2, g1, g2)
                    for r2 in robots
                    if r2 != r1
                    for g2 in grasps
                    if (m, g1, g2, r1, r2) in hand and (m, target, g2, r2) in place
                ]
    return out


def graph_signature(
    graph: TaskGraph,
) -> tuple[frozenset[str], frozenset[str], frozenset[tuple[Action, frozenset[str], frozenset[str]]]]:
    """(objects, M*, {(action, pick obstacles, place obstacles)}): a graph up to the order of its lists."""
    return (
        frozenset(graph.objects),
        frozenset(graph.must_move),
        frozenset(
            (a, frozenset(graph.block_pick[i]), frozenset(graph.block_place[i])) for i, a in enumerate(graph.actions)
        ),
    )


def problem_graph(problem: "Problem", must_move: Sequence[str] | None = None, moved: Iterable[str] = ()) -> TaskGraph:
    """:func:`reference_task_graph` of a checked problem's facts (its ``:init``): M* defaults to the goal
    objects not already in their goal region; ``moved`` are the objects of a grounded suffix.  It reads the
    facts, it does not compute them: a geometric problem's own file (no facts in its ``:init``) gives an
    empty graph, which reads as "infeasible"; give it the file ``mrgc facts -o`` writes (a facts file with
    only ``in-region`` facts is a problem whose robots reach nothing, and is infeasible indeed).
    """
    facts = [(f.predicate, *f.args) for f in problem.init]
    region = {f.args[0]: f.args[1] for f in problem.init if f.predicate == "in-region"}
    if must_move is None:
        must_move = [o for o, r in problem.goal_regions.items() if region.get(o) != r]
    return reference_task_graph(
        [r.name for r in problem.robots],
        {m.name: problem.grasps_of(m.name) for m in problem.movable},
        problem.goal_regions,
        region,
        facts,
        must_move,
        moved,
    )
