"""What the facts of a problem say, for a person: ``mrgc facts FILE --summary`` and :func:`mrgc.facts_summary`.

Phase 1 answers hundreds of questions (which robot picks which object with which grasp, ...); placing arms
in a new cell needs the few answers behind them (docs/tutorial.md, "Placing the arms"):

- **per robot**: the objects it can pick (some ``reachable-pick``), the regions it can place in (some
  ``reachable-place``), its handover partners (``enable-goal-handover`` with it as giver or taker) and its
  relay partners (``enable-relay``);
- **per goal** ``M -> G``: how it can be delivered: ``direct`` (one robot picks M and places it in G with
  the same grasp), else by a ``handover`` (giver -> taker: the giver picks M with the handover's first
  grasp, the taker places it in G with the second), else by a ``relay`` (the same, through a set-down),
  else ``none`` (no single action, handover or relay: longer chains are the planner's to find, the task
  graph tells); ``already`` when M starts in G;
- **what nobody reaches**: objects no robot can pick and goals no robot can place, each with the *nearest
  miss*: the arm whose reach bound comes closest and how far the object's centre (or the nearest point of
  the goal region) lies beyond it (``RobotModel.reach`` from the arm's shoulder, plus its tool centre
  point's offset).  A miss inside the bound (distance 0) means the arm could reach there but phase 1 found
  no collision-free grasp (an obstacle, the table, joint limits).  Planar robots drive: they have no reach
  bound, and their misses have no distance.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Iterable

import numpy as np

from mrgc.errors import Diagnostic
from mrgc.language.model import Fact, Problem

if TYPE_CHECKING:
    from mrgc.geometry.scene import SceneSpec


@dataclass(frozen=True)
class RobotSummary:
    """What one robot can do, by the facts."""

    name: str
    picks: tuple[str, ...]
    places: tuple[str, ...]
    handover_partners: tuple[str, ...]
    relay_partners: tuple[str, ...]


@dataclass(frozen=True)
class GoalRoute:
    """How goal ``obj -> region`` can be delivered: ``route`` is ``already``, ``direct``, ``handover``,
    ``relay`` or ``none``; ``by`` the robots (``r1``, or ``r1->r2`` for a handover or relay)."""

    obj: str
    region: str
    route: str
    by: tuple[str, ...] = ()


@dataclass(frozen=True)
class Miss:
    """An object nobody can pick (``region`` None) or a goal nobody can place: the nearest arm (None: no arm)
    and how far (m) the target lies beyond its reach bound (0: inside the bound; None: no arm)."""

    obj: str
    region: str | None
    nearest: str | None
    distance: float | None


@dataclass
class FactsSummary:
    """The summary of a problem's facts (module docstring)."""

    problem: str
    facts: int
    robots: list[RobotSummary] = field(default_factory=list)
    goals: list[GoalRoute] = field(default_factory=list)
    missed: list[Miss] = field(default_factory=list)
    #: the layout warnings about the problem (W271-W273: docs/errors.md), when :func:`mrgc.facts_summary` ran
    warnings: tuple[Diagnostic, ...] = ()

    @property
    def needs_help(self) -> list[GoalRoute]:
        """The goals that need a handover or a relay."""
        return [g for g in self.goals if g.route in ("handover", "relay")]

    def to_json(self) -> dict[str, Any]:
        """The summary as plain data (``mrgc facts --summary --format json``)."""
        return {
            "problem": self.problem,
            "facts": self.facts,
            "robots": [{k: v if isinstance(v, str) else list(v) for k, v in vars(r).items()} for r in self.robots],
            "goals": [{"object": g.obj, "region": g.region, "route": g.route, "by": list(g.by)} for g in self.goals],
            "unreachable": [
                {"object": m.obj, "region": m.region, "nearest": m.nearest, "distance": m.distance} for m in self.missed
            ],
        }

    def text(self) -> str:
        """The summary as ``mrgc facts --summary`` prints it."""
        lines = [f"problem {self.problem}: {self.facts} facts", "robots:"]
        for r in self.robots:
            lines.append(f"  {r.name}: picks {_names(r.picks)}; places in {_names(r.places)}")
            lines.append(f"  {' ' * len(r.name)}  hands over with {_names(r.handover_partners)}; ")
            lines[-1] += f"relays with {_names(r.relay_partners)}"
        lines.append("goals:")
        for g in self.goals:
            by = f" by {', '.join(g.by)}" if g.by else ""
            what = {"none": "no one action, handover or relay delivers it", "already": "already there"}.get(
                g.route, g.route + by
            )
            lines.append(f"  {g.obj} -> {g.region}: {what}")
        help_ = self.needs_help
        lines.append(
            "need a handover or a relay: " + (", ".join(f"{g.obj} ({g.route})" for g in help_) if help_ else "none")
        )
        lines.append("nobody reaches:" + ("" if self.missed else " nothing"))
        for m in self.missed:
            lines.append(f"  {_miss_subject(m)}: {_miss_text(m)}")
        return "\n".join(lines) + "\n"


def _names(names: Iterable[str]) -> str:
    found = list(names)
    return " ".join(found) if found else "nothing"


def _miss_subject(m: Miss) -> str:
    return f"object {m.obj} (no pick)" if m.region is None else f"goal {m.obj} -> {m.region} (no place)"


def _miss_text(m: Miss) -> str:
    if m.nearest is None or m.distance is None:
        return "no arm; planar robots find no path or grasp"
    if m.distance > 0:
        return f"nearest {m.nearest}, {m.distance:.2f} m out of reach"
    return f"within {m.nearest}'s reach, but no collision-free grasp (an obstacle, the table or joint limits)"


def summarize(problem: Problem, facts: Iterable[Fact]) -> FactsSummary:
    """The summary of ``problem``'s ``facts`` (its nearest misses measured on its scene when geometric)."""
    facts = list(facts)
    by: dict[str, list[tuple[str, ...]]] = {}
    for f in facts:
        by.setdefault(f.predicate, []).append(f.args)
    picks = {(a[0], a[2]) for a in by.get("reachable-pick", [])}
    places = {(a[0], a[1], a[3]) for a in by.get("reachable-place", [])}
    handovers = by.get("enable-goal-handover", [])
    relays = by.get("enable-relay", [])
    out = FactsSummary(problem.name, len(facts))
    for r in problem.robots:
        out.robots.append(
            RobotSummary(
                r.name,
                tuple(sorted({o for o, who in picks if who == r.name})),
                tuple(sorted({g for _, g, who in places if who == r.name})),
                _partners(r.name, [(a[3], a[4]) for a in handovers]),
                _partners(r.name, [(a[4], a[5]) for a in relays]),
            )
        )
    start = {f.args[0]: f.args[1] for f in facts if f.predicate == "in-region"}
    for obj, region in problem.goal_regions.items():
        out.goals.append(_route(obj, region, start, by, handovers, relays))
    picked = {o for o, _ in picks}
    targets: list[tuple[str, str | None]] = [(m.name, None) for m in problem.movable if m.name not in picked]
    targets += [(g.obj, g.region) for g in out.goals if not any(o == g.obj and p == g.region for o, p, _ in places)]
    targets = [t for t in targets if not (t[1] is not None and start.get(t[0]) == t[1])]
    out.missed = _misses(problem, targets)
    return out


def _partners(robot: str, pairs: list[tuple[str, str]]) -> tuple[str, ...]:
    return tuple(sorted({b for a, b in pairs if a == robot} | {a for a, b in pairs if b == robot} - {robot}))


def _route(
    obj: str,
    region: str,
    start: dict[str, str],
    by: dict[str, list[tuple[str, ...]]],
    handovers: list[tuple[str, ...]],
    relays: list[tuple[str, ...]],
) -> GoalRoute:
    if start.get(obj) == region:
        return GoalRoute(obj, region, "already")
    pick = {(a[1], a[2]) for a in by.get("reachable-pick", []) if a[0] == obj}
    place = {(a[2], a[3]) for a in by.get("reachable-place", []) if a[0] == obj and a[1] == region}
    direct = sorted({r for g, r in pick & place})
    if direct:
        return GoalRoute(obj, region, "direct", tuple(direct))
    # a handover or relay delivers M when its giver can pick M with g1 and its taker place M in G with g2
    passes = sorted({f"{a[3]}->{a[4]}" for a in handovers if a[0] == obj and _delivers(a[1:3], a[3:5], pick, place)})
    if passes:
        return GoalRoute(obj, region, "handover", tuple(passes))
    sets = sorted(
        {f"{a[4]}->{a[5]} on {a[1]}" for a in relays if a[0] == obj and _delivers(a[2:4], a[4:6], pick, place)}
    )
    if sets:
        return GoalRoute(obj, region, "relay", tuple(sets))
    return GoalRoute(obj, region, "none")


def _delivers(
    grasps: tuple[str, ...], robots: tuple[str, ...], pick: set[tuple[str, str]], place: set[tuple[str, str]]
) -> bool:
    """Whether the giver picks with the first grasp and the taker places with the second."""
    return (grasps[0], robots[0]) in pick and (grasps[1], robots[1]) in place


def _misses(problem: Problem, targets: list[tuple[str, str | None]]) -> list[Miss]:
    """The nearest miss of each (object, None) pick target and (object, region) place target."""
    if not targets:
        return []
    if problem.symbolic:
        return [Miss(o, r, None, None) for o, r in targets]
    from mrgc.geometry.scene import scene_from_problem

    scene = scene_from_problem(problem)
    arms = arm_bounds(scene)
    out = []
    for obj, region in targets:
        body = scene.body(obj) if region is None else scene.region(region)
        shape = body.shape if region is not None else None
        gaps = [(max(0.0, _gap(body.pose, shape, c) - bound), name) for name, c, bound in arms]
        if not gaps:
            out.append(Miss(obj, region, None, None))
            continue
        gap, name = min(gaps)
        out.append(Miss(obj, region, name, round(gap, 3)))
    return out


def arm_bounds(scene: SceneSpec) -> list[tuple[str, np.ndarray, float]]:
    """Each arm of ``scene``: its name, its shoulder in the world and its reach bound (the model's reach
    plus the tool centre point's offset from the end-effector link), in declaration order."""
    from mrgc.geometry.kinematics import model_for_kind
    from mrgc.geometry.transforms import from_pose

    out = []
    for r in scene.robots:
        if r.kind.driven:
            continue
        model = model_for_kind(r.kind, r.base_dir)
        tcp = float(np.linalg.norm(from_pose(r.kind.tcp)[:3, 3])) if r.kind.tcp is not None else 0.0
        shoulder = (r.base @ np.append(model.shoulder, 1.0))[:3]
        out.append((r.name, shoulder, model.reach + tcp))
    return out


def _gap(pose: np.ndarray, shape: Any, point: np.ndarray) -> float:
    """Distance from ``point`` to a body's centre (``shape`` None) or to the nearest point of a region."""
    if shape is None:
        return float(np.linalg.norm(pose[:3, 3] - point))
    from mrgc.geometry.scene import half_extents

    inv = np.linalg.inv(pose)
    local = inv[:3, :3] @ point + inv[:3, 3]
    return float(np.linalg.norm(np.maximum(np.abs(local) - half_extents(shape), 0.0)))
