"""The paper's benchmark suites as seeded layouts: PA5, PA7, PA10 and PA18 (packaging), BO8 (box-moving).

``preset(name, seed, robots)`` returns a self-contained ``.mrg`` problem like the paper's instances
(docs/generators.md, "Presets"): in packaging, boxes packed in a block in front of r1 on a pitch so tight
that neighbours obstruct each other's side grasps, three bins reached by different arms (so goals need
handovers), the goal objects drawn from the block; in box-moving, two rooms whose doorways are both blocked,
a goal box shut in an alcove behind a plug, clutter on both sides.  Unlike ``mrgc generate packaging
--robots ...``, whose layouts are drawn over wide ranges and may have no plan, a preset keeps every
object, bin and handover point where the arms can work, so its instances are meant to be solvable; the
seed varies sizes, pitch, positions, which objects are goals and where they go.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mrgc.generate.document import box_decl, document, num, pose, problem_text
from mrgc.generate.footprint import Footprint, overlaps
from mrgc.generate.sampling import ATTEMPTS, check_seed, usage_error
from mrgc.generate.sampling import uniform as _u


@dataclass(frozen=True)
class Preset:
    """A suite of the paper: its domain kind, goal and other objects, and the robot counts it allows."""

    kind: str
    goals: int
    others: int
    robots: tuple[int, int]  # inclusive range; the first is the default
    title: str


#: preset name (``mrgc generate KIND --preset NAME``) -> suite
PRESETS: dict[str, Preset] = {
    "pa5": Preset("packaging", 3, 2, (2, 2), "PA5: 2 arms, 3 goal boxes, 2 others"),
    "pa7": Preset("packaging", 3, 4, (2, 2), "PA7: 2 arms, 3 goal boxes, 4 others"),
    "pa10": Preset("packaging", 3, 7, (2, 2), "PA10: 2 arms, 3 goal boxes, 7 others"),
    "pa18": Preset("packaging", 5, 13, (2, 6), "PA18: 2-6 arms, 5 goal boxes, 13 others"),
    "bo8": Preset("box-moving", 2, 6, (2, 2), "BO8: 2 carts, 2 goal boxes, 6 others"),
}

# ---------------------------------------------------------------- packaging
#: arm bases (x, y, yaw) around the 1.4 x 1.6 m table: r1 in front of the block, r2 across, r3/r4 at the
#: sides, r5/r6 at the far corners; the first N are used
ARMS = [
    (0.0, -0.7, 90.0),
    (0.0, 0.7, -90.0),
    (0.65, 0.0, 180.0),
    (-0.65, 0.0, 0.0),
    (0.55, 0.65, -130.0),
    (-0.55, 0.65, -50.0),
]
#: handover points, each with the number of arms from which it is used: h1 between r1 and r2, h2/h3 where
#: the side arms meet r1 and r2
HANDOVERS = [((0.0, 0.05, 0.4), 2), ((0.3, 0.0, 0.4), 3), ((-0.3, 0.0, 0.4), 4)]
BINS = [("bin-a", 0.5, -0.45), ("bin-b", -0.3, 0.4), ("bin-c", 0.3, 0.4)]  # 0.2 x 0.2 m: r1's, r2's, r2's
BLOCK_Y = -0.22  # y of the block's centre (in front of r1)
PITCH = (0.085, 0.095)  # centre-to-centre, drawn per axis: 4-5 cm gaps, narrower than a side grasp needs
SIDE = (0.035, 0.045)  # box footprint sides
HEIGHT = (0.10, 0.14)  # lower boxes are picked off the table only from the top, and cannot be handed over
JITTER = 0.004  # each box moves up to this off its cell centre
YAW = 8.0  # and turns up to this (degrees)
MARGIN = 0.07  # the start region reaches this far past the block (room to set obstacles aside)


def preset(name: str, seed: int = 0, robots: int | None = None) -> str:
    """The ``.mrg`` text of instance ``seed`` of suite ``name`` (``robots``: only PA18 takes 2-6 arms).

    InputError (E000) for an unknown suite, a robot count the suite does not take or a negative seed."""
    suite = PRESETS.get(name)
    if suite is None:
        raise usage_error(f"unknown preset {name!r} (choose from {', '.join(PRESETS)})")
    lo, hi = suite.robots
    n = lo if robots is None else robots
    if not lo <= n <= hi:
        what = f"from {lo} to {hi}" if lo != hi else f"{lo}"
        raise usage_error(f"--robots must be {what} for --preset {name} (got {n})")
    check_seed(seed)
    rng = np.random.default_rng(seed)
    command = f"mrgc generate {suite.kind} --preset {name}" + (f" --robots {n}" if lo != hi else "") + f" --seed {seed}"
    problem = f"{name}-r{n}-s{seed}" if lo != hi else f"{name}-s{seed}"
    if suite.kind == "packaging":
        summary, body = _packaging(rng, problem, n, suite.goals, suite.others)
    else:
        summary, body = _box_moving(rng, problem, suite.goals)
    return document(suite.kind, command, [suite.title + " (the paper's suite, seeded layout).", *summary], body)


def _packaging(rng: np.random.Generator, name: str, arms: int, goals: int, others: int) -> tuple[list[str], str]:
    n = goals + others
    cols = round(math.sqrt(2 * n))
    rows = math.ceil(n / cols)
    px, py = _u(rng, *PITCH), _u(rng, *PITCH)
    cells = sorted(int(c) for c in rng.choice(rows * cols, n, replace=False))  # spare cells at random
    boxes = []
    for k, cell in enumerate(cells):
        r, c = divmod(cell, cols)
        x = (c - (cols - 1) / 2) * px + _u(rng, -JITTER, JITTER)
        y = BLOCK_Y + ((rows - 1) / 2 - r) * py + _u(rng, -JITTER, JITTER)
        sx, sy, h = _u(rng, *SIDE), _u(rng, *SIDE), _u(rng, *HEIGHT, 2)
        boxes.append((f"o{k + 1}", x, y, sx, sy, h, float(round(rng.uniform(-YAW, YAW)))))
    goal_idx = sorted(int(i) for i in rng.choice(n, goals, replace=False))
    order = [BINS[int(i)][0] for i in rng.permutation(len(BINS))]
    goal_bin = {i: order[k % len(order)] for k, i in enumerate(goal_idx)}
    hx = round(cols * px / 2 + MARGIN, 3)
    hy = round(rows * py / 2 + MARGIN, 3)
    points = [(f"h{k + 1}", p) for k, (p, need) in enumerate(HANDOVERS) if arms >= need]
    summary = [
        f"{n} boxes packed {rows} x {cols} on a {px:g} x {py:g} m pitch in front of r1, {goals} goals over "
        f"three bins, {len(points)} handover point{'s' * (len(points) != 1)}."
    ]
    body = problem_text(
        name,
        "packaging",
        [f"(r{k + 1} :kind panda :base {pose(x, y, 0, yaw)})" for k, (x, y, yaw) in enumerate(ARMS[:arms])],
        ["(table :shape (box 1.4 1.6 0.05) :pose (0 0 -0.025 0))"],
        [box_decl("start", 0, BLOCK_Y, hx, hy, 0.3), *[box_decl(b, x, y, 0.1, 0.1, 0.3) for b, x, y in BINS]],
        [box_decl(o, x, y, sx / 2, sy / 2, h, yaw) for o, x, y, sx, sy, h, yaw in boxes],
        [f"(in-region {boxes[i][0]} {goal_bin[i]})" for i in goal_idx],
        [f"({h} :position ({num(x)} {num(y)} {num(z)}))" for h, (x, y, z) in points],
    )
    return summary, body


# ---------------------------------------------------------------- box-moving
HALF_X, HALF_Y = 3.0, 2.0  # inner floor half sizes: two 3 x 4 m rooms, the divider at x = 0
DOOR_Y = (0.9, 1.3)  # |y| of each doorway's centre (one north, one south)
DOOR_W = (0.8, 0.95)
BOX = (0.26, 0.34)  # box sides; every box is 0.3 m high
ALCOVE_W, ALCOVE_D = 0.5, 0.8  # inner width and depth of the pocket on the west wall
GAP = 0.08  # least free space between boxes, walls and carts


def _box_moving(rng: np.random.Generator, name: str, goals: int) -> tuple[list[str], str]:
    for _ in range(ATTEMPTS):
        layout = _bo_layout(rng)
        if layout is not None:
            break
    else:  # pragma: no cover - never seen
        raise AssertionError("no BO8 layout")
    walls, carts, boxes = layout
    summary = ["Both doorways of the divider are blocked, g2 stands in an alcove behind 'plug', clutter on both sides."]
    body = problem_text(
        name,
        "box-moving",
        [f"(r{k + 1} :kind mover :base {pose(c.x, c.y, 0, c.yaw)})" for k, c in enumerate(carts)],
        [box_decl(n, f.x, f.y, f.hx, f.hy, 0.5) for n, f in walls],
        [box_decl("start", -1.4, 0, 1.6, HALF_Y, 0.5), box_decl("goal", 1.6, 0, 1.4, HALF_Y, 0.5)],
        [box_decl(n, f.x, f.y, f.hx, f.hy, 0.3, f.yaw) for n, f in boxes],
        [f"(in-region g{k + 1} goal)" for k in range(goals)],
    )
    return summary, body


def _bo_layout(rng: np.random.Generator):  # type: ignore[no-untyped-def]
    """Walls, carts and boxes of one BO8 attempt, or None when something found no place."""
    t = 0.1
    walls = [
        ("wall-s", Footprint(0.0, -HALF_Y - t / 2, HALF_X + t, t / 2)),
        ("wall-n", Footprint(0.0, HALF_Y + t / 2, HALF_X + t, t / 2)),
        ("wall-w", Footprint(-HALF_X - t / 2, 0.0, t / 2, HALF_Y + t)),
        ("wall-e", Footprint(HALF_X + t / 2, 0.0, t / 2, HALF_Y + t)),
    ]
    yn, ys = _u(rng, *DOOR_Y, 2), -_u(rng, *DOOR_Y, 2)
    wn, ws = _u(rng, *DOOR_W, 2), _u(rng, *DOOR_W, 2)
    for label, lo, hi in (("s", -HALF_Y, ys - ws / 2), ("m", ys + ws / 2, yn - wn / 2), ("n", yn + wn / 2, HALF_Y)):
        walls.append((f"divider-{label}", Footprint(0.0, round((lo + hi) / 2, 3), t / 2, round((hi - lo) / 2, 3))))
    ya = _u(rng, -1.3, 1.3, 2)  # the alcove on the west wall: two short walls
    for label, sign in (("n", 1), ("s", -1)):
        walls.append(
            (
                f"alcove-{label}",
                Footprint(-HALF_X + ALCOVE_D / 2, round(ya + sign * (ALCOVE_W + t) / 2, 3), ALCOVE_D / 2, t / 2),
            )
        )
    taken = [f for _, f in walls]
    carts: list[Footprint] = []
    for x, y in ((-1.2, 0.5), (-1.2, -0.5)):
        carts.append(
            Footprint(x + _u(rng, -0.15, 0.15), y + _u(rng, -0.15, 0.15), 0.25, 0.2, float(rng.integers(-20, 21)))
        )
    if overlaps(carts[0], carts[1], GAP):
        return None
    boxes: list[tuple[str, Footprint]] = []

    def put(name: str, x: tuple[float, float], y: tuple[float, float], yaw: bool = True) -> bool:
        for _ in range(ATTEMPTS):
            f = Footprint(
                _u(rng, *x),
                _u(rng, *y),
                _u(rng, *BOX) / 2,
                _u(rng, *BOX) / 2,
                float(rng.integers(-30, 31)) if yaw else 0.0,
            )
            if not any(overlaps(f, o, GAP) for o in (*taken, *carts, *(b for _, b in boxes))):
                boxes.append((name, f))
                return True
        return False

    ok = (
        put("g1", (-2.0, -0.6), (-1.7, 1.7))
        and put("g2", (-HALF_X + 0.28, -HALF_X + 0.38), (ya - 0.02, ya + 0.02), yaw=False)
        and put("door-n", (-0.05, 0.01), (yn - 0.08, yn + 0.08), yaw=False)
        and put("door-s", (-0.05, 0.01), (ys - 0.08, ys + 0.08), yaw=False)
        and put("plug", (-HALF_X + ALCOVE_D + 0.25, -HALF_X + ALCOVE_D + 0.45), (ya - 0.05, ya + 0.05), yaw=False)
        and put("b1", (-2.6, -0.5), (-1.7, 1.7))
        and put("b2", (0.9, 2.3), (-1.0, 1.0))
        and put("b3", (0.5, 2.7), (-1.7, 1.7))
    )
    return (walls, carts, boxes) if ok else None
