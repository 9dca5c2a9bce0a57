"""Placements: a collision-free pose of an object inside a region, for the reverse search to put it at.

A placement rests on the region's floor (:data:`~mrgc.geometry.conventions.ARM_PLACE_LIFT` above it), lies
entirely inside the region (``in-region``), and hits no fixed object, no parked planar robot, none of the
objects to avoid (at their current poses) and nothing of a given volume (the future volume V_fut of the
paper's reverse search).  Candidates come in a fixed order: phase 1's 3 x 3 lattice first (so a placement the
facts relied on is tried first), then seeded random positions at the four yaws; a bin several objects share
is *packed*, corners and walls first, so that each object leaves the most room to the ones the reverse
search places after it (:func:`_packing_grid`).  :meth:`Placements.comfortable` ranks candidates by the
placing arm's reach, :meth:`Placements.crowded_out` asks whether a placement leaves room for the objects
still to come.
"""

from __future__ import annotations

import functools
import hashlib
from typing import Callable, Iterable, Iterator

import numpy as np

from mrgc.geometry.answers import Answer, GroundStatus
from mrgc.geometry.collision import TOLERANCE, Posed, posed_collide
from mrgc.geometry.conventions import ARM_PLACE_LIFT, lattice_offsets, seed_for
from mrgc.geometry.grasps import grasp_transform
from mrgc.geometry.robot import Pieces, Sweep
from mrgc.geometry.scene import Body as SceneBody
from mrgc.geometry.scene import SceneSpec, floor_support, half_extents, inside, inside_test, outline, surface
from mrgc.geometry.step_world import StepWorld
from mrgc.geometry.transforms import rot_z, translation
from mrgc.language.model import Box

#: the share of an arm's reach bound that :meth:`Placements.comfortable` placements keep within
COMFORT = 0.85
#: the rooms :meth:`Placements.crowded_out` keeps (the last asked)
ROOMS = 32
#: m: the shorter side a fixed box's top needs for obstacles to be set aside on it (:func:`aside_tops`): a
#: table's, not a wall's or a post's
ASIDE_SIDE = 0.3
#: m: how far an obstacle set aside on a fixed top keeps from every region's footprint (:func:`off_regions`)
ASIDE_GAP = 0.02


def aside_tops(scene: SceneSpec) -> list[SceneBody]:
    """The tops of the fixed boxes an obstacle may be set aside on beyond the regions (each the
    :func:`~mrgc.geometry.scene.surface` of a fixed box whose footprint is at least :data:`ASIDE_SIDE` on both
    sides, in the order the problem lists them): where an arm puts an object out of the way on a table when no
    region has room for it.  The validator accepts an object set down on a fixed top that holds it up."""
    return [
        surface(b)
        for b in scene.fixed
        if isinstance(b.shape, Box) and min(b.shape.sx, b.shape.sy) >= ASIDE_SIDE and abs(b.pose[2, 2] - 1) < 1e-9
    ]


def nearest_on_top(top: SceneBody, point: np.ndarray) -> np.ndarray:
    """The point of ``top``'s footprint (a top of :func:`aside_tops`, seen from above) nearest to ``point``, at the
    height of the top face: whether an arm reaches any of the top is whether it reaches that point."""
    inv = np.linalg.inv(top.pose)
    local = inv[:3, :3] @ point + inv[:3, 3]
    half = half_extents(top.shape)
    near = np.array([*np.clip(local[:2], -half[:2], half[:2]), -half[2]])
    out: np.ndarray = top.pose[:3, :3] @ near + top.pose[:3, 3]
    return out


def off_regions(scene: SceneSpec, obj: str, gap: float = ASIDE_GAP) -> Callable[[np.ndarray], bool]:
    """Whether ``obj`` at a pose (4, 4) keeps ``gap`` clear of every region's footprint (the regions'
    boxes seen from above, grown by ``gap``, against the corners of the object's bounding box in each region's
    frame: conservative, a pose that only nears a turned region's corner may be refused): an obstacle set aside
    on a fixed top takes no room of a region, a goal bin's least of all."""
    corners = outline(scene.body(obj).shape)
    frames = [(np.linalg.inv(r.pose), half_extents(r.shape)[:2] + gap) for r in scene.regions]

    def test(pose: np.ndarray) -> bool:
        world = corners @ pose[:3, :3].T + pose[:3, 3]
        for inv, half in frames:
            local = (world @ inv[:3, :3].T + inv[:3, 3])[:, :2]
            if np.all(local.min(axis=0) <= half) and np.all(local.max(axis=0) >= -half):
                return False
        return True

    return test


class Placements(StepWorld):
    """Poses of objects inside regions (see the module docstring)."""

    def placement(
        self,
        obj: str,
        region: str | SceneBody,
        avoid: Iterable[str] = (),
        volume: Sweep | None = None,
        samples: int = 200,
        key: str = "",
        skip: int = 0,
        packed: bool = False,
    ) -> Answer:
        """A pose of ``obj`` entirely inside ``region`` that hits no fixed object, none of ``avoid`` (at their
        current poses) and nothing of ``volume``: phase 1's lattice first, then random positions and the four
        yaws; ``skip`` passes over that many valid candidates (to get another one on a retry).

        ``packed`` (a bin that several objects share): first a grid over the region at the four yaws,
        corners and walls first, so that each object leaves the largest free space in the middle for the
        ones placed before it (the reverse search places the last object first); the middle-first lattice
        scatters them and leaves no room for a third or fourth."""
        for pose in self.placements(obj, region, avoid, volume, samples, key, packed):
            if skip == 0:
                return Answer(GroundStatus.OK, pose=pose)
            skip -= 1  # the caller wants a different placement than the ones it already tried
        return Answer(GroundStatus.NO_PLACEMENT)

    def placements(
        self,
        obj: str,
        region: str | SceneBody,
        avoid: Iterable[str] = (),
        volume: Sweep | None = None,
        samples: int = 200,
        key: str = "",
        packed: bool = False,
        prefer: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> Iterator[np.ndarray]:
        """The poses :meth:`placement` would return with ``skip`` 0, 1, 2 ..., in that order, each checked
        once (asking :meth:`placement` for the k-th checks the first k again).  ``prefer`` (ranks of poses
        (N, 4, 4) -> (N,), e.g. :meth:`comfortable`'s) orders the grid and lattice candidates by rank, keeping
        their order among equal ranks.  ``region`` is a region's name or a region body (a relay's spot on a
        fixed object's top: :func:`mrgc.geometry.relays.spot_region`)."""
        body = self.scene.body(obj)
        reg = region if isinstance(region, SceneBody) else self.scene.body(region)
        if not isinstance(reg.shape, Box):
            return
        rng = np.random.default_rng(seed_for("placement", obj, reg.name, key, seed=self.seed))
        h_o, h_r = half_extents(body.shape), half_extents(reg.shape)
        vol = _around(self._volumes.posed(volume), reg) if volume else None
        avoid = tuple(a for a in avoid if a != obj)
        shape = self.shape(obj)
        within = inside_test(reg, body.shape)
        # a region's floor off the ground holds objects up only over a fixed box's top (floor_support)
        held = None if isinstance(region, SceneBody) else self._held_by(reg)  # a relay's spot: on its fixed top
        # first the 3 × 3 lattice phase 1 uses (so a placement the facts relied on is tried first), then
        # random positions and the four yaws
        room = np.maximum(h_r[:2] - h_o[:2], 0) * 0.9
        fixed: list[tuple[float, float, float]] = [(0.0, a * room[0], b * room[1]) for a, b in lattice_offsets(3)]
        if packed:
            fixed = _packing_grid(h_r[:2] - min(h_o[0], h_o[1])) + fixed
        if prefer is not None:  # by the preference's rank, keeping their order among equal ranks
            rank = prefer(_candidate_poses(reg.pose, fixed, -h_r[2] + h_o[2] + ARM_PLACE_LIFT))
            fixed = [fixed[i] for i in np.argsort(rank, kind="stable")]
        for k in range(len(fixed) + samples):
            if self.late():
                return
            if k < len(fixed):
                yaw, x, y = fixed[k]
            else:
                yaw = (np.pi / 2) * (k % 4)
                x, y = rng.uniform(-1, 1, 2) * np.maximum(h_r[:2] - min(h_o[0], h_o[1]), 0)
            pose = reg.pose @ translation(x, y, -h_r[2] + h_o[2] + ARM_PLACE_LIFT) @ rot_z(yaw)
            if not within(pose) or (held is not None and not held(pose)):
                continue
            probe = [(shape, pose)]
            self.queries += 1
            if self.world.probe_collides(probe, against="fixed"):
                continue
            if self.parked and self.world.probe_collides(probe, against="robots"):
                continue
            if avoid and self.world.probe_collides(probe, against=avoid):
                continue
            if vol is not None and posed_collide(Posed.of(probe), vol):
                continue
            yield pose

    def _held_by(self, region: SceneBody) -> Callable[[np.ndarray], bool] | None:
        """What holds up an object set down on a scene region's floor (:func:`floor_support`), made once per
        region: the placements of every grounding ask it."""
        if region.name not in self._floor_held:
            self._floor_held[region.name] = floor_support(self.scene.fixed, region)
        held: Callable[[np.ndarray], bool] | None = self._floor_held[region.name]
        return held

    def crowded_out(
        self,
        objs: Iterable[str],
        region: str,
        avoid: Iterable[str] = (),
        volume: Sweep | None = None,
        key: str = "",
        extra: Pieces = (),
    ) -> str | None:
        """The first of ``objs`` that has no free pose left in ``region`` (the candidates and checks of a
        packed :meth:`placements`: fixed objects, ``avoid``, ``volume`` and ``extra``), or None when each has
        one; objects already inside the region are not asked.  The reverse search asks it after grounding a
        placement into a bin that objects placed *earlier* still have to reach: a placement whose approach and
        carry sweep the whole bin leaves them none, and every grounding of an earlier step would then fail on it.

        ``extra`` (the motions of the placement just grounded) is asked apart from ``volume`` (the suffix's
        V_fut): each try at a step's placement into a bin asks the same room under the same V_fut with its
        own motions, so the candidates free of all but ``extra`` are kept (:meth:`_room`) and walked again,
        each then asked against ``extra`` alone.  The answers are those of ``volume`` and ``extra`` as one
        volume (a pose collides with a union of pieces when it collides with one of them); on a 6-arm,
        40-object instance this question was a quarter of the grounding's time, some 450 candidates per ask,
        most of them asked before."""
        avoid, reg = tuple(avoid), self.scene.body(region)
        pad = volume.pad if isinstance(volume, Posed) else TOLERANCE
        more = _around(Posed.of(extra, pad), reg) if extra else None
        # only what of the volume the region can meet: the same answers, and a room holds no more of it
        part = _around(self._volumes.posed(volume), reg) if volume is not None else None
        # what the rooms asked now depend on besides the object: where the objects to avoid are, the part
        where = b"".join(self.world.transform(name).tobytes() for name in avoid if name in self.world)
        context = (region, avoid, where, _content(part), key)
        for obj in objs:
            if self.late():
                return None
            if inside(reg, self.scene.body(obj).shape, self.poses[obj]):
                continue
            shape = self.shape(obj)
            room = self._room(obj, context, part)
            if not any(more is None or not posed_collide(Posed.of([(shape, pose)]), more) for pose in room):
                return obj
        return None

    def _room(self, obj: str, context: tuple[str, tuple[str, ...], bytes, bytes, str], part: Posed | None) -> _Room:
        """The free packed placements of ``obj`` in a region (:meth:`placements` with ``key`` ``room:<key>``),
        kept per object and ``context`` (the region, the objects to avoid, their poses, the content of the
        ``part`` of the volume the region can meet (:func:`_content`) and the key): walked again, a kept room
        gives the poses it found before and then looks further (the last :data:`ROOMS` asked are kept)."""
        region, avoid, _, _, key = context
        index = (obj, *context)
        room: _Room | None = self._rooms.pop(index, None)
        if room is None:
            room = _Room(self.placements(obj, region, avoid, part, key=f"room:{key}", packed=True), part)
        self._rooms[index] = room  # the most recent last
        while len(self._rooms) > ROOMS:
            del self._rooms[next(iter(self._rooms))]
        return room

    def comfortable(
        self, robot: str, obj: str, grasp: str, share: float = COMFORT
    ) -> Callable[[np.ndarray], np.ndarray]:
        """A rank of placements of ``obj`` (object poses (N, 4, 4) -> ranks (N,)) for ``robot`` holding it with
        ``grasp``: its :meth:`Robot.comfort <mrgc.geometry.robot.Robot.comfort>` of the tool poses (an arm: 0
        where the end effector lies within ``share`` of its reach bound from the shoulder, else its distance
        from the shoulder, nearer first; a bin at the edge of an arm's reach is reachable in its near part
        only, and IK at its far corners fails after every restart).  0 everywhere for a grasp without
        geometry."""
        spec = self.scene.grasp_specs.get(grasp)
        if spec is None:
            return lambda poses: np.zeros(len(poses))
        mover = self.robot(robot)
        g_t = grasp_transform(spec, self.scene.body(obj).shape)
        return lambda poses: mover.comfort(poses @ g_t, share)

    def out_of_reach(self, robot: str, obj: str, grasp: str) -> Callable[[np.ndarray], bool]:
        """Whether a placement of ``obj`` (an object pose (4, 4)) is certainly out of ``robot``'s reach holding it
        with ``grasp``: its end effector would lie past the reach bound (:meth:`comfortable` at share 1, above
        0), an upper bound of where it can be, so no inverse kinematics answer exists there.  Never true for a
        robot without a reach bound (a cart) or a grasp without geometry."""
        rank = self.comfortable(robot, obj, grasp, share=1.0)
        return lambda pose: bool(rank(pose[None])[0] > 0)


class _Room:
    """The free placements of one object in one region under one volume (:meth:`Placements._room`): those
    found so far, then the rest of the search for them (``source``, resumed where it stopped).  ``volume`` (the
    part of it the region can meet) is held so that the ids of its shapes, part of the room's key
    (:func:`_content`), are not reused meanwhile."""

    def __init__(self, source: Iterator[np.ndarray], volume: object) -> None:
        self.source, self.volume = source, volume
        self.found: list[np.ndarray] = []
        self.done = False

    def __iter__(self) -> Iterator[np.ndarray]:
        k = 0
        while True:
            if k < len(self.found):
                yield self.found[k]
                k += 1
                continue
            if self.done:
                return
            pose = next(self.source, None)
            if pose is None:
                self.done = True
                return
            self.found.append(pose)


def _content(part: Posed | None) -> bytes:
    """A volume's pieces (what of it a region can meet: :func:`_around`) as bytes: their shapes (by id: the
    room that holds the part keeps them alive), kinds and transforms, in order.  Two volumes with the same
    content give every candidate the same answers (a step grounded again under the same suffix makes its
    V_fut anew)."""
    if part is None:
        return b""
    shapes = np.array([id(s) for s in part.shapes], dtype=np.int64)
    return hashlib.blake2b(shapes.tobytes() + part.kind.tobytes() + part.transforms.tobytes(), digest_size=16).digest()


def _around(vol: Posed, region: SceneBody) -> Posed:
    """The pieces of ``vol`` that meet ``region``'s box (grown by twice the collision tolerance and 1 mm):
    every candidate placement lies inside the region, so only those can touch it (the same answers, far
    fewer pieces to look through when the volume is a whole suffix's sweep and the region a bin)."""
    reach = np.abs(region.pose[:3, :3]) @ half_extents(region.shape) + 2 * TOLERANCE + 1e-3
    return vol.within(region.pose[:3, 3] - reach, region.pose[:3, 3] + reach)


def _candidate_poses(region: np.ndarray, cands: list[tuple[float, float, float]], z: float) -> np.ndarray:
    """The world poses (N, 4, 4) of candidates (yaw, x, y) at height ``z`` in the ``region`` pose's frame,
    made in one go (each is ``region @ translation(x, y, z) @ rot_z(yaw)``)."""
    c = np.array(cands, dtype=float).reshape(-1, 3)
    local = np.zeros((len(c), 4, 4))
    cos, sin = np.cos(c[:, 0]), np.sin(c[:, 0])
    local[:, 0, 0], local[:, 0, 1], local[:, 1, 0], local[:, 1, 1] = cos, -sin, sin, cos
    local[:, 2, 2] = local[:, 3, 3] = 1.0
    local[:, 0, 3], local[:, 1, 3], local[:, 2, 3] = c[:, 1], c[:, 2], z
    out: np.ndarray = region @ local
    return out


def _packing_grid(room: np.ndarray, cells: int = 15) -> list[tuple[float, float, float]]:
    """(yaw, x, y) over ``[-room, room]`` (region frame) on a grid of at most ``cells`` per side (at least 1 cm
    apart), the four yaws at each point, points nearest a corner first (a new list; the grid of a room is
    made once)."""
    room = np.maximum(room, 0.0)
    return list(_grid(float(room[0]), float(room[1]), cells))


@functools.lru_cache(maxsize=64)
def _grid(rx: float, ry: float, cells: int) -> tuple[tuple[float, float, float], ...]:
    """:func:`_packing_grid` of the room ``(rx, ry)`` (kept: a bin's grid is asked for at every placement)."""
    room = np.array([rx, ry])
    axes = [np.linspace(-r, r, max(1, min(cells, int(2 * r / 0.01) + 1))) for r in room]
    scale = np.maximum(room, 1e-9)

    def level(x: float, y: float) -> float:
        return float(-round(abs(x) / scale[0] + abs(y) / scale[1], 9))  # numpy's round, as before

    # the points of one level (the four corners, ...) at one yaw before the next yaw: a place that fails
    # at one corner (out of reach) is tried at the others before another yaw
    cands = [(level(float(x), float(y)), k, float(x), float(y)) for x in axes[0] for y in axes[1] for k in range(4)]
    return tuple((k * np.pi / 2, x, y) for _, k, x, y in sorted(cands))
