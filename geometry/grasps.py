"""Grasps: the one place a grasp's specification becomes frames and a finger opening.

A grasp is a :class:`~mrgc.language.model.GraspSpec` (built in, or declared by the domain): ``approach``,
the axis of the object frame along which the tool moves into the object, ``fingers``, the axis the fingers
close along, ``depth`` and ``offset``.  The conventions (docs/geometry.md, "Grasps", draws them):

- **Tool frame** (the tool centre point, TCP, between the fingertips): +z is the approach direction
  (pointing into the object), +y the finger axis, +x = y × z.
- **Grasp pose**: the TCP sits ``depth`` inside the face it approaches (the fingers wrap that much of the
  object; never past the centre), then moves by ``offset`` (object frame): the tool pose in the object
  frame is :func:`grasp_transform`.
- **Pre-grasp**: the grasp pose backed off by :data:`APPROACH` along the tool's -z
  (:func:`pregrasp_transform`).
- **Finger opening**: the object's width along the finger axis (of its bounding box) plus
  :data:`FINGER_CLEARANCE` (:func:`finger_opening`).  A robot kind whose ``gripper_opening`` is smaller cannot
  use the grasp on that object (:func:`fits`; ``mrgc check`` warns, W270).  An arm's fingers stand at
  that opening while it approaches the object and while it holds it, fully open otherwise (callers pass
  the opening to :meth:`~mrgc.geometry.arm.Arm.link_transforms` / ``ReplayScene.set_fingers``).

Phase 1 (geometry/predicates.py), grounding (geometry/grounding.py) and the validator (validator/replay.py)
read grasps only through this module.  The built-in names' specs are data of the language
(:data:`~mrgc.language.model.BUILTIN_GRASPS`), so the checker knows them without the geometry layer.
"""

from __future__ import annotations

import numpy as np

from mrgc.errors import Diagnostic
from mrgc.geometry.scene import half_extents
from mrgc.language.model import GraspSpec, Problem, RobotKind, Shape

APPROACH = 0.08  # pre-grasp back-off along the approach axis (m)
FINGER_CLEARANCE = 0.01  # the fingers open this much wider than the object (m)


def grasp_transform(spec: GraspSpec, shape: Shape) -> np.ndarray:
    """Tool pose in the object frame for grasp ``spec`` of an object of ``shape``."""
    (y0, y1, y2), (z0, z1, z2) = (float(v) for v in spec.fingers), (float(v) for v in spec.approach)
    z = np.array((z0, z1, z2))
    reach = float(np.abs(z) @ half_extents(shape))  # half extent along the approach axis
    t = np.eye(4)
    t[:3, 0] = (y1 * z2 - y2 * z1, y2 * z0 - y0 * z2, y0 * z1 - y1 * z0)  # x = y × z
    t[:3, 1], t[:3, 2] = (y0, y1, y2), z
    t[:3, 3] = -z * max(reach - min(spec.depth, reach), 0.0) + np.array(spec.offset, dtype=float)
    return t


def pregrasp_transform(grasp_t: np.ndarray, approach: float = APPROACH) -> np.ndarray:
    """The grasp pose backed off by ``approach`` along the tool's -z."""
    back = np.eye(4)
    back[2, 3] = -approach
    return grasp_t @ back


def width(spec: GraspSpec, shape: Shape) -> float:
    """The object's extent along the finger axis (of its bounding box, in its own frame)."""
    return float(2 * np.abs(np.array(spec.fingers, dtype=float)) @ half_extents(shape))


def finger_opening(spec: GraspSpec, shape: Shape) -> float:
    """How far apart the fingers stand for this grasp: the object's width plus :data:`FINGER_CLEARANCE`."""
    return width(spec, shape) + FINGER_CLEARANCE


def fits(spec: GraspSpec, shape: Shape, kind: RobotKind) -> bool:
    """Whether robots of ``kind`` open wide enough for this grasp of an object of ``shape``."""
    return finger_opening(spec, shape) <= kind.gripper_opening + 1e-9


def grasp_warnings(problem: Problem) -> list[Diagnostic]:
    """W270 for each (object, grasp) of a geometric problem that some robot kind of its arms cannot open
    wide enough for (those robots get no facts for it)."""
    if problem.symbolic:
        return []
    kinds = {r.kind for r in problem.robots}
    arms = [k for k in problem.domain.robot_kinds if k.name in kinds and not k.driven]
    specs = problem.grasp_specs
    out = []
    for m in problem.movable:
        if m.shape is None:
            continue
        for g in problem.grasps_of(m.name):
            spec = specs.get(g)
            narrow = [k for k in arms if spec is not None and not fits(spec, m.shape, k)]
            if spec is None or not narrow:
                continue
            w = width(spec, m.shape)
            names = ", ".join(f"'{k.name}' opens {k.gripper_opening:g} m" for k in narrow)
            out.append(
                Diagnostic(
                    "W270",
                    f"grasp '{g}' of '{m.name}' needs the fingers {w + FINGER_CLEARANCE:g} m apart ({w:g} m "
                    f"wide + {FINGER_CLEARANCE:g} m clearance), but robot kind {names}: no facts for it",
                    m.span,
                    severity="warning",
                )
            )
    return out
