"""Base paths: a planar robot's SE(2) paths over the floor, carrying an object or not, remembered.

A base path is searched on the robot's lattice (:mod:`mrgc.geometry.lattice`: deterministic, complete at the
lattice's resolution), its states at the validator's resolution and every motion between two of them checked
(the lattice's segment test), free of fixed objects, of the other planar robots parked at their starts, of
the objects to avoid (at their current poses) and of what the robots moving at the same time sweep (``busy``,
as hulls over runs of its pieces for the lattice's occupancy: :func:`_swept_hulls`).  Hopeless queries are
refused at once by an inscribed-disc grid test (:class:`~mrgc.geometry.planar.DiscGrid`).  Answers are
remembered: the same query (same obstacles at the same poses) gets the same answer.
"""

from __future__ import annotations

from functools import cached_property
from typing import Hashable, Iterable, Sequence

import numpy as np

from mrgc.geometry.answers import BUSY, Answer, GroundStatus
from mrgc.geometry.collision import CollisionShape, ConvexHull, Posed, posed_collide
from mrgc.geometry.conventions import PATH_RESOLUTION
from mrgc.geometry.lattice import Body, LatticePlanner, box_corners
from mrgc.geometry.motion import MotionStatus
from mrgc.geometry.planar import DiscGrid, scene_bounds
from mrgc.geometry.volumes import Volumes
from mrgc.language.model import Shape


class BasePaths(Volumes):
    """A planar robot's paths (see the module docstring)."""

    @cached_property
    def _grids(self) -> dict[str, DiscGrid]:
        """Each planar robot's inscribed-disc grid, made on its first path query."""
        return {}

    @cached_property
    def _lattices(self) -> dict[str, LatticePlanner]:
        """Each planar robot's lattice, made on its first path query."""
        return {}

    def base_path(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        holding: tuple[str, str] | None = None,
        avoid: Iterable[str] = (),
        busy: Sequence[tuple[CollisionShape, np.ndarray]] = (),
    ) -> Answer:
        """An SE(2) path for a planar robot, free of fixed objects, of the other robots parked at their
        starts, of ``avoid`` (objects at their current poses) and of the volume ``busy`` (what robots moving
        at the same time sweep), searched on the robot's lattice
        (:mod:`mrgc.geometry.lattice`: deterministic, complete at the lattice's resolution), its states at
        the validator's resolution and every motion between two of them checked (the lattice's segment test,
        against ``busy`` too: the states of what the other robots sweep, not the motions between them);
        hopeless queries are refused at once by an inscribed-disc grid test.  Answers are cached: the same
        query (same obstacles at the same poses) gets the same answer, and the search never asks twice."""
        movers = sorted({a for a in avoid if not holding or a != holding[0]})
        key = (robot, holding, tuple(movers), *self.fingerprint([start, goal, *(self.poses[a] for a in movers)], busy))

        def ask() -> Answer:
            answer = self._base_path(robot, start, goal, holding, movers, busy)
            if answer.status is GroundStatus.NO_PATH and busy and not self.cut:
                # no path: is it the step's other robots (a path exists without them) or the scene?
                alone = self.base_path(robot, start, goal, holding, avoid, ())
                if alone.ok:
                    answer = Answer(GroundStatus.NO_PATH, detail=BUSY)
            return answer

        return self._remembered(key, ask)

    def _base_path(
        self,
        robot: str,
        start: np.ndarray,
        goal: np.ndarray,
        holding: tuple[str, str] | None,
        movers: list[str],
        busy: Sequence[tuple[CollisionShape, np.ndarray]],
    ) -> Answer:
        others = [name for r, names in self.parked.items() if r != robot for name in names]
        arms = (*self._homes(), *self._bases)  # the arms at home and their mounts (an arm that moves is in busy)
        against = ("fixed", *others, *arms, *movers)
        ignore = (holding[0],) if holding else ()
        if robot not in self._grids:
            self._grids[robot] = DiscGrid(self.planar(robot), self.scene, scene_bounds(self.scene, 0.5))
            self._lattices[robot] = LatticePlanner(scene_bounds(self.scene, 0.5))
        # the disc grid knows objects at their initial poses only: objects moved since are left to the lattice
        obstacles = frozenset(
            [b.name for b in self.scene.fixed]
            + [a for a in movers if np.array_equal(self.poses[a], self.scene.body(a).pose)]
        )
        if not self._grids[robot].connected(np.asarray(start), np.asarray(goal), obstacles):
            return Answer(GroundStatus.NO_PATH)  # not even the footprint's inscribed disc gets through

        sweep = self._busy(busy)

        pr = self.planar(robot)
        carried = self._held(robot, holding)

        def clear(q: np.ndarray, margin: float) -> bool:
            self.queries += 1
            if self.late():
                return False
            probe = pr.probe(q, carried, margin)
            if sweep is not None and posed_collide(Posed.of(probe), sweep):
                return False
            return not self.world.probe_collides(probe, against=against, ignore=ignore)

        def valid(q: np.ndarray) -> bool:
            return clear(q, 0.0)

        parts: list[tuple[Shape, np.ndarray]] = [(pr.footprint, pr.lift)]
        if holding is not None:
            body = self.scene.body(holding[0])
            parts.append((body.shape, pr.carry_transform(body.shape, holding[1])))
        lattice = self._lattices[robot]
        occupied = lattice.occupancy(parts, self._lattice_bodies(robot, movers, busy))
        res = lattice.plan(
            occupied,
            np.asarray(start, dtype=float),
            np.asarray(goal, dtype=float),
            valid,
            PATH_RESOLUTION,
            PATH_RESOLUTION,
            clear=clear,
            reach=pr.reach(carried),
            deadline=self.deadline,
        )
        if self.late() or res.status is MotionStatus.TIME_LIMIT:
            self.cut = True
            return Answer(GroundStatus.TIME_LIMIT)
        return Answer(GroundStatus.OK if res.solved else GroundStatus.NO_PATH, path=list(res.path))

    def _lattice_bodies(
        self, robot: str, movers: list[str], busy: Sequence[tuple[CollisionShape, np.ndarray]]
    ) -> list[tuple[Hashable, Body, np.ndarray]]:
        """What the lattice's occupancy keeps ``robot`` clear of: the fixed objects, ``movers`` where they are,
        the other parked robots where they wait, the arms at home and their mounts (a cart drove through a
        Panda on the floor, and every plan was refused), and what ``busy`` sweeps."""
        bodies: list[tuple[Hashable, Body, np.ndarray]] = [(b.name, b.shape, b.pose) for b in self.scene.fixed]
        bodies += [((a, self.poses[a].tobytes()), self.scene.body(a).shape, self.poses[a]) for a in movers]
        for r, names in self.parked.items():  # the other parked robots where they wait
            if r != robot:
                bodies += [(name, _body(shape), t) for name, (shape, t) in zip(names, self.robot(r).rest().home)]
        for spec in self.scene.robots:  # the arms at home, and their mounts
            if not self.robot(spec.name).parks:
                rest = self.robot(spec.name).rest()
                bodies += [((spec.name, i), _body(shape), t) for i, (shape, t) in enumerate(rest.home)]
                bodies += [((spec.name, "base", j), _body(shape), t) for j, (_, shape, t) in enumerate(rest.mount)]
        bodies += [(("busy", pts.tobytes()), pts, np.eye(4)) for pts in _swept_hulls(busy)]
        return bodies


def _swept_hulls(volume: Sequence[tuple[CollisionShape, np.ndarray]], chunk: int = 8) -> list[np.ndarray]:
    """World points whose hulls cover ``volume``: the bounding-box corners of runs of ``chunk`` consecutive
    pieces of one shape (a path's states sweep little between them), for the lattice's occupancy."""
    runs: dict[int, list[np.ndarray]] = {}
    flushed: set[int] = set()
    out = []
    for shape, t in volume:
        run = runs.setdefault(id(shape), [])
        run.append(box_corners(shape) @ t[:3, :3].T + t[:3, 3])
        if len(run) == chunk:
            out.append(np.concatenate(run))
            runs[id(shape)] = [run[-1]]  # the next run starts where this one ended
            flushed.add(id(shape))
    out += [np.concatenate(run) for key, run in runs.items() if len(run) > 1 or key not in flushed]
    return out


def _body(shape: CollisionShape) -> Body:
    """A piece of a parked robot as the lattice reads it: its own geometry (a primitive's or a mesh's outline),
    a hull by its collision shape."""
    return shape if isinstance(shape.geometry, ConvexHull) else shape.geometry
