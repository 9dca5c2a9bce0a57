"""Reading a URDF file: its links, joints and collision shapes as checked, located data.

The file is parsed with expat (the standard library's XML parser) keeping each element's line, so every
complaint points at ``file.urdf:LINE`` (E400): malformed XML, an entity declaration (refused: no entity
expansion), a joint without parent or child, a link that is the child of two joints, a joint naming an
undeclared link, a **joint cycle** (found by the traversal, which visits each link once, so a cycle can
no longer loop forever), not exactly one root link, and any number that is not finite or beyond its
bound (positions and sizes within :data:`MAX_LENGTH` metres, angles and limits within
:data:`MAX_ANGLE`).

Paths: a URDF's mesh files resolve relative to the URDF file (``package://`` and ``file://`` stripped;
also without the package name, and from the URDF's parent folder, as ROS packages lay them out), never
relative to the current folder, and a missing mesh is an error (a link silently without geometry would
give wrong facts).  When ``roots`` is given (the problem's folder tree and ``--allow-outside`` folders),
a mesh outside them and outside pybullet_data is refused (E236).
"""

from __future__ import annotations

import functools
import math
import os
import xml.etree.ElementTree as ET
import xml.parsers.expat
from dataclasses import dataclass

import numpy as np

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.geometry import transforms as tf
from mrgc.language.files import FileTooLarge, read_regular

#: code of "robot URDF not found or unreadable"
E_URDF = "E400"
#: URDF files larger than this are refused
MAX_BYTES = 16 * 1024 * 1024
#: bound on positions, sizes and prismatic limits, in metres
MAX_LENGTH = 1e4
#: bound on angles, revolute limits and velocities (pybullet_data's URDFs use limits up to 1e16 for
#: "no limit": they are read as unbounded revolute joints, -pi..pi)
MAX_ANGLE = 1e6


class UrdfError(Exception):
    """A complaint about the URDF at ``line`` (turned into E400 by :func:`parse_urdf`)."""

    def __init__(self, message: str, line: int = 1) -> None:
        super().__init__(message)
        self.line = line


@dataclass(frozen=True)
class UrdfJoint:
    """A joint as the URDF states it (``origin``: parent link frame → joint frame at 0)."""

    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    lower: float
    upper: float
    velocity: float
    line: int = 0
    #: ``<mimic joint=J multiplier=m offset=o>``: this joint's value is ``m * value(J) + o`` (None: it has none)
    mimic: tuple[str, float, float] | None = None


@dataclass(frozen=True)
class Urdf:
    """A parsed URDF: its links in topological order (root first), joints by child link, link elements
    and the line of every element."""

    path: str
    name: str
    order: tuple[str, ...]
    joint_of: dict[str, UrdfJoint]
    links: dict[str, ET.Element]
    lines: dict[ET.Element, int]

    def line(self, el: ET.Element) -> int:
        """The line of the file an element starts on (1 when unknown)."""
        return self.lines.get(el, 1)


def urdf_error(path: str, message: str, line: int = 1, note: str | None = None) -> InputError:
    """E400 located at ``path:line``."""
    return InputError(
        [
            Diagnostic(
                E_URDF,
                f"robot URDF '{os.path.basename(path)}': {message}",
                Span(path, line, 1, line, 2),
                notes=(note,) if note else (),
            )
        ]
    )


@functools.lru_cache(maxsize=None)
def parse_urdf(path: str) -> Urdf:
    """The URDF at ``path`` (a resolved, real path), or InputError E400 at the offending line."""
    try:
        data = read_regular(path, MAX_BYTES)
    except FileTooLarge as exc:
        raise urdf_error(path, f"{exc.size} bytes; the limit is {MAX_BYTES} bytes") from None
    except OSError as exc:
        raise urdf_error(path, f"cannot be read: {exc.strerror or exc}") from None
    try:
        root, lines = _xml(data)
    except xml.parsers.expat.ExpatError as exc:
        raise urdf_error(path, f"not well-formed XML: {xml.parsers.expat.ErrorString(exc.code)}", exc.lineno) from None
    except UrdfError as exc:
        raise urdf_error(path, str(exc), exc.line) from None
    try:
        return _structure(path, root, lines)
    except UrdfError as exc:
        raise urdf_error(path, str(exc), exc.line) from None


def _xml(data: bytes) -> tuple[ET.Element, dict[ET.Element, int]]:
    builder = ET.TreeBuilder()
    lines: dict[ET.Element, int] = {}
    parser = xml.parsers.expat.ParserCreate()

    def start(tag: str, attrs: dict[str, str]) -> None:
        lines[builder.start(tag, attrs)] = parser.CurrentLineNumber

    def entity(*args: object) -> None:
        raise UrdfError("declares an XML entity (refused: entities can expand without bound)", parser.CurrentLineNumber)

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.EntityDeclHandler = entity
    parser.Parse(data, True)
    return builder.close(), lines


def _structure(path: str, root: ET.Element, lines: dict[ET.Element, int]) -> Urdf:
    """The URDF's tree: links declared once, joints naming declared links, one parent per link, one root
    and no cycle (UrdfError at the offending line otherwise); links in depth-first order."""
    if root.tag != "robot":
        raise UrdfError(f"the root element is <{root.tag}>, not <robot>", lines.get(root, 1))
    links = _links(root, lines)
    joint_of: dict[str, UrdfJoint] = {}
    children: dict[str, list[str]] = {}
    for el in root.findall("joint"):
        j = _joint(el, lines)
        for end in (j.parent, j.child):
            if end not in links:
                raise UrdfError(f"joint {j.name!r} names link {end!r}, which is not declared", j.line)
        if j.child in joint_of:
            raise UrdfError(
                f"link {j.child!r} is the child of joint {j.name!r} and of joint "
                f"{joint_of[j.child].name!r} (line {joint_of[j.child].line}): a link has one parent",
                j.line,
            )
        joint_of[j.child] = j
        children.setdefault(j.parent, []).append(j.child)
    roots = [name for name in links if name not in joint_of]
    if len(roots) != 1:
        if not roots and joint_of:
            raise UrdfError(_cycle(joint_of, next(iter(joint_of))), next(iter(joint_of.values())).line)
        raise UrdfError(f"expected one root link (a link no joint moves), found {roots or 'none'}")
    order = _depth_first(roots[0], children, joint_of)
    if len(order) != len(links):  # links not below the root: they hang in a joint cycle
        stray = next(n for n in links if n not in set(order))
        raise UrdfError(_cycle(joint_of, stray), joint_of[stray].line)
    return Urdf(path, root.get("name", ""), tuple(order), joint_of, links, lines)


def _links(root: ET.Element, lines: dict[ET.Element, int]) -> dict[str, ET.Element]:
    """The ``<link>`` elements by name (UrdfError for a link without a name or declared twice)."""
    links: dict[str, ET.Element] = {}
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise UrdfError("a <link> without a name", lines.get(el, 1))
        if name in links:
            raise UrdfError(
                f"link {name!r} is declared twice (first at line {lines.get(links[name], 1)})", lines.get(el, 1)
            )
        links[name] = el
    return links


def _depth_first(root: str, children: dict[str, list[str]], joint_of: dict[str, UrdfJoint]) -> list[str]:
    """The links below ``root``, depth first, children in document order, each once."""
    order: list[str] = []
    seen: set[str] = set()
    stack = [root]
    while stack:
        name = stack.pop()
        if name in seen:  # pragma: no cover - one parent per link makes this impossible; kept as a guard
            raise UrdfError(_cycle(joint_of, name), joint_of[name].line)
        seen.add(name)
        order.append(name)
        stack.extend(reversed(children.get(name, [])))
    return order


def _cycle(joint_of: dict[str, UrdfJoint], start: str) -> str:
    """``joint cycle: a -> b -> a`` found by following parents from ``start``."""
    path, at = [start], start
    while at in joint_of:
        at = joint_of[at].parent
        if at in path:
            loop = path[path.index(at) :] + [at]
            return "joint cycle: " + " -> ".join(reversed(loop)) + " (each link must hang below the root link)"
        path.append(at)
    return f"link {start!r} does not hang below the root link"  # pragma: no cover


def _joint(el: ET.Element, lines: dict[ET.Element, int]) -> UrdfJoint:
    line = lines.get(el, 1)
    name = el.get("name") or "?"
    kind = el.get("type")
    if kind not in ("revolute", "continuous", "prismatic", "fixed", "floating", "planar"):
        raise UrdfError(
            f"joint {name!r} has type {kind!r} (revolute, continuous, prismatic, fixed, floating or planar)", line
        )
    parent, child = el.find("parent"), el.find("child")
    if parent is None or child is None or not parent.get("link") or not child.get("link"):
        raise UrdfError(f"joint {name!r} lacks its <parent link=...> or <child link=...>", line)
    axis_el = el.find("axis")
    axis = np.array(
        vec(
            axis_el.get("xyz") if axis_el is not None else None,
            (1.0, 0.0, 0.0),
            lines.get(axis_el, line) if axis_el is not None else line,
            MAX_LENGTH,
            "axis",
        )
    )
    norm = float(np.linalg.norm(axis))
    if norm == 0 and kind in ("revolute", "continuous", "prismatic"):
        raise UrdfError(f"joint {name!r} has a zero axis", line)
    lim = el.find("limit")
    lim_line = lines.get(lim, line) if lim is not None else line
    bound = MAX_LENGTH if kind == "prismatic" else MAX_ANGLE
    lo = scalar(lim.get("lower") if lim is not None else None, 0.0, lim_line, "lower limit", None)
    hi = scalar(lim.get("upper") if lim is not None else None, 0.0, lim_line, "upper limit", None)
    vel = scalar(lim.get("velocity") if lim is not None else None, 0.0, lim_line, "velocity", MAX_ANGLE)
    if kind == "continuous" or (kind == "revolute" and (lo >= hi or max(abs(lo), abs(hi)) > bound)):
        lo, hi = -math.pi, math.pi
    elif kind == "prismatic" and max(abs(lo), abs(hi)) > bound:
        raise UrdfError(f"joint {name!r}: limits {lo:g} .. {hi:g} exceed {bound:g}", lim_line)
    org = el.find("origin")
    mimic = None
    mim = el.find("mimic")
    if mim is not None and mim.get("joint"):
        mim_line = lines.get(mim, line)
        mimic = (
            mim.get("joint", ""),
            scalar(mim.get("multiplier"), 1.0, mim_line, "mimic multiplier", MAX_ANGLE),
            scalar(mim.get("offset"), 0.0, mim_line, "mimic offset", MAX_ANGLE),
        )
    return UrdfJoint(
        name,
        kind,
        parent.get("link", ""),
        child.get("link", ""),
        origin(org, lines.get(org, line) if org is not None else line),
        axis / norm if norm > 0 else axis,
        lo,
        hi,
        vel,
        line,
        mimic,
    )


def scalar(text: str | None, default: float, line: int, what: str, bound: float | None) -> float:
    """A number attribute: finite (and within ``bound`` when given), else UrdfError."""
    if text is None:
        return default
    try:
        x = float(text)
    except ValueError:
        raise UrdfError(f"{what} {text[:40]!r} is not a number", line) from None
    if not math.isfinite(x) or (bound is not None and abs(x) > bound):
        raise UrdfError(
            f"{what} {text[:40]!r} is not a finite number" + (f" within {bound:g}" if bound is not None else ""), line
        )
    return x


def vec(
    text: str | None, default: tuple[float, ...], line: int = 1, bound: float = MAX_LENGTH, what: str = "value"
) -> tuple[float, ...]:
    """A space-separated vector attribute of ``len(default)`` finite numbers within ``bound``."""
    if text is None:
        return default
    toks = text.split()
    if len(toks) != len(default):
        raise UrdfError(f"{what} needs {len(default)} numbers, got {text[:60]!r}", line)
    return tuple(scalar(t, 0.0, line, what, bound) for t in toks)


def origin(el: ET.Element | None, line: int = 1) -> np.ndarray:
    """The 4×4 transform of an ``<origin xyz=... rpy=...>`` element (identity when absent)."""
    if el is None:
        return np.eye(4)
    return tf.from_xyz_rpy(
        vec(el.get("xyz"), (0.0, 0.0, 0.0), line, MAX_LENGTH, "origin xyz"),
        vec(el.get("rpy"), (0.0, 0.0, 0.0), line, MAX_ANGLE, "origin rpy"),
    )


def mesh_path(filename: str, urdf: str, line: int, roots: tuple[str, ...] = (), data: str | None = None) -> str:
    """The real path of a mesh file named in a URDF (see the module docstring), or InputError."""
    from mrgc.language.loader import inside

    here = os.path.dirname(urdf)
    rel = filename
    for prefix in ("package://", "file://"):
        if rel.startswith(prefix):
            rel = rel[len(prefix) :]
    if not rel:
        raise urdf_error(urdf, "a <mesh> without a filename", line)
    if os.path.isabs(rel):
        cands = [rel]
    else:
        cands = [os.path.join(here, rel), os.path.join(here, rel.split("/", 1)[-1]), os.path.join(here, os.pardir, rel)]
    found = next((c for c in cands if os.path.isfile(c)), None)
    if found is None:
        raise urdf_error(
            urdf,
            f"mesh file {filename!r} not found (looked for "
            f"{' or '.join(repr(os.path.normpath(c)) for c in dict.fromkeys(cands))})",
            line,
        )
    real = os.path.realpath(found)
    allowed = roots + ((data,) if data else ())
    if roots and not inside(real, allowed):
        raise InputError(
            [
                Diagnostic(
                    "E236",
                    f"mesh file {filename!r} of robot URDF '{urdf}' is outside the "
                    f"folder tree of the problem and pybullet_data; pass --allow-outside FOLDER "
                    f"to allow it",
                    Span(urdf, line, 1, line, 2),
                )
            ]
        )
    return real


def referenced_files(urdf: Urdf) -> list[str]:
    """Real paths of the mesh files the URDF's collision and visual elements name and that exist (what a
    copy of the URDF needs beside it)."""
    out: list[str] = []
    for el in urdf.lines:
        if el.tag == "mesh" and el.get("filename"):
            try:
                path = mesh_path(el.get("filename", ""), urdf.path, urdf.line(el))
            except InputError:  # a missing visual mesh: pybullet skips it, so does a copy
                continue
            if path not in out:
                out.append(path)
    return out
