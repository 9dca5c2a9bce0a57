"""The collaborative manipulation task graph (CMTG, :mod:`mrgc.compiler.task_graph`) as Graphviz DOT.

Styled as the paper's figure: object nodes are circles, filled red for the objects that must be moved (M*);
action nodes are rounded rectangles labelled with robots, object, region and grasps; *action edges* (object
→ action that moves it) are yellow, *block-pick edges* (action → object obstructing its pick) blue,
*block-place edges* (action → object obstructing its place) purple.  With a skeleton highlighted, its
actions are filled and carry their step, and their action edges are drawn thick.  The text depends only on
the problem (and the facts phase 1 computes for a geometric problem), so it can be kept as a golden file.
``.svg`` and ``.png`` come from Graphviz's ``dot`` program.
"""

from __future__ import annotations

import shutil
import subprocess
from typing import Any

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action, TaskGraph
from mrgc.errors import MissingBackendError, MrgcError
from mrgc.language.model import Problem
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING

FORMATS = (".dot", ".svg", ".png")
MUST_MOVE = "#e41a1c"  # red, as the paper's M* nodes
ACTION_EDGE = "#e6ab02"  # yellow
BLOCK_PICK = "#1f78b4"  # blue
BLOCK_PLACE = "#7b3294"  # purple
HIGHLIGHT = "#fff3b0"
DOT_SECONDS = 300
#: a graph with more actions than this is large: clustered by object, and only a skeleton drawn by default
LARGE_ACTIONS = 24
#: the size guard: a drawing wider or higher than this (pixels at :data:`DPI`) is scaled down to fit
MAX_PIXELS = 2400
DPI = 96


def _q(text: str) -> str:
    """A DOT string; ``\\n`` in ``text`` stays a DOT line break (names hold no backslashes)."""
    return '"' + text.replace('"', '\\"') + '"'


def to_dot(
    graph: TaskGraph,
    name: str,
    skeleton: Skeleton | None = None,
    skeleton_index: int | None = None,
    only_skeleton: bool = False,
    clusters: bool = False,
) -> str:
    """The DOT text of ``graph`` (problem ``name``), ``skeleton`` highlighted when given; with
    ``only_skeleton`` just its actions, the objects they move and the objects in their way (and M*); with
    ``clusters`` each object boxed together with the actions that move it."""
    step_of = {a: t for t, step in enumerate(skeleton.steps, 1) for a in step} if skeleton else {}
    must = set(graph.must_move)
    shown = [i for i, a in enumerate(graph.actions, 1) if not only_skeleton or a in step_of]
    objects = [o for o in graph.objects if not only_skeleton or o in _touched(graph, shown) | must]
    title = (
        f"CMTG of {name}: {len(graph.objects)} objects, {len(graph.actions)} actions; "
        f"M* = {{{', '.join(graph.must_move)}}}"
    )
    if skeleton is not None:
        title += f"\\nskeleton {skeleton_index}: makespan {skeleton.makespan}, moves {', '.join(skeleton.moved)}"
    if only_skeleton:
        title += f"\\nskeleton {skeleton_index}'s {len(shown)} actions only (mrgc graph --full draws all)"
    lines = [
        f"digraph {_q('cmtg ' + name)} {{",
        f"  graph [label={_q(title)}, labelloc=t, fontname=Helvetica, rankdir=LR, nodesep=0.25];",
        "  node [fontname=Helvetica, fontsize=10];",
        "  edge [arrowsize=0.7, fontname=Helvetica, fontsize=9];",
    ]
    if clusters:
        lines += _clusters(graph, objects, shown, must, step_of)
    else:
        lines += [_object_node(graph, o, must) for o in objects]
        lines += [_action_node(graph.actions[i - 1], i, step_of) for i in shown]
    for i in shown:
        a = graph.actions[i - 1]
        width = ", penwidth=3" if a in step_of else ""
        lines.append(f'  {_q(a.obj)} -> "a{i}" [color="{ACTION_EDGE}"{width}];')
        for o in graph.block_pick[i - 1]:
            lines.append(f'  "a{i}" -> {_q(o)} [color="{BLOCK_PICK}", tooltip="block-pick"];')
        for o in graph.block_place[i - 1]:
            lines.append(f'  "a{i}" -> {_q(o)} [color="{BLOCK_PLACE}", tooltip="block-place"];')
    lines += [
        "  subgraph cluster_legend {",
        '    label="legend"; fontsize=9; color=grey;',
        f'    "legend: must move" [shape=circle, style=filled, fillcolor="{MUST_MOVE}", fontcolor=white, '
        'label="M*", fontsize=8];',
        '    "legend: action" [shape=box, style=rounded, label="action", fontsize=8];',
        '    "legend: object" [shape=circle, label="object", fontsize=8];',
        f'    "legend: must move" -> "legend: action" [color="{ACTION_EDGE}", label="action", fontsize=8];',
        f'    "legend: action" -> "legend: object" [color="{BLOCK_PICK}", label="block-pick", fontsize=8];',
        f'    "legend: action" -> "legend: object" [color="{BLOCK_PLACE}", label="block-place", fontsize=8];',
        "  }",
        "}",
    ]
    return "\n".join(lines) + "\n"


def _clusters(
    graph: TaskGraph, objects: list[str], shown: list[int], must: set[str], step_of: dict[Action, int]
) -> list[str]:
    """Each object's node boxed with the nodes of the actions moving it (an object nothing moves: alone)."""
    nodes = {o: [_object_node(graph, o, must)] for o in objects}
    for i in shown:
        nodes[graph.actions[i - 1].obj].append(_action_node(graph.actions[i - 1], i, step_of))
    lines = []
    for o in objects:
        if len(nodes[o]) == 1:
            lines += nodes[o]
            continue
        lines.append(f"  subgraph {_q('cluster_' + o)} {{")
        lines.append(f'    label={_q("moves of " + o)}; style=rounded; color="#bbbbbb"; fontsize=9;')
        lines += ["  " + n for n in nodes[o]]
        lines.append("  }")
    return lines


def _touched(graph: TaskGraph, shown: list[int]) -> set[str]:
    """The objects the actions ``shown`` (1-based) move or are blocked by."""
    out: set[str] = set()
    for i in shown:
        out.add(graph.actions[i - 1].obj)
        out.update(graph.block_pick[i - 1], graph.block_place[i - 1])
    return out


def _object_node(graph: TaskGraph, o: str, must: set[str]) -> str:
    style = f'style=filled, fillcolor="{MUST_MOVE}", fontcolor=white' if o in must else "style=solid"
    goal = f"\\n→ {graph.goal[o]}" if o in graph.goal else ""
    return f"  {_q(o)} [shape=circle, {style}, label={_q(o + goal)}];"


def _action_node(a: Action, i: int, step_of: dict[Action, int]) -> str:
    who = a.pick_robot if not a.handover else f"{a.pick_robot}→{a.place_robot}"
    grasp = a.pick_grasp if not a.handover else f"{a.pick_grasp}→{a.place_grasp}"
    label = f"{who}\\n{a.obj} → {a.region}\\n{grasp}"
    extra = ""
    if a in step_of:
        label += f"\\nstep {step_of[a]}"
        extra = f', fillcolor="{HIGHLIGHT}", penwidth=2.5'
    return f'  "a{i}" [shape=box, style="rounded,filled", fillcolor=white, label={_q(label)}{extra}];'


def task_graph_dot(
    problem: Problem,
    skeleton: int | None = None,
    backend: str = DEFAULT_BACKEND,
    encoding: str = DEFAULT_ENCODING,
    seed: int = 0,
    full: bool = False,
) -> tuple[str, str]:
    """The DOT text of the problem's CMTG (phase 1 first for a geometric problem without facts) and a
    one-line summary; ``skeleton`` (1-based) highlights that skeleton (E000 when there are fewer).  A graph
    of more than :data:`LARGE_ACTIONS` actions is drawn with its objects clustered and, unless ``full``,
    only the chosen skeleton's actions (the first when none is chosen; all actions when it has none)."""
    from mrgc.compiler.facts import FactBase
    from mrgc.compiler.task_graph import build_task_graph
    from mrgc.planner.skeletons import must_move, problem_facts

    facts, _ = problem_facts(problem, seed=seed)
    graph = build_task_graph(FactBase.from_problem(problem, facts), must_move(problem, facts))
    large = len(graph.actions) > LARGE_ACTIONS
    chosen = None
    if skeleton is not None:
        chosen = _skeleton(problem, facts, skeleton, backend, encoding, seed, required=True)
    elif large and not full:
        chosen = _skeleton(problem, facts, 1, backend, encoding, seed, required=False)
    index = skeleton or (1 if chosen is not None else None)
    only = large and not full and chosen is not None
    picks = sum(len(b) for b in graph.block_pick)
    places = sum(len(b) for b in graph.block_place)
    info = f"{len(graph.objects)} objects, {len(graph.actions)} actions, {picks} block-pick and {places} block-place"
    info += " edges"
    if only:
        assert chosen is not None
        info += f"; large: skeleton {index}'s {len(chosen.actions)} actions only (--full draws all)"
    elif chosen is not None:
        info += f"; skeleton {index} highlighted"
    return to_dot(graph, problem.name, chosen, index, only_skeleton=only, clusters=large), info


def _skeleton(
    problem: Problem, facts: Any, k: int, backend: str, encoding: str, seed: int, required: bool
) -> Skeleton | None:
    """The ``k``-th skeleton of the problem; fewer: E000 when ``required``, else None."""
    from mrgc.errors import Diagnostic, InputError
    from mrgc.planner.skeletons import compile_problem

    result = compile_problem(problem, backend=backend, encoding=encoding, skeletons=k, facts=facts, seed=seed)
    if len(result.skeletons) >= k:
        return result.skeletons[k - 1]
    if not required:
        return None
    raise InputError(
        [
            Diagnostic(
                "E000",
                f"--skeleton {k}: problem {problem.name} has {len(result.skeletons)} skeleton(s) ({result.status})",
            )
        ]
    )


def require_dot() -> str:
    """The path of Graphviz's ``dot``; MissingBackendError (exit code 4) when it is not on PATH."""
    path = shutil.which("dot")
    if path is None:
        raise MissingBackendError(
            "Graphviz's dot is not on PATH: install Graphviz (Debian: apt-get install "
            "graphviz) to write .svg or .png, or write .dot"
        )
    return path


def run_dot(text: str, fmt: str, out: str) -> str:
    """Lay out ``text`` with ``dot -T<fmt>`` into ``out`` (a PNG at :data:`DPI`); a drawing larger than
    :data:`MAX_PIXELS` a side is scaled down to fit (the size guard).  Returns a note on its size."""
    width, height = layout_size(text)
    note = f"{width}x{height} px"
    if max(width, height) > MAX_PIXELS:
        inches = MAX_PIXELS / DPI
        at = text.index("  node [")
        text = text[:at] + f'  graph [size="{inches:g},{inches:g}"];\n' + text[at:]
        k = MAX_PIXELS / max(width, height)
        note = f"{round(width * k)}x{round(height * k)} px, scaled down from {note} (the size guard)"
    _dot(text, [f"-T{fmt}", *([f"-Gdpi={DPI}"] if fmt == "png" else []), "-o", out])
    return note


def layout_size(text: str) -> tuple[int, int]:
    """The width and height (pixels at :data:`DPI`) of ``text`` laid out by dot."""
    first = _dot(text, ["-Tplain"]).split("\n", 1)[0].split()  # graph <scale> <width> <height> (inches)
    return round(float(first[2]) * DPI), round(float(first[3]) * DPI)


def _dot(text: str, args: list[str]) -> str:
    try:
        done = subprocess.run(
            [require_dot(), *args], input=text.encode("utf-8"), capture_output=True, timeout=DOT_SECONDS
        )
    except subprocess.TimeoutExpired:
        raise MrgcError(f"Graphviz's dot did not finish within {DOT_SECONDS} s; write .dot instead") from None
    if done.returncode != 0:
        raise MrgcError(f"Graphviz's dot failed: {done.stderr.decode('utf-8', 'replace').strip()[:300]}")
    return done.stdout.decode("utf-8", "replace")
