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

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import TaskGraph
from mrgc.errors import MissingBackendError, MrgcError
from mrgc.language.model import Problem

FORMATS = (".dot", ".svg", ".png")
MUST_MOVE = "#e41a1c"  # red, as the paper's M* nodes
ACTION_EDGE = "#e6ab02"  # yellow
BLOCK_PICK = "#1f78b4"  # blue
BLOCK_PLACE = "#7b3294"  # purple
HIGHLIGHT = "#fff3b0"
DOT_SECONDS = 300


def _q(text: str) -> str:
    """A DOT string; ``\\n`` in ``text`` stays a DOT line break (names hold no backslashes)."""
    return '"' + text.replace('"', '\\"') + '"'


def to_dot(graph: TaskGraph, name: str, skeleton: Skeleton | None = None, skeleton_index: int | None = None) -> str:
    """The DOT text of ``graph`` (problem ``name``), ``skeleton`` highlighted when given."""
    step_of = {a: t for t, step in enumerate(skeleton.steps, 1) for a in step} if skeleton else {}
    must = set(graph.must_move)
    title = (
        f"CMTG of {name}: {len(graph.objects)} objects, {len(graph.actions)} actions; "
        f"M* = {{{', '.join(graph.must_move)}}}"
    )
    if skeleton is not None:
        title += f"\\nskeleton {skeleton_index}: makespan {skeleton.makespan}, moves {', '.join(skeleton.moved)}"
    lines = [
        f"digraph {_q('cmtg ' + name)} {{",
        f"  graph [label={_q(title)}, labelloc=t, fontname=Helvetica, rankdir=LR, nodesep=0.25];",
        "  node [fontname=Helvetica, fontsize=10];",
        "  edge [arrowsize=0.7, fontname=Helvetica, fontsize=9];",
    ]
    for o in graph.objects:
        style = f'style=filled, fillcolor="{MUST_MOVE}", fontcolor=white' if o in must else "style=solid"
        goal = f"\\n→ {graph.goal[o]}" if o in graph.goal else ""
        lines.append(f"  {_q(o)} [shape=circle, {style}, label={_q(o + goal)}];")
    for i, a in enumerate(graph.actions, 1):
        who = a.pick_robot if not a.handover else f"{a.pick_robot}→{a.place_robot}"
        grasp = a.pick_grasp if not a.handover else f"{a.pick_grasp}→{a.place_grasp}"
        label = f"{who}\\n{a.obj} → {a.region}\\n{grasp}"
        extra = ""
        if a in step_of:
            label += f"\\nstep {step_of[a]}"
            extra = f', fillcolor="{HIGHLIGHT}", penwidth=2.5'
        lines.append(f'  "a{i}" [shape=box, style="rounded,filled", fillcolor=white, label={_q(label)}{extra}];')
    for i, a in enumerate(graph.actions, 1):
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


def task_graph_dot(
    problem: Problem, skeleton: int | None = None, backend: str = "cpsat", encoding: str = "time-of-move", seed: int = 0
) -> tuple[str, str]:
    """The DOT text of the problem's CMTG (phase 1 first for a geometric problem without facts) and a
    one-line summary; ``skeleton`` (1-based) highlights that skeleton (E000 when there are fewer)."""
    from mrgc.compiler.facts import FactBase
    from mrgc.compiler.task_graph import build_task_graph
    from mrgc.errors import Diagnostic, InputError
    from mrgc.planner.skeletons import compile_problem, must_move, problem_facts

    facts, _ = problem_facts(problem, seed=seed)
    graph = build_task_graph(FactBase.from_problem(problem, facts), must_move(problem, facts))
    chosen = None
    if skeleton is not None:
        result = compile_problem(
            problem, backend=backend, encoding=encoding, skeletons=skeleton, facts=facts, seed=seed
        )
        if len(result.skeletons) < skeleton:
            raise InputError(
                [
                    Diagnostic(
                        "E000",
                        f"--skeleton {skeleton}: problem {problem.name} has "
                        f"{len(result.skeletons)} skeleton(s) ({result.status})",
                    )
                ]
            )
        chosen = result.skeletons[skeleton - 1]
    picks = sum(len(b) for b in graph.block_pick)
    places = sum(len(b) for b in graph.block_place)
    info = (
        f"{len(graph.objects)} objects, {len(graph.actions)} actions, {picks} block-pick and {places} "
        f"block-place edges" + (f"; skeleton {skeleton} highlighted" if chosen is not None else "")
    )
    return to_dot(graph, problem.name, chosen, skeleton), info


def require_dot() -> str:
    """The path of Graphviz's ``dot``; MissingBackendError (exit code 4) when it is not on PATH."""
    path = shutil.which("dot")
    if path is None:
        raise MissingBackendError(
            "Graphviz's dot is not on PATH: install Graphviz (Debian: apt-get install "
            "graphviz) to write .svg or .png, or write .dot"
        )
    return path


def run_dot(text: str, fmt: str, out: str) -> None:
    """Lay out ``text`` with ``dot -T<fmt>`` into ``out``."""
    try:
        done = subprocess.run(
            [require_dot(), f"-T{fmt}", "-o", out], input=text.encode("utf-8"), capture_output=True, timeout=DOT_SECONDS
        )
    except subprocess.TimeoutExpired:
        raise MrgcError(f"Graphviz's dot did not finish within {DOT_SECONDS} s; write .dot instead") from None
    if done.returncode != 0:
        raise MrgcError(f"Graphviz's dot failed: {done.stderr.decode('utf-8', 'replace').strip()[:300]}")
