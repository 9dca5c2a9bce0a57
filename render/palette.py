"""Colours of everything drawn, by what a thing is in the plan (its role), shared by every output format.

Objects are coloured by role: a *goal* object (named in the goal), a *moved obstacle* (moved by the plan
but not a goal: it was in the way), or *untouched*.  Regions are translucent, goal regions in the goal
colour; fixed objects are neutral.  Each robot gets its own colour, the same in the replays, the Gantt
chart and the task graph, so a robot can be followed from one picture to the next.

The colours are chosen to stay apart where they meet: the replays draw a region as a tinted floor and an
outline (:mod:`mrgc.render.raster`), never as a veil over what stands in it, so a robot or an object keeps
its own colour inside a region; the robot colours are saturated hues at least 25 degrees from each other
and from the object roles' green and orange (and the dark sixth is far from the untouched grey in
lightness), so shading, which changes lightness, does not make one look like another.
:func:`legend_entries` names them for every picture's legend.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

RGB = tuple[float, float, float]


class Role(str, enum.Enum):
    """What an object is to a plan."""

    GOAL = "goal"
    MOVED = "moved obstacle"
    UNTOUCHED = "untouched"


#: object colour by role (RGB in [0, 1])
ROLE_COLOURS: dict[Role, RGB] = {
    Role.GOAL: (0.17, 0.63, 0.17),  # green
    Role.MOVED: (1.00, 0.50, 0.05),  # orange
    Role.UNTOUCHED: (0.62, 0.62, 0.62),  # grey
}
#: translucent regions: the goal regions in a light goal green, the others light blue; how opaque they are
#: (the HTML replay's boxes; the pictures tint a region's floor with :data:`REGION_FLOOR_ALPHA`)
GOAL_REGION: RGB = (0.45, 0.85, 0.45)
OTHER_REGION: RGB = (0.55, 0.70, 0.95)
REGION_ALPHA = 0.28
REGION_FLOOR_ALPHA = 0.4
#: fixed objects (tables, walls)
FIXED: RGB = (0.80, 0.72, 0.60)
#: robots in declaration order (cycled): blue (hue 217 degrees), violet (273), crimson (345), teal (187),
#: magenta (318), charcoal; saturated, at least 25 degrees apart and from the goal green (120) and the
#: moved-obstacle orange (29)
ROBOT_COLOURS: tuple[RGB, ...] = (
    (0.12, 0.40, 0.85),
    (0.55, 0.22, 0.82),
    (0.85, 0.10, 0.30),
    (0.00, 0.62, 0.72),
    (0.92, 0.28, 0.75),
    (0.22, 0.22, 0.26),
)
#: the heading marker on a planar robot's footprint
HEADING: RGB = (0.97, 0.97, 0.97)


def roles(objects: Iterable[str], goal: Mapping[str, str], moved: Iterable[str]) -> dict[str, Role]:
    """The role of each object: goal objects first, then objects the plan moves, then the rest."""
    moved_set = set(moved)
    return {o: Role.GOAL if o in goal else Role.MOVED if o in moved_set else Role.UNTOUCHED for o in objects}


def moved_objects(plan: Mapping[str, Any]) -> list[str]:
    """The objects a plan (JSON) moves, in step order."""
    return [a["object"] for step in plan.get("steps", []) for a in step.get("actions", [])]


def robot_colours(robots: Iterable[str]) -> dict[str, RGB]:
    """Each robot's colour, by declaration order."""
    return {r: ROBOT_COLOURS[i % len(ROBOT_COLOURS)] for i, r in enumerate(robots)}


def hex_colour(rgb: RGB) -> str:
    """``#rrggbb`` of an RGB colour in [0, 1]."""
    return "#" + "".join(f"{round(max(0.0, min(1.0, c)) * 255):02x}" for c in rgb)


def byte_colour(rgb: RGB) -> tuple[int, int, int]:
    """An RGB colour in [0, 1] as bytes (0-255)."""
    r, g, b = (round(max(0.0, min(1.0, c)) * 255) for c in rgb)
    return r, g, b


def darker(rgb: RGB, k: float = 0.6) -> RGB:
    """``rgb`` darkened (outlines and the names of regions)."""
    return (rgb[0] * k, rgb[1] * k, rgb[2] * k)


@dataclass(frozen=True)
class LegendEntry:
    """One line of a legend: what a colour means, and how its swatch is drawn (``robot``, ``object``,
    ``region``: a light fill with a dark outline, ``fixed``)."""

    text: str
    colour: RGB
    kind: str


def legend_entries(
    robots: Mapping[str, RGB], role_of: Mapping[str, Role], goal_regions: Iterable[str], regions: Iterable[str]
) -> list[LegendEntry]:
    """The legend of a picture: each robot by name, then the object roles present, the kinds of region
    present (goal regions, other regions) and fixed objects."""
    out = [LegendEntry(name, colour, "robot") for name, colour in robots.items()]
    present = set(role_of.values())
    names = {Role.GOAL: "goal object", Role.MOVED: "moved obstacle", Role.UNTOUCHED: "other object"}
    out += [LegendEntry(names[r], ROLE_COLOURS[r], "object") for r in Role if r in present]
    goal = set(goal_regions)
    kinds = {name in goal for name in regions}
    if True in kinds:
        out.append(LegendEntry("goal region", GOAL_REGION, "region"))
    if False in kinds:
        out.append(LegendEntry("region", OTHER_REGION, "region"))
    out.append(LegendEntry("fixed", FIXED, "fixed"))
    return out
