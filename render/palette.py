"""Colours of everything drawn, by what a thing is in the plan (its role), shared by every output format.

Objects are coloured by role: a *goal* object (named in the goal), a *moved obstacle* (moved by the plan
but not a goal: it was in the way), or *untouched*.  Regions are translucent, goal regions in the goal
colour; fixed objects are neutral.  Each robot gets its own colour, the same in the replays, the Gantt
chart and the task graph, so a robot can be followed from one picture to the next.
"""

from __future__ import annotations

import enum
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
GOAL_REGION: RGB = (0.45, 0.85, 0.45)
OTHER_REGION: RGB = (0.55, 0.70, 0.95)
REGION_ALPHA = 0.28
#: fixed objects (tables, walls)
FIXED: RGB = (0.80, 0.72, 0.60)
#: robots in declaration order (cycled): blue, purple, teal, pink, olive, brown; never a role colour
ROBOT_COLOURS: tuple[RGB, ...] = (
    (0.12, 0.47, 0.71),
    (0.58, 0.40, 0.74),
    (0.09, 0.75, 0.81),
    (0.89, 0.47, 0.76),
    (0.74, 0.74, 0.13),
    (0.55, 0.34, 0.29),
)


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
