"""The Gantt chart of a plan with matplotlib (the one render module that imports it).

One row per robot (the problem's order, top to bottom, names in the robot's colour), one column per step.
Each action is a bar in its robot's row and its step's column, coloured by the object's role (goal object,
moved obstacle; :mod:`mrgc.render.palette`) and labelled with the object, where it goes and the grasp.  A
handover is a bar in both robots' rows (the giver's says whom it passes to) linked by an arrow from the
giver to the taker, labelled with the handover point.  Empty cells are waits.  Works for symbolic plans
too: nothing here needs geometry.  SVG output is deterministic (no date, fixed ids).
"""

from __future__ import annotations

from typing import Any, Mapping

from mrgc.language.model import Problem
from mrgc.planner.plan import moved_text
from mrgc.render.palette import ROLE_COLOURS, Role, moved_objects, robot_colours, roles

BAR = 0.74  # bar width (steps) and height (rows)


def write(problem: Problem, plan: Mapping[str, Any], path: str) -> None:
    """Draw the Gantt chart of ``plan`` (JSON) for ``problem`` into ``path`` (.svg or .png)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch, Rectangle

    robots = [r.name for r in problem.robots]
    row = {r: i for i, r in enumerate(robots)}
    colours = robot_colours(robots)
    role = roles([m.name for m in problem.movable], problem.goal_regions, moved_objects(plan))
    steps = plan.get("steps", [])
    n = max(1, len(steps))
    with matplotlib.rc_context({"svg.hashsalt": "mrgc", "svg.fonttype": "none", "font.size": 9}):
        fig, ax = plt.subplots(figsize=(1.2 + 1.9 * n, 0.9 + 0.75 * len(robots)))
        for t, step in enumerate(steps, 1):
            for a in step.get("actions", []):
                face = ROLE_COLOURS[role.get(a["object"], Role.MOVED)]
                giver, taker = a["pick_robot"], a["place_robot"]
                bars = [(taker, f"{a['object']} \u2192 {a['region']}\n{a['place_grasp']}")]
                if giver != taker:
                    bars.insert(0, (giver, f"{a['object']} \u2192 {taker}\n{a['pick_grasp']}"))
                for robot, label in bars:
                    y = row.get(robot, 0)
                    ax.add_patch(
                        Rectangle(
                            (t - BAR / 2, y - BAR / 2),
                            BAR,
                            BAR,
                            facecolor=face,
                            edgecolor=colours.get(robot, (0, 0, 0)),
                            linewidth=2.0,
                        )
                    )
                    ax.text(t, y, label, ha="center", va="center", fontsize=8, color="white", fontweight="bold")
                if giver != taker:
                    y0, y1 = row.get(giver, 0), row.get(taker, 0)
                    x = t + BAR / 2 + 0.05
                    ax.annotate(
                        "", xy=(x, y1), xytext=(x, y0), arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.8}
                    )
                    if a.get("handover_point"):
                        ax.text(x + 0.02, (y0 + y1) / 2, a["handover_point"], ha="left", va="center", fontsize=8)
        ax.set_xlim(0.5, n + 0.5)
        ax.set_ylim(len(robots) - 0.5, -0.5)
        ax.set_xticks(range(1, n + 1), [f"step {t}" for t in range(1, n + 1)])
        ax.set_yticks(range(len(robots)), robots)
        for tick in ax.get_yticklabels():
            tick.set_color(colours[tick.get_text()])
            tick.set_fontweight("bold")
        ax.set_xticks([t + 0.5 for t in range(n)], minor=True)
        ax.grid(which="minor", axis="x", color="0.85")
        ax.tick_params(which="minor", length=0)
        ax.set_title(
            f"{problem.name}: {len(steps)} step{'s' * (len(steps) != 1)}, "
            + moved_text([[a["object"] for a in s.get("actions", [])] for s in steps])
        )
        shown = {role.get(a["object"], Role.MOVED) for s in steps for a in s.get("actions", [])}
        keys = [(Role.GOAL, "goal object"), (Role.MOVED, "moved obstacle")]
        ax.legend(  # the colours the chart has (a plan moving no obstacle has no "moved obstacle" key)
            handles=[Patch(facecolor=ROLE_COLOURS[r], label=text) for r, text in keys if r in shown or not steps],
            loc="upper center",
            bbox_to_anchor=(0.5, -0.12 - 0.05 / max(1, len(robots))),
            ncol=2,
            frameon=False,
        )
        fig.tight_layout()
        fig.savefig(path, format=path.rsplit(".", 1)[-1].lower(), dpi=110, metadata=_metadata(path))
        plt.close(fig)


def _metadata(path: str) -> dict[str, Any]:
    """No creation date in SVG (the file depends on the plan only); PNG keeps matplotlib's defaults."""
    return {"Date": None} if path.lower().endswith(".svg") else {}
