"""Bounds of a phase's pairs without pybullet's distance queries: lower bounds on distances, motion rates.

Every robot link is held by a sphere about its centre of mass
(:attr:`~mrgc.validator.bounds.ArmBounds.spheres`), a planar robot's footprint and a carried object
by one about its frame, every object that stands still in the phase by its bounding box; two spheres are at
least the distance of their centres less both radii apart, a sphere and a box the distance of the centre
from the box less the radius.

:class:`Spheres` reads the positions from pybullet at the state the world is set to (the sweep's
:attr:`~mrgc.validator.sweep.Sweep.bound`); :class:`PhaseBounds` computes them for many times at once with
the validator's numpy kinematics (:mod:`mrgc.validator.fk`), and with them each element's motion
rate at those times (its points' largest distance from each joint's axis, from its motion spheres, at most
its global rate), for the certifier (:mod:`mrgc.validator.certify`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from mrgc.geometry.conventions import wrap_angle
from mrgc.geometry.scene import half_extents
from mrgc.language.model import Box, Shape
from mrgc.validator.fk import SPHERE_PAD, ArmChain, axis_reach, centres, pack
from mrgc.validator.sweep import Pair

if TYPE_CHECKING:
    from mrgc.validator.world import ReplayScene

FK_PAD = 1e-5  # m: the numpy kinematics against pybullet's single-precision frames (measured 3e-7)


class Spheres:
    """Lower bounds on the distances of a phase's sub-pairs (module docstring), positions read from pybullet
    at the world's current state (:meth:`__call__`).  ``ph``: the replay's phase world (its parts, tracks,
    objects); ``pairs`` and ``sides``: the sweep's pairs and their two parts."""

    def __init__(self, ph: Any, pairs: list[Pair], sides: list[tuple[Any, Any, Any, str]]) -> None:
        rp, rs = ph.rp, ph.rp.rs
        self.rs: ReplayScene = rs
        index: dict[tuple[str, int], int] = {}
        radius: list[float] = []
        half: list[np.ndarray | None] = []
        rows: list[np.ndarray] = []
        self.arms: list[tuple[str, list[int], np.ndarray]] = []  # arm, its links, their elements
        self.bodies: list[tuple[str, int]] = []  # moving rigid bodies (planar robots, carried objects)
        self.owner: list[tuple[Any, int]] = []  # each element's part and link
        moving = {tr.robot for tr in ph.tracks}
        static: list[tuple[str, int]] = []
        for part in (*ph.parts.values(), *ph.objects.values()):
            first = len(radius)
            arm = part.robot and not rp.planar[part.name]
            for link, row in part.rows.items():
                index[(part.name, link)] = len(radius)
                rows.append(row)
                self.owner.append((part, link))
                if arm:
                    b = rp.bounds[part.name]
                    radius.append(float(b.spheres[b.column(link)]))
                    half.append(None)
                    continue
                h = half_extents(rp.footprint_shape[part.name] if part.robot else rp.shapes[part.name])
                radius.append(float(np.linalg.norm(h)) + 1e-6)
                half.append(None if part.robot or part.track >= 0 else h + 1e-6)
            elems = np.arange(first, len(radius))
            if arm:
                self.arms.append((part.name, list(part.rows), elems))
            elif part.track >= 0 or part.name in moving:
                self.bodies.append((part.name, first))
            else:
                static.append((part.name, first))
        self.index = index
        self.rows = np.array(rows).reshape(len(rows), -1)
        self.radius = np.array(radius)
        self.box = np.array([h is not None for h in half])
        self.half = np.array([h if h is not None else np.zeros(3) for h in half]).reshape(-1, 3)
        self.centre = np.zeros((len(radius), 3))
        self.rot = np.tile(np.eye(3), (len(radius), 1, 1))
        for name, e in static:  # what stands still, where it stands at the start of the phase
            self.centre[e], self.rot[e] = rs.body_frame(name)
        self.arms_moving = [arm for arm in self.arms if arm[0] in moving]
        for robot, links, elems in self.arms:
            self.centre[elems] = rs.link_centres(robot, links)
        ends = np.array(
            [(index[(a.name, la)], index[(b.name, lb)]) for p, (a, b, _, _) in zip(pairs, sides) for la, lb in p.subs]
        ).reshape(-1, 2)
        self.ends = ends.copy()  # (side a, side b) as the pairs list them
        flip = self.box[ends[:, 0]] & ~self.box[ends[:, 1]]  # the sphere first, the box second
        ends[flip] = ends[flip][:, ::-1]
        self.a, self.b = ends[:, 0], ends[:, 1]
        self.reach = self.radius[self.a] + np.where(self.box[self.b], 0.0, self.radius[self.b])
        self.to_box = np.flatnonzero(self.box[self.b])
        self.box_a, self.box_b = self.a[self.to_box], self.b[self.to_box]

    def __call__(self) -> np.ndarray:
        """The lower bound of every sub-pair's distance (in the sweep's order) at the world's current state."""
        rs, centre = self.rs, self.centre
        for robot, links, elems in self.arms_moving:
            centre[elems] = rs.link_centres(robot, links)
        for name, e in self.bodies:
            centre[e] = rs.position(name)
        out: np.ndarray = self._bound(centre[None])[0]
        return out

    def _bound(self, centre: np.ndarray) -> np.ndarray:
        """Lower bounds (T, S) from element centres (T, E, 3)."""
        gap = centre[:, self.a] - centre[:, self.b]
        if len(self.to_box):  # the sphere's centre in the box's frame, its distance from the box
            inside = np.einsum("nji,tnj->tni", self.rot[self.box_b], gap[:, self.to_box])
            gap[:, self.to_box] = np.maximum(np.abs(inside) - self.half[self.box_b], 0.0)
        out: np.ndarray = np.sqrt(np.einsum("tij,tij->ti", gap, gap)) - self.reach
        return out


class PhaseBounds(Spheres):
    """:class:`Spheres` for many times at once from the numpy kinematics, and each element's motion rate
    (module docstring; the certifier's :attr:`~mrgc.validator.certify.Phase.bounds`).  ``offsets``: for each
    track that carries an object, the object's frame in its robot's end-effector frame (a planar robot's:
    its base frame); ``chains(robot)``: an arm's :class:`~mrgc.validator.fk.ArmChain` with its fingers
    as they are now, and its links' motion spheres (:func:`~mrgc.validator.fk.motion_spheres`)."""

    def __init__(
        self,
        ph: Any,
        pairs: list[Pair],
        sides: list[tuple[Any, Any, Any, str]],
        offsets: dict[int, np.ndarray],
        chains: Callable[[str], tuple[ArmChain, list[tuple[np.ndarray, np.ndarray]]]],
    ) -> None:
        super().__init__(ph, pairs, sides)
        rp, rs = ph.rp, ph.rp.rs
        self.tracks = ph.tracks
        self.planar = [rp.planar[tr.robot] for tr in ph.tracks]
        self.offset = ph.offset
        self.chains: dict[int, ArmChain] = {}
        self.links: dict[int, list[tuple[int, int]]] = {}  # track -> (element, pybullet link) of its arm
        self.motion: dict[int, list[tuple[int, int, np.ndarray, np.ndarray]]] = {}  # track -> spheres
        self.carried: dict[int, tuple[int, np.ndarray]] = {}  # track -> (element, object origin in ee frame)
        self.lift: dict[int, float] = {}
        self.packed: dict[int, tuple[np.ndarray, tuple[np.ndarray, ...]]] = {}
        self.ee: dict[int, int] = {}
        for i, tr in enumerate(ph.tracks):
            part = ph.parts[tr.robot]
            if self.planar[i]:
                self.lift[i] = float(rs.robots[tr.robot].lift[2, 3])
                continue
            self.chains[i], spheres = chains(tr.robot)
            self.ee[i] = rs.robots[tr.robot].ee
            b = rp.bounds[tr.robot]
            self.links[i] = [(self.index[(tr.robot, link)], link) for link in part.rows]
            self.motion[i] = [(self.index[(tr.robot, link)], link, *spheres[b.column(link)]) for link in part.rows]
        for o, part in ph.objects.items():
            if part.track >= 0 and part.track in offsets:
                e = self.index[(o, -1)]
                self.carried[part.track] = (e, offsets[part.track])
                if not self.planar[part.track]:
                    self.motion[part.track].append(
                        (e, self.ee[part.track], *_held_spheres(rp.shapes[o], offsets[part.track], float(rp.radius[o])))
                    )
        for i, motion in self.motion.items():
            self.packed[i] = (np.array([m[0] for m in motion]), pack([m[2:] for m in motion], [m[1] for m in motion]))
        self.faces = self._face_pairs()
        self.still: dict[int, np.ndarray] = {}  # arm track -> its elements' distances from each axis, at its start
        self.revolute = np.zeros(self.rows.shape[1], dtype=bool)
        for i, tr in enumerate(ph.tracks):
            if not self.planar[i]:
                turns = rp.bounds[tr.robot].turns > 0
                self.revolute[self.offset[i] : self.offset[i] + len(turns)] = turns

    def at(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Lower bounds (T, S) of every sub-pair's distance and rates (T, E, C) of every element at
        ``times``."""
        t = np.asarray(times, dtype=float)
        centre = np.repeat(self.centre[None], len(t), axis=0)
        rate = np.repeat(self.rows[None], len(t), axis=0)
        spheres: dict[int, np.ndarray] = {}  # arm track -> its motion spheres' centres (T, spheres, 3)
        for i, tr in enumerate(self.tracks):
            q = _configs_at(tr.configs, t, self.planar[i])
            if self.planar[i]:
                self._planar(i, q, centre)
                continue
            chain = self.chains[i]
            rot, pos = chain.frames(q)
            elems = np.array([e for e, _ in self.links[i]])
            links = np.array([link + 1 for _, link in self.links[i]])
            centre[:, elems] = pos[:, links] + np.einsum("tlij,lj->tli", rot[:, links], chain.com[links])
            spheres[i] = self._arm_rates(i, rot, pos, centre, rate)
        lb = self._bound(centre) - FK_PAD
        for i, world in spheres.items():
            if i in self.faces:
                boxes, subs, which, local = self.faces[i]
                packed = self.packed[i][1]
                bound = face_bounds(self.centre[boxes], self.rot[boxes], self.half[boxes], world, packed[2], packed[3])
                lb[:, subs] = np.maximum(lb[:, subs], bound[:, local, which] - FK_PAD)
        return lb, rate

    def _planar(self, i: int, q: np.ndarray, centre: np.ndarray) -> None:
        """A planar track's footprint and carried object at configurations ``q`` (T, 3)."""
        x, y, yaw = q[:, 0], q[:, 1], q[:, 2]
        part = self.tracks[i].robot
        e = self.index[(part, -1)]
        centre[:, e] = np.stack([x, y, np.full(len(q), self.lift[i])], axis=1)
        if i in self.carried:
            e, off = self.carried[i]
            c, s = np.cos(yaw), np.sin(yaw)
            ox, oy, oz = off[:3, 3]
            centre[:, e] = np.stack([x + c * ox - s * oy, y + s * ox + c * oy, np.full(len(q), oz)], axis=1)

    def _arm_rates(self, i: int, rot: np.ndarray, pos: np.ndarray, centre: np.ndarray, rate: np.ndarray) -> np.ndarray:
        """An arm track's carried object's centre, and its elements' rates: the largest distance of their
        motion spheres from each revolute joint's axis (at most the global rate).  Returns the motion spheres'
        centres (T, spheres, 3)."""
        chain = self.chains[i]
        at = self.offset[i]
        cols = slice(at, at + len(chain.child))
        if i in self.carried:
            e, off = self.carried[i]
            ee = self.ee[i] + 1
            centre[:, e] = pos[:, ee] + rot[:, ee] @ off[:3, 3]
        elems, packed = self.packed[i]
        world = centres(rot, pos, packed)
        tight = axis_reach(chain, rot, pos, packed, world) + FK_PAD  # (T, elements, dof)
        g = self.rows[elems][:, cols]
        rate[:, elems, cols] = np.where(self.revolute[cols], np.minimum(g[None], tight), g[None])
        return world

    def first_joint(self, upstream: int, column: int) -> float:
        """The largest distance of element ``upstream`` (a link of a moving arm) from the axis of chain joint
        ``column`` (of the same arm) when that axis is fixed in the element's frame (the joint hangs on the
        link or on links bolted to it: no chain joint between), else inf."""
        for i, (elems, packed) in self.packed.items():
            at = self.offset[i]
            if upstream not in elems.tolist() or not at <= column < at + len(self.chains[i].child):
                continue
            chain, k = self.chains[i], elems.tolist().index(upstream)
            link = int(packed[0][packed[3][k]])  # the element's link (index + 1)
            parent = chain.joints[int(chain.child[column - at]) - 1].parent
            while parent != link and parent > 0 and chain.joints[parent - 1].column < 0:
                parent = chain.joints[parent - 1].parent
            if parent != link:
                return float("inf")
            if i not in self.still:
                rot, pos = chain.frames(np.asarray(self.tracks[i].configs[:1], dtype=float))
                self.still[i] = axis_reach(chain, rot, pos, packed)[0]
            return float(self.still[i][k, column - at]) + FK_PAD
        return float("inf")

    def _face_pairs(self) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
        """For each arm track paired with boxes that stand still: those boxes (elements, (B,)), the sub-pairs
        of its elements (links, carried object) with them (N,), and for each sub-pair its box (a position in
        the first array) and its element's position in the track's packed elements (:func:`face_bounds`)."""
        out: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        for i, (elems, _) in self.packed.items():
            where = {int(e): k for k, e in enumerate(elems.tolist())}
            subs = np.flatnonzero(self.box[self.b] & np.isin(self.a, elems))
            if not len(subs):
                continue
            boxes, which = np.unique(self.b[subs], return_inverse=True)
            local = np.array([where[int(e)] for e in self.a[subs]], dtype=int)
            out[i] = (boxes, subs, which.reshape(-1), local)
        return out


def _configs_at(configs: np.ndarray, t: np.ndarray, planar: bool) -> np.ndarray:
    """Configurations (T, dof) of a motion at times ``t`` (:func:`mrgc.validator.sampling.config_at`, many at
    once)."""
    m = len(configs)
    if m == 1:
        return np.repeat(np.asarray(configs[:1], dtype=float), len(t), axis=0)
    x = t * (m - 1)
    j = np.clip(np.floor(x).astype(int), 0, m - 2)
    u = (x - j)[:, None]
    d = configs[j + 1] - configs[j]
    if planar:
        d = d.copy()
        d[:, 2] = wrap_angle(d[:, 2])
    out: np.ndarray = configs[j] + u * d
    return out


def _held_spheres(shape: Shape, offset: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Motion spheres of a held object in its robot's end-effector frame (``offset``: the object's frame
    there): a box's 8 corners (its hull's vertices), otherwise one sphere of ``radius`` about its frame."""
    if isinstance(shape, Box):
        h = (shape.sx / 2, shape.sy / 2, shape.sz / 2)
        corners = np.array([[x * h[0], y * h[1], z * h[2], 1.0] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        return (corners @ offset.T)[:, :3], np.full(8, SPHERE_PAD)
    return offset[:3, 3][None].copy(), np.array([radius])


def face_bound(
    centre: np.ndarray, rot: np.ndarray, half: np.ndarray, world: np.ndarray, radius: np.ndarray, first: np.ndarray
) -> np.ndarray:
    """A lower bound (T, elements) of the signed distance of each element from a box (``centre`` (3,),
    ``rot`` (3, 3), ``half`` extents (3,)): the largest over the box's six face planes of the least signed
    distance of the element's motion spheres (centres ``world`` (T, spheres, 3), ``radius`` (spheres,), each
    element's first sphere at ``first``) from the plane.  Sound for the element's convex hull: a point's
    signed distance from a box is at least its distance from each face plane (inside: exactly the largest),
    the least plane distance over a convex hull is at a vertex, which a motion sphere holds, and for two
    convex shapes that overlap, the overlap along a face normal is at least the penetration depth."""
    out: np.ndarray = face_bounds(centre[None], rot[None], half[None], world, radius, first)[..., 0]
    return out


def face_bounds(
    centre: np.ndarray, rot: np.ndarray, half: np.ndarray, world: np.ndarray, radius: np.ndarray, first: np.ndarray
) -> np.ndarray:
    """:func:`face_bound` of B boxes at once (``centre`` (B, 3), ``rot`` (B, 3, 3), ``half`` (B, 3)): (T,
    elements, B).  The spheres' coordinates in every box's frame come from one matrix product."""
    n, (t, s, _) = len(centre), world.shape
    axes = np.swapaxes(rot, 0, 1).reshape(3, 3 * n)  # column 3b + i: box b's axis i
    local = (world.reshape(-1, 3) @ axes).reshape(t, s, n, 3) - np.einsum("bj,bji->bi", centre, rot)
    faces = np.concatenate([local - half, -local - half], axis=3) - radius[None, :, None, None]  # (T, S, B, 6)
    out: np.ndarray = np.minimum.reduceat(faces, first, axis=1).max(axis=3)
    return out
