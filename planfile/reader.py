"""Reading plans: the one strict way from a plan file (or a written plan) to typed values.

The planner (:mod:`mrgc.planner.plan`) writes plans with the types of :mod:`mrgc.planfile.format`; this
module reads them back, in four stages, each with its own error (an :class:`~mrgc.errors.InputError`, exit
code 2; codes in docs/errors.md):

1. **Limits, before parsing** (E504): at most :data:`MAX_BYTES`; brackets nested at most :data:`MAX_DEPTH`
   deep (counted on the text, outside strings, so a plan nested 100,000 deep never reaches the JSON
   parser's recursion); integers of at most :data:`MAX_INTEGER_DIGITS` digits and finite numbers (checked
   as the parser meets them: a 400-digit integer or ``1e999`` is refused, not turned into inf).
2. **JSON** (E501): the text parses, with no ``NaN``/``Infinity`` and no key given twice in one object.
3. **Schema** (E503 another version; E502 otherwise): ``docs/plan.schema.json`` checked by a real JSON
   Schema validator (``jsonschema``, Draft 2020-12): required fields, types, enums, sizes, and no unknown
   field anywhere but in ``stats``.  A field the schema does not know may carry meaning this reader cannot
   check, so it is bad input, like a missing one (docs/validator.md).
4. **Typed values**: :class:`~mrgc.planfile.format.PlanFile`, its :class:`~mrgc.planfile.format.Step` s
   and :class:`~mrgc.planfile.format.PlannedAction` s, the
   :class:`~mrgc.planfile.format.MotionModel`.  The validator works on these only.  Names are not resolved
   here: whether a robot, object, region, grasp or handover point exists is a question about the problem,
   answered by the validator (``[unknown-name]`` violations).
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
from functools import lru_cache
from itertools import islice
from pathlib import Path
from typing import Any

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.planfile.format import SCHEMA, MotionModel, PlanFile, PlannedAction, Step

#: diagnostic codes of unusable plan files
E_READ, E_JSON, E_SCHEMA, E_VERSION, E_LIMIT = "E500", "E501", "E502", "E503", "E504"

SCHEMA_FILE = Path(__file__).resolve().parent.parent / "docs" / "plan.schema.json"
MAX_BYTES = 32 * 2**20  # a plan file larger than this is refused unread
MAX_DEPTH = 32  # brackets nested deeper than this (a plan needs 8; its stats a few more)
MAX_INTEGER_DIGITS = 20  # an integer literal longer than this (|n| < 1e20) is refused


# ------------------------------------------------------------------------------------------ reading
class CheckedJSON(dict):  # type: ignore[type-arg]
    """Parsed plan JSON that passed the limits and the schema (:func:`read_plan` does not check it again)."""


def load_plan(path: str) -> CheckedJSON:
    """The JSON of plan file ``path``, within the limits and following the schema (InputError E500-E504);
    :func:`read_plan` turns it into typed values."""
    text = _read_text(path)
    check_limits(text, path)
    data = parse_json(text, path)
    check_schema(data, path)
    return CheckedJSON(data)


def read_plan_file(path: str) -> PlanFile:
    """Plan file ``path`` as typed values (InputError E500-E504)."""
    return read_plan(load_plan(path), path)


def _read_text(path: str) -> str:
    try:
        st = os.stat(path)
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError("it is a folder")
        if not stat.S_ISREG(st.st_mode):
            raise OSError("it is not a regular file")
        if st.st_size > MAX_BYTES:
            raise InputError(
                [
                    Diagnostic(
                        E_LIMIT,
                        f"plan {path!r} is {st.st_size} bytes; a plan file may hold at "
                        f"most {MAX_BYTES} ({MAX_BYTES // 2**20} MiB)",
                    )
                ]
            )
        with open(path, "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
        if len(raw) > MAX_BYTES:
            raise InputError([Diagnostic(E_LIMIT, f"plan {path!r} holds more than {MAX_BYTES} bytes")])
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError([Diagnostic(E_READ, f"cannot read plan {path!r}: it is not UTF-8 text")]) from None
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise InputError([Diagnostic(E_READ, f"cannot read plan {path!r}: {reason}")]) from None


#: a string (group 1 holds its closing quote, empty when the text ends inside it) or a bracket
_TOKENS = re.compile(r'"(?:[^"\\]|\\.)*("?)|[\[\]{}]')


def check_limits(text: str, where: str = "plan") -> None:
    """InputError E504 when ``text`` nests brackets deeper than :data:`MAX_DEPTH` (outside strings)."""
    depth = 0
    for m in _TOKENS.finditer(text):
        ch = m.group()
        if ch in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                line = text.count("\n", 0, m.start()) + 1
                col = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
                raise InputError(
                    [
                        Diagnostic(
                            E_LIMIT,
                            f"plan nests arrays and objects more than {MAX_DEPTH} deep (a plan needs 8)",
                            Span(where, line, col, line, col + 1),
                        )
                    ]
                )
        elif ch in "]}":
            depth -= 1


class _Refused(ValueError):
    """A number the reader refuses (its literal text, and why)."""

    def __init__(self, literal: str, why: str) -> None:
        super().__init__(why)
        self.literal = literal


def _parse_int(s: str) -> int:
    if len(s.lstrip("-")) > MAX_INTEGER_DIGITS:
        raise _Refused(s, f"an integer of {len(s.lstrip('-'))} digits (at most {MAX_INTEGER_DIGITS})")
    return int(s)


def _parse_float(s: str) -> float:
    v = float(s)
    if not math.isfinite(v):
        raise _Refused(s, f"the number {s[:30]}{'...' if len(s) > 30 else ''} lies beyond double precision")
    return v


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"the key {k!r} appears twice in one object")
        out[k] = v
    return out


def parse_json(text: str, where: str = "plan") -> Any:
    """The JSON value of ``text`` (InputError E501 when it is not JSON, E504 for a refused number)."""
    try:
        return json.loads(
            text,
            parse_constant=_no_constant,
            parse_int=_parse_int,
            parse_float=_parse_float,
            object_pairs_hook=_no_duplicates,
        )
    except json.JSONDecodeError as exc:
        span = Span(where, exc.lineno, exc.colno, exc.lineno, exc.colno + 1)
        what = (
            "it is empty"
            if not text.strip()
            else f"it ends early (truncated?): {exc.msg}"
            if _ends_early(text)
            else exc.msg
        )
        raise InputError([Diagnostic(E_JSON, f"plan is not JSON: {what}", span)], {where: text}) from None
    except _Refused as exc:
        at = text.find(exc.literal)
        line = text.count("\n", 0, at) + 1
        col = at - (text.rfind("\n", 0, at) + 1) + 1
        raise InputError([Diagnostic(E_LIMIT, f"plan holds {exc}", Span(where, line, col, line, col + 1))]) from None
    except RecursionError:  # pragma: no cover - check_limits keeps the depth far below the recursion limit
        raise InputError([Diagnostic(E_LIMIT, "plan nests too deep to read")]) from None
    except ValueError as exc:
        raise InputError([Diagnostic(E_JSON, f"plan is not JSON: {exc}")]) from None


def _ends_early(text: str) -> bool:
    """Whether the text stops inside a string or with brackets still open (a cut-off file)."""
    depth, open_string = 0, False
    for m in _TOKENS.finditer(text):
        ch = m.group()
        if ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        open_string = ch.startswith('"') and not m.group(1)
    return open_string or depth > 0


# ------------------------------------------------------------------------------------------- schema
@lru_cache(maxsize=1)
def _validator() -> Any:
    import jsonschema

    schema = json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


def check_schema(plan: Any, where: str = "plan") -> None:
    """Raise InputError E503 (another schema version) or E502 (not following docs/plan.schema.json)."""
    if isinstance(plan, dict) and "schema" in plan and plan["schema"] != SCHEMA:
        shown = plan["schema"] if isinstance(plan["schema"], str) else json.dumps(plan["schema"])[:40]
        raise InputError(
            [Diagnostic(E_VERSION, f"{where}: schema {shown!r} is not supported (this mrgc reads {SCHEMA!r})")]
        )
    errors = schema_errors(plan)
    if errors:
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise InputError([Diagnostic(E_SCHEMA, f"{where} does not follow the plan schema {SCHEMA}: {errors[0]}{more}")])


def schema_errors(plan: Any, limit: int = 20) -> list[str]:
    """Where ``plan`` departs from ``docs/plan.schema.json``, one line each (at most ``limit``), in document
    order.  A plan that follows it is checked on a thin copy (:func:`_thin`: every list of configurations
    that follows the schema's ``configs`` definition emptied); a plan that does not, in full (its errors are
    the full check's)."""
    thin = _thin(plan)
    if thin is not plan and not any(True for _ in islice(_validator().iter_errors(thin), 1)):
        return []
    errors = list(islice(_validator().iter_errors(plan), limit))
    errors.sort(key=lambda e: [str(p) for p in e.absolute_path])
    return [_describe(e) for e in errors]


@lru_cache(maxsize=1)
def _configs_rule() -> tuple[frozenset[str], frozenset[str], int, int, int] | None:
    """What the schema's ``configs`` definition asks, read from the schema: the ``configs`` and ``paths``
    fields of an action that use it, the most configurations, the fewest and most values of one; None when
    the definition is not the shape :func:`_configs_follow` checks (then every plan is checked in full)."""
    schema = json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    try:
        action = schema["properties"]["steps"]["items"]["properties"]["actions"]["items"]["properties"]
        d = schema["$defs"]["configs"]
        q = d["items"]
        shape = (set(d) - {"description"}, set(q) - {"description"}, q["items"], d["type"], q["type"])
        if shape != (
            {"type", "maxItems", "items"},
            {"type", "minItems", "maxItems", "items"},
            {"type": "number"},
            "array",
            "array",
        ):
            return None
        ref = {"$ref": "#/$defs/configs"}
        fields = [frozenset(k for k, v in action[f]["properties"].items() if v == ref) for f in ("configs", "paths")]
        return fields[0], fields[1], int(d["maxItems"]), int(q["minItems"]), int(q["maxItems"])
    except (KeyError, TypeError, ValueError):
        return None


def _configs_follow(value: Any, most: int, fewest_values: int, most_values: int) -> bool:
    """Whether ``value`` follows the ``configs`` definition: a list of at most ``most`` lists of
    ``fewest_values``..``most_values`` numbers (int or float, never bool: stricter than JSON Schema's number,
    never looser)."""
    if type(value) is not list or len(value) > most:
        return False
    for q in value:
        if type(q) is not list or not fewest_values <= len(q) <= most_values:
            return False
        for x in q:
            if type(x) is not float and type(x) is not int:
                return False
    return True


def _thin(plan: Any) -> Any:
    """``plan`` with every list of configurations of an action (``configs`` and ``paths`` fields that the
    schema's ``configs`` definition covers) that follows that definition replaced by ``[]``, which follows it
    too: the copy follows the schema exactly when the plan does, and checks in a fraction of the time (a plan
    is mostly numbers).  ``plan`` itself when there is nothing to thin."""
    rule = _configs_rule()
    steps = plan.get("steps") if isinstance(plan, dict) else None
    if rule is None or type(steps) is not list:
        return plan
    fields = {"configs": rule[0], "paths": rule[1]}
    thin_steps = []
    for step in steps:
        actions = step.get("actions") if isinstance(step, dict) else None
        if type(actions) is not list:
            thin_steps.append(step)
            continue
        thin_actions = []
        for a in actions:
            if isinstance(a, dict):
                a = dict(a)
                for name, known in fields.items():
                    motions = a.get(name)
                    if isinstance(motions, dict):
                        a[name] = {
                            k: [] if k in known and _configs_follow(v, *rule[2:]) else v for k, v in motions.items()
                        }
            thin_actions.append(a)
        thin_steps.append({**step, "actions": thin_actions})
    return {**plan, "steps": thin_steps}


_ARTICLE = {
    "object": "an object",
    "array": "an array",
    "string": "a string",
    "integer": "an integer",
    "number": "a finite number",
    "boolean": "true or false",
    "null": "null",
}


def _where(path: Any) -> str:
    out = "plan"
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else f".{p}"
    return out


def _show(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _describe(e: Any) -> str:
    """One line for a jsonschema ValidationError, naming the field."""
    at, kw, arg, value = _where(e.absolute_path), e.validator, e.validator_value, e.instance
    if kw == "type":
        types = [str(t) for t in (arg if isinstance(arg, list) else [arg])]
        return f"{at} should be {' or '.join(_ARTICLE.get(t, t) for t in types)}, not {_show(value)}"
    if kw == "required":
        missing = [k for k in arg if isinstance(value, dict) and k not in value]
        return f"{at} lacks {missing[0]!r}" if missing else f"{at}: {e.message}"
    if kw == "additionalProperties":
        extra = sorted(k for k in value if k not in e.schema.get("properties", {}))
        return f"{at} has an unknown field {extra[0]!r}" if extra else f"{at}: {e.message}"
    if kw == "enum":
        return f"{at} should be one of {', '.join(map(_show, arg))}, not {_show(value)}"
    if kw == "const":
        return f"{at} should be {_show(arg)}, not {_show(value)}"
    if kw in ("minItems", "maxItems"):
        lo, hi = e.schema.get("minItems", 0), e.schema.get("maxItems")
        want = f"{lo}" if lo == hi else f"{lo} to {hi}" if hi is not None else f"at least {lo}"
        return f"{at} should hold {want} items, not {len(value)}"
    if kw in ("minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"):
        words = {
            "minimum": "at least",
            "exclusiveMinimum": "more than",
            "maximum": "at most",
            "exclusiveMaximum": "less than",
        }
        return f"{at} should be {words[kw]} {arg}, not {_show(value)}"
    if kw in ("minLength", "maxLength"):
        return f"{at} should be {'at least' if kw == 'minLength' else 'at most'} {arg} characters long"
    if kw == "pattern":
        return f"{at} {_show(value)} does not match {arg}"
    return f"{at}: {e.message[:120]}"


# ------------------------------------------------------------------------------------- typed values
def read_plan(data: Any, where: str = "plan") -> PlanFile:
    """Typed values of a plan: ``data`` is parsed plan JSON (checked here against the schema) or a written
    plan (:class:`~mrgc.planner.plan.Plan`, anything with ``to_json``; InputError E502/E503 when it breaks
    the schema)."""
    if isinstance(data, PlanFile):
        return data
    if not isinstance(data, dict) and hasattr(data, "to_json"):
        data = parse_json(json.dumps(data.to_json()), where)
    if not isinstance(data, CheckedJSON):
        check_schema(data, where)
    model = data.get("motion_model")
    return PlanFile(
        schema=data["schema"],
        mrgc_version=data["mrgc_version"],
        problem=data["problem"],
        problem_file=data["problem_file"],
        problem_sha256=data["problem_sha256"],
        backend=data["backend"],
        encoding=data["encoding"],
        seed=int(data["seed"]),
        status=data["status"],
        symbolic=data["symbolic"],
        makespan=None if data["makespan"] is None else int(data["makespan"]),
        motion_cost=None if data["motion_cost"] is None else int(data["motion_cost"]),
        steps=tuple(
            Step(int(s["index"]), tuple(_action(a) for a in s["actions"]), tuple(s["waiting"])) for s in data["steps"]
        ),
        motion_model=MotionModel.from_json(model) if model is not None else None,
        problem_digest=data.get("problem_digest"),
    )


def _configurations(qs: list[list[float]]) -> list[list[float]]:
    return [[float(v) for v in q] for q in qs]


def _action(a: dict[str, Any]) -> PlannedAction:
    pose = a.get("place_pose")
    return PlannedAction(
        a["object"],
        a["region"],
        a["pick_robot"],
        a["place_robot"],
        a["pick_grasp"],
        a["place_grasp"],
        None if pose is None else _configurations(pose),
        a.get("handover_point"),
        {k: _configurations(v) for k, v in a.get("configs", {}).items()},
        {k: _configurations(v) for k, v in a.get("paths", {}).items()},
        bool(a.get("relay", False)),
        stated_kind=a["kind"],
    )
