"""Names in the pictures: where each robot's, region's and (on request) object's name goes in a frame, and
the legend of a world's colours.

A label is a name, the colour of what it names and a 3D anchor projected into the picture: an arm's base
(its name sits below it, off the arm); the top face of a planar robot's footprint at the frame's pose (the
name rides with the robot), of a region, of an object (on request: pa10 holds ten small boxes), the name
sitting above its highest corner.  Drawing them, out of each other's way, is
:func:`mrgc.render.picture.draw_labels`; the HTML replay puts the same names at the same anchors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mrgc.geometry.scene import half_extents
from mrgc.render.camera import Camera
from mrgc.render.frames import Frame
from mrgc.render.palette import RGB, ROLE_COLOURS, LegendEntry, legend_entries
from mrgc.render.world import World

#: what can be labelled, in drawing order (a later label moves out of an earlier one's way)
KINDS = ("robot", "region", "object")


@dataclass(frozen=True)
class Label:
    """A name at a pixel: ``kind`` (robot, region or object), the colour of what it names, and where its
    box goes: centred on ``x``, above ``y`` (``below``: under it)."""

    text: str
    kind: str
    colour: RGB
    x: float
    y: float
    below: bool = False


def anchors(world: World, frame: Frame, kinds: tuple[str, ...] = ("robot", "region")) -> list[tuple[Label, np.ndarray]]:
    """Each label of ``kinds`` and its 3D anchor (world) at ``frame`` (pixel position still 0)."""
    out: list[tuple[Label, np.ndarray]] = []
    if "robot" in kinds:
        for name, view in world.robots.items():
            if view.planar:
                at = view.mobile.body_transform(frame.configs[name])
                out.append((Label(name, "robot", view.colour, 0.0, 0.0), _top(at, view.mobile.half)))
            else:
                out.append((Label(name, "robot", view.colour, 0.0, 0.0, below=True), view.spec.base[:3, 3].copy()))
    if "region" in kinds:
        for body, colour in world.regions:
            out.append((Label(body.name, "region", colour, 0.0, 0.0), _top(body.pose, half_extents(body.shape))))
    if "object" in kinds:
        for name, pose in frame.poses.items():
            label = Label(name, "object", ROLE_COLOURS[world.roles[name]], 0.0, 0.0)
            out.append((label, _top(pose, half_extents(world.shapes[name]))))
    return out


def _top(pose: np.ndarray, half: np.ndarray) -> np.ndarray:
    """The corners of a box's top face (world), the box at ``pose`` with half extents ``half``."""
    corners = np.array([[sx * half[0], sy * half[1], half[2]] for sx in (-1, 1) for sy in (-1, 1)])
    top: np.ndarray = corners @ pose[:3, :3].T + pose[:3, 3]
    return top


def frame_labels(
    world: World, frame: Frame, camera: Camera, width: int, height: int, kinds: tuple[str, ...] = ("robot", "region")
) -> list[Label]:
    """The labels of ``frame`` in a ``width`` × ``height`` picture seen by ``camera``, anchors in pixels
    (above the highest corner of the top face, centred on it; an arm's below its base); those behind the
    eye are left out."""
    out = []
    for label, points in anchors(world, frame, kinds):
        cols, rows, z = camera.project(points, width, height)
        if (z <= camera.near).any():
            continue
        x = float(cols.mean())
        y = float(rows.max()) if label.below else float(rows.min())
        out.append(Label(label.text, label.kind, label.colour, x, y, label.below))
    return out


def world_legend(world: World) -> list[LegendEntry]:
    """The legend of ``world``'s colours: its robots, the object roles and region kinds it has, fixed."""
    goal = set(world.scene.goal.values())
    names = [b.name for b, _ in world.regions]
    return legend_entries(world.colours, world.roles, goal, names)
