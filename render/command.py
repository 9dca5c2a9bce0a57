"""``mrgc render`` and ``mrgc graph``: their command-line options and what they run.

:func:`add_commands` registers both on the CLI's sub-parsers; nothing here imports a heavy library until a
command runs.  Output files are written through :mod:`mrgc.outputs` (checked before any drawing, replaced
atomically); the replay's path is printed when it is written.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from typing import Any, Iterator

from mrgc.errors import Diagnostic, InputError
from mrgc.exits import ExitCode
from mrgc.language.files import add_allow_outside
from mrgc.limits import count
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING

MAX_SIDE = 4096  # pixels
DEFAULT_SIZE = "400x300"
MAX_FPS = 60.0
#: the camera presets of :data:`mrgc.render.camera.PRESETS`, for --help without loading numpy (a test keeps
#: the two in step)
CAMERA_HELP = "iso, front, back, side or top"


def add_commands(sub: Any) -> None:
    """Add ``render`` and ``graph`` to the CLI's sub-parsers."""
    p = sub.add_parser(
        "render",
        help="draw a plan or a scene: .gif/.mp4 replay, .png sheet or scene, .html 3D replay, .svg/.png Gantt chart",
    )
    p.add_argument("file", metavar="FILE", help="the problem file")
    p.add_argument(
        "plan", metavar="PLAN", nargs="?", help="the plan JSON (mrgc plan -o PLAN); leave out to draw the scene alone"
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        required=True,
        help=".gif or .mp4 (replay), .png (key frames; the scene without PLAN), .html (3D replay), "
        ".svg or *gantt.png (Gantt chart)",
    )
    p.add_argument("--problem", help="which problem of the file (default: the one the plan names, else its only one)")
    p.add_argument(
        "--size",
        default=DEFAULT_SIZE,
        metavar="WxH",
        help="picture size in pixels (default 400x300; 900x700 for --reach)",
    )
    p.add_argument("--fps", type=float, default=10.0, help="frames per second of the replay (default 10)")
    p.add_argument("--camera", default="iso", help=f"viewing direction: {CAMERA_HELP} (default iso)")
    p.add_argument(
        "--object-labels", action="store_true", help="name the movable objects too (robots and regions always are)"
    )
    p.add_argument("--no-labels", action="store_true", help="no names and no legend: the scene and the caption alone")
    p.add_argument("--gantt", action="store_true", help="write the Gantt chart (.svg or .png)")
    p.add_argument(
        "--force", action="store_true", help="draw a plan whose status is not 'solved' (exit code 1 all the same)"
    )
    p.add_argument(
        "--reach",
        action="store_true",
        help="write the reach map (.png or .svg): the scene from above with where each arm reaches at the "
        "objects' pick height, to place arms by looking",
    )
    add_no_cache(p)
    add_allow_outside(p)
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("graph", help="draw the collaborative manipulation task graph (CMTG): .dot, .svg or .png")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", metavar="OUT", required=True, help=".dot, or .svg/.png through Graphviz's dot")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument("--skeleton", type=int, metavar="K", help="highlight the K-th task skeleton (1 = the first)")
    p.add_argument(
        "--full",
        action="store_true",
        help="draw every action of a large graph (more than 24 actions; by default only a skeleton's)",
    )
    p.add_argument(
        "--backend",
        default=DEFAULT_BACKEND,
        help=f"backend generating skeletons for --skeleton (default {DEFAULT_BACKEND})",
    )
    p.add_argument("--encoding", default=DEFAULT_ENCODING)
    p.add_argument("--seed", type=count("--seed"), default=0)
    add_no_cache(p)
    add_allow_outside(p)
    p.set_defaults(func=cmd_graph)


def add_no_cache(p: Any) -> None:
    """``--no-cache`` (as ``mrgc plan``'s): the facts of a problem without them come from phase 1 run now."""
    p.add_argument("--no-cache", action="store_true", help="compute phase 1 even when the facts cache holds it")


def _usage(message: str) -> InputError:
    return InputError([Diagnostic("E000", message)])


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` → (width, height), each 16 to :data:`MAX_SIDE` pixels (E000 otherwise)."""
    parts = text.lower().split("x")
    try:
        w, h = (int(v) for v in parts)
    except ValueError:
        raise _usage(f"--size {text!r}: give width x height in pixels, e.g. 640x480") from None
    if not (16 <= w <= MAX_SIDE and 16 <= h <= MAX_SIDE):
        raise _usage(f"--size {text!r}: each side must be 16 to {MAX_SIDE} pixels")
    return w, h


@contextlib.contextmanager
def _progress(label: str) -> Iterator[Any]:
    """A rich progress bar on a terminal (stderr); a silent callback otherwise."""
    if not sys.stderr.isatty():
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as bar:
        task = bar.add_task(label, total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        yield update


def _check_view(args: argparse.Namespace, cameras: Any) -> None:
    """E000 for a camera, frame rate or pair of label options ``render`` cannot honour."""
    if args.camera not in cameras:
        raise _usage(f"--camera {args.camera!r}: choose {CAMERA_HELP}")
    if not 0 < args.fps <= MAX_FPS:
        raise _usage(f"--fps must be above 0 and at most {MAX_FPS:g}")
    if args.object_labels and args.no_labels:  # not one of them silently ignored
        raise _usage("--object-labels and --no-labels ask for opposite pictures: give one of them")


def cmd_render(args: argparse.Namespace) -> int:
    """``mrgc render``: a replay, key frames, the scene, an HTML replay or a Gantt chart, by the output's extension."""
    from mrgc import outputs as files
    from mrgc.language.loader import parse_file
    from mrgc.render import outputs
    from mrgc.render.camera import PRESETS

    width, height = parse_size(args.size)
    _check_view(args, PRESETS)
    kind = outputs.kind_of(args.output, args.gantt, args.plan is not None, args.reach)
    mf = parse_file(args.file, allow_outside=tuple(args.allow_outside or ()))
    inputs = list(mf.files) + ([args.plan] if args.plan else [])
    files.check_output(args.output, inputs)
    plan = None
    name = args.problem
    if args.plan is not None:
        from mrgc.planfile.reader import load_plan
        from mrgc.planner.outcome import not_solved

        plan = load_plan(args.plan)
        unsolved = not_solved(args.plan, plan)
        if unsolved is not None:
            print(unsolved, file=sys.stderr)
            if not args.force:
                print(f"mrgc render: nothing drawn (--force draws {os.path.basename(args.plan)})", file=sys.stderr)
                return ExitCode.NO_PLAN
        if name is None and len(mf.problems) > 1 and any(p.name == plan["problem"] for p in mf.problems):
            name = plan["problem"]
    problem = mf.problem(name)
    names = () if args.no_labels else ("robot", "region", "object") if args.object_labels else ("robot", "region")
    opts = outputs.Options(width, height, args.fps, args.camera, names, not args.no_labels)
    source = args.plan or args.file
    with files.atomic_path(args.output, inputs) as tmp, _progress(f"drawing {os.path.basename(args.output)}") as bar:
        if kind == "reach":
            stats = outputs.write_reach(problem, tmp, opts, args.size != DEFAULT_SIZE)
        elif kind == "gantt":
            assert plan is not None
            stats = outputs.write_gantt(problem, plan, tmp)
        elif kind == "html":
            stats = outputs.write_html(problem, plan, tmp, opts, source, bar)
        elif kind == "scene":
            stats = outputs.write_scene(problem, tmp, opts)
        elif kind == "sheet":
            assert plan is not None
            stats = outputs.write_sheet(problem, plan, tmp, opts, source, bar)
        else:
            assert plan is not None
            stats = outputs.write_animation(problem, plan, tmp, opts, source, bar)
    print(_written(kind, args.output, stats))
    return ExitCode.NO_PLAN if plan is not None and plan.get("status") != "solved" else ExitCode.OK


def _written(kind: str, path: str, stats: dict[str, Any]) -> str:
    where = os.path.abspath(path)
    if kind == "reach":
        reached = ", ".join(f"{r} reaches {n}" for r, n in stats["reached"].items())
        what = (
            f"{reached} of {stats['points']} points" if reached else f"no arm in the problem; {stats['points']} points"
        )
        return f"{path}: reach map ({what})\n  written to {where}"
    steps = f"{stats.get('steps', 0)} step{'s' * (stats.get('steps', 0) != 1)}"
    what = {
        "animation": f"replay of {steps}, {stats['frames']} frames",
        "sheet": f"contact sheet of {stats['frames']} key frames",
        "scene": "the scene",
        "html": (
            f"3D replay of {steps}, {stats['frames']} frames; open it in a web browser"
            if stats["steps"]
            else "the scene in 3D; open it in a web browser"
        ),
        "gantt": f"Gantt chart of {steps}",
    }[kind]
    timing = f", {stats['draw_seconds']:.1f} s" if "draw_seconds" in stats else ""
    return f"{path}: {what}{timing}\n  written to {where}"


def cmd_graph(args: argparse.Namespace) -> int:
    """``mrgc graph``: the collaborative manipulation task graph, drawn through Graphviz."""
    from mrgc import outputs as files
    from mrgc.language.loader import parse_file
    from mrgc.render import graph

    ext = os.path.splitext(args.output.lower())[1]
    if ext not in graph.FORMATS:
        raise _usage(f"cannot write {args.output!r}: mrgc graph writes {', '.join(graph.FORMATS)}")
    if args.skeleton is not None and args.skeleton < 1:
        raise _usage("--skeleton must be at least 1")
    if args.skeleton is None and (args.backend, args.encoding) != (DEFAULT_BACKEND, DEFAULT_ENCODING):
        raise _usage("--backend and --encoding choose how the skeleton of --skeleton K is made: give --skeleton")
    mf = parse_file(args.file, allow_outside=tuple(args.allow_outside or ()))
    files.check_output(args.output, list(mf.files))
    if ext != ".dot":
        graph.require_dot()
    problem = mf.problem(args.problem)
    text, info = graph.task_graph_dot(problem, args.skeleton, args.backend, args.encoding, args.seed, args.full)
    if ext == ".dot":
        files.write_text(args.output, text, list(mf.files))
    else:
        with files.atomic_path(args.output, list(mf.files)) as tmp:
            info += "; " + graph.run_dot(text, ext[1:], tmp)
    print(f"{args.output}: task graph of {problem.name}: {info}")
    return ExitCode.OK
