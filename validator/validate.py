"""The independent plan validator: does a plan really solve its problem?  (``mrgc validate FILE PLAN``)

It shares no code with the planner's search or grounding (:mod:`mrgc.planner.ground`,
:mod:`mrgc.planner.mcts`, :mod:`mrgc.geometry.grounding`, :mod:`mrgc.geometry.predicates`, coal): it reads
the plan through :mod:`mrgc.planfile.reader` (limits, JSON Schema, typed actions), re-derives what each
action means from the problem and the model's specifications (grasp frames of :mod:`mrgc.geometry.grasps`,
the planar-robot model of :mod:`mrgc.geometry.planar`, ``inside`` of :mod:`mrgc.geometry.scene`), and
replays geometric plans in pybullet (:mod:`mrgc.validator.replay`).

Outcomes are values: :func:`validate` returns a :class:`ValidationReport` listing every
:class:`Violation`, one line each.  A plan *file* that cannot be used at all (unreadable, beyond the
reader's limits, not JSON, not following ``docs/plan.schema.json``, another schema version) raises
:class:`~mrgc.errors.InputError` (E500-E504): that is bad input, not an invalid plan.

Checks on every plan (codes in brackets):

- the plan is for this problem: same name ``[problem]``, same contents ``[problem-changed]`` (the plan's
  ``problem_digest`` must equal the checked problem's content digest of :mod:`mrgc.language.digest`, its
  ``problem_sha256`` then only records the file's bytes: the file the plan was made from and its facts
  file both qualify; a plan without a digest compares its sha256 with the problem file's bytes), symbolic
  flag as the problem's ``[plan-kind]``; status ``solved``
  ``[status]``; ``makespan``/``motion_cost``/step
  indices agree with the steps ``[summary]``;
- every name is declared (objects, regions, robots of actions and of ``waiting``, handover points), every
  grasp allowed for its object ``[unknown-name]``; the ``kind`` matches the robots, and a pick-and-place
  keeps its grasp (no regrasp in hand) ``[action]``;
- each object moves at most once, or twice when its first move is a *relay move* (``"relay": true``: it is
  only set down on its way; beyond the paper, ``enable-relay``) and its second, the *onward move*, comes at
  a later step and is no relay ``[moved-twice]``; a relay move with no onward move ``[relay]``; a relay
  move is a pick-and-place of a goal object into a region other than its goal ``[region]``;
- a robot does at most one action per step, a handover occupying both of its robots ``[robot-busy]``;
  ``waiting`` lists exactly the robots in no action of the step, once each ``[waiting]``; at the end every
  goal holds ``[goal]``.

Symbolic plans (a symbolic problem) are checked against the problem's facts, as the model defines actions
(DESIGN.md section 5): a pick needs ``reachable-pick``, a place ``reachable-place``, a handover
``enable-goal-handover`` and is only for goal objects into their goal region; objects outside the goal
only move within their own region ``[unsupported]``, ``[region]``; every ``occludes-pick`` obstacle of an
action (and every ``occludes-handover`` obstacle of a handover) moves at a strictly earlier step, every
``occludes-goal-place`` obstacle no later ``[pick-obstacle]``, ``[place-obstacle]``.  A relay move of M into
Re by R1 with g1 needs ``reachable-pick M g1 R1`` and ``enable-relay M Re g1 g2 R1 R2``, R2 and g2 the robot
and grasp that pick M in its onward move; it has pick obstacles only.  The onward move needs what a move into
the goal needs except ``reachable-pick`` (the relay fact covers picking M where it was set down) and has place
obstacles only.  Geometric checks (the motion model, motions, collisions, support; an onward move picks M
where its relay move placed it) are listed in
:mod:`mrgc.validator.replay`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from mrgc.language.model import Problem
from mrgc.planfile.format import PlanFile, PlannedAction, Step, file_sha256
from mrgc.planfile.reader import read_plan
from mrgc.validator.violation import Violation


@dataclass
class ValidationReport:
    """``ok`` iff there is no violation; ``stats`` counts what was checked."""

    ok: bool
    violations: list[Violation] = field(default_factory=list)
    stats: dict[str, Any] = field(default_factory=dict)

    def lines(self) -> list[str]:
        """The report as ``mrgc validate`` prints it: ``valid: ...``, or each violation and a count."""
        if self.ok:
            s = self.stats
            geo = (
                f"; replayed {s['configurations']} configurations, {s['distance_queries']} pybullet distance queries"
                if "configurations" in s
                else ""
            )
            steps, moved = s.get("steps", 0), s.get("moved", 0)
            return [
                f"valid: plan for {s.get('problem')}: {steps} step{'s' * (steps != 1)}, {moved} "
                f"object{'s' * (moved != 1)} moved ({s.get('mode')} checks{geo})"
            ]
        n = len(self.violations)
        return [str(v) for v in self.violations] + [f"invalid: {n} violation{'s' * (n != 1)}"]

    def to_json(self) -> dict[str, Any]:
        """The report as ``mrgc validate --format json`` prints it."""
        return {"ok": self.ok, "violations": [v.to_json() for v in self.violations], "stats": self.stats}


# ------------------------------------------------------------------------------------------ validating
def validate(
    problem: Problem, plan: Any, problem_path: str | None = None, first_only: bool = False
) -> ValidationReport:
    """Check ``plan`` against ``problem``, read from ``problem_path`` (whose sha256 must match the plan's;
    None skips that comparison).  ``plan`` is a :class:`~mrgc.planfile.format.PlanFile`, parsed plan JSON
    (as :func:`~mrgc.planfile.reader.load_plan` returns it) or a written plan (:class:`~mrgc.planner.plan.Plan`);
    InputError when it breaks the schema.  ``first_only``: the geometric replay stops at the first phase that
    finds a violation (the verdict is the same; the report lists fewer violations), for a referee inside a
    search."""
    doc = read_plan(plan)
    out: list[Violation] = []
    steps = [s.actions for s in doc.steps]
    stats: dict[str, Any] = {
        "problem": problem.name,
        "steps": len(steps),
        "moved": len({a.object for step in steps for a in step}),
        "mode": "symbolic" if problem.symbolic else "geometric",
    }
    _header(problem, doc, problem_path, out)
    if doc.status != "solved":
        out.append(Violation(None, None, "status", f"the plan's status is {doc.status!r}: it holds no plan"))
        return ValidationReport(False, out, stats)
    usable = _names(problem, doc, out)
    stats["moved"] = len({a.object for step in steps for a in step if id(a) in usable})
    relays = _structure(problem, doc, usable, out)
    if problem.symbolic:
        _symbolic(problem, steps, usable, relays, out)
        final = dict(problem.initial_regions)
        for step in steps:
            for a in step:
                if id(a) in usable:
                    final[a.object] = a.region
        for obj, region in sorted(problem.goal_regions.items()):
            if final.get(obj) != region:
                where = f"in {final[obj]!r}" if obj in final else "nowhere known"
                out.append(
                    Violation(
                        None, obj, "goal", f"goal (in-region {obj} {region}) does not hold at the end: {obj} is {where}"
                    )
                )
    elif not doc.symbolic and not (first_only and out):  # a symbolic plan carries no geometry to replay
        from mrgc.validator.replay import replay

        assert doc.motion_model is not None  # the schema requires it of geometric plans
        out.extend(replay(problem, doc.motion_model, steps, usable, stats, first_only=first_only))
    return ValidationReport(not out, out, stats)


def _header(problem: Problem, plan: PlanFile, problem_path: str | None, out: list[Violation]) -> None:
    if plan.problem != problem.name:
        out.append(Violation(None, None, "problem", f"the plan is for problem {plan.problem!r}, not {problem.name!r}"))
    changed = _changed(problem, plan, problem_path)
    if changed:
        out.append(Violation(None, None, "problem-changed", changed))
    if plan.symbolic != problem.symbolic:
        what = (
            "a symbolic plan for a geometric problem (it carries no geometry to check)"
            if plan.symbolic
            else "a geometric plan for a symbolic problem"
        )
        out.append(Violation(None, None, "plan-kind", f"this is {what}"))
    if plan.status != "solved":
        return
    for i, s in enumerate(plan.steps, 1):
        if s.index != i:
            out.append(Violation(i, None, "summary", f"step {i} is numbered {s.index}"))
    moved = sum(len(s.actions) for s in plan.steps)
    if plan.makespan != len(plan.steps) or plan.motion_cost != moved:
        out.append(
            Violation(
                None,
                None,
                "summary",
                f"the plan says makespan {plan.makespan}, motion cost {plan.motion_cost}; its steps "
                f"give {len(plan.steps)} and {moved}",
            )
        )
    for i, s in enumerate(plan.steps, 1):
        if not s.actions:
            out.append(Violation(i, None, "summary", "the step is empty"))


def _changed(problem: Problem, plan: PlanFile, problem_path: str | None) -> str:
    """Why the plan is not for this problem's content ("" when it is).  A plan with a ``problem_digest``
    is for the problem whose content digest (:mod:`mrgc.language.digest`) that is, whatever its
    ``problem_sha256`` says (the file it was made from and that file's facts file both qualify); a plan
    without one (an older plan) is for the problem file whose bytes its ``problem_sha256`` hashes, or whose
    content digest it is; a plan with neither, or without a digest and no file to compare, is accepted."""
    from mrgc.language.digest import problem_digest

    if plan.problem_digest is not None:
        content = problem_digest(problem)
        if plan.problem_digest == content:
            return ""
        return (
            f"the plan was made for other problem contents: problem digest {plan.problem_digest[:12]}... in "
            f"the plan, {content[:12]}... now"
        )
    if plan.problem_sha256 is None or problem_path is None:
        return ""
    try:
        file_digest = file_sha256(problem_path)
    except OSError as exc:
        file_digest = f"unreadable ({exc.strerror})"
    if plan.problem_sha256 in (file_digest, problem_digest(problem)):
        return ""
    return (
        f"the problem file changed since the plan was made: sha256 {plan.problem_sha256[:12]}... in the plan, "
        f"{file_digest[:12]}... now"
    )


@dataclass(frozen=True)
class _Names:
    """The names a problem declares, by what they name."""

    robots: frozenset[str]
    regions: frozenset[str]
    objects: frozenset[str]
    points: frozenset[str]
    fixed: frozenset[str]

    @classmethod
    def of(cls, problem: Problem) -> _Names:
        return cls(
            frozenset(r.name for r in problem.robots),
            frozenset(r.name for r in problem.regions),
            frozenset(m.name for m in problem.movable),
            frozenset(h.name for h in problem.handover_points),
            frozenset(f.name for f in problem.fixed),
        )


def _names(problem: Problem, plan: PlanFile, out: list[Violation]) -> set[int]:
    """Ids of the actions whose names all resolve (the others are reported and left out of later checks);
    unknown robots in ``waiting`` are reported too."""
    names = _Names.of(problem)
    usable: set[int] = set()
    for t, s in enumerate(plan.steps, 1):
        out.extend(
            Violation(t, r, "unknown-name", f"no robot {r!r} (waiting)") for r in s.waiting if r not in names.robots
        )
        for a in s.actions:
            bad = _unknown_names(problem, names, a)
            out.extend(Violation(t, a.object, "unknown-name", b) for b in bad)
            if not bad:
                _kind(t, a, out)
                usable.add(id(a))
    return usable


def _unknown_names(problem: Problem, names: _Names, a: PlannedAction) -> list[str]:
    """What of action ``a`` names nothing the problem declares (or a grasp its object does not allow)."""
    bad = []
    obj = a.object
    if obj not in names.objects:
        bad.append(
            f"{obj!r} is a fixed object, which never moves" if obj in names.fixed else f"no movable object {obj!r}"
        )
    if a.region not in names.regions and a.region not in names.fixed:
        bad.append(f"no region or fixed object {a.region!r}")
    for role, robot in (("pick robot", a.pick_robot), ("place robot", a.place_robot)):
        if robot not in names.robots:
            bad.append(f"no robot {robot!r} ({role})")
    if obj in names.objects:
        allowed = problem.grasps_of(obj)
        for grasp in dict.fromkeys((a.pick_grasp, a.place_grasp)):
            if grasp not in allowed:
                bad.append(f"grasp {grasp!r} is not allowed for {obj} (allowed: {', '.join(allowed)})")
    if a.handover_point is not None and a.handover_point not in names.points:
        bad.append(f"no handover point {a.handover_point!r}")
    return bad


def _kind(t: int, a: PlannedAction, out: list[Violation]) -> None:
    """The action's ``kind`` matches its robots, and a pick-and-place keeps its grasp ``[action]``."""
    kind = "handover" if a.handover else "pick-place"
    if a.kind != kind:
        out.append(
            Violation(
                t, a.object, "action", f"kind {a.kind!r} but robots {a.pick_robot} and {a.place_robot} make it a {kind}"
            )
        )
    if kind == "pick-place" and a.pick_grasp != a.place_grasp:
        out.append(
            Violation(
                t,
                a.object,
                "action",
                f"{a.pick_robot} picks with {a.pick_grasp} but places "
                f"with {a.place_grasp}: a robot cannot regrasp in hand",
            )
        )


@dataclass
class _Relays:
    """The relay moves of a plan paired with their onward moves (ids of actions): ``onward`` relay -> the
    object's next move, at a later step and not a relay itself; ``relay_of`` the reverse."""

    onward: dict[int, PlannedAction] = field(default_factory=dict)
    relay_of: dict[int, PlannedAction] = field(default_factory=dict)


def _structure(problem: Problem, plan: PlanFile, usable: set[int], out: list[Violation]) -> _Relays:
    """The structural checks (module docstring): how often objects move ``[moved-twice]``, ``[relay]``,
    relay moves ``[region]``, robots ``[robot-busy]``, ``[waiting]``; the relay moves and their onward moves."""
    history: dict[str, list[tuple[int, PlannedAction]]] = {}
    relays = _Relays()
    robots = [r.name for r in problem.robots]
    for t, s in enumerate(plan.steps, 1):
        for a in s.actions:
            if id(a) not in usable:
                continue
            before = history.setdefault(a.object, [])
            again = _moved_again(t, a, before)
            if again:
                out.append(Violation(t, a.object, "moved-twice", again))
            elif before:  # the onward move of a relay move
                relays.onward[id(before[0][1])], relays.relay_of[id(a)] = a, before[0][1]
            before.append((t, a))
            if a.relay:
                _relay_region(problem, t, a, out)
        _robots(t, s, robots, out)
    for obj, moves in history.items():
        if len(moves) == 1 and moves[0][1].relay:
            out.append(
                Violation(moves[0][0], obj, "relay", f"{obj} is set down at step {moves[0][0]} and never moved on")
            )
    return relays


def _robots(t: int, s: Step, robots: list[str], out: list[Violation]) -> None:
    """A robot does at most one action in step ``t`` ``[robot-busy]``; ``waiting`` lists exactly the others
    ``[waiting]``."""
    busy: dict[str, str] = {}
    for a in s.actions:
        for r in dict.fromkeys(a.robots()):
            if r in busy:
                out.append(
                    Violation(
                        t, r, "robot-busy", f"{r} is in two actions of the step (moving {busy[r]} and {a.object})"
                    )
                )
            else:
                busy[r] = a.object
    seen: set[str] = set()
    for r in s.waiting:
        if r in busy:
            out.append(Violation(t, r, "waiting", f"{r} is listed as waiting but moves {busy[r]} in the step"))
        elif r in seen:
            out.append(Violation(t, r, "waiting", f"{r} is listed as waiting twice"))
        seen.add(r)
    for r in robots:
        if r not in busy and r not in seen:
            out.append(Violation(t, r, "waiting", f"{r} is in no action of the step and not listed as waiting"))


def _moved_again(t: int, a: PlannedAction, before: list[tuple[int, PlannedAction]]) -> str:
    """Why moving ``a.object`` at step ``t`` after its moves ``before`` breaks "each object moves at most
    once, or twice when the first move is a relay move and the second, at a later step, is not" ("" if it
    does not)."""
    obj = a.object
    if not before:
        return ""
    t0, first = before[0]
    if not first.relay:
        return f"{obj} is moved again (first at step {t0}); each object moves at most once"
    if len(before) > 1:
        return (
            f"{obj} is moved a third time (set down at step {t0}, moved on at step {before[1][0]}); an object "
            "moves at most once, or twice through a relay"
        )
    if t0 == t:
        return f"{obj} is moved again in step {t}, where it is set down; its onward move comes at a later step"
    if a.relay:
        return f"{obj} is set down again (first at step {t0}); a relay move is followed by its onward move, not a relay"
    return ""


def _relay_region(problem: Problem, t: int, a: PlannedAction, out: list[Violation]) -> None:
    """A relay move is a pick-and-place of a goal object into a region that is not its goal ``[region]``."""
    o, goal = a.object, problem.goal_regions.get(a.object)
    if a.handover:
        out.append(
            Violation(
                t,
                o,
                "region",
                f"a relay move is a pick-and-place: {a.pick_robot} sets {o} down itself, not a "
                f"handover to {a.place_robot}",
            )
        )
    if goal is None:
        out.append(Violation(t, o, "region", f"{o} is not a goal object: only goal objects are relayed (enable-relay)"))
    elif a.region == goal:
        out.append(
            Violation(
                t,
                o,
                "region",
                f"{o} is set down in its goal region {goal!r}: a relay move sets it down on its way, in another region",
            )
        )


Facts = set[tuple[str, tuple[str, ...]]]


def _symbolic(
    problem: Problem, steps: list[tuple[PlannedAction, ...]], usable: set[int], relays: _Relays, out: list[Violation]
) -> None:
    """The checks of a symbolic plan against the problem's facts (module docstring)."""
    facts = {(f.predicate, f.args) for f in problem.init}
    moved_at: dict[str, int] = {}
    for t, step in enumerate(steps, 1):
        for a in step:
            if id(a) in usable:
                moved_at.setdefault(a.object, t)
    for t, step in enumerate(steps, 1):
        for a in step:
            if id(a) not in usable:
                continue
            if a.relay:
                _relay_supported(facts, t, a, relays.onward.get(id(a)), out)
            else:
                _supported(problem, facts, t, a, id(a) in relays.relay_of, out)
            _obstacles_moved(facts, moved_at, t, a, out, pick=id(a) not in relays.relay_of, place=not a.relay)


def _relay_supported(
    facts: Facts, t: int, a: PlannedAction, onward: PlannedAction | None, out: list[Violation]
) -> None:
    """A relay move needs ``reachable-pick`` and the ``enable-relay`` fact naming the robot and grasp that
    pick the object up again in its onward move ``[unsupported]``."""
    o, re_, r1, g1 = a.object, a.region, a.pick_robot, a.pick_grasp
    need: list[tuple[str, tuple[str, ...]]] = [("reachable-pick", (o, g1, r1))]
    if onward is not None:
        need.append(("enable-relay", (o, re_, g1, onward.pick_grasp, r1, onward.pick_robot)))
    elif not any(p == "enable-relay" and args[:3] == (o, re_, g1) and args[4] == r1 for p, args in facts):
        need.append(("enable-relay", (o, re_, g1, "_", r1, "_")))
    for pred, args in need:
        if (pred, args) not in facts:
            out.append(Violation(t, o, "unsupported", f"no fact ({pred} {' '.join(args)}) supports '{a.describe()}'"))


def _supported(problem: Problem, facts: Facts, t: int, a: PlannedAction, onward: bool, out: list[Violation]) -> None:
    """Facts support action ``a`` ``[unsupported]`` (an ``onward`` move picks where a relay move set the
    object down: its relay fact covers the pick); only goal objects are handed over, and an object goes
    only to its goal region or, outside the goal, within its own region ``[region]``."""
    goal = problem.goal_regions
    o, re_, r1, r2, g1, g2 = a.object, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp
    need: list[tuple[str, tuple[str, ...]]] = [("reachable-place", (o, re_, g2, r2))]
    if not onward:
        need.insert(0, ("reachable-pick", (o, g1, r1)))
    if r1 != r2:
        need.insert(-1, ("enable-goal-handover", (o, g1, g2, r1, r2)))
        if o not in goal:
            out.append(
                Violation(
                    t,
                    o,
                    "region",
                    f"{o} is not a goal object: only goal objects are handed over (enable-goal-handover)",
                )
            )
    for pred, args in need:
        if (pred, args) not in facts:
            out.append(Violation(t, o, "unsupported", f"no fact ({pred} {' '.join(args)}) supports '{a.describe()}'"))
    target = goal.get(o, problem.initial_regions.get(o))
    if target is not None and re_ != target:
        why = "its goal region" if o in goal else "its own region (it is only moved out of the way)"
        out.append(
            Violation(t, o, "region", f"{o} goes to {re_!r}, but the model moves it only into {target!r}, {why}")
        )


def _obstacles_moved(
    facts: Facts, moved_at: dict[str, int], t: int, a: PlannedAction, out: list[Violation], pick: bool, place: bool
) -> None:
    """Every ``occludes-pick`` obstacle of action ``a`` (and of a handover its ``occludes-handover`` ones)
    moves at a strictly earlier step, every
    ``occludes-goal-place`` obstacle no later ``[pick-obstacle]``, ``[place-obstacle]``; ``pick``/``place``:
    whether the action has obstacles of that kind (an onward move picks where its relay move set the object
    down, a relay move places on the way, outside the facts' view)."""
    o, re_, r1, r2, g1, g2 = a.object, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp
    for pred, args in facts:
        if pick and (
            (pred == "occludes-pick" and args[1:] == (o, g1, r1))
            or (pred == "occludes-handover" and r1 != r2 and not a.relay and args[1:] == (o, g1, g2, r1, r2))
        ):
            when = moved_at.get(args[0])
            if when is None or when >= t:
                state = "never moves" if when is None else f"moves at step {when}"
                what = f"{r1} picking {o} with {g1}" if pred == "occludes-pick" else f"{r1} handing {o} to {r2}"
                out.append(
                    Violation(
                        t, o, "pick-obstacle", f"{args[0]} blocks {what} and {state}; it must move at an earlier step"
                    )
                )
        elif place and pred == "occludes-goal-place" and args[1:] == (o, re_, g2, r2):
            when = moved_at.get(args[0])
            if when is None or when > t:
                state = "never moves" if when is None else f"moves at step {when}"
                out.append(
                    Violation(
                        t,
                        o,
                        "place-obstacle",
                        f"{args[0]} blocks {r2} placing {o} in {re_} with {g2} and {state}; it must move by step {t}",
                    )
                )
