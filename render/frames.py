"""A plan as motion: its steps cut into timed phases, and frames sampled from them.

The replay follows the validator's execution model (:mod:`mrgc.validator.replay`), so a picture shows what
was checked.  Every robot starts a step at home.  A step runs in phases, each present only when some action
of the step has a motion in it (:data:`PHASES`):

1. ``to-pick``: pick robots go from home to their first pick configuration;
2. ``pick``: along ``configs.pick`` (pre-grasp first); the object is taken at the last one;
3. ``to-handover``: givers carry the object to ``configs.handover[0]``, takers go to ``configs.handover[1]``;
4. ``handover``: both hold still while the object passes from giver to taker;
5. ``to-place``: place robots carry the object to their first place configuration;
6. ``place``: along ``configs.place``; the object is released at ``place_pose``;
7. ``home``: back home (givers from their exchange configuration).

A motion between two configurations is the plan's path for it (``paths``: planar robots' drives) when the
plan gives one, else a straight line in joint space (the plan leaves an arm's transit free, and the
validator does not check it).  Within a phase every motion runs over the same time, its configurations
equally spaced, as the validator pairs them.  A robot without a motion in a phase stays where it is.

Timing is for watching, not a robot's real speed: a phase lasts :data:`MIN_PHASE` plus its largest motion
at :data:`ARM_SPEED` (joints, rad/s) or :data:`BASE_SPEED` (planar bases, m/s), at most :data:`MAX_PHASE`
(a hand-edited joint of 10,000 rad is shown at that pace, not over hours of frames); a handover pauses
:data:`HANDOVER_PAUSE`.  A plan's numbers must be finite and within the language's bound on any number
(:data:`~mrgc.language.props.MAX_MAGNITUDE`: 10 km, 10^4 rad), or it does not fit (E510).  At ``fps``
frames per second a phase gets ``ceil(duration · fps)`` frames (at least one, the last at its end), so every
phase of every step is seen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import numpy as np

from mrgc.errors import Diagnostic, InputError
from mrgc.language.props import MAX_MAGNITUDE
from mrgc.planner.plan import moved_text
from mrgc.render.world import World

#: the phases of a step, in order
PHASES = ("to-pick", "pick", "to-handover", "handover", "to-place", "place", "home")
#: phases whose last frame is a key frame (contact sheets)
KEY_PHASES = frozenset({"pick", "handover", "place"})
ARM_SPEED = 4.0  # rad/s of the fastest joint
BASE_SPEED = 1.5  # m/s of a planar base
MIN_PHASE = 0.1  # s
HANDOVER_PAUSE = 0.3  # s
MAX_PHASE = 5.0  # s: the longest a phase lasts, its motions however long
#: the code of a plan that does not fit its problem (names it lacks, configurations of the wrong size)
E_PLAN_FIT = "E510"


@dataclass(frozen=True)
class Motion:
    """One robot moving through ``configs`` (m, dof) over a phase, maybe holding an object."""

    robot: str
    configs: np.ndarray
    holding: str | None = None
    grasp: str | None = None
    fingers: float | None = None


@dataclass(frozen=True)
class Phase:
    """A phase of a step: its motions, how long it lasts, and what changes hands at its end."""

    step: int
    name: str
    motions: tuple[Motion, ...]
    duration: float
    caption: str
    #: at the end: object -> (robot, grasp) now holding it
    take: dict[str, tuple[str, str]] = field(default_factory=dict)
    #: at the end: object -> the pose it is released at
    release: dict[str, np.ndarray] = field(default_factory=dict)


@dataclass(frozen=True)
class Frame:
    """Everything drawn at one moment: robot configurations and finger openings, object poses."""

    time: float
    step: int  # 0: before the first step
    phase: str  # a PHASES name, or "start"
    caption: str
    configs: dict[str, np.ndarray]
    fingers: dict[str, float | None]
    poses: dict[str, np.ndarray]
    key: bool = False  # the end of a pick, handover or place, or the first or last frame


@dataclass
class Timeline:
    """The phases of a whole plan and the state before the first one."""

    world: World
    title: str
    phases: list[Phase]
    steps: int

    @property
    def duration(self) -> float:
        """The replay's length (s)."""
        return sum(p.duration for p in self.phases)

    def frames(self, fps: float) -> list[Frame]:
        """The frames at ``fps``: the start, then ``ceil(duration · fps)`` per phase (at least one)."""
        w = self.world
        configs = {r: v.home.copy() for r, v in w.robots.items()}
        fingers: dict[str, float | None] = dict.fromkeys(w.robots)
        poses = {o: p.copy() for o, p in w.start.items()}
        holder: dict[str, tuple[str, str]] = {}
        out = [Frame(0.0, 0, "start", self.title, dict(configs), dict(fingers), dict(poses), key=True)]
        t0 = 0.0
        for ph in self.phases:
            n = max(1, math.ceil(ph.duration * fps - 1e-9))
            for i in range(1, n + 1):
                s = i / n
                for m in ph.motions:
                    configs[m.robot] = interpolate(m.configs, s, w.robots[m.robot].planar)
                    fingers[m.robot] = m.fingers
                if i == n:
                    holder.update(ph.take)
                    for obj, pose in ph.release.items():
                        holder.pop(obj, None)
                        poses[obj] = pose
                for obj, (robot, grasp) in holder.items():
                    poses[obj] = w.robots[robot].held_pose(configs[robot], w.shapes[obj], grasp)
                out.append(
                    Frame(
                        t0 + s * ph.duration,
                        ph.step,
                        ph.name,
                        ph.caption,
                        dict(configs),
                        dict(fingers),
                        dict(poses),
                        key=i == n and ph.name in KEY_PHASES,
                    )
                )
            t0 += ph.duration
        if len(out) > 1:
            last = out[-1]
            out[-1] = Frame(
                last.time, last.step, last.phase, last.caption, last.configs, last.fingers, last.poses, key=True
            )
        return out


def interpolate(configs: np.ndarray, s: float, planar: bool = False) -> np.ndarray:
    """The configuration at ``s`` in [0, 1] along ``configs`` (m, dof), consecutive configurations equally
    spaced, straight lines between them (a planar yaw turns the shorter way)."""
    c = np.asarray(configs, dtype=float)
    if len(c) == 1:
        first: np.ndarray = c[0].copy()
        return first
    if planar:
        c = c.copy()
        c[:, 2] = np.unwrap(c[:, 2])
    grid = np.linspace(0.0, 1.0, len(c))
    return np.array([np.interp(min(max(s, 0.0), 1.0), grid, c[:, j]) for j in range(c.shape[1])], dtype=float)


# ------------------------------------------------------------------------------------------- building
@dataclass
class _Act:
    obj: str
    region: str
    giver: str
    taker: str
    g1: str
    g2: str
    pose: np.ndarray
    configs: dict[str, np.ndarray]
    paths: dict[str, np.ndarray]
    point: str | None
    relay: bool = False  # the object is only set down in ``region`` on its way (a relay move)

    @property
    def handover(self) -> bool:
        return self.giver != self.taker

    def label(self) -> str:
        who = self.giver if not self.handover else f"{self.giver}->{self.taker}"
        grasp = self.g1 if not self.handover else f"{self.g1}->{self.g2}"
        at = f" at {self.point}" if self.handover and self.point else ""
        where = f"set down in {self.region}" if self.relay else f"-> {self.region}"
        return f"{who}: {self.obj} {where} ({grasp}){at}"


def build_timeline(world: World, plan: Mapping[str, Any], source: str = "plan") -> Timeline:
    """The timeline of a geometric plan (JSON) in ``world``; InputError E510 when the plan does not fit the
    problem (``source`` names the plan file in messages)."""
    steps = [
        [_parse(world, a, t, source) for a in step.get("actions", [])]
        for t, step in enumerate(plan.get("steps", []), 1)
    ]
    home = {r: v.home for r, v in world.robots.items()}
    phases: list[Phase] = []
    n = len(steps)
    for t, acts in enumerate(steps, 1):
        phases += _step_phases(world, t, n, acts, home)
    title = (
        f"{world.problem.name}: {n} step{'s' * (n != 1)}, {moved_text([[a.obj for a in acts] for acts in steps])}"
        if n
        else f"{world.problem.name}: the plan has no steps"
    )
    return Timeline(world, title, phases, n)


def _step_phases(world: World, t: int, n: int, acts: list[_Act], home: Mapping[str, np.ndarray]) -> list[Phase]:
    head = f"step {t}/{n}"
    what = "; ".join(a.label() for a in acts)
    out: list[Phase] = []

    def opening(robot: str, a: _Act, grasp: str | None) -> float | None:
        return world.robots[robot].opening(world.shapes[a.obj], grasp)

    def path(a: _Act, name: str, start: np.ndarray, end: np.ndarray) -> np.ndarray:
        return a.paths[name] if name in a.paths else np.stack([start, end])

    def add(
        name: str,
        motions: Iterable[Motion],
        take: dict[str, tuple[str, str]] | None = None,
        release: dict[str, np.ndarray] | None = None,
        pause: float = 0.0,
    ) -> None:
        ms = tuple(motions)
        if not ms:
            return
        move = 0.0
        for m in ms:
            view = world.robots[m.robot]
            speed = BASE_SPEED if view.planar else ARM_SPEED
            length = sum(view.distance(m.configs[i], m.configs[i + 1]) for i in range(len(m.configs) - 1))
            move = max(move, min(length / speed, MAX_PHASE - MIN_PHASE))
        out.append(Phase(t, name, ms, MIN_PHASE + move + pause, f"{head} | {name} | {what}", take or {}, release or {}))

    hands = [a for a in acts if a.handover]
    add(
        "to-pick",
        (
            Motion(a.giver, path(a, "to-pick", home[a.giver], a.configs["pick"][0]), fingers=opening(a.giver, a, a.g1))
            for a in acts
        ),
    )
    add(
        "pick",
        (Motion(a.giver, a.configs["pick"], fingers=opening(a.giver, a, a.g1)) for a in acts),
        take={a.obj: (a.giver, a.g1) for a in acts},
    )
    add(
        "to-handover",
        [
            m
            for a in hands
            for m in (
                Motion(
                    a.giver,
                    path(a, "to-handover", a.configs["pick"][-1], a.configs["handover"][0]),
                    a.obj,
                    a.g1,
                    opening(a.giver, a, a.g1),
                ),
                Motion(
                    a.taker,
                    path(a, "taker-to-handover", home[a.taker], a.configs["handover"][1]),
                    fingers=opening(a.taker, a, a.g2),
                ),
            )
        ],
    )
    add(
        "handover",
        [
            m
            for a in hands
            for m in (
                Motion(a.giver, a.configs["handover"][:1], a.obj, a.g1, opening(a.giver, a, a.g1)),
                Motion(a.taker, a.configs["handover"][1:], a.obj, a.g2, opening(a.taker, a, a.g2)),
            )
        ],
        take={a.obj: (a.taker, a.g2) for a in hands},
        pause=HANDOVER_PAUSE,
    )
    add(
        "to-place",
        (
            Motion(
                a.taker,
                path(
                    a,
                    "to-place",
                    a.configs["handover"][1] if a.handover else a.configs["pick"][-1],
                    a.configs["place"][0],
                ),
                a.obj,
                a.g2,
                opening(a.taker, a, a.g2),
            )
            for a in acts
        ),
    )
    add(
        "place",
        (Motion(a.taker, a.configs["place"], a.obj, a.g2, opening(a.taker, a, a.g2)) for a in acts),
        release={a.obj: a.pose for a in acts},
    )
    add(
        "home",
        [
            m
            for a in acts
            for m in (
                [Motion(a.taker, path(a, "home", a.configs["place"][-1], home[a.taker]))]
                + (
                    [Motion(a.giver, path(a, "giver-home", a.configs["handover"][0], home[a.giver]))]
                    if a.handover
                    else []
                )
            )
        ],
    )
    return out


def _parse(world: World, a: Mapping[str, Any], t: int, source: str) -> _Act:
    """One action of the plan, checked against the world (E510 when it does not fit)."""

    def fail(message: str) -> InputError:
        return InputError([Diagnostic(E_PLAN_FIT, f"{source}: step {t}: {message} (problem '{world.problem.name}')")])

    obj, region, giver, taker = a["object"], a["region"], a["pick_robot"], a["place_robot"]
    problem = _names_misfit(world, a)
    if problem:
        raise fail(problem)
    pose = _numbers(a.get("place_pose"))
    if pose is None or pose.shape != (4, 4):
        raise fail(f"moving {obj} has no 4x4 place_pose of numbers within {MAX_MAGNITUDE:g}")
    configs: dict[str, np.ndarray] = {}
    need = {"pick": (giver, 1), "place": (taker, 1)}
    if giver != taker:
        need["handover"] = (giver, 2)
    for name, (robot, count) in need.items():
        arr = _configs(a.get("configs", {}).get(name), world.robots[robot].home.size)
        if arr is None or len(arr) < count:
            raise fail(
                f"moving {obj}: configs.{name} must hold at least {count} configuration(s) of "
                f"{world.robots[robot].home.size} values within {MAX_MAGNITUDE:g} ({robot})"
            )
        configs[name] = arr
    from mrgc.validator.actions import PATH_PHASES

    paths: dict[str, np.ndarray] = {}
    for name, qs in (a.get("paths") or {}).items():
        if name not in PATH_PHASES:
            continue
        robot = a[PATH_PHASES[name][0]]
        arr = _configs(qs, world.robots[robot].home.size)
        if arr is None or len(arr) < 1:
            raise fail(
                f"moving {obj}: path {name!r} must be configurations of {world.robots[robot].home.size} "
                f"values within {MAX_MAGNITUDE:g} ({robot})"
            )
        paths[name] = arr
    return _Act(
        obj,
        region,
        giver,
        taker,
        a["pick_grasp"],
        a["place_grasp"],
        pose,
        configs,
        paths,
        a.get("handover_point"),
        bool(a.get("relay", False)),
    )


def _names_misfit(world: World, a: Mapping[str, Any]) -> str | None:
    """Why the action's object, region, robots or grasps do not fit the world (None: they do)."""
    obj, region, giver, taker = a["object"], a["region"], a["pick_robot"], a["place_robot"]
    if obj not in world.objects:
        return f"object {obj!r} is not a movable object of the problem"
    if region not in {b.name for b, _ in world.regions} and region not in {b.name for b in world.scene.fixed}:
        # a fixed object's name: set down on its top (a relay's spot, an obstacle set aside on a table)
        return f"region {region!r} is neither a region nor a fixed object of the problem"
    for r in (giver, taker):
        if r not in world.robots:
            return f"robot {r!r} is not a robot of the problem"
    for r, g in ((giver, a["pick_grasp"]), (taker, a["place_grasp"])):
        if not world.robots[r].planar and g not in world.scene.grasp_specs:
            return f"grasp {g!r} has no geometry in the problem's domain"
        if world.robots[r].planar:
            from mrgc.geometry.planar_grasps import planar_grasp

            if not planar_grasp(g):
                return f"planar robot {r} cannot use grasp {g!r}"
    return None


def _numbers(values: Any) -> np.ndarray | None:
    """``values`` as a float array when they are numbers within the language's bound (None: they are not)."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        return None
    if not np.all(np.isfinite(arr)) or (arr.size and float(np.abs(arr).max()) > MAX_MAGNITUDE):
        return None
    return arr


def _configs(qs: Any, dof: int) -> np.ndarray | None:
    arr = _numbers(qs)
    if arr is None or arr.ndim != 2 or arr.shape[1] != dof:
        return None
    return arr
