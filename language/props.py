"""Reading ``:key value`` properties into typed values, with one diagnostic per problem found.

Which properties each declaration accepts is data (:data:`SCHEMAS`); the readers turn a syntax value into a
pose, a shape, a vector, a name list, an axis ... or report E240/E242/E250-E253/E256 and return ``None``.
"""

from __future__ import annotations

import math
import os
from typing import Callable, Optional

from mrgc.errors import Diagnostic, Span
from mrgc.language import ast
from mrgc.language.model import AXES, BASE_TYPES, Axis, Box, Cylinder, Mesh, Pose, Shape, Sphere
from mrgc.language.suggest import did_you_mean

#: declaration kind -> property name -> value type
SCHEMAS: dict[str, dict[str, str]] = {
    "robot-kind": {
        "urdf": "string",
        "base": "base-type",
        "end-effector": "string",
        "home": "vector",
        "footprint": "shape",
        "carry": "pose",
        "reach": "length",
        "tcp": "pose",
        "gripper-opening": "length",
    },
    "grasp": {"approach": "axis", "fingers": "axis", "depth": "distance", "offset": "point"},
    "robots": {"kind": "name", "base": "pose"},
    "fixed": {"shape": "shape", "pose": "pose"},
    "regions": {"shape": "shape", "pose": "pose"},
    "movable": {"shape": "shape", "pose": "pose", "grasps": "names", "handover": "names"},
    "handover-points": {"position": "point"},
}

#: bound on every number of a property (coordinates, sizes, angles, joint values): 10 km or 10^4 rad
#: keep the geometry's arithmetic exact enough and free of overflow (E259)
MAX_MAGNITUDE = 1e4
#: smallest positive size (1 micrometre): smaller shapes are a unit mistake and degenerate for collision
MIN_LENGTH = 1e-6

#: the properties that make a declaration geometric
GEOMETRIC_PROPS = frozenset({"shape", "pose", "base", "position"})

#: shape name -> the names of its dimensions
SHAPE_ARGS: dict[str, tuple[str, ...]] = {
    "box": ("x size", "y size", "z size"),
    "cylinder": ("radius", "height"),
    "sphere": ("radius",),
    "mesh": ("path", "scale"),
}


class PropReader:
    """Reads properties of one file, appending diagnostics to ``diags``."""

    def __init__(self, diags: list[Diagnostic], file: str) -> None:
        self.diags = diags
        self.file = file

    def err(self, code: str, message: str, span: Span) -> None:
        """Record a diagnostic."""
        self.diags.append(Diagnostic(code, message, span))

    # ------------------------------------------------------------ property tables
    def table(self, kind: str, what: str, props: tuple[ast.Property, ...]) -> dict[str, ast.Property]:
        """Index ``props`` by key, reporting duplicate (E202) and unknown (E254) keys."""
        schema = SCHEMAS[kind]
        out: dict[str, ast.Property] = {}
        for prop in props:
            if prop.key not in schema:
                hint = did_you_mean(prop.key, schema) or f" (allowed: {', '.join(':' + k for k in schema)})"
                self.err("E254", f"unknown property ':{prop.key}' for {what}{hint}", prop.span)
            elif prop.key in out:
                self.err("E202", f"property ':{prop.key}' given twice for {what}", prop.span)
            else:
                out[prop.key] = prop
        return out

    def read(self, kind: str, prop: ast.Property) -> object:
        """The typed value of ``prop`` by its schema type, or None after reporting why not."""
        reader: Callable[[ast.Value, str], object] = getattr(self, "_" + SCHEMAS[kind][prop.key].replace("-", "_"))
        return reader(prop.value, f"':{prop.key}'")

    # ------------------------------------------------------------ value readers
    def _number(self, value: ast.Value, what: str) -> Optional[float]:
        if not isinstance(value, ast.Number):
            self.err("E253", f"{what} must be a number, not {_kind_of(value)}", value.span)
            return None
        if not math.isfinite(value.value):
            self.err("E251", f"{what} is not a finite number", value.span)
            return None
        if abs(value.value) > MAX_MAGNITUDE:
            self.err(
                "E259",
                f"{what} is {_fmt(value.value)}, beyond the bound of {MAX_MAGNITUDE:g} (metres, radians)",
                value.span,
            )
            return None
        return value.value

    def _length(self, value: ast.Value, what: str) -> Optional[float]:
        x = self._number(value, what)
        if x is not None and x <= 0:
            self.err("E250", f"{what} must be positive, got {_fmt(x)}", value.span)
            return None
        if x is not None and x < MIN_LENGTH:
            self.err("E259", f"{what} is {_fmt(x)}, below the smallest size of {MIN_LENGTH:g} m", value.span)
            return None
        return x

    def _distance(self, value: ast.Value, what: str) -> Optional[float]:
        x = self._number(value, what)
        if x is not None and x < 0:
            self.err("E242", f"{what} must not be negative, got {_fmt(x)}", value.span)
            return None
        return x

    def _axis(self, value: ast.Value, what: str) -> Optional[Axis]:
        words = [w for w in AXES if w[0] in "+-"]
        if not isinstance(value, ast.Symbol):
            self.err("E240", f"{what} must be an axis ({' '.join(words)}), not {_kind_of(value)}", value.span)
            return None
        if value.name not in AXES:
            word = value.name.lower()
            word = word if word in AXES else word[::-1] if word[::-1] in AXES else ""  # -Z, z-
            hint = (
                f" (did you mean '{word}'?)" if word else did_you_mean(value.name, AXES) or f" (use {' '.join(words)})"
            )
            self.err("E240", f"unknown axis '{value.name}' for {what}{hint}", value.span)
            return None
        return AXES[value.name]

    def _numbers(self, value: ast.Value, what: str, length: int | None) -> Optional[tuple[float, ...]]:
        if not isinstance(value, ast.ListValue):
            self.err("E253", f"{what} must be a list of numbers like (0 0 0), not {_kind_of(value)}", value.span)
            return None
        out: list[float] = []
        ok = True
        for item in value.items:
            x = self._number(item, f"{what} entry")
            ok = ok and x is not None
            out.append(x if x is not None else 0.0)
        if length is not None and len(out) != length:
            self.err("E252", f"{what} needs {length} numbers, got {len(out)}", value.span)
            return None
        if length is None and not out:
            self.err("E252", f"{what} needs at least one number", value.span)
            return None
        return tuple(out) if ok else None

    def _vector(self, value: ast.Value, what: str) -> Optional[tuple[float, ...]]:
        return self._numbers(value, what, None)

    def _point(self, value: ast.Value, what: str) -> Optional[tuple[float, float, float]]:
        v = self._numbers(value, what + " (x y z)", 3)
        return (v[0], v[1], v[2]) if v is not None else None

    def _pose(self, value: ast.Value, what: str) -> Optional[Pose]:
        v = self._numbers(value, what + " (x y z yaw)", 4)
        return Pose(*v) if v is not None else None

    def _name(self, value: ast.Value, what: str) -> Optional[str]:
        if not isinstance(value, ast.Symbol):
            self.err("E253", f"{what} must be a name, not {_kind_of(value)}", value.span)
            return None
        return value.name

    def _names(self, value: ast.Value, what: str) -> Optional[tuple[tuple[str, Span], ...]]:
        if isinstance(value, ast.Symbol):
            return ((value.name, value.span),)
        if not isinstance(value, ast.ListValue):
            self.err("E253", f"{what} must be a list of names like (a b), not {_kind_of(value)}", value.span)
            return None
        if not value.items:
            self.err("E253", f"{what} must list at least one name (leave it out to allow them all)", value.span)
            return None
        out = []
        for item in value.items:
            if not isinstance(item, ast.Symbol):
                self.err("E253", f"{what} entries must be names, not {_kind_of(item)}", item.span)
                return None
            out.append((item.name, item.span))
        return tuple(out)

    def _string(self, value: ast.Value, what: str) -> Optional[str]:
        if not isinstance(value, ast.String):
            self.err("E253", f'{what} must be a string like "path", not {_kind_of(value)}', value.span)
            return None
        return value.value

    def _base_type(self, value: ast.Value, what: str) -> Optional[str]:
        name = self._name(value, what)
        if name is not None and name not in BASE_TYPES:
            hint = did_you_mean(name, BASE_TYPES) or f" (use {' or '.join(BASE_TYPES)})"
            self.err("E257", f"unknown base type '{name}'{hint}", value.span)
            return None
        return name

    def _shape(self, value: ast.Value, what: str) -> Optional[Shape]:
        if not isinstance(value, ast.ListValue) or not value.items or not isinstance(value.items[0], ast.Symbol):
            self.err("E253", f"{what} must be a shape like (box 0.1 0.1 0.1), not {_kind_of(value)}", value.span)
            return None
        head, args = value.items[0], value.items[1:]
        if head.name not in SHAPE_ARGS:
            hint = did_you_mean(head.name, SHAPE_ARGS) or f" (use {', '.join(SHAPE_ARGS)})"
            self.err("E256", f"unknown shape '{head.name}'{hint}", head.span)
            return None
        names = SHAPE_ARGS[head.name]
        if head.name == "mesh":
            return self._mesh(value, args)
        if len(args) != len(names):
            self.err(
                "E252", f"a {head.name} needs {len(names)} numbers ({', '.join(names)}), got {len(args)}", value.span
            )
            return None
        dims = [self._length(a, f"{head.name} {n}") for a, n in zip(args, names)]
        given = [d for d in dims if d is not None]
        if len(given) < len(dims):
            return None
        if head.name == "box":
            return Box(*given)
        return Cylinder(*given) if head.name == "cylinder" else Sphere(*given)

    def _mesh(self, value: ast.ListValue, args: tuple[ast.Number | ast.Symbol | ast.String, ...]) -> Optional[Mesh]:
        if not 1 <= len(args) <= 2 or not isinstance(args[0], ast.String):
            self.err("E253", 'a mesh is written (mesh "file.obj") or (mesh "file.obj" scale)', value.span)
            return None
        scale = self._length(args[1], "mesh scale") if len(args) == 2 else 1.0
        if scale is None:
            return None
        path = args[0].value
        full = path if os.path.isabs(path) else os.path.join(os.path.dirname(self.file), path)
        if not os.path.isfile(full):
            self.err("E258", f"mesh file '{path}' not found (looked for {full})", args[0].span)
            return None
        return Mesh(os.path.normpath(full), scale)


def _kind_of(value: ast.Value | ast.Number | ast.Symbol | ast.String) -> str:
    if isinstance(value, ast.Number):
        return f"the number {_fmt(value.value)}"
    if isinstance(value, ast.Symbol):
        return f"the name '{value.name}'"
    if isinstance(value, ast.String):
        return "a string"
    return "a list"


def _fmt(x: float) -> str:
    return str(int(x)) if x.is_integer() and abs(x) < 1e15 else repr(x)
