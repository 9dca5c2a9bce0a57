"""The content digest of a checked problem: what a plan records to say which problem it solves.

A plan made from a problem file and validated against another file holding the same problem (the facts
file ``mrgc facts`` writes from it, the same problem reformatted, moved or with other comments) is for the
same problem; a byte hash of the file cannot tell that, so plans record :func:`problem_digest` too
(``problem_digest`` in the plan JSON, docs/validator.md).

The digest is the SHA-256 of a canonical JSON text of the checked problem: its name and kind, the domain
(requirements, robot kinds, grasps and their geometry), every declaration with its shape and pose, and the
goal.  Facts count only in a symbolic problem (they are its content); in a geometric problem they are
derived from the geometry (``mrgc facts``), so a problem and its facts file share one digest.  Files a
problem names count by their bytes, not their paths: a mesh shape, a robot kind's URDF (the file itself,
not the meshes it names), so the copies a facts file written elsewhere carries beside it keep the digest.
Spans, source paths and comments never count.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import fields, is_dataclass
from typing import Any

from mrgc.language.model import Mesh, Problem, RobotKind

#: files larger than this count by their path (a digest never reads more)
MAX_HASHED = 256 << 20


def problem_digest(problem: Problem) -> str:
    """The SHA-256 (hex) of ``problem``'s content (see the module docstring)."""
    data = {
        "problem": problem.name,
        "symbolic": problem.symbolic,
        "domain": _value(problem.domain, problem.domain.source),
        "robots": _value(problem.robots, problem.source),
        "fixed": _value(problem.fixed, problem.source),
        "regions": _value(problem.regions, problem.source),
        "movable": _value(problem.movable, problem.source),
        "handover_points": _value(problem.handover_points, problem.source),
        "init": sorted(map(str, problem.init)) if problem.symbolic else [],
        "goal": sorted(map(str, problem.goal)),
    }
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _value(node: Any, source: str) -> Any:
    """A JSON value for a model value: dataclasses by their compared fields (no spans, sources, roots)."""
    if isinstance(node, Mesh):
        return {"mesh": _file_hash(node.path), "scale": node.scale}
    if isinstance(node, RobotKind):
        out = {f.name: _value(getattr(node, f.name), source) for f in fields(node) if f.compare and f.name != "urdf"}
        out["urdf"] = _urdf_hash(node)
        return out
    if is_dataclass(node) and not isinstance(node, type):
        return {
            "type": type(node).__name__,
            **{f.name: _value(getattr(node, f.name), source) for f in fields(node) if f.compare},
        }
    if isinstance(node, (tuple, list)):
        return [_value(v, source) for v in node]
    if isinstance(node, float):
        return repr(node)  # exact, and JSON has no inf/nan
    return node


def _urdf_hash(kind: RobotKind) -> str | None:
    if kind.urdf is None:
        return None
    from mrgc.language.loader import urdf_candidates

    base = os.path.dirname(os.path.abspath(kind.source)) if kind.source else os.getcwd()
    for candidate, _ in urdf_candidates(kind.urdf, base):
        if os.path.isfile(candidate):
            return _file_hash(candidate)
    return f"path:{kind.urdf}"


def _file_hash(path: str) -> str:
    try:
        if os.path.getsize(path) > MAX_HASHED:
            return f"path:{os.path.realpath(path)}"
        with open(path, "rb") as fh:
            return "sha256:" + hashlib.sha256(fh.read()).hexdigest()
    except OSError:
        return f"path:{path}"
