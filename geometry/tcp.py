"""The tool centre point of a robot kind that does not state one (``:tcp`` absent): derived from its URDF.

An arm grasps with its tool centre point (TCP), the point between the fingertips, given relative to the
end-effector link.  A kind without ``:tcp`` gets one from its URDF, tried in this order
(docs/language.md, "Robot kinds"):

1. **a grasp-target link**: a link fixed to the end-effector link (through fixed joints only) whose name
   says it is the grasp point: it ends (case and ``_``/``-`` ignored) in ``grasptarget``, ``grasppoint``,
   ``graspframe``, ``tcp`` or ``toolcenterpoint`` (pybullet_data's Franka Panda has ``panda_grasptarget``,
   0.105 m along the hand's z axis: exactly the shipped domain's ``:tcp (0 0 0.105 0)``).  Its origin is
   the TCP; its rotation must be a turn about z (a ``:tcp`` is a pose with a yaw), else it is not used;
2. **the fingertips**: the gripper's fingertip links (:attr:`~mrgc.geometry.kinematics.RobotModel.fingertips`:
   the links the gripper's joints move, prismatic fingers or a revolute linkage with mimic joints, that
   reach farthest along the end-effector link's +z), fully open; when their collision geometry lies along
   that axis (the approach direction of every built-in grasp, docs/geometry.md), the TCP is the middle
   between the fingers (the mean of their frames' x and y) at the far end of their collision geometry
   along z (the fingertips).

A kind for which neither works (no such link, no fingers, fingers that do not point along +z) keeps the
end-effector link's origin as its TCP, and ``mrgc check`` warns (W273): grasps would put the link's
origin, not the fingers, on the object.  ``mrgc check`` prints the derived value as a note with its source.
:func:`mrgc.geometry.scene.scene_from_problem` puts the derived value into the scene's robot kinds, so the
planner, the validator and the pictures all use the same TCP.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass

import numpy as np

from mrgc.errors import InputError
from mrgc.language.model import Pose, RobotKind

__all__ = ["DerivedTcp", "GRASP_TARGET_SUFFIXES", "derive_tcp", "kind_base_dir", "with_tcp"]

#: a link whose name (lower case, ``_`` and ``-`` dropped) ends in one of these is a grasp-target link
GRASP_TARGET_SUFFIXES = ("grasptarget", "grasppoint", "graspframe", "toolcenterpoint", "tcp")


@dataclass(frozen=True)
class DerivedTcp:
    """A TCP derived from a URDF: the pose (relative to the end-effector link) and where it came from
    (``link 'panda_grasptarget'``, ``fingertips 'l', 'r'``), and the URDF's path."""

    pose: Pose
    source: str
    urdf: str

    def text(self) -> str:
        """The pose as a ``:tcp`` value is written: ``(x y z yaw)``, millimetres rounded."""
        p = self.pose
        return "(" + " ".join(_num(v) for v in (p.x, p.y, p.z, p.yaw)) + ")"


def _num(v: float) -> str:
    r = round(v, 4)
    return "0" if r == 0 else f"{r:g}"


def kind_base_dir(kind: RobotKind) -> str:
    """The folder a kind's URDF is relative to (the declaring file's)."""
    return os.path.dirname(os.path.abspath(kind.source)) if kind.source else os.getcwd()


def derive_tcp(kind: RobotKind) -> DerivedTcp | None:
    """The TCP of ``kind`` derived from its URDF (module docstring), or None when it cannot be derived or
    the kind is not an arm (planar, or no ``:urdf``/``:end-effector``).  A URDF that cannot be found or
    read gives None too: the commands that load it report that (E400/E401)."""
    if kind.driven or kind.urdf is None or kind.end_effector is None:
        return None
    from mrgc.geometry.kinematics import resolve_urdf

    try:
        path = resolve_urdf(kind.urdf, kind_base_dir(kind), kind.span, kind.roots)
    except InputError:
        return None
    return _derive(path, kind.end_effector, kind.roots)


@functools.lru_cache(maxsize=64)
def _derive(path: str, end_effector: str, roots: tuple[str, ...]) -> DerivedTcp | None:
    from mrgc.geometry.urdf import parse_urdf

    try:
        urdf = parse_urdf(path)
    except InputError:
        return None
    if end_effector not in urdf.order:
        return None
    found = _grasp_target(urdf, end_effector)
    if found is not None:
        return DerivedTcp(found[1], f"link '{found[0]}'", path)
    return _fingertips(path, end_effector, roots)


def _grasp_target(urdf: object, end_effector: str) -> tuple[str, Pose] | None:
    """The first grasp-target link (URDF order) fixed to ``end_effector``, and its pose in its frame."""
    from mrgc.geometry.urdf import Urdf

    assert isinstance(urdf, Urdf)
    for name in urdf.order:
        key = name.lower().replace("_", "").replace("-", "")
        if name == end_effector or not key.endswith(GRASP_TARGET_SUFFIXES):
            continue
        t = np.eye(4)
        k = name
        while k != end_effector and k in urdf.joint_of and urdf.joint_of[k].kind == "fixed":
            t = urdf.joint_of[k].origin @ t
            k = urdf.joint_of[k].parent
        if k == end_effector:
            pose = _yaw_pose(t)
            if pose is not None:
                return name, pose
    return None


def _yaw_pose(t: np.ndarray) -> Pose | None:
    """``t`` as a pose (x y z yaw) when its rotation is a turn about z, else None."""
    r = t[:3, :3]
    if abs(r[2, 2] - 1.0) > 1e-6:
        return None
    yaw = float(np.degrees(np.arctan2(r[1, 0], r[0, 0])))
    x, y, z = (round(float(v), 9) + 0.0 for v in t[:3, 3])
    return Pose(x, y, z, round(yaw, 9) + 0.0)


def _fingertips(path: str, end_effector: str, roots: tuple[str, ...]) -> DerivedTcp | None:
    """The middle between the fully open fingers at their tips along the end-effector's +z (docstring)."""
    from mrgc.geometry.kinematics import load_robot_model

    try:
        model = load_robot_model(path, os.path.dirname(path), end_effector, roots=roots)
    except InputError:
        return None
    from mrgc.geometry.kinematics import gripper_frames

    frames = gripper_frames(model)  # the gripper open
    fingers = [model.links[k] for k in model.fingertips]
    if len(fingers) < 2:
        return None
    points = np.concatenate([(frames[f.index][:3, :3] @ f.points.T).T + frames[f.index][:3, 3] for f in fingers])
    axes = [frames[f.index][:3, :3] @ f.axis for f in fingers if f.finger]
    if np.min(points[:, 2]) < -1e-9 or any(abs(float(a[2])) > 1e-6 for a in axes):
        return None  # not fingers closing across the end effector's +z axis
    middle = np.mean([frames[f.index][:3, 3] for f in fingers], axis=0)
    tip = float(np.max(points[:, 2]))
    names = ", ".join(f"'{f.name}'" for f in fingers)
    pose = Pose(round(float(middle[0]), 9) + 0.0, round(float(middle[1]), 9) + 0.0, round(tip, 9), 0.0)
    return DerivedTcp(pose, f"fingertips of {names}", path)


def with_tcp(kind: RobotKind) -> RobotKind:
    """``kind`` with its ``:tcp`` derived when it has none and one can be (else ``kind`` itself)."""
    if kind.tcp is not None:
        return kind
    derived = derive_tcp(kind)
    if derived is None:
        return kind
    from dataclasses import replace

    return replace(kind, tcp=derived.pose)
