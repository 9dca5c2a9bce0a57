"""Robot models: a URDF read once into plain, picklable kinematic and collision data.

A :class:`RobotModel` holds everything the rest of the geometry layer needs about a robot without touching
pybullet again: the chain of movable joints from the base link to the end-effector link, every link with
its collision geometry (mesh vertices read from the files), and the fixed transforms of links hanging off
the chain (a Panda's hand and fingers).  Forward kinematics (:mod:`mrgc.geometry.fk`) and inverse
kinematics (:mod:`mrgc.geometry.ik`) are numpy on this data.

The URDF's joints and collisions are read with the standard library's XML parser (pybullet reports joint
frames relative to centres of mass, with their rotations inverted); pybullet loads every URDF too, as a
validity check and as the reference.  pybullet itself lives in :mod:`mrgc.geometry.bullet` (the only module
that imports it); its forward and inverse kinematics and distance references, which tests and benchmarks
compare this module's models against, are :mod:`mrgc.testing.pybullet_reference`.

Frames: a link's frame is its URDF link frame (pybullet's ``worldLinkFrame``, not its centre of mass); a
movable joint's frame is its child link's frame.  Off-chain movable joints are frozen at
:attr:`Link.frozen_value`: a prismatic one at its upper limit (gripper open), a revolute one at 0 clamped
into its limits, a ``<mimic>`` one at ``multiplier * value + offset`` of the joint it mimics (clamped).

**The gripper** is the off-chain movable joints below the end-effector link (:attr:`Link.finger`): a
Panda's two prismatic fingers, an xArm's revolute knuckles and fingers (a parallel linkage whose joints but
one mimic that one).  Forward kinematics sets them from one *drive value* (:meth:`RobotModel.finger_value`
turns a finger opening into it): every gripper joint that mimics none takes it, every mimic joint follows
its URDF rule (:meth:`RobotModel.gripper_value`).  Prismatic fingers each travel half the opening (a Panda
finger joint is opening / 2); a revolute gripper's opening is measured: the gap between its two fingertips
(:attr:`RobotModel.fingertips`, the gripper links reaching farthest along the end effector's +z) across the
closing direction, tabulated over the drive joint's range and inverted (:attr:`RobotModel.opening_table`);
such a gripper is frozen open at the drive value of the widest gap.

**The mount** (:attr:`RobotModel.mount`): the root link and every link fixed to it through fixed joints
(a Panda's ``panda_link0``; an xArm's dummy root ``world`` and ``link_base``) stand on what the robot is
bolted to: they never move, and they are exempt from collisions with the surface under them (they are
left out of an arm's collision probes and are obstacles to the other arms), whatever they are called.
"""

from __future__ import annotations

import functools
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import Iterator

import numpy as np

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.geometry.bullet import check_urdf, data_path
from mrgc.geometry.meshes import checked_vertices, read_mesh
from mrgc.geometry.urdf import MAX_LENGTH, Urdf, UrdfError, mesh_path, parse_urdf, scalar, urdf_error, vec
from mrgc.geometry.urdf import origin as urdf_origin
from mrgc.language.model import RobotKind

__all__ = [
    "E_LINK",
    "E_URDF",
    "Collision",
    "Joint",
    "Link",
    "RobotModel",
    "gripper_frames",
    "load_robot_model",
    "model_for_kind",
    "read_mesh",
    "resolve_urdf",
]

#: code of "robot URDF not found or unreadable" and of "end-effector link not in the URDF"
E_URDF = "E400"
E_LINK = "E401"


# ----------------------------------------------------------------------------------------------- data


@dataclass(frozen=True, eq=False)
class Collision:
    """One collision shape of a link.

    ``kind`` is ``mesh``, ``box``, ``sphere``, ``cylinder``, ``capsule`` or ``plane``; ``origin`` maps the
    shape's frame to its link's frame.  ``size``: box full side lengths (sx, sy, sz); sphere (radius,);
    cylinder and capsule (radius, length along z); mesh its scale (sx, sy, sz).  ``vertices`` (V, 3) are in
    the shape frame, scaled (for primitives, points on the surface: a box's 8 corners, 16-gons for round
    shapes); ``faces`` (F, 3) index triangles of a mesh (empty for primitives).
    """

    kind: str
    origin: np.ndarray
    size: tuple[float, ...]
    mesh_path: str | None
    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True, eq=False)
class Link:
    """A link and the joint that attaches it to its parent link.

    ``origin`` maps the joint frame at joint value 0 (= this link's frame) into the parent link's frame;
    ``axis`` is the unit joint axis in the joint frame.  ``joint_kind`` is ``base`` (the root, ``parent``
    -1), ``fixed``, ``revolute`` or ``prismatic``.  ``chain_index`` is the joint's position in the
    configuration vector, or -1 when the joint is not on the base→end-effector chain; such a movable joint
    is frozen at ``frozen_value``.  ``points`` (P, 3) are all collision vertices in the link frame.
    ``lower`` and ``upper`` are the joint's limits (0 for fixed joints and the base).
    """

    name: str
    index: int
    parent: int
    joint: str | None
    joint_kind: str
    origin: np.ndarray
    axis: np.ndarray
    chain_index: int
    frozen_value: float
    collisions: tuple[Collision, ...]
    points: np.ndarray
    lower: float = 0.0
    upper: float = 0.0
    #: the index of the link whose joint this link's joint mimics (``<mimic>``), -1 when it mimics none
    mimic: int = -1
    multiplier: float = 1.0
    offset: float = 0.0
    #: an off-chain movable joint below the end-effector link: a joint of the gripper
    gripper: bool = False

    @property
    def finger(self) -> bool:
        """A joint of the gripper (off the chain, movable, below the end-effector link): the finger opening
        drives it (:meth:`RobotModel.gripper_value`)."""
        return self.gripper

    @property
    def solid(self) -> bool:
        """The link has collision geometry (at least 4 points: a volume, whose hull the collision checks use)."""
        return len(self.points) >= 4


@dataclass(frozen=True, eq=False)
class Joint:
    """A movable joint of the chain.  ``origin``: parent link frame → joint frame at 0 (the URDF origin);
    ``pre``: frame of the previous chain joint (or the base link) → this joint's frame at 0, folding in any
    fixed joints between them.  ``link`` is the index of the child link in :attr:`RobotModel.links`."""

    name: str
    kind: str
    axis: np.ndarray
    origin: np.ndarray
    pre: np.ndarray
    lower: float
    upper: float
    max_velocity: float
    link: int
    continuous: bool = False


@dataclass(frozen=True, eq=False)
class RobotModel:
    """A robot read from a URDF: chain, links, limits, end effector and a reach bound; plain data.

    ``key`` identifies the model across processes (resolved URDF path and end-effector link).  Links are in
    topological order (a parent before its children), ``links[0]`` is the base link.  ``ee_offset`` maps
    the end-effector link's frame into the frame of the last chain joint.  ``shoulder`` (base frame) and
    ``reach`` bound the workspace: every end-effector position lies within ``reach`` of ``shoulder``.
    """

    key: str
    urdf: str
    name: str
    end_effector: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    ee_link: int
    ee_offset: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    shoulder: np.ndarray
    reach: float
    #: a revolute gripper's drive values (ascending) and the fingertip gap (m) at each; None: prismatic
    #: fingers (each travels half the opening) or no gripper
    opening_table: tuple[np.ndarray, np.ndarray] | None = None
    #: the gripper links whose tips reach farthest along the end effector's +z (module docstring)
    fingertips: tuple[int, ...] = ()

    @property
    def dof(self) -> int:
        """The number of joints of the chain (the configuration's length)."""
        return len(self.joints)

    @property
    def link_names(self) -> tuple[str, ...]:
        """Every link's name, by index."""
        return tuple(link.name for link in self.links)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The chain's joints' names, in configuration order."""
        return tuple(j.name for j in self.joints)

    @functools.cached_property
    def self_collision_pairs(self) -> tuple[tuple[int, int], ...]:
        """The pairs of links (indices ``a < b``) an arm must keep apart from each other: both links
        :attr:`~Link.solid`, and the path between them in the URDF's tree passes through more than one joint
        of the configuration chain (:attr:`Link.chain_index` >= 0).  Fixed joints and off-chain joints (a
        Panda's fingers) do not count, so links bolted together (link7, link8, hand), the gripper (hand and
        both fingers) and a link and its neighbours across one chain joint (link6 and link7, the hand and the
        fingers; link0 and link1) are exempt: they touch by construction.  Derived once per model
        (docs/geometry.md, "Self-collision"); the validator derives the same rule from the URDF in pybullet."""
        solid = [link.index for link in self.links if link.solid]
        pairs = []
        for i, a in enumerate(solid):
            for b in solid[i + 1 :]:
                if self.chain_joints_between(a, b) > 1:
                    pairs.append((a, b))
        return tuple(pairs)

    def chain_joints_between(self, a: int, b: int) -> int:
        """How many joints of the configuration chain the tree path between links ``a`` and ``b`` passes
        through (the joints attaching the links of the path, below their common ancestor, to their parents)."""
        up_a, up_b = self._ancestry(a), self._ancestry(b)
        common = next(k for k in up_a if k in up_b)
        path = up_a[: up_a.index(common)] + up_b[: up_b.index(common)]
        return sum(1 for k in path if self.links[k].chain_index >= 0)

    def _ancestry(self, k: int) -> list[int]:
        """Link ``k`` and its ancestors up to the base link, ``k`` first."""
        out = [k]
        while self.links[k].parent >= 0:
            k = self.links[k].parent
            out.append(k)
        return out

    def link_index(self, name: str) -> int:
        """The index of the link called ``name``."""
        for link in self.links:
            if link.name == name:
                return link.index
        raise KeyError(name)

    @functools.cached_property
    def mount(self) -> tuple[int, ...]:
        """The root link and every link attached to it through fixed joints only (module docstring): the
        links standing on what the robot is bolted to, exempt from collisions with it."""
        out = [0]
        for link in self.links[1:]:
            if link.joint_kind == "fixed" and link.parent in out:
                out.append(link.index)
        return tuple(out)

    def finger_value(self, opening: float) -> float:
        """The drive value that opens the gripper ``opening`` metres: prismatic fingers each travel half of
        it; a revolute gripper's from :attr:`opening_table` (an opening beyond its range: the nearest end).
        Forward kinematics clamps it into each gripper joint's limits."""
        if self.opening_table is None:
            return opening / 2
        values, gaps = self.opening_table
        order = np.argsort(gaps, kind="stable")
        return float(np.interp(opening, gaps[order], values[order]))

    def gripper_value(self, k: int, drive: float) -> float:
        """The value of gripper link ``k``'s joint when the gripper's drive value is ``drive``: the drive
        itself for a joint that mimics none, ``multiplier * value + offset`` of the mimicked joint for the
        others (its URDF ``<mimic>``), clamped into the joint's limits."""
        link = self.links[k]
        v = drive if link.mimic < 0 else link.multiplier * self.gripper_value(link.mimic, drive) + link.offset
        return float(min(max(v, link.lower), link.upper))

    def clamp(self, q: np.ndarray) -> np.ndarray:
        """``q`` clipped into the joint limits."""
        clipped: np.ndarray = np.clip(q, self.lower, self.upper)
        return clipped

    def within_limits(self, q: np.ndarray, eps: float = 1e-9) -> np.ndarray:
        """Whether each configuration of ``q`` (..., dof) respects the limits."""
        q = np.asarray(q)
        inside: np.ndarray = np.all((q >= self.lower - eps) & (q <= self.upper + eps), axis=-1)
        return inside

    def __repr__(self) -> str:
        return f"RobotModel({self.name!r}, ee={self.end_effector!r}, dof={self.dof}, links={len(self.links)})"


# ----------------------------------------------------------------------------------------- loading


def resolve_urdf(urdf: str, base_dir: str, span: Span | None = None, roots: tuple[str, ...] = ()) -> str:
    """The real path of ``urdf``: relative to ``base_dir`` (the declaring .mrg file's folder) if it exists
    there, else relative to pybullet_data (never the current folder); InputError E400 when neither exists,
    E236 when ``roots`` is given and the file found is outside them and pybullet_data."""
    from mrgc.language.loader import inside, urdf_candidates

    candidates = [c for c, _ in urdf_candidates(urdf, base_dir)]
    for c in candidates:
        if os.path.isfile(c):
            real = os.path.realpath(c)
            if roots and not inside(real, roots + (os.path.realpath(data_path()),)):
                raise InputError(
                    [
                        Diagnostic(
                            "E236",
                            f"robot URDF {urdf!r} is outside the folder tree of the "
                            f"problem and pybullet_data; pass --allow-outside FOLDER to allow it",
                            span,
                        )
                    ]
                )
            return real
    looked = " or ".join(repr(c) for c in candidates)
    raise InputError([Diagnostic(E_URDF, f"robot URDF {urdf!r} not found (looked for {looked})", span)])


def load_robot_model(
    urdf: str, base_dir: str, end_effector: str, *, span: Span | None = None, roots: tuple[str, ...] = ()
) -> RobotModel:
    """Read the robot of ``urdf`` (resolved by :func:`resolve_urdf`) with ``end_effector`` as its tool link.

    Raises :class:`~mrgc.errors.InputError` with E400 when the URDF is missing, malformed (located at its
    line, see :mod:`mrgc.geometry.urdf`) or refused by pybullet, E401 when it has no link named
    ``end_effector``, E403 for a bad mesh file, E236 for a file outside ``roots`` (when given).  Cached per
    (resolved path, end effector, roots).
    """
    path = resolve_urdf(urdf, base_dir, span, roots)
    note = f"robot kind declared at {span}" if span is not None else None
    try:
        names = parse_urdf(path).order
        model = _build_model(path, end_effector, tuple(roots)) if end_effector in names else None
    except InputError as exc:
        if note is not None:
            exc.diagnostics = tuple(replace(d, notes=d.notes + (note,)) for d in exc.diagnostics)
        raise
    refused = check_urdf(path)  # pybullet must accept the file too: it is the reference and replays plans
    if refused is not None:
        raise InputError([Diagnostic(E_URDF, f"pybullet cannot load robot URDF {path!r}: {refused}", span)])
    if model is None:
        raise InputError(
            [
                Diagnostic(
                    E_LINK,
                    f"end-effector link {end_effector!r} is not a link of {path!r} (links: {', '.join(names)})",
                    span,
                )
            ]
        )
    return model


def model_for_kind(kind: RobotKind, base_dir: str) -> RobotModel:
    """The model of a robot kind of a geometric domain (``base_dir``: folder of the file declaring it;
    the kind's ``roots`` confine its URDF and meshes)."""
    if kind.urdf is None or kind.end_effector is None:
        what = ":urdf" if kind.urdf is None else ":end-effector"
        raise InputError([Diagnostic(E_URDF, f"robot kind {kind.name!r} has no {what}", kind.span)])
    return load_robot_model(kind.urdf, base_dir, kind.end_effector, span=kind.span, roots=kind.roots)


# The URDF itself is read with the standard library (geometry/urdf.py) rather than through pybullet's
# getJointInfo, whose parentFrameOrn is expressed in the parent's centre-of-mass frame and comes back with
# the rotation inverted (bullet3 issues #3253, #4231); pybullet still loads every file, as the reference and
# as a validity check.


@functools.lru_cache(maxsize=None)
def _build_model(path: str, end_effector: str, roots: tuple[str, ...] = ()) -> RobotModel:
    urdf = parse_urdf(path)
    index = {name: i for i, name in enumerate(urdf.order)}
    ee = index[end_effector]
    chain_names: list[str] = []
    k_name = end_effector
    while k_name in urdf.joint_of:
        j = urdf.joint_of[k_name]
        if j.kind in ("revolute", "continuous", "prismatic"):
            chain_names.append(k_name)
        elif j.kind != "fixed":
            raise urdf_error(
                path,
                f"joint {j.name!r} between the base and {end_effector!r} is {j.kind}, "
                f"not revolute, continuous, prismatic or fixed",
                j.line,
            )
        k_name = j.parent
    chain_names.reverse()

    links: list[Link] = []
    for k, name in enumerate(urdf.order):
        uj = urdf.joint_of.get(name)
        if uj is None:
            kind, origin, axis, parent, jname, lo, hi = "base", np.eye(4), np.zeros(3), -1, None, 0.0, 0.0
        else:
            kind = {"continuous": "revolute"}.get(uj.kind, uj.kind)
            if kind not in ("revolute", "prismatic"):
                kind = "fixed"  # off-chain floating/planar joints are frozen at zero
            origin, axis, parent, jname, lo, hi = uj.origin, uj.axis, index[uj.parent], uj.name, uj.lower, uj.upper
        chain_index = chain_names.index(name) if name in chain_names else -1
        frozen = 0.0
        if chain_index < 0 and kind == "prismatic":
            frozen = hi  # a gripper finger: open
        elif chain_index < 0 and kind == "revolute":
            frozen = float(min(max(0.0, lo), hi))
        collisions = tuple(_collisions(urdf, urdf.links[name], roots))
        pts = [(c.origin[:3, :3] @ c.vertices.T).T + c.origin[:3, 3] for c in collisions if len(c.vertices)]
        links.append(
            Link(
                name=name,
                index=k,
                parent=parent,
                joint=jname,
                joint_kind=kind,
                origin=_ro(origin),
                axis=_ro(axis),
                chain_index=chain_index,
                frozen_value=frozen,
                collisions=collisions,
                points=_ro(np.concatenate(pts) if pts else np.zeros((0, 3))),
                lower=float(lo),
                upper=float(hi),
            )
        )

    links, table, tips = _gripper(urdf, links, ee)
    joints: list[Joint] = []
    prev = 0  # frame of the previous chain joint (its child link) or the base link
    for name in chain_names:
        k = index[name]
        j = urdf.joint_of[name]
        pre = _fixed_between(links, prev, links[k].parent) @ links[k].origin
        joints.append(
            Joint(
                name=j.name,
                kind=links[k].joint_kind,
                axis=links[k].axis,
                origin=links[k].origin,
                pre=_ro(pre),
                lower=j.lower,
                upper=j.upper,
                max_velocity=j.velocity,
                link=k,
                continuous=j.kind == "continuous",
            )
        )
        prev = k
    ee_offset = _fixed_between(links, prev, ee)
    shoulder, reach = _reach_bound(joints, ee_offset)
    return RobotModel(
        key=f"{path}#{end_effector}",
        urdf=path,
        name=urdf.name,
        end_effector=end_effector,
        links=tuple(links),
        joints=tuple(joints),
        ee_link=ee,
        ee_offset=_ro(ee_offset),
        lower=_ro(np.array([j.lower for j in joints])),
        upper=_ro(np.array([j.upper for j in joints])),
        max_velocity=_ro(np.array([j.max_velocity for j in joints])),
        shoulder=_ro(shoulder),
        reach=reach,
        opening_table=table,
        fingertips=tips,
    )


def _gripper(
    urdf: Urdf, links: list[Link], ee: int
) -> tuple[list[Link], tuple[np.ndarray, np.ndarray] | None, tuple[int, ...]]:
    """The links with their mimic rules, gripper flags and frozen values set (module docstring), a revolute
    gripper's opening table and the fingertip links."""
    by_joint = {link.joint: link.index for link in links if link.joint is not None}
    below = {ee}
    for link in links:  # parents first: the links below the end effector
        if link.parent in below:
            below.add(link.index)
    out = list(links)
    for link in links:
        uj = urdf.joint_of.get(link.name)
        movable_off_chain = link.chain_index < 0 and link.joint_kind in ("revolute", "prismatic")
        src = by_joint.get(uj.mimic[0], -1) if uj is not None and uj.mimic is not None else -1
        if not movable_off_chain or src < 0 or links[src].chain_index >= 0 or src == link.index:
            src = -1  # a mimic of a chain joint (or of nothing known) stays frozen on its own
        out[link.index] = replace(
            link,
            mimic=src,
            multiplier=uj.mimic[1] if src >= 0 and uj is not None and uj.mimic else 1.0,
            offset=uj.mimic[2] if src >= 0 and uj is not None and uj.mimic else 0.0,
            gripper=movable_off_chain and link.index in below and link.index != ee,
        )
    for link in out:  # break mimic cycles: a joint whose mimic chain comes back to it mimics none
        seen, k = {link.index}, link.mimic
        while k >= 0 and k not in seen:
            seen.add(k)
            k = out[k].mimic
        if k >= 0:
            out[link.index] = replace(out[link.index], mimic=-1)
    tips = _fingertips(out, ee)
    table = (
        _opening_table(out, ee, tips)
        if any(link.gripper and link.mimic < 0 and link.joint_kind == "revolute" for link in out)
        else None
    )
    drive_open = float(table[0][int(np.argmax(table[1]))]) if table is not None else None
    for link in out:
        if link.chain_index >= 0 or link.joint_kind not in ("revolute", "prismatic"):
            continue
        if link.mimic >= 0:
            value = _frozen_mimic(out, link.index, drive_open)
        elif link.gripper and drive_open is not None:
            value = min(max(drive_open, link.lower), link.upper)
        else:
            value = link.frozen_value
        out[link.index] = replace(link, frozen_value=float(value))
    return out, table, tips


def _frozen_mimic(links: list[Link], k: int, drive_open: float | None) -> float:
    """The frozen value of a mimic joint: its rule applied to the frozen value of the joint it mimics."""
    link = links[k]
    if link.mimic < 0:
        v = drive_open if link.gripper and drive_open is not None else link.frozen_value
    else:
        v = link.multiplier * _frozen_mimic(links, link.mimic, drive_open) + link.offset
    return float(min(max(v, link.lower), link.upper))


def _gripper_frames(links: list[Link], ee: int, drive: float | None) -> dict[int, np.ndarray]:
    """The frames of the links below ``ee`` in its frame, the gripper at ``drive`` (None: frozen values)."""
    frames: dict[int, np.ndarray] = {ee: np.eye(4)}
    for link in links:  # parents first
        if link.parent in frames and link.index not in frames:
            value = link.frozen_value if drive is None or not link.gripper else _gripper_at(links, link.index, drive)
            frames[link.index] = frames[link.parent] @ _joint_local(link, value)
    return frames


def _gripper_at(links: list[Link], k: int, drive: float) -> float:
    link = links[k]
    v = drive if link.mimic < 0 else link.multiplier * _gripper_at(links, link.mimic, drive) + link.offset
    return float(min(max(v, link.lower), link.upper))


def _joint_local(link: Link, value: float) -> np.ndarray:
    """The transform parent link → ``link`` with its joint at ``value`` (Rodrigues about its axis)."""
    if link.joint_kind == "prismatic":
        move = np.eye(4)
        move[:3, 3] = link.axis * value
        return link.origin @ move
    if link.joint_kind != "revolute" or value == 0.0:
        return link.origin
    x, y, z = link.axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    turn = np.eye(4)
    turn[:3, :3] = np.eye(3) + math.sin(value) * k + (1 - math.cos(value)) * (k @ k)
    return link.origin @ turn


def _moved_by_gripper(links: list[Link], ee: int, k: int) -> bool:
    while k != ee and k >= 0:
        if links[k].gripper:
            return True
        k = links[k].parent
    return False


def _fingertips(links: list[Link], ee: int) -> tuple[int, ...]:
    """The solid links the gripper moves whose geometry reaches within 5 mm of the farthest any of them
    reaches along the end effector's +z, the gripper open (frozen values)."""
    frames = _gripper_frames(links, ee, None)
    moved = [k for k in frames if k != ee and links[k].solid and _moved_by_gripper(links, ee, k)]
    if not moved:
        return ()
    reach = {k: float(np.max((frames[k][:3, :3] @ links[k].points.T)[2] + frames[k][2, 3])) for k in moved}
    top = max(reach.values())
    return tuple(sorted(k for k in moved if reach[k] >= top - 0.005))


def _opening_table(
    links: list[Link], ee: int, tips: tuple[int, ...], samples: int = 49
) -> tuple[np.ndarray, np.ndarray] | None:
    """A revolute gripper's fingertip gap over its drive joint's range (module docstring); None when its
    fingertips are not two sides of a gap."""
    drive = next(link for link in links if link.gripper and link.mimic < 0 and link.joint_kind == "revolute")
    if len(tips) < 2:
        return None
    values = np.linspace(drive.lower, drive.upper, samples)
    frames = _gripper_frames(links, ee, float(values[0]))
    centres = np.array([frames[k][:3, :3] @ links[k].points.mean(axis=0) + frames[k][:3, 3] for k in tips])
    axis = centres[0] - centres[-1]
    axis[2] = 0.0
    if float(np.linalg.norm(axis)) < 1e-6:
        return None
    axis /= np.linalg.norm(axis)
    side = (centres - centres.mean(axis=0)) @ axis > 0
    gaps = []
    for v in values:
        frames = _gripper_frames(links, ee, float(v))
        across = [(frames[k][:3, :3] @ links[k].points.T).T @ axis + frames[k][:3, 3] @ axis for k in tips]
        gaps.append(
            min(float(a.min()) for a, s in zip(across, side) if s)
            - max(float(a.max()) for a, s in zip(across, side) if not s)
        )
    return _ro(values), _ro(np.maximum(np.array(gaps), 0.0))


def gripper_frames(model: RobotModel, drive: float | None = None) -> dict[int, np.ndarray]:
    """The frames of the links below the end-effector link, in its frame, by link index (the end effector
    itself included): the gripper at drive value ``drive`` (:meth:`RobotModel.finger_value`), or open
    (frozen values) when None."""
    return _gripper_frames(list(model.links), model.ee_link, drive)


def _fixed_between(links: list[Link], ancestor: int, k: int) -> np.ndarray:
    """Transform from link ``ancestor``'s frame to link ``k``'s, through fixed joints only."""
    t = np.eye(4)
    while k != ancestor:
        t = links[k].origin @ t
        k = links[k].parent
    return t


def _reach_bound(joints: list[Joint], ee_offset: np.ndarray) -> tuple[np.ndarray, float]:
    """A point fixed in the base frame and a radius around it that contains every end-effector position.

    The shoulder is the first chain joint's origin (a revolute joint's origin lies on its axis, so it does
    not move); the radius sums the lengths of the translations after it (triangle inequality) plus the
    travel of prismatic joints.
    """
    if not joints:
        return ee_offset[:3, 3].copy(), 0.0
    shoulder = joints[0].pre[:3, 3].copy()
    reach = sum(float(np.linalg.norm(j.pre[:3, 3])) for j in joints[1:]) + float(np.linalg.norm(ee_offset[:3, 3]))
    reach += sum(max(abs(j.lower), abs(j.upper)) for j in joints if j.kind == "prismatic")
    return shoulder, reach


def _ro(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


# ------------------------------------------------------------------------------ collision geometry


def _collisions(urdf: Urdf, link: ET.Element, roots: tuple[str, ...]) -> Iterator[Collision]:
    data = os.path.realpath(data_path()) if roots else None
    for col in link.findall("collision"):
        geom = col.find("geometry")
        shape = geom[0] if geom is not None and len(geom) else None
        if shape is None:
            continue
        line = urdf.line(shape)
        try:
            org = col.find("origin")
            origin = _ro(urdf_origin(org, urdf.line(org) if org is not None else urdf.line(col)))
            faces = np.zeros((0, 3), dtype=np.int64)
            mesh_file = None
            if shape.tag == "mesh":
                size = vec(shape.get("scale"), (1.0, 1.0, 1.0), line, MAX_LENGTH, "mesh scale")
                mesh_file = mesh_path(shape.get("filename", ""), urdf.path, line, roots, data)
                _, faces = read_mesh(mesh_file)
                verts = checked_vertices(mesh_file, size)
            elif shape.tag == "box":
                size = vec(shape.get("size"), (0.0, 0.0, 0.0), line, MAX_LENGTH, "box size")
                verts = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]) * size
            elif shape.tag == "sphere":
                size = (scalar(shape.get("radius"), 0.0, line, "radius", MAX_LENGTH),)
                verts = _sphere_points(size[0])
            elif shape.tag in ("cylinder", "capsule"):
                size = (
                    scalar(shape.get("radius"), 0.0, line, "radius", MAX_LENGTH),
                    scalar(shape.get("length"), 0.0, line, "length", MAX_LENGTH),
                )
                verts = _ring_points(size[0], size[1], capsule=shape.tag == "capsule")
            else:  # planes and unknown shapes carry no points
                size, verts = (), np.zeros((0, 3))
        except UrdfError as exc:
            raise urdf_error(urdf.path, str(exc), exc.line) from None
        yield Collision(
            kind=shape.tag, origin=origin, size=tuple(size), mesh_path=mesh_file, vertices=_ro(verts), faces=faces
        )


def _ring_points(radius: float, length: float, capsule: bool, segments: int = 16) -> np.ndarray:
    a = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)
    pts = [np.column_stack([ring, np.full(segments, z)]) for z in (-length / 2, length / 2)]
    if capsule:
        pts.append(np.array([[0.0, 0.0, -length / 2 - radius], [0.0, 0.0, length / 2 + radius]]))
    return np.concatenate(pts)


def _sphere_points(radius: float) -> np.ndarray:
    d = np.array(
        [[x, y, z] for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1) if (x, y, z) != (0, 0, 0)], dtype=float
    )
    points: np.ndarray = radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    return points
