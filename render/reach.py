"""The reach map, ``mrgc render FILE --reach -o reach.png``: the scene from above with where each arm reaches.

Each arm's reach at the pick height of the problem's objects (:mod:`mrgc.geometry.reach`: inverse
kinematics from above and level, obstacles not checked) is a translucent area in the robot's colour with
its outline; the arm's base is a dot labelled with its name.  Regions are dashed outlines labelled with
their names (goal regions in the goal colour), movable objects filled by role (goal objects green, the
others grey) and labelled, fixed objects light, handover points crosses, planar robots their footprint at
their start with a heading arrow.  A legend names every colour.  matplotlib draws it (this module and
:mod:`mrgc.render.gantt` are its only importers in ``render/``); ``.png`` or ``.svg``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mrgc.geometry.scene import Body, half_extents, outline, scene_from_problem
from mrgc.language.model import Box, Cylinder, Problem, Sphere
from mrgc.render.palette import FIXED, GOAL_REGION, OTHER_REGION, ROLE_COLOURS, Role, darker, robot_colours

#: points of a round outline
ROUND = 32


def write(problem: Problem, path: str, width: int, height: int) -> dict[str, Any]:
    """Draw the reach map of ``problem`` into ``path`` (.png or .svg), ``width`` × ``height`` pixels (about);
    the statistics: how many grid points each arm reaches, the heights tried."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Polygon

    from mrgc.geometry.reach import reach_map

    scene = scene_from_problem(problem)
    found = reach_map(scene)
    colours = robot_colours([r.name for r in scene.robots])
    goal = scene.goal
    dpi = 100
    with matplotlib.rc_context({"svg.hashsalt": "mrgc", "svg.fonttype": "none", "font.size": 8}):
        fig, ax = plt.subplots(figsize=(width / dpi, height / dpi))
        for b in scene.fixed:
            ax.add_patch(Polygon(_shape_xy(b), closed=True, facecolor=FIXED, alpha=0.35, edgecolor="none", zorder=0))
        handles: list[Any] = []
        for name, reached in found.reached.items():
            c = colours[name]
            if reached.any():
                ax.contourf(found.xs, found.ys, reached.astype(float), levels=[0.5, 1.5], colors=[c], alpha=0.22)
                ax.contour(found.xs, found.ys, reached.astype(float), levels=[0.5], colors=[c], linewidths=1.6)
            handles.append(Patch(facecolor=c, alpha=0.45, edgecolor=c, label=f"{name} reaches"))
        for region in scene.regions:
            rc = GOAL_REGION if region.name in goal.values() else OTHER_REGION
            xy = _shape_xy(region)
            ax.add_patch(Polygon(xy, closed=True, fill=False, edgecolor=darker(rc), linestyle="--", lw=1.4, zorder=3))
            ax.annotate(
                region.name,
                (float(xy[:, 0].mean()), float(xy[:, 1].max())),
                xytext=(0, 2),
                textcoords="offset points",
                ha="center",
                va="bottom",
                color=darker(rc),
                fontweight="bold",
                zorder=6,
            )
        for b in scene.movable:
            oc = ROLE_COLOURS[Role.GOAL if b.name in goal else Role.UNTOUCHED]
            xy = _shape_xy(b)
            ax.add_patch(Polygon(xy, closed=True, facecolor=oc, edgecolor="black", lw=0.6, zorder=4))
            ax.annotate(
                b.name, (float(xy[:, 0].mean()), float(xy[:, 1].mean())), ha="center", va="center", fontsize=6, zorder=6
            )
        for name, point in scene.handover_points.items():
            ax.plot([point[0]], [point[1]], marker="x", color="black", ms=7, mew=1.8, zorder=5)
            ax.annotate(name, (point[0], point[1]), xytext=(4, 4), textcoords="offset points", fontsize=7, zorder=6)
        for r in scene.robots:
            _robot(ax, r.name, r.base, colours[r.name], r.kind.footprint if r.kind.driven else None)
        handles += [
            Patch(facecolor=ROLE_COLOURS[Role.GOAL], edgecolor="black", label="goal object"),
            Patch(facecolor=ROLE_COLOURS[Role.UNTOUCHED], edgecolor="black", label="other object"),
            Patch(fill=False, edgecolor=darker(GOAL_REGION), linestyle="--", label="goal region"),
            Patch(fill=False, edgecolor=darker(OTHER_REGION), linestyle="--", label="region"),
            Patch(facecolor=FIXED, alpha=0.5, label="fixed object"),
        ]
        if scene.handover_points:
            handles.append(Line2D([], [], marker="x", color="black", linestyle="none", label="handover point"))
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        ax.set_xlim(float(found.xs[0]), float(found.xs[-1]))
        ax.set_ylim(float(found.ys[0]), float(found.ys[-1]))
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.grid(color="0.9", lw=0.5)
        title = (
            f"{problem.name}: where each arm reaches (tool from above at z = {found.top_z:.2f} m, "
            f"level at z = {found.side_z:.2f} m; obstacles not checked)"
            if found.reached
            else f"{problem.name} from above (no arms: planar robots drive; arrows show where they face)"
        )
        ax.set_title(title, fontsize=8)
        fig.tight_layout()
        fig.savefig(path, format=path.rsplit(".", 1)[-1].lower(), dpi=dpi, metadata=_metadata(path))
        plt.close(fig)
    return {
        "reached": {name: int(r.sum()) for name, r in found.reached.items()},
        "points": int(found.xs.size * found.ys.size),
        "top_z": found.top_z,
        "side_z": found.side_z,
    }


def _robot(ax: Any, name: str, base: np.ndarray, colour: tuple[float, float, float], footprint: Any) -> None:
    """A robot's base: a dot (an arm) or its footprint with a heading arrow (a planar robot), and its name."""
    from matplotlib.patches import Polygon

    x, y = float(base[0, 3]), float(base[1, 3])
    if footprint is None:
        ax.plot([x], [y], marker="o", color=colour, mec="black", ms=9, zorder=7)
    else:
        ax.add_patch(
            Polygon(_shape_xy(Body(name, footprint, base)), closed=True, facecolor=colour, alpha=0.7, zorder=4)
        )
        length = float(half_extents(footprint)[0])
        ax.annotate(
            "",
            xy=(x + length * base[0, 0], y + length * base[1, 0]),
            xytext=(x, y),
            arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.5},
            zorder=7,
        )
    ax.annotate(
        name, (x, y), xytext=(6, -10), textcoords="offset points", color=darker(colour), fontweight="bold", zorder=7
    )


def _shape_xy(body: Body) -> np.ndarray:
    """The outline of a body seen from above (world x, y): a box's rectangle, a round shape's circle, a
    mesh's convex hull."""
    shape = body.shape
    if isinstance(shape, Box):
        hx, hy = shape.sx / 2, shape.sy / 2
        local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    elif isinstance(shape, (Cylinder, Sphere)):
        r = shape.radius
        a = np.linspace(0, 2 * math.pi, ROUND, endpoint=False)
        local = np.column_stack([r * np.cos(a), r * np.sin(a)])
    else:
        local = _hull(outline(shape)[:, :2])
    xy: np.ndarray = local @ body.pose[:2, :2].T + body.pose[:2, 3]
    return xy


def _hull(points: np.ndarray) -> np.ndarray:
    """The 2D convex hull of ``points`` (monotone chain), counter-clockwise."""
    pts = sorted({(round(float(p[0]), 9), round(float(p[1]), 9)) for p in points})
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _metadata(path: str) -> dict[str, Any]:
    return {"Date": None} if path.lower().endswith(".svg") else {}
