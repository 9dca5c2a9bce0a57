"""What ``mrgc render`` writes, chosen by the output file's name: one function per kind of picture.

| output | with a plan | without a plan |
| --- | --- | --- |
| ``.gif``, ``.mp4`` | the replay, every phase of every step interpolated | (needs a plan) |
| ``.png`` | a contact sheet of the key frames | the scene |
| ``.html`` | an interactive 3D replay, self-contained | the scene in 3D |
| ``.svg``, ``*gantt.png``, ``--gantt`` | the Gantt chart (symbolic plans too) | (needs a plan) |

Animations, sheets and scenes are drawn by :mod:`mrgc.render.raster` and framed by one camera for the
whole replay (:func:`mrgc.render.camera.fit` over the scene and every robot pose), so nothing leaves the
picture and the view never jumps.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np

from mrgc.errors import Diagnostic, InputError
from mrgc.language.model import Problem
from mrgc.render.camera import DEFAULT_PRESET, Camera, fit
from mrgc.render.frames import Frame, Timeline, build_timeline
from mrgc.render.world import World

Progress = Callable[[int, int], None]  # (frames done, frames in all)

ANIMATIONS = (".gif", ".mp4")
#: robot poses used to frame a replay's camera: every k-th frame
FRAMING_STRIDE = 4
#: the HTML replay's first view is this much further away than the fitted picture's
HTML_BACK_OFF = 1.35


@dataclass(frozen=True)
class Options:
    """How to draw: picture size in pixels, frames per second, camera preset; the kinds of thing named
    (:data:`mrgc.render.labels.KINDS`) and whether a legend is drawn."""

    width: int = 400
    height: int = 300
    fps: float = 10.0
    camera: str = DEFAULT_PRESET
    labels: tuple[str, ...] = ("robot", "region")
    legend: bool = True


def kind_of(path: str, gantt: bool, has_plan: bool, reach: bool = False) -> str:
    """``animation``, ``sheet``, ``scene``, ``html``, ``gantt`` or ``reach`` for output ``path`` (E000 when
    the name or the missing plan does not allow one)."""
    lower = path.lower()
    ext = os.path.splitext(lower)[1]
    if reach:
        if ext not in (".png", ".svg") or gantt or has_plan:
            raise _usage(
                "--reach writes the reach map of a problem as .png or .svg, without a plan or --gantt: "
                f"mrgc render FILE --reach -o {os.path.splitext(os.path.basename(path))[0] or 'reach'}.png"
            )
        return "reach"
    if gantt or ext == ".svg" or lower.endswith("gantt.png"):
        if ext not in (".svg", ".png"):
            raise _usage(f"a Gantt chart is written as .svg or .png, not {ext or 'a file without extension'}")
        kind = "gantt"
    elif ext in ANIMATIONS:
        kind = "animation"
    elif ext == ".png":
        kind = "sheet" if has_plan else "scene"
    elif ext == ".html":
        kind = "html"
    else:
        raise _usage(f"cannot write {path!r}: mrgc render writes .gif, .mp4, .png, .html or .svg")
    if not has_plan and kind in ("animation", "gantt"):
        raise _usage(
            f"{'an animation' if kind == 'animation' else 'a Gantt chart'} needs a plan: "
            f"mrgc render FILE PLAN -o {os.path.basename(path)} (without a plan, write the scene as .png "
            "or .html)"
        )
    return kind


def _usage(message: str) -> InputError:
    return InputError([Diagnostic("E000", message)])


#: the reach map's size when --size is not given (pixels)
REACH_SIZE = (900, 700)


def write_reach(problem: Problem, path: str, opts: Options, sized: bool) -> dict[str, Any]:
    """The reach map (:mod:`mrgc.render.reach`) of ``problem``, ``opts``' size when ``sized`` (else
    :data:`REACH_SIZE`)."""
    from mrgc.render import reach

    width, height = (opts.width, opts.height) if sized else REACH_SIZE
    return reach.write(problem, path, width, height)


def frame_layout(world: World, frames: list[Frame], opts: Options, captions: bool = True, legend: bool = True) -> Any:
    """The :class:`~mrgc.render.picture.Layout` of ``frames``: their captions (when ``captions``), the
    world's legend (when ``legend`` and ``opts.legend``), the names ``opts`` asks for."""
    from mrgc.render.labels import world_legend
    from mrgc.render.picture import layout

    entries = world_legend(world) if legend and opts.legend else []
    texts = [f.caption for f in frames] if captions else []
    return layout(opts.width, opts.height, texts, entries, opts.labels)


def replay_frames(
    problem: Problem, plan: Mapping[str, Any], opts: Options, source: str
) -> tuple[World, Timeline, list[Frame], Camera]:
    """The world, timeline, frames at ``opts.fps`` and one camera framing all of them."""
    world = World(problem, plan)
    timeline = build_timeline(world, plan, source)
    frames = timeline.frames(opts.fps)
    return world, timeline, frames, frame_camera(world, frames, opts)


def frame_camera(world: World, frames: list[Frame], opts: Options, layout: Any = None) -> Camera:
    """The camera of ``opts.camera`` showing the scene and every robot and object in ``frames`` in the
    scene part of ``layout`` (default: :func:`frame_layout`)."""
    lay = layout or frame_layout(world, frames, opts)
    pts = [world.static_points()]
    for f in frames[::FRAMING_STRIDE] + frames[-1:]:
        pts.append(world.robot_points(f.configs))
        pts.append(np.array([p[:3, 3] for p in f.poses.values()]).reshape(-1, 3))
    return fit(np.concatenate(pts), opts.camera, opts.width / lay.scene_height)


def draw(
    world: World,
    frames: list[Frame],
    camera: Camera,
    opts: Options,
    progress: Progress | None = None,
    captions: bool = True,
    layout: Any = None,
) -> tuple[list[np.ndarray], float]:
    """Every frame as an image laid out by ``layout`` (default :func:`frame_layout`; with ``captions``
    False and no layout: the scene alone, nothing written on it), and the seconds the drawing took.  Long
    replays are drawn by one forked process per usable core (:func:`mrgc.workers.map_in_workers`), each
    its own renderer over a contiguous share of the frames; the images are the same either way."""
    from mrgc.render.picture import Layout
    from mrgc.workers import map_in_workers, worker_count

    if layout is None:
        layout = frame_layout(world, frames, opts) if captions else Layout(opts.width, opts.height, 9)
    t0 = time.perf_counter()
    workers = worker_count(None, len(frames) // PARALLEL_FRAMES)
    if workers <= 1:
        images = _draw_share((world, frames, camera, opts, layout), progress)
    else:
        size = -(-len(frames) // workers)
        shares = [(world, frames[i : i + size], camera, opts, layout) for i in range(0, len(frames), size)]
        _SHARES[:] = shares  # forked workers find their share here (nothing large is pickled to them)
        try:
            images = [img for part in map_in_workers(_draw_job, list(range(len(shares))), workers) for img in part]
        finally:
            _SHARES.clear()
        if progress is not None:
            progress(len(frames), len(frames))
    return images, time.perf_counter() - t0


#: fewest frames per worker process worth forking for
PARALLEL_FRAMES = 24
_SHARES: list[tuple[World, list[Frame], Camera, Options, Any]] = []


def _draw_job(index: int) -> list[np.ndarray]:
    return _draw_share(_SHARES[index], None)


def _draw_share(share: tuple[World, list[Frame], Camera, Options, Any], progress: Progress | None) -> list[np.ndarray]:
    from mrgc.render.labels import frame_labels
    from mrgc.render.picture import compose
    from mrgc.render.raster import Rasterizer

    world, frames, camera, opts, lay = share
    images = []
    h = lay.scene_height
    with Rasterizer(world) as r:
        for i, f in enumerate(frames, 1):
            img = r.draw(f, camera, opts.width, h)
            names = frame_labels(world, f, camera, opts.width, h, lay.labels) if lay.labels else []
            images.append(compose(img, lay, f.caption, names))
            if progress is not None:
                progress(i, len(frames))
    return images


def write_animation(
    problem: Problem, plan: Mapping[str, Any], path: str, opts: Options, source: str, progress: Progress | None = None
) -> dict[str, Any]:
    """The replay as ``.gif`` or ``.mp4``; returns what was written (frames, steps, seconds)."""
    from mrgc.render.picture import HOLD_LAST, write_gif

    mp4 = path.lower().endswith(".mp4")
    if mp4:
        from mrgc.render.video import require_mp4, write_mp4

        require_mp4(path)  # before any drawing
    world, timeline, frames, camera = replay_frames(problem, plan, opts, source)
    images, seconds = draw(world, frames, camera, opts, progress)
    t0 = time.perf_counter()
    if mp4:
        write_mp4(path, images, opts.fps, HOLD_LAST)
    else:
        write_gif(path, images, opts.fps)
    return {
        "frames": len(images),
        "steps": timeline.steps,
        "draw_seconds": seconds,
        "write_seconds": time.perf_counter() - t0,
        "duration": timeline.duration,
    }


def write_sheet(
    problem: Problem, plan: Mapping[str, Any], path: str, opts: Options, source: str, progress: Progress | None = None
) -> dict[str, Any]:
    """A contact sheet of the key frames (the start, the end of every pick, handover and place, the end)."""
    from mrgc.render.labels import world_legend
    from mrgc.render.picture import sheet, text_size, with_legend, write_png

    world, timeline, frames, _ = replay_frames(problem, plan, opts, source)
    keys = [f for f in frames if f.key]
    lay = frame_layout(world, keys, opts, legend=False)  # one legend for the whole sheet
    images, seconds = draw(world, keys, frame_camera(world, frames, opts, lay), opts, progress, layout=lay)
    legend = world_legend(world) if opts.legend else []
    write_png(path, with_legend(sheet(images), legend, text_size(max(opts.height, 300))))
    return {"frames": len(images), "steps": timeline.steps, "draw_seconds": seconds}


def write_scene(problem: Problem, path: str, opts: Options) -> dict[str, Any]:
    """The scene alone, robots at home, with the problem's name and what it asks as the caption."""
    from mrgc.render.picture import write_png

    world = World(problem)
    frame = scene_frame(world)
    camera = frame_camera(world, [frame], opts)
    images, seconds = draw(world, [frame], camera, opts)
    write_png(path, images[0])
    return {"frames": 1, "steps": 0, "draw_seconds": seconds}


def scene_frame(world: World) -> Frame:
    """The scene at the start: robots at home, objects where the problem puts them."""
    goal = ", ".join(f"{o} in {r}" for o, r in sorted(world.scene.goal.items()))
    text = (
        f"{world.problem.name}: {len(world.robots)} robots, {len(world.objects)} objects, "
        f"{len(world.regions)} regions; goal: {goal or 'none'}"
    )
    return Frame(
        0.0,
        0,
        "start",
        text,
        {r: v.home for r, v in world.robots.items()},
        dict.fromkeys(world.robots),
        dict(world.start),
        key=True,
    )


def write_html(
    problem: Problem,
    plan: Mapping[str, Any] | None,
    path: str,
    opts: Options,
    source: str,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """The interactive 3D replay (or the scene) as one self-contained HTML file."""
    from mrgc.render.html import write

    if plan is None:
        world = World(problem)
        frames = [scene_frame(world)]
        steps = 0
    else:
        world = World(problem, plan)
        timeline = build_timeline(world, plan, source)
        frames = timeline.frames(opts.fps)
        steps = timeline.steps
    camera = html_camera(world, frames, opts)
    t0 = time.perf_counter()
    size = write(world, frames, camera, opts.fps, path, progress, opts.labels, opts.legend)
    return {"frames": len(frames), "steps": steps, "draw_seconds": time.perf_counter() - t0, "bytes": size}


def html_camera(world: World, frames: list[Frame], opts: Options) -> Camera:
    """The HTML replay's first view: the fitted camera (whole picture, no bands) moved back by
    :data:`HTML_BACK_OFF`, since a browser window has any shape and a control bar."""
    from mrgc.render.picture import Layout

    fitted = frame_camera(world, frames, opts, Layout(opts.width, opts.height, 9))
    return Camera(
        fitted.target + HTML_BACK_OFF * (fitted.eye - fitted.target),
        fitted.target,
        fitted.up,
        fitted.fov,
        fitted.near,
        fitted.far * HTML_BACK_OFF,
    )


def write_gantt(problem: Problem, plan: Mapping[str, Any], path: str) -> dict[str, Any]:
    """The plan's Gantt chart (.svg or .png)."""
    from mrgc.render.gantt import write

    write(problem, plan, path)
    return {"frames": 0, "steps": len(plan.get("steps", []))}
