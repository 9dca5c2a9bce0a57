"""The interactive 3D replay: one self-contained HTML file built with viser (the one module importing it).

Why viser: it is maintained on PyPI (1.x, released through 2026; meshcat-python's last release, 0.3.2, is
from 2021), its wheel ships its whole web viewer as one ``index.html`` (about 0.8 MB: JavaScript, fonts and
environment map inline), and it records a scene with timed updates into a file the viewer replays with
play/pause, a time slider and speeds, the camera orbiting freely.  :meth:`StateSerializer.as_html` puts the
recording (zstd-compressed msgpack, base64) into that page: no server, no network, no CDN.  meshcat's static
HTML is self-contained too, but it would tie mrgc to an unmaintained package and a ZeroMQ server process.

viser records what a live ``ViserServer`` sends, so a server is started for the duration of the export,
bound to the loopback interface on a free port (``127.0.0.1:0``); no client ever connects and it is stopped
before the file is written.  The scene is :class:`~mrgc.render.world.World`'s drawables: fixed objects,
regions (translucent), objects coloured by role, robots as their collision shapes; each frame updates only
the poses that changed, and a label shows the caption.  Robots, regions and (on request) objects carry
their names as viser labels under the scene node ``/labels`` (the viewer's scene tree hides them all with
one click; a planar robot's name moves with it), and a legend of the colours is plain HTML added to the
page over the viewer's top-left corner.
"""

from __future__ import annotations

import contextlib
import html
import io
import math
from typing import Any, Callable

import numpy as np

from mrgc.geometry.transforms import to_quaternion
from mrgc.render.camera import Camera
from mrgc.render.frames import Frame
from mrgc.render.palette import REGION_ALPHA, byte_colour, darker, hex_colour
from mrgc.render.world import Drawable, World, shape_drawable


def write(
    world: World,
    frames: list[Frame],
    camera: Camera,
    fps: float,
    path: str,
    progress: Callable[[int, int], None] | None = None,
    labels: tuple[str, ...] = ("robot", "region"),
    legend: bool = True,
) -> int:
    """Write the replay of ``frames`` (one frame: a still scene) to ``path``, naming ``labels``' kinds,
    with the legend when ``legend``; returns the file's size in bytes."""
    page = build(world, frames, camera, fps, progress, labels)
    if legend:
        page = with_legend(page, legend_html(world))
    data = page.encode("utf-8")
    with open(path, "wb") as fh:
        fh.write(data)
    return len(data)


def build(
    world: World,
    frames: list[Frame],
    camera: Camera,
    fps: float,
    progress: Callable[[int, int], None] | None = None,
    labels: tuple[str, ...] = ("robot", "region"),
) -> str:
    """The HTML page of the replay (names of ``labels``' kinds under the scene node ``/labels``)."""
    with contextlib.redirect_stdout(io.StringIO()):  # viser reports its server's start and stop
        import viser

        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        try:
            return _record(server, world, frames, camera, fps, progress, labels)
        finally:
            server.stop()


def with_legend(page: str, legend: str) -> str:
    """``page`` with ``legend`` (HTML) as the last element of its body."""
    at = page.rfind("</body>")
    return page[:at] + legend + page[at:] if at >= 0 else page + legend


def legend_html(world: World) -> str:
    """The legend as a box of plain HTML over the viewer's top-right corner (the top-left one is the
    viewer's notices'): each colour's swatch and meaning, the regions' names after their kind, and how to
    hide the names."""
    from mrgc.render.labels import world_legend

    goal = set(world.scene.goal.values())
    regions = {"goal region": [b.name for b, _ in world.regions if b.name in goal]}
    regions["region"] = [b.name for b, _ in world.regions if b.name not in goal]
    rows = []
    for e in world_legend(world):
        names = regions.get(e.text, []) if e.kind == "region" else []
        text = html.escape(e.text + (": " + ", ".join(names) if names else ""))
        rows.append(
            f'<div class="mrgc-{e.kind}"><span style="display:inline-block;width:0.9em;height:0.9em;'
            f"margin-right:0.4em;vertical-align:-0.1em;background:{hex_colour(e.colour)};"
            f'border:1px solid {hex_colour(darker(e.colour))}"></span>{text}</div>'
        )
    hint = "names: Scene tree button, then the eye of /labels"
    return (
        '<div id="mrgc-legend" style="position:fixed;right:0.6em;top:0.6em;z-index:5;pointer-events:none;'
        "background:rgba(255,255,255,0.88);color:#222;font:11px/1.3 sans-serif;padding:0.4em 0.6em;"
        f'border-radius:4px">{"".join(rows)}<div style="color:#666;margin-top:0.3em">{hint}</div></div>'
    )


def _record(
    server: Any,
    world: World,
    frames: list[Frame],
    camera: Camera,
    fps: float,
    progress: Callable[[int, int], None] | None,
    labels: tuple[str, ...],
) -> str:
    """The replay as one HTML file: the scene at the first frame, then each frame's moves recorded one
    ``1 / fps`` apart."""
    handles, label = _first_frame(server, world, frames[0], camera)
    names = _add_names(server.scene, world, frames[0], labels)
    serializer = server.get_scene_serializer()
    last = dict.fromkeys([*handles, *names])
    text = frames[0].caption
    for i, frame in enumerate(frames[1:], 2):
        serializer.insert_sleep(1.0 / fps)
        for name, pose in frame.poses.items():
            _move(handles[name], pose, last, name)
        for robot, q in frame.configs.items():
            for part, pose in world.robots[robot].part_poses(q, frame.fingers.get(robot)):
                _move(handles[part.name], pose, last, part.name)
        for key, pose in _name_poses(world, frame, labels).items():
            _move(names[key], pose, last, key)
        if frame.caption != text:
            label.text = text = frame.caption
        if progress is not None:
            progress(i, len(frames))
    if len(frames) > 1:
        serializer.insert_sleep(1.5)  # hold the end before the replay loops
    return str(serializer.as_html())


def _first_frame(server: Any, world: World, first: Frame, camera: Camera) -> tuple[dict[str, Any], Any]:
    """The camera, the fixed bodies and regions, and the objects and robots at the first frame, with the
    caption: the handles of what moves, by name, and the caption's label."""
    scene = server.scene
    scene.set_up_direction("+z")
    cam = server.initial_camera
    cam.position = tuple(float(v) for v in camera.eye)
    cam.look_at = tuple(float(v) for v in camera.target)
    cam.up = tuple(float(v) for v in camera.up)
    cam.fov = math.radians(camera.fov)
    for part, pose in world.fixed:
        _add(scene, f"/fixed/{part.name}", part, pose)
    for body, colour in world.regions:
        _add(scene, f"/regions/{body.name}", shape_drawable(body.name, body.shape, colour, REGION_ALPHA), body.pose)
    handles: dict[str, Any] = {}
    for name, part in world.objects.items():
        handles[name] = _add(scene, f"/objects/{name}", part, first.poses[name])
    for robot, q in first.configs.items():
        for part, pose in world.robots[robot].part_poses(q, first.fingers.get(robot)):
            handles[part.name] = _add(scene, f"/robots/{part.name}", part, pose)
    # the caption floats above the middle of the scene, a fifth of the viewing distance up
    top = camera.target + np.array([0.0, 0.0, 0.2 * float(np.linalg.norm(camera.eye - camera.target))])
    label = scene.add_label(
        "/caption", first.caption, position=tuple(float(v) for v in top), anchor="bottom-center", font_screen_scale=1.2
    )
    return handles, label


def _name_poses(world: World, frame: Frame, labels: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Where each name of ``labels``' kinds is at ``frame`` (a pose: only its position counts), by its node."""
    from mrgc.render.labels import anchors

    out = {}
    for label, points in anchors(world, frame, labels):
        pose = np.eye(4)
        pose[:3, 3] = points.mean(axis=0) if points.ndim == 2 else points
        out[f"/labels/{label.kind}s/{label.text}"] = pose
    return out


def _add_names(scene: Any, world: World, first: Frame, labels: tuple[str, ...]) -> dict[str, Any]:
    """A label for each robot, region and (when asked) object under ``/labels`` (hidden all at once in the
    viewer's scene tree): above its top, an arm's under its base; the handles by node name."""
    from mrgc.render.labels import anchors

    below = {f"/labels/{lb.kind}s/{lb.text}" for lb, _ in anchors(world, first, labels) if lb.below}
    out = {}
    for node, pose in _name_poses(world, first, labels).items():
        out[node] = scene.add_label(
            node,
            node.rsplit("/", 1)[1],
            position=tuple(float(v) for v in pose[:3, 3]),
            anchor="top-center" if node in below else "bottom-center",
            font_screen_scale=1.0 if "/objects/" not in node else 0.8,
        )
    return out


def _move(handle: Any, pose: np.ndarray, last: dict[str, Any], name: str) -> None:
    """Send ``pose`` to ``handle`` unless it is where it was (to a micrometre and a microradian)."""
    pos, (x, y, z, w) = to_quaternion(np.asarray(pose, dtype=float))
    key = tuple(round(v, 6) for v in (*pos, w, x, y, z))
    if last[name] == key:
        return
    last[name] = key
    handle.position = pos
    handle.wxyz = (w, x, y, z)


def _add(scene: Any, name: str, d: Drawable, pose: np.ndarray) -> Any:
    """Add drawable ``d`` at ``pose`` as scene node ``name``."""
    pos, (x, y, z, w) = to_quaternion(np.asarray(pose, dtype=float))
    where: dict[str, Any] = {"position": pos, "wxyz": (w, x, y, z)}
    colour = byte_colour(d.colour)
    opacity = d.opacity if d.opacity < 1 else None
    if d.kind == "box":
        return scene.add_box(name, colour, tuple(d.size), opacity=opacity, **where)
    if d.kind == "sphere":
        return scene.add_icosphere(name, radius=d.size[0], color=colour, opacity=opacity, **where)
    if d.kind in ("cylinder", "capsule"):
        return scene.add_cylinder(name, radius=d.size[0], height=d.size[1], color=colour, opacity=opacity, **where)
    vertices, faces = d.vertices, d.faces
    if vertices is None or faces is None:
        assert d.mesh_path is not None
        from mrgc.geometry.kinematics import read_mesh

        v, faces = read_mesh(d.mesh_path)
        vertices = v * np.asarray(d.size)
    return scene.add_mesh_simple(
        name,
        np.asarray(vertices, dtype=np.float32),
        np.asarray(faces, dtype=np.uint32),
        color=colour,
        opacity=opacity,
        side="double" if opacity else "front",
        **where,
    )
