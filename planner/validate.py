"""The independent plan validator: does a plan really solve its problem?  (``mrgc validate FILE PLAN``)

It shares no code with the planner's search or grounding (:mod:`mrgc.planner.ground`,
:mod:`mrgc.planner.mcts`, :mod:`mrgc.geometry.grounding`, :mod:`mrgc.geometry.predicates`, coal): it reads
the plan JSON, re-derives what each action means from the problem and the model's specifications (grasp
frames of :mod:`mrgc.geometry.grasps`, the planar-robot model of :mod:`mrgc.geometry.planar`, ``inside``
of :mod:`mrgc.geometry.scene`), and replays geometric plans in pybullet (:mod:`mrgc.planner.replay`).

Outcomes are values: :func:`validate` returns a :class:`ValidationReport` listing every
:class:`Violation`, one line each.  A plan *file* that cannot be used at all (unreadable, not JSON, not
following ``docs/plan.schema.json``, another schema version) raises :class:`~mrgc.errors.InputError`
(E500–E503): that is bad input, not an invalid plan.

Checks on every plan (codes in brackets):

- the plan is for this problem: same name ``[problem]``, same file contents (sha256 of the problem file;
  a mismatch is an error: the plan was made for other contents) ``[problem-changed]``, symbolic flag as
  the problem's ``[plan-kind]``; status ``solved`` ``[status]``; ``makespan``/``motion_cost``/step
  indices agree with the steps ``[summary]``;
- every name is declared, every grasp allowed for its object ``[unknown-name]``, ``[grasp]``; the
  ``kind`` matches the robots, and a pick-and-place keeps its grasp (no regrasp in hand) ``[action]``;
- each object moves at most once ``[moved-twice]``; a robot does at most one action per step, a handover
  occupying both of its robots ``[robot-busy]``; at the end every goal holds ``[goal]``.

Symbolic plans (a symbolic problem) are checked against the problem's facts, as the model defines actions
(DESIGN.md section 5): a pick needs ``reachable-pick``, a place ``reachable-place``, a handover
``enable-goal-handover`` and is only for goal objects into their goal region; objects outside the goal
only move within their own region ``[unsupported]``, ``[region]``; every ``occludes-pick`` obstacle of an
action moves at a strictly earlier step, every ``occludes-goal-place`` obstacle no later ``[pick-obstacle]``,
``[place-obstacle]``.  Geometric checks are listed in :mod:`mrgc.planner.replay`.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.language.model import Problem
from mrgc.planner.plan import SCHEMA, file_sha256

#: diagnostic codes of unusable plan files
E_READ, E_JSON, E_SCHEMA, E_VERSION = "E500", "E501", "E502", "E503"

_SCHEMA_FILE = Path(__file__).resolve().parent.parent / "docs" / "plan.schema.json"
_MAX_BYTES = 256 * 2**20


@dataclass(frozen=True)
class Violation:
    """One way a plan fails: the step (1-based, None for the whole plan), the robot or object concerned
    (None when none in particular), a stable code and a one-line message."""

    step: int | None
    subject: str | None
    code: str
    message: str

    def __str__(self) -> str:
        where = "".join([f"step {self.step}: " if self.step is not None else "",
                         f"{self.subject}: " if self.subject else ""])
        return f"{where}{self.message} [{self.code}]"

    def to_json(self) -> dict[str, Any]:
        return {"step": self.step, "subject": self.subject, "code": self.code, "message": self.message}


@dataclass
class ValidationReport:
    """``ok`` iff there is no violation; ``stats`` counts what was checked."""

    ok: bool
    violations: list[Violation] = field(default_factory=list)
    stats: dict[str, Any] = field(default_factory=dict)

    def lines(self) -> list[str]:
        if self.ok:
            s = self.stats
            geo = (f"; replayed {s['configurations']} configurations, {s['distance_queries']} pybullet distance "
                   f"queries" if "configurations" in s else "")
            return [f"valid: plan for {s.get('problem')}: {s.get('steps', 0)} steps, {s.get('moved', 0)} objects "
                    f"moved ({s.get('mode')} checks{geo})"]
        n = len(self.violations)
        return [str(v) for v in self.violations] + [f"invalid: {n} violation{'s' * (n != 1)}"]

    def to_json(self) -> dict[str, Any]:
        return {"ok": self.ok, "violations": [v.to_json() for v in self.violations], "stats": self.stats}


# ---------------------------------------------------------------------------------- reading plan files
def load_plan(path: str) -> dict[str, Any]:
    """The plan in file ``path``, checked against the plan schema (InputError E500–E503 otherwise)."""
    try:
        if os.path.isdir(path):
            raise IsADirectoryError("it is a folder")
        if os.path.getsize(path) > _MAX_BYTES:
            raise OSError(f"it is larger than {_MAX_BYTES} bytes")
        with open(path, "rb") as fh:
            raw = fh.read()
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError([Diagnostic(E_READ, f"cannot read plan {path!r}: it is not UTF-8 text")]) from None
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise InputError([Diagnostic(E_READ, f"cannot read plan {path!r}: {reason}")]) from None
    try:
        plan = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        span = Span(path, exc.lineno, exc.colno, exc.lineno, exc.colno + 1)
        what = ("it is empty" if not text.strip() else
                f"it ends early (truncated?): {exc.msg}" if _ends_early(text) else exc.msg)
        raise InputError([Diagnostic(E_JSON, f"plan is not JSON: {what}", span)], {path: text}) from None
    except ValueError as exc:
        raise InputError([Diagnostic(E_JSON, f"plan is not JSON: {exc}")]) from None
    check_schema(plan, path)
    return plan  # type: ignore[no-any-return]


def _ends_early(text: str) -> bool:
    """Whether the text stops inside a string or with brackets still open (a cut-off file)."""
    depth, in_string, escape = 0, False, False
    for ch in text:
        if in_string:
            if escape:
                escape = False
            elif ch == "\\":
                escape = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
    return in_string or depth > 0


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def check_schema(plan: Any, where: str = "plan") -> None:
    """Raise InputError E503 (another schema version) or E502 (not following the schema)."""
    if isinstance(plan, dict) and "schema" in plan and plan["schema"] != SCHEMA:
        raise InputError([Diagnostic(E_VERSION, f"{where}: schema {plan['schema']!r} is not supported "
                                                f"(this mrgc reads {SCHEMA!r})")])
    errors = schema_errors(plan)
    if errors:
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise InputError([Diagnostic(E_SCHEMA, f"{where} does not follow the plan schema {SCHEMA}: {errors[0]}{more}")])


def schema_errors(plan: Any) -> list[str]:
    """Where ``plan`` departs from ``docs/plan.schema.json`` (a JSON-schema subset interpreted here)."""
    try:
        schema = json.loads(_SCHEMA_FILE.read_text(encoding="utf-8"))
    except (OSError, ValueError):  # pragma: no cover - an installation without docs: the top level only
        schema = {"type": "object", "required": ["schema", "steps"]}
    out: list[str] = []
    _check(plan, schema, schema, "plan", out)
    return out


_ARTICLE = {"object": "an object", "array": "an array", "string": "a string", "integer": "an integer",
            "number": "a finite number", "boolean": "true or false"}
_TYPES = {"object": dict, "array": list, "string": str, "boolean": bool, "null": type(None)}


def _type_ok(value: Any, name: str) -> bool:
    if name == "integer":
        return isinstance(value, int) and not isinstance(value, bool)
    if name == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    return isinstance(value, _TYPES[name])


def _show(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _check(value: Any, schema: dict[str, Any], root: dict[str, Any], path: str, out: list[str]) -> None:
    if len(out) >= 20:
        return
    if "$ref" in schema:
        node: Any = root
        for part in schema["$ref"].lstrip("#/").split("/"):
            node = node[part]
        _check(value, node, root, path, out)
        return
    if "type" in schema:
        types = schema["type"] if isinstance(schema["type"], list) else [schema["type"]]
        if not any(_type_ok(value, t) for t in types):
            out.append(f"{path} should be {' or '.join(_ARTICLE.get(t, t) for t in types)}, not {_show(value)}")
            return
    if "const" in schema and value != schema["const"]:
        out.append(f"{path} should be {_show(schema['const'])}, not {_show(value)}")
    if "enum" in schema and value not in schema["enum"]:
        out.append(f"{path} should be one of {', '.join(map(_show, schema['enum']))}, not {_show(value)}")
    if "pattern" in schema and isinstance(value, str) and not re.search(schema["pattern"], value):
        out.append(f"{path} {_show(value)} does not match {schema['pattern']}")
    if "minimum" in schema and isinstance(value, (int, float)) and value < schema["minimum"]:
        out.append(f"{path} should be at least {schema['minimum']}, not {value}")
    if isinstance(value, dict):
        for key in schema.get("required", ()):
            if key not in value:
                out.append(f"{path} lacks {key!r}")
        props = schema.get("properties", {})
        extra = schema.get("additionalProperties", True)
        for key, item in value.items():
            if key in props:
                _check(item, props[key], root, f"{path}.{key}", out)
            elif extra is False:
                out.append(f"{path} has an unknown field {key!r}")
            elif isinstance(extra, dict):
                _check(item, extra, root, f"{path}.{key}", out)
    if isinstance(value, list):
        if len(value) < schema.get("minItems", 0) or len(value) > schema.get("maxItems", len(value)):
            lo, hi = schema.get("minItems", 0), schema.get("maxItems")
            want = f"{lo}" if lo == hi else f"{lo} to {hi}" if hi is not None else f"at least {lo}"
            out.append(f"{path} should hold {want} items, not {len(value)}")
        if "items" in schema:
            for i, item in enumerate(value):
                _check(item, schema["items"], root, f"{path}[{i}]", out)


# ------------------------------------------------------------------------------------------ validating
def validate(problem: Problem, plan: dict[str, Any], problem_path: str | None = None) -> ValidationReport:
    """Check ``plan`` (a parsed plan JSON) against ``problem``, read from ``problem_path`` (whose sha256
    must match the plan's; None skips that comparison).  ``plan`` may also be a :class:`~mrgc.planner.plan.Plan`.
    InputError when ``plan`` breaks the schema."""
    if not isinstance(plan, dict) and hasattr(plan, "to_json"):
        plan = json.loads(json.dumps(plan.to_json()))
    check_schema(plan)
    out: list[Violation] = []
    steps: list[list[dict[str, Any]]] = [s["actions"] for s in plan["steps"]]
    stats: dict[str, Any] = {"problem": problem.name, "steps": len(steps), "moved": sum(map(len, steps)),
                             "mode": "symbolic" if problem.symbolic else "geometric"}
    _header(problem, plan, problem_path, out)
    if plan["status"] != "solved":
        out.append(Violation(None, None, "status", f"the plan's status is {plan['status']!r}: it holds no plan"))
        return ValidationReport(False, out, stats)
    usable = _names(problem, steps, out)
    _structure(steps, usable, out)
    if problem.symbolic:
        _symbolic(problem, steps, usable, out)
        final = dict(problem.initial_regions)
        for step in steps:
            for a in step:
                if id(a) in usable:
                    final[a["object"]] = a["region"]
        for obj, region in sorted(problem.goal_regions.items()):
            if final.get(obj) != region:
                where = f"in {final[obj]!r}" if obj in final else "nowhere known"
                out.append(Violation(None, obj, "goal", f"goal (in-region {obj} {region}) does not hold at the "
                                                        f"end: {obj} is {where}"))
    else:
        from mrgc.planner.replay import replay

        out.extend(replay(problem, steps, usable, stats))
    return ValidationReport(not out, out, stats)


def _header(problem: Problem, plan: dict[str, Any], problem_path: str | None, out: list[Violation]) -> None:
    if plan["problem"] != problem.name:
        out.append(Violation(None, None, "problem", f"the plan is for problem {plan['problem']!r}, "
                                                    f"not {problem.name!r}"))
    if problem_path is not None:
        try:
            digest = file_sha256(problem_path)
        except OSError as exc:
            digest = f"unreadable ({exc.strerror})"
        if digest != plan["problem_sha256"]:
            out.append(Violation(None, None, "problem-changed",
                                 f"the problem file changed since the plan was made: sha256 "
                                 f"{plan['problem_sha256'][:12]}... in the plan, {digest[:12]}... now"))
    if plan["symbolic"] != problem.symbolic:
        what = ("a symbolic plan for a geometric problem (it carries no geometry to check)" if plan["symbolic"]
                else "a geometric plan for a symbolic problem")
        out.append(Violation(None, None, "plan-kind", f"this is {what}"))
    if plan["status"] != "solved":
        return
    steps = plan["steps"]
    for i, s in enumerate(steps, 1):
        if s["index"] != i:
            out.append(Violation(i, None, "summary", f"step {i} is numbered {s['index']}"))
    moved = sum(len(s["actions"]) for s in steps)
    if plan["makespan"] != len(steps) or plan["motion_cost"] != moved:
        out.append(Violation(None, None, "summary", f"the plan says makespan {plan['makespan']}, motion cost "
                                                    f"{plan['motion_cost']}; its steps give {len(steps)} and {moved}"))
    for i, s in enumerate(steps, 1):
        if not s["actions"]:
            out.append(Violation(i, None, "summary", "the step is empty"))


def _names(problem: Problem, steps: list[list[dict[str, Any]]], out: list[Violation]) -> set[int]:
    """Ids of the actions whose names all resolve (the others are reported and left out of later checks)."""
    robots = {r.name for r in problem.robots}
    regions = {r.name for r in problem.regions}
    objects = {m.name for m in problem.movable}
    points = {h.name for h in problem.handover_points}
    fixed = {f.name for f in problem.fixed}
    usable: set[int] = set()
    for t, step in enumerate(steps, 1):
        for a in step:
            bad = []
            obj = a["object"]
            if obj not in objects:
                bad.append(f"{obj!r} is a fixed object, which never moves" if obj in fixed
                           else f"no movable object {obj!r}")
            if a["region"] not in regions:
                bad.append(f"no region {a['region']!r}")
            for role in ("pick_robot", "place_robot"):
                if a[role] not in robots:
                    bad.append(f"no robot {a[role]!r} ({role.replace('_', ' ')})")
            if obj in objects:
                allowed = problem.grasps_of(obj)
                for role in ("pick_grasp", "place_grasp"):
                    if a[role] not in allowed:
                        bad.append(f"grasp {a[role]!r} is not allowed for {obj} (allowed: {', '.join(allowed)})")
            hp = a.get("handover_point")
            if hp is not None and hp not in points:
                bad.append(f"no handover point {hp!r}")
            if bad:
                for b in bad:
                    out.append(Violation(t, obj, "unknown-name", b))
                continue
            kind = "handover" if a["pick_robot"] != a["place_robot"] else "pick-place"
            if a["kind"] != kind:
                out.append(Violation(t, obj, "action", f"kind {a['kind']!r} but robots {a['pick_robot']} and "
                                                       f"{a['place_robot']} make it a {kind}"))
            if kind == "pick-place" and a["pick_grasp"] != a["place_grasp"]:
                out.append(Violation(t, obj, "action", f"{a['pick_robot']} picks with {a['pick_grasp']} but places "
                                                       f"with {a['place_grasp']}: a robot cannot regrasp in hand"))
            usable.add(id(a))
    return usable


def _structure(steps: list[list[dict[str, Any]]], usable: set[int], out: list[Violation]) -> None:
    moved_at: dict[str, int] = {}
    for t, step in enumerate(steps, 1):
        busy: dict[str, str] = {}
        for a in step:
            if id(a) not in usable:
                continue
            obj = a["object"]
            if obj in moved_at:
                out.append(Violation(t, obj, "moved-twice", f"{obj} is moved again (first at step {moved_at[obj]}); "
                                                            f"each object moves at most once"))
            else:
                moved_at[obj] = t
            for r in dict.fromkeys((a["pick_robot"], a["place_robot"])):
                if r in busy:
                    out.append(Violation(t, r, "robot-busy", f"{r} is in two actions of the step "
                                                             f"(moving {busy[r]} and {obj})"))
                else:
                    busy[r] = obj


def _symbolic(problem: Problem, steps: list[list[dict[str, Any]]], usable: set[int], out: list[Violation]) -> None:
    facts = {(f.predicate, f.args) for f in problem.init}
    goal = problem.goal_regions
    initial = problem.initial_regions
    moved_at: dict[str, int] = {}
    for t, step in enumerate(steps, 1):
        for a in step:
            if id(a) in usable:
                moved_at.setdefault(a["object"], t)
    for t, step in enumerate(steps, 1):
        for a in step:
            if id(a) not in usable:
                continue
            o, re_, r1, r2, g1, g2 = (a[k] for k in ("object", "region", "pick_robot", "place_robot", "pick_grasp",
                                                     "place_grasp"))
            need = [("reachable-pick", (o, g1, r1)), ("reachable-place", (o, re_, g2, r2))]
            if r1 != r2:
                need.insert(1, ("enable-goal-handover", (o, g1, g2, r1, r2)))
                if o not in goal:
                    out.append(Violation(t, o, "region", f"{o} is not a goal object: only goal objects are handed "
                                                         f"over (enable-goal-handover)"))
            for pred, args in need:
                if (pred, args) not in facts:
                    out.append(Violation(t, o, "unsupported", f"no fact ({pred} {' '.join(args)}) supports "
                                                              f"'{_describe(a)}'"))
            target = goal.get(o, initial.get(o))
            if target is not None and re_ != target:
                why = "its goal region" if o in goal else "its own region (it is only moved out of the way)"
                out.append(Violation(t, o, "region", f"{o} goes to {re_!r}, but the model moves it only into "
                                                     f"{target!r}, {why}"))
            for pred, args in facts:
                if pred == "occludes-pick" and args[1:] == (o, g1, r1):
                    when = moved_at.get(args[0])
                    if when is None or when >= t:
                        state = "never moves" if when is None else f"moves at step {when}"
                        out.append(Violation(t, o, "pick-obstacle", f"{args[0]} blocks {r1} picking {o} with {g1} "
                                                                    f"and {state}; it must move at an earlier step"))
                elif pred == "occludes-goal-place" and args[1:] == (o, re_, g2, r2):
                    when = moved_at.get(args[0])
                    if when is None or when > t:
                        state = "never moves" if when is None else f"moves at step {when}"
                        out.append(Violation(t, o, "place-obstacle",
                                             f"{args[0]} blocks {r2} placing {o} in {re_} with {g2} and {state}; "
                                             f"it must move by step {t}"))


def _describe(a: dict[str, Any]) -> str:
    if a["pick_robot"] == a["place_robot"]:
        return f"{a['pick_robot']} moves {a['object']} to {a['region']} ({a['pick_grasp']})"
    return (f"{a['pick_robot']}->{a['place_robot']} moves {a['object']} to {a['region']} "
            f"({a['pick_grasp']}->{a['place_grasp']})")
