"""Random packaging problems: Franka Panda arms around a table, objects packed in a start region, bins.

``packaging(robots, goals, others, seed)`` draws every quantity uniformly from the documented ranges
below (docs/generators.md) and keeps only what makes the file valid: nothing overlaps at the start,
every object lies in a region, every bin and the start region are within the nominal reach of some arm,
every object fits the gripper across one horizontal axis.  It does not check that a plan exists.

``grid_benchmark(name, n, arms, seed)`` is the older fixed-layout generator of the shipped PA-n problems
(pa5.mrg, pa10.mrg, pa18-4arms.mrg; ``python domains/packaging/generate.py`` rewrites them).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

import numpy as np

from mrgc.errors import Diagnostic
from mrgc.generate.document import document, num, pose, problem_text
from mrgc.generate.footprint import Footprint, overlaps
from mrgc.generate.sampling import ATTEMPTS, draw_layout
from mrgc.generate.sampling import uniform as _u
from mrgc.language.parser import parse_text
from mrgc.language.printer import format_source

#: argument ranges (inclusive)
RANGES = {"--robots": (2, 6), "--goals": (1, 12), "--others": (0, 30)}

SHOULDER = 0.333  # height of the Panda's shoulder (first joint) above its base (m)
REACH = 0.8  # the reach sphere around the shoulder that bins and the start region are kept in (Panda: 0.855)
#: a goal object's centre lies within this of some arm's shoulder: measured with the analytic solver
#: (benchmarks/reach_audit.py; a box at table height, 12 azimuths and yaws per distance), every sample has a
#: grasp with a reachable pre-grasp up to 0.84 m, 9/12 at 0.86, a few at 0.90-0.96, none from 0.98 m (the
#: Panda's 0.855 m to the flange plus its tool bounds it by 1.0 m in theory, but not in practice)
GOAL_REACH = 0.85
ARM_SPACING = 0.35  # least distance between two arm bases
BASE_CLEARANCE = 0.15  # regions keep this far (horizontally) from every arm base
EDGE_OFFSET = (-0.12, 0.10)  # base distance outside the table edge (negative: on the table)
YAW_JITTER = 20.0  # degrees off "facing the table centre"
TABLE_MIN = (0.9, 0.7)  # table size ranges: x in [max(0.9, start + 0.4), max(1.6, start + 0.7)], y likewise
TABLE_MAX = (1.6, 1.4)
PITCH = (0.07, 0.14)  # neighbour pitch of the start grid, drawn per axis
NEIGHBOUR_GAP = 0.005  # least free space between neighbours in the grid
SIZE = (0.03, 0.10)  # box footprint sides
FIT = 0.07  # at least one horizontal side (a cylinder's diameter) is at most this: the gripper opens 8 cm
RADIUS = (0.015, 0.035)
HEIGHT = (0.04, 0.20)
CYLINDERS = 0.25  # share of cylinders
OBJECT_YAW = 20.0  # boxes turned up to this (degrees), when the turned box still fits its cell
REGION_HEIGHT = 0.3
BINS = 4  # at most this many bins (and at most one per goal)
BIN_SIZE = (0.15, 0.35)
BIN_GAP = 0.03  # free space between bins and the start region
#: a bin's floor holds its goals when its area is at least this many times the sum of their cells (a cell:
#: the square of the object's largest footprint side plus PLACE_GAP), and each side holds the largest cell
BIN_ROOM = 1.5
PLACE_GAP = 0.02
BIN_GROW_MAX = 0.5  # a bin grown to hold its goals stays at most this long a side; more goals get a new bin
HANDOVERS = 3  # at most this many handover points
HANDOVER_Z = (0.25, 0.5)


@dataclass(frozen=True)
class Arm:
    """An arm of a generated packaging cell: where it stands and how far it reaches."""

    name: str
    x: float
    y: float
    yaw: float

    def shoulder_distance(self, x: float, y: float, z: float) -> float:
        """Distance from the arm's shoulder to a point (m)."""
        return math.dist((self.x, self.y, SHOULDER), (x, y, z))


@dataclass(frozen=True)
class Item:
    """A placed box (``radius`` 0) or cylinder standing on the table, or a region."""

    name: str
    foot: Footprint
    height: float

    def shape(self) -> str:
        """The ``.mrg`` shape of the body."""
        if self.foot.disc:
            return f"(cylinder {num(self.foot.radius)} {num(self.height)})"
        return f"(box {num(2 * self.foot.hx)} {num(2 * self.foot.hy)} {num(self.height)})"

    def decl(self) -> str:
        """The ``.mrg`` declaration of the body."""
        where = pose(self.foot.x, self.foot.y, self.height / 2, self.foot.yaw)
        return f"({self.name} :shape {self.shape()} :pose {where})"


def packaging(robots: int = 2, goals: int = 3, others: int = 2, seed: int = 0) -> str:
    """A random packaging problem as ``.mrg`` text (the shipped domain inlined); same arguments, same text.

    InputError (E000) for arguments outside RANGES or a negative seed.
    """
    counts = {"--robots": robots, "--goals": goals, "--others": others}
    rng, layout = draw_layout("packaging", RANGES, counts, seed, lambda rng: _layout(rng, robots, goals, others))
    table, arms, start, objects, bins, handovers, pitch = layout
    goal_idx = _within_reach(arms, objects, [int(i) for i in rng.choice(len(objects), goals, replace=False)])
    goal_bin = {i: bins[int(rng.integers(len(bins)))].name for i in goal_idx}
    # streams of their own, so that a layout that needs no repair stays exactly as drawn
    bins = _size_bins(np.random.default_rng([seed, 2]), table, arms, start, objects, bins, goal_bin)
    handovers = _connect(np.random.default_rng([seed, 1]), arms, table, objects, bins, goal_bin, handovers)
    name = f"packaging-r{robots}-g{goals}-o{others}-s{seed}"
    command = f"mrgc generate packaging --robots {robots} --goals {goals} --others {others} --seed {seed}"
    n_cyl = sum(o.foot.disc for o in objects)
    summary = [
        f"A random packaging problem: {robots} Panda arms around a {2 * table.hx:g} x {2 * table.hy:g} m "
        f"table, {len(objects)} objects ({n_cyl} of them cylinders)",
        f"on a {pitch[0]:g} x {pitch[1]:g} m pitch in 'start', {goals} goals over {len(bins)} bins, "
        f"{len(handovers)} handover points.",
        "Generated within the ranges of docs/generators.md; a plan may not exist.",
    ]
    body = problem_text(
        name,
        "packaging",
        [f"({a.name} :kind panda :base {pose(a.x, a.y, 0, a.yaw)})" for a in arms],
        [f"(table :shape (box {num(2 * table.hx)} {num(2 * table.hy)} 0.05) :pose (0 0 -0.025 0))"],
        [r.decl() for r in (start, *bins)],
        [o.decl() for o in objects],
        [f"(in-region {objects[i].name} {goal_bin[i]})" for i in goal_idx],
        [f"({h} :position ({num(x)} {num(y)} {num(z)}))" for h, (x, y, z) in handovers],
    )
    return document("packaging", command, summary, body)


def _within_reach(arms: list[Arm], objects: list[Item], drawn: list[int]) -> list[int]:
    """The goal objects, sorted: the drawn ones, except that a drawn object whose centre lies farther than
    GOAL_REACH from every arm's shoulder (no arm can grasp it at all) is swapped for the nearest object
    within GOAL_REACH of some shoulder that is not a goal yet (ties: the lower index), while there is one.
    No random number is drawn, so a draw whose goals are all within reach is kept as it is."""

    def graspable(item: Item) -> bool:
        return any(a.shoulder_distance(item.foot.x, item.foot.y, item.height / 2) <= GOAL_REACH for a in arms)

    goals = list(drawn)
    for k, i in enumerate(drawn):
        if graspable(objects[i]):
            continue
        spare = [j for j in range(len(objects)) if j not in goals and graspable(objects[j])]
        if spare:
            here = objects[i].foot
            goals[k] = min(spare, key=lambda j: (math.hypot(objects[j].foot.x - here.x, objects[j].foot.y - here.y), j))
    return sorted(goals)


def _layout(rng: np.random.Generator, robots: int, goals: int, others: int):  # type: ignore[no-untyped-def]
    """One attempt at a whole layout, or None when some item found no place (the caller draws again)."""
    n = goals + others
    pitch = (_u(rng, *PITCH), _u(rng, *PITCH))
    spare = int(rng.integers(0, n // 4 + 2))
    aspect = float(rng.uniform(0.5, 2.0))
    cols = max(1, math.ceil(math.sqrt((n + spare) * aspect)))
    rows = math.ceil((n + spare) / cols)
    margin = _u(rng, 0.005, 0.04)
    start_hx = round(cols * pitch[0] / 2 + margin, 3)
    start_hy = round(rows * pitch[1] / 2 + margin, 3)
    table = Footprint(
        0.0,
        0.0,
        _u(rng, max(TABLE_MIN[0], 2 * start_hx + 0.4), max(TABLE_MAX[0], 2 * start_hx + 0.7), 2) / 2,
        _u(rng, max(TABLE_MIN[1], 2 * start_hy + 0.4), max(TABLE_MAX[1], 2 * start_hy + 0.7), 2) / 2,
    )
    arms = _arms(rng, robots, table)
    if arms is None:
        return None
    start_foot = _region_spot(rng, table, arms, start_hx, start_hy, [])
    if start_foot is None:
        return None
    start = Item("start", start_foot, REGION_HEIGHT)
    cells = sorted(int(c) for c in rng.choice(rows * cols, n, replace=False))
    objects = [_object(rng, f"o{k + 1}", start_foot, rows, cols, pitch, c) for k, c in enumerate(cells)]
    bins: list[Item] = []
    for k in range(int(rng.integers(1, min(goals, BINS) + 1))):
        hx, hy = _u(rng, *BIN_SIZE, 2) / 2, _u(rng, *BIN_SIZE, 2) / 2
        foot = _region_spot(rng, table, arms, hx, hy, [start_foot, *(b.foot for b in bins)])
        if foot is None:
            return None
        bins.append(Item(f"bin-{chr(ord('a') + k)}", foot, REGION_HEIGHT))
    handovers = _handovers(rng, arms, table)
    if handovers is None:
        return None
    return table, arms, start, objects, bins, handovers, pitch


def _arms(rng: np.random.Generator, n: int, table: Footprint) -> list[Arm] | None:
    """Arm bases on or beside the table edge, facing the table centre (give or take YAW_JITTER)."""
    edges = [  # (length, start point, direction along the edge, outward normal)
        (2 * table.hx, (-table.hx, -table.hy), (1, 0), (0, -1)),
        (2 * table.hy, (table.hx, -table.hy), (0, 1), (1, 0)),
        (2 * table.hx, (table.hx, table.hy), (-1, 0), (0, 1)),
        (2 * table.hy, (-table.hx, table.hy), (0, -1), (-1, 0)),
    ]
    perimeter = sum(e[0] for e in edges)
    arms: list[Arm] = []
    for k in range(n):
        for _ in range(ATTEMPTS):
            t = float(rng.uniform(0, perimeter))
            off = float(rng.uniform(*EDGE_OFFSET))
            jitter = float(rng.uniform(-YAW_JITTER, YAW_JITTER))
            for edge in edges:
                if t <= edge[0]:
                    break
                t -= edge[0]
            _, (sx, sy), (dx, dy), (nx, ny) = edge
            x, y = round(sx + t * dx + off * nx, 3), round(sy + t * dy + off * ny, 3)
            yaw = round(math.degrees(math.atan2(-y, -x)) + jitter)
            yaw = (yaw + 180) % 360 - 180
            if all(math.hypot(x - a.x, y - a.y) >= ARM_SPACING for a in arms):
                arms.append(Arm(f"r{k + 1}", x + 0.0, y + 0.0, float(yaw)))
                break
        else:
            return None
    return arms


def _region_spot(
    rng: np.random.Generator, table: Footprint, arms: list[Arm], hx: float, hy: float, taken: list[Footprint]
) -> Footprint | None:
    """An axis-aligned region of half sizes hx, hy on the table, clear of the arm bases and of ``taken``,
    whose centre (10 cm above the table) is within REACH of some arm's shoulder."""
    if hx > table.hx or hy > table.hy:
        return None
    for _ in range(ATTEMPTS):
        foot = Footprint(_u(rng, -table.hx + hx, table.hx - hx), _u(rng, -table.hy + hy, table.hy - hy), hx, hy)
        if not foot.inside(table):
            continue
        if any(foot.distance_to_point(a.x, a.y) < BASE_CLEARANCE for a in arms):
            continue
        if any(overlaps(foot, t, BIN_GAP) for t in taken):
            continue
        if min(a.shoulder_distance(foot.x, foot.y, 0.1) for a in arms) <= REACH:
            return foot
    return None


def _object(
    rng: np.random.Generator, name: str, start: Footprint, rows: int, cols: int, pitch: tuple[float, float], cell: int
) -> Item:
    """A box or cylinder in grid cell ``cell`` of the start region, jittered within its cell."""
    r, c = divmod(cell, cols)
    cx = start.x + (c - (cols - 1) / 2) * pitch[0]
    cy = start.y + ((rows - 1) / 2 - r) * pitch[1]
    room_x, room_y = pitch[0] / 2 - NEIGHBOUR_GAP / 2, pitch[1] / 2 - NEIGHBOUR_GAP / 2  # half cell, less the gap
    height = _u(rng, *HEIGHT)
    if rng.random() < CYLINDERS:
        radius = _u(rng, RADIUS[0], min(RADIUS[1], room_x - 0.001, room_y - 0.001))
        foot = Footprint(cx, cy, radius=radius)
    else:
        sx = _u(rng, SIZE[0], min(SIZE[1], 2 * room_x - 0.002))
        sy = _u(rng, SIZE[0], min(SIZE[1], 2 * room_y - 0.002))
        if min(sx, sy) > FIT:
            if rng.random() < 0.5:
                sx = _u(rng, SIZE[0], FIT)
            else:
                sy = _u(rng, SIZE[0], FIT)
        yaw = round(float(rng.uniform(-OBJECT_YAW, OBJECT_YAW)))
        foot = Footprint(cx, cy, sx / 2, sy / 2, float(yaw))
        bx, by = foot.half_box()
        if bx > room_x - 0.001 or by > room_y - 0.001:
            foot = Footprint(cx, cy, sx / 2, sy / 2, 0.0)
    bx, by = foot.half_box()
    x = cx + float(rng.uniform(-1, 1)) * max(room_x - bx - 0.001, 0.0)
    y = cy + float(rng.uniform(-1, 1)) * max(room_y - by - 0.001, 0.0)
    return Item(name, Footprint(round(x, 3) + 0.0, round(y, 3) + 0.0, foot.hx, foot.hy, foot.yaw, foot.radius), height)


def _handovers(
    rng: np.random.Generator, arms: list[Arm], table: Footprint
) -> list[tuple[str, tuple[float, float, float]]] | None:
    """Handover points above the table between two arms, within REACH of both shoulders when any pair of
    arms is close enough for that (else between the closest pair, without the guarantee)."""
    pairs = [(a, b) for i, a in enumerate(arms) for b in arms[i + 1 :]]
    close = [p for p in pairs if math.hypot(p[0].x - p[1].x, p[0].y - p[1].y) <= 2 * math.sqrt(REACH**2 - 0.01)]
    pool = close or [min(pairs, key=lambda p: math.hypot(p[0].x - p[1].x, p[0].y - p[1].y))]
    points: list[tuple[str, tuple[float, float, float]]] = []
    for k in range(int(rng.integers(1, min(HANDOVERS, len(pool)) + 1))):
        for _ in range(ATTEMPTS):
            a, b = pool[int(rng.integers(len(pool)))]
            w = float(rng.uniform(0.35, 0.65))
            x = _u(rng, -0.1, 0.1) + a.x + w * (b.x - a.x)
            y = _u(rng, -0.1, 0.1) + a.y + w * (b.y - a.y)
            z = _u(rng, *HANDOVER_Z)
            x, y = round(x, 3) + 0.0, round(y, 3) + 0.0
            if not table.distance_to_point(x, y) == 0.0:
                continue
            if close and max(a.shoulder_distance(x, y, z), b.shoulder_distance(x, y, z)) > REACH:
                continue
            if any(math.dist((x, y, z), p) < 0.1 for _, p in points):
                continue
            points.append((f"h{k + 1}", (x, y, z)))
            break
        else:
            return None
    return points


def cell_side(obj: Item) -> float:
    """The side of the square an object needs on a bin's floor: its largest footprint side (a cylinder's
    diameter), whatever its yaw, plus PLACE_GAP."""
    f = obj.foot
    return 2 * (f.radius if f.disc else max(f.hx, f.hy)) + PLACE_GAP


def holds(region: Footprint, goals: list[Item]) -> bool:
    """Whether a bin's floor is roomy enough for ``goals`` (BIN_ROOM times their cells' area, each side at
    least the largest cell): a rule of thumb a person would accept, not a packing."""
    if not goals:
        return True
    side = max(cell_side(o) for o in goals)
    need = BIN_ROOM * sum(cell_side(o) ** 2 for o in goals)
    return min(2 * region.hx, 2 * region.hy) >= side and 4 * region.hx * region.hy >= need


def _size_bins(
    rng: np.random.Generator,
    table: Footprint,
    arms: list[Arm],
    start: Item,
    objects: list[Item],
    bins: list[Item],
    goal_bin: dict[int, str],
) -> list[Item]:
    """Bins that hold the goals sent to them (:func:`holds`).  A bin too small for its goals grows (at most
    BIN_GROW_MAX a side) in place when it still fits there (on the table, clear of the bases and the other
    regions), else at a spot drawn for its grown size; the goals that no such bin holds go, the last ones
    first, to new bins sized for them (:func:`_new_bins`; processed the same way in turn); when no spot is
    left for a new bin, they go to bins with room to spare, else they stay where they were sent (such an
    instance may have no plan).  ``goal_bin`` is updated.  A layout whose bins hold their goals is left as
    drawn (no random number is drawn for it)."""
    out = list(bins)
    k = 0
    while k < len(out):
        goals = sorted(i for i, b in goal_bin.items() if b == out[k].name)
        taken = [start.foot] + [b.foot for j, b in enumerate(out) if j != k]
        moved: list[int] = []
        while goals and not holds(out[k].foot, [objects[i] for i in goals]):
            grown = _grown(out[k].foot, [objects[i] for i in goals])
            spot = _placed(rng, table, arms, grown, taken) if holds(grown, [objects[i] for i in goals]) else None
            if spot is not None:
                out[k] = Item(out[k].name, spot, REGION_HEIGHT)
                break
            moved.insert(0, goals.pop())
        _new_bins(rng, table, arms, objects, out, goal_bin, moved, taken + [out[k].foot], out[k].name)
        k += 1
    return out


def _new_bins(
    rng: np.random.Generator,
    table: Footprint,
    arms: list[Arm],
    objects: list[Item],
    out: list[Item],
    goal_bin: dict[int, str],
    moved: list[int],
    taken: list[Footprint],
    sent: str,
) -> None:
    """New bins (appended to ``out``) for the goals ``moved`` out of bin ``sent``: one for all of them, or,
    when no spot fits a bin that size, for the first half of them and so on; goals no new bin takes go to
    bins with room to spare, else back to ``sent``."""
    chunk = list(moved)
    while moved and chunk:
        foot = _grown(Footprint(0.0, 0.0, BIN_SIZE[0] / 2, BIN_SIZE[0] / 2), [objects[i] for i in chunk])
        spot = _region_spot(rng, table, arms, foot.hx, foot.hy, taken + [b.foot for b in out])
        if spot is None:
            chunk = chunk[: len(chunk) // 2]
            continue
        out.append(Item(f"bin-{chr(ord('a') + len(out))}", spot, REGION_HEIGHT))
        for i in chunk:
            goal_bin[i] = out[-1].name
        moved = [i for i in moved if i not in chunk]
        chunk = list(moved)
    for i in moved:
        goal_bin[i] = next((b.name for b in out if _room_for(b, i, objects, goal_bin)), sent)


def _room_for(region: Item, i: int, objects: list[Item], goal_bin: dict[int, str]) -> bool:
    """Whether bin ``region`` holds its goals and object ``i`` besides."""
    goals = [objects[j] for j, b in goal_bin.items() if b == region.name and j != i]
    return holds(region.foot, goals + [objects[i]])


def _grown(foot: Footprint, goals: list[Item]) -> Footprint:
    """``foot`` scaled about its centre, keeping its aspect, until it holds ``goals``, each side at most
    BIN_GROW_MAX (then it may not hold them)."""
    side = max(cell_side(o) for o in goals)
    need = BIN_ROOM * sum(cell_side(o) ** 2 for o in goals)
    f = max(math.sqrt(need / (4 * foot.hx * foot.hy)), side / (2 * min(foot.hx, foot.hy)), 1.0)
    hx = min(math.ceil(foot.hx * f * 1000) / 1000, BIN_GROW_MAX / 2)
    hy = min(math.ceil(foot.hy * f * 1000) / 1000, BIN_GROW_MAX / 2)
    return Footprint(foot.x, foot.y, hx, hy)


def _placed(
    rng: np.random.Generator, table: Footprint, arms: list[Arm], foot: Footprint, taken: list[Footprint]
) -> Footprint | None:
    """Where a grown bin ``foot`` goes: where it stands when it fits there, else a spot drawn for its size
    (None: no spot found)."""
    fits = (
        foot.inside(table)
        and all(foot.distance_to_point(a.x, a.y) >= BASE_CLEARANCE for a in arms)
        and not any(overlaps(foot, t, BIN_GAP) for t in taken)
    )
    return foot if fits else _region_spot(rng, table, arms, foot.hx, foot.hy, taken)


def reaches(arm: Arm, item: Item) -> bool:
    """Whether ``item`` (an object: its centre; a bin: its centre 10 cm above the table) is within REACH of
    the arm's shoulder: the generator's coarse reach test (no kinematics)."""
    z = item.height / 2 if item.height < REGION_HEIGHT else 0.1
    return arm.shoulder_distance(item.foot.x, item.foot.y, z) <= REACH


def connected(
    arms: list[Arm], obj: Item, region: Item, handovers: list[tuple[str, tuple[float, float, float]]]
) -> bool:
    """Whether some arm reaches both ``obj`` and ``region``, or a handover point lies within REACH of an arm
    that reaches ``obj`` and of another arm that reaches ``region``."""
    pickers = [a for a in arms if reaches(a, obj)]
    placers = [a for a in arms if reaches(a, region)]
    if any(a in placers for a in pickers):
        return True
    return any(
        a.shoulder_distance(*p) <= REACH and b.shoulder_distance(*p) <= REACH
        for _, p in handovers
        for a in pickers
        for b in placers
    )


def _connect(
    rng: np.random.Generator,
    arms: list[Arm],
    table: Footprint,
    objects: list[Item],
    bins: list[Item],
    goal_bin: dict[int, str],
    handovers: list[tuple[str, tuple[float, float, float]]],
) -> list[tuple[str, tuple[float, float, float]]]:
    """Handover points added where a goal object is not :func:`connected` to its bin: between the closest
    pair of an arm that reaches the object and one that reaches the bin, within REACH of both shoulders (as
    drawn points are), when such a pair is close enough.  The layout is otherwise left as drawn."""
    points = list(handovers)
    region = {b.name: b for b in bins}
    for i, name in sorted(goal_bin.items()):
        obj, reg = objects[i], region[name]
        if connected(arms, obj, reg, points):
            continue
        pairs = sorted(
            ((a, b) for a in arms if reaches(a, obj) for b in arms if b is not a and reaches(b, reg)),
            key=lambda p: (math.hypot(p[0].x - p[1].x, p[0].y - p[1].y), p[0].name, p[1].name),
        )
        for a, b in pairs:
            spot = _between(rng, a, b, table, points)
            if spot is not None:
                points.append((f"h{len(points) + 1}", spot))
                break
    return points


def _between(
    rng: np.random.Generator, a: Arm, b: Arm, table: Footprint, points: list[tuple[str, tuple[float, float, float]]]
) -> tuple[float, float, float] | None:
    """A handover point above the table between arms ``a`` and ``b`` as :func:`_handovers` draws them, within
    REACH of both shoulders and 10 cm from the other points; None when ATTEMPTS draws find none."""
    for _ in range(ATTEMPTS):
        w = float(rng.uniform(0.35, 0.65))
        x = round(_u(rng, -0.1, 0.1) + a.x + w * (b.x - a.x), 3) + 0.0
        y = round(_u(rng, -0.1, 0.1) + a.y + w * (b.y - a.y), 3) + 0.0
        z = _u(rng, *HANDOVER_Z)
        if table.distance_to_point(x, y) != 0.0:
            continue
        if max(a.shoulder_distance(x, y, z), b.shoulder_distance(x, y, z)) > REACH:
            continue
        if any(math.dist((x, y, z), p) < 0.1 for _, p in points):
            continue
        return (x, y, z)
    return None


# ---------------------------------------------------------------- the shipped PA-n benchmark problems
_GRID_ARMS = {
    2: ["(r1 :kind panda :base (0 -0.7 0 90))", "(r2 :kind panda :base (0 0.7 0 -90))"],
    4: [
        "(r1 :kind panda :base (0 -0.7 0 90))",
        "(r2 :kind panda :base (0 0.7 0 -90))",
        "(r3 :kind panda :base (0.65 0 0 180))",
        "(r4 :kind panda :base (-0.65 0 0 0))",
    ],
}


def grid_benchmark(name: str, n: int, arms: int, seed: int = 0) -> str:
    """The PA-n layout of the shipped benchmark problems: n 4 cm boxes packed on a 9 cm grid in front of r1
    (neighbours block each other's side grasps), three bins reachable by different arms, so some goals need
    a handover at h1.  Canonical text, as ``mrgc fmt`` writes it; deterministic in (n, arms, seed)."""
    rng = random.Random(seed)
    cols = min(n, 6)
    rows = (n + cols - 1) // cols
    pitch = 0.09
    objs = []
    for i in range(n):
        r, c = divmod(i, cols)
        x = (c - (cols - 1) / 2) * pitch
        y = -0.2 - (r - (rows - 1) / 2) * pitch
        h = rng.choice([0.08, 0.1, 0.12])
        objs.append(f"(o{i + 1} :shape (box 0.04 0.04 {h:g}) :pose ({x:.3f} {y:.3f} {h / 2:g} 0))")
    bins = ["bin-a", "bin-b", "bin-c"]
    n_goals = max(2, n // 3)
    goal_objs = rng.sample(range(n), n_goals)
    goals = " ".join(f"(in-region o{i + 1} {bins[k % 3]})" for k, i in enumerate(sorted(goal_objs)))
    width = 0.12 + cols * pitch
    depth = 0.1 + rows * pitch
    lines = [
        f"; Generated by domains/packaging/generate.py: {n} boxes packed {rows}x{cols} in front of r1, {arms} arms,",
        f"; {n_goals} goals over three bins (bin-b and bin-c need a handover from r1's side).",
        f"(define (problem {name})",
        "  (:domain packaging)",
        "  (:robots",
        *[f"    {a}" for a in _GRID_ARMS[arms]],
        "  )",
        "  (:fixed",
        "    (table :shape (box 1.4 1.6 0.05) :pose (0 0 -0.025 0)))",
        "  (:regions",
        f"    (start :shape (box {width:.2f} {depth:.2f} 0.3) :pose (0 -0.2 0.15 0))",
        "    (bin-a :shape (box 0.2 0.2 0.3) :pose (0.4 -0.4 0.15 0))",
        "    (bin-b :shape (box 0.2 0.2 0.3) :pose (-0.3 0.4 0.15 0))",
        "    (bin-c :shape (box 0.2 0.2 0.3) :pose (0.3 0.4 0.15 0)))",
        "  (:movable",
        *[f"    {o}" for o in objs],
        "  )",
        "  (:handover-points",
        "    (h1 :position (0 0.05 0.4)))",
        f"  (:goal (and {goals})))",
    ]
    text = "\n".join(lines) + "\n"
    tree = parse_text(text, name)
    assert not isinstance(tree, Diagnostic), tree
    return format_source(tree, text)


#: the shipped PA-n problems: (file name without .mrg, objects, arms, seed); seed 0 of pa18-4arms gives an
#: object no arm can bring to its bin, so it uses seed 2
SHIPPED = [("pa5", 5, 2, 0), ("pa10", 10, 2, 0), ("pa18-4arms", 18, 4, 2)]
