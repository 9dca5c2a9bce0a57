"""Phase 1 in *path mode*: the geometric facts of a planar mobile robot (the box-moving domain).

The robot model (footprint, grasp faces, pick/place base poses, carried objects, placements) is in
:mod:`mrgc.geometry.planar`.  Swept volumes come from base paths searched on the robot's SE(2) lattice
(:class:`~mrgc.geometry.lattice.LatticePlanner`: deterministic, complete at the lattice's resolution, every
state of a returned path checked with coal at :data:`RESOLUTION` / :data:`YAW_RESOLUTION`):
the footprint (and the carried object) at every state of the dense path.  For robot R:

- ``reachable-pick M g R`` (g a side grasp): the footprint at the pick base pose is free of fixed objects
  and a base path leads there from R's start pose, avoiding the fixed objects and M itself (R cannot drive
  through the object it is about to pick; the pick pose keeps :data:`~mrgc.geometry.planar_grasps.CLEARANCE`
  from it).  The path is planned first avoiding every movable object too, and only if that fails with
  respect to the fixed objects (and M) alone — the paper's "collision-free, if possible".
- ``occludes-pick M1 M g R``: M1 is hit by the footprint along the chosen pick path.  When the chosen path
  had to cross movable objects, the set is reduced greedily (a cheap minimum-constraint-removal): for each
  object hit, in name order, a path avoiding every movable object except the remaining hits is tried, and
  when one exists its (smaller) hit set is kept.  An object therefore appears when R really has to move it,
  as far as the lattice can tell.
- ``reachable-place M Re g R`` (for a reachable pick, Re = M's goal region and M's current region): some
  placement of M in Re (:func:`~mrgc.geometry.planar.placements`) whose object pose and place base pose are
  free of fixed objects, and a base path from the pick base pose to the place base pose carrying M,
  avoiding the fixed objects (M's own initial pose is vacated).
- ``occludes-goal-place M1 M Re g R`` (goal pairs only): M1 is hit by the footprint and the carried M along
  the chosen place path, or by M at the chosen placement.  Placements whose pose and base pose are free of
  movable objects are tried first with paths avoiding the movable objects; failing that, paths avoiding
  only the fixed objects on the first few placements, the one hitting fewest objects kept and reduced
  greedily as for picks.
- ``enable-goal-handover``: none.  The paper leaves handovers out of the box-moving domain ("they do not
  contribute significantly ... with mobile robots in synchronous setups"); a planar robot's
  :class:`~mrgc.geometry.facts.RobotFacts` has an empty ``handover`` map, so the fixed-arm handover
  pass of :func:`~mrgc.geometry.predicates.compute_facts` adds nothing for it.

Before a query is planned, :class:`~mrgc.geometry.planar.DiscGrid` checks a necessary condition (can the
footprint's inscribed disc get from start to goal on a 5 cm grid?); a query it rules out is one the planner
could not have solved, so it is answered "no path" at once without building the lattice's occupancy —
which is what most "free of movable objects, if possible" attempts in a blocked doorway are.  Paths are cached per
(start, goal, carried object and grasp, obstacle set).  Everything is deterministic, on an idle or a loaded
machine: the lattice search draws no random numbers and reads no clock (the seconds in ``stats`` are
statistics only).
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from mrgc.geometry.collision import CollisionShape, CollisionWorld, collision_shape, scene_world
from mrgc.geometry.facts import RobotFacts
from mrgc.geometry.lattice import LatticePlanner
from mrgc.geometry.planar import DiscGrid, PlanarRobot, placements, scene_bounds
from mrgc.geometry.planar_grasps import planar_grasp
from mrgc.geometry.scene import Body, SceneSpec, inside
from mrgc.language.model import Fact

#: largest translation (m) and turn (rad) between checked path states
RESOLUTION = 0.05
YAW_RESOLUTION = 0.1
#: greedy hit-set reductions tried per chosen path
MAX_REDUCE = 4
#: placements tried per (object, region, grasp) with paths avoiding movable objects / only fixed objects
PLACE_FREE_TRIES = 2
PLACE_FIXED_TRIES = 3

Carried = tuple[CollisionShape, np.ndarray] | None
Path = list[np.ndarray]


class PlanarEvaluator:
    """Computes one planar robot's facts of a scene: ``PlanarEvaluator(scene, robot, seed).run()``."""

    def __init__(self, scene: SceneSpec, robot: str, seed: int = 0) -> None:
        self.scene = scene
        self.robot = PlanarRobot(scene.robot(robot))
        self.world: CollisionWorld = scene_world(scene)
        self.seed = seed
        self.bounds = scene_bounds(scene, self.robot.radius + 0.1)
        self.movable = frozenset(m.name for m in scene.movable)
        self.fixed = frozenset(b.name for b in scene.fixed)
        self.grid = DiscGrid(self.robot, scene, self.bounds)
        self.lattice = LatticePlanner(self.bounds)
        #: movable objects named as occluders by the facts so far (preferred when a path must cross some)
        self.occluders: set[str] = set()
        self.current = {m.name: r.name for m in scene.movable for r in scene.regions if inside(r, m.shape, m.pose)}
        self.out = RobotFacts()
        self.paths: dict[tuple[object, ...], Path | None] = {}
        #: counters: path queries planned, their validity checks and seconds, cache hits
        self.stats: dict[str, float] = {
            "path_queries": 0,
            "path_checks": 0,
            "path_seconds": 0.0,
            "path_cache_hits": 0,
            "grid_rejections": 0,
        }

    # ------------------------------------------------------------------------------------ primitives
    def _collides(self, probe: list[tuple[CollisionShape, np.ndarray]], obstacles: Iterable[str]) -> bool:
        self.out.collision_checks += 1
        return self.world.probe_collides(probe, against=("fixed", *sorted(obstacles)))

    def _in_bounds(self, q: np.ndarray) -> bool:
        xmin, xmax, ymin, ymax = self.bounds
        return bool(xmin <= q[0] <= xmax and ymin <= q[1] <= ymax)

    def _path(
        self,
        start: np.ndarray,
        goal: np.ndarray,
        carried: Carried,
        carry_key: tuple[str, ...],
        obstacles: frozenset[str],
    ) -> Path | None:
        """A base path avoiding the fixed objects and ``obstacles`` (movable names), or None; cached."""
        key = (tuple(np.round(start, 6)), tuple(np.round(goal, 6)), carry_key, obstacles)
        if key in self.paths:
            self.stats["path_cache_hits"] += 1
            return self.paths[key]
        if not self.grid.connected(start, goal, self.fixed | obstacles):
            self.stats["grid_rejections"] += 1
            self.paths[key] = None
            return None
        against = ("fixed", *sorted(obstacles))
        robot, world, out = self.robot, self.world, self.out

        def valid(q: np.ndarray) -> bool:
            out.collision_checks += 1
            return not world.probe_collides(robot.probe(q, carried), against=against)

        parts: list[tuple[object, np.ndarray]] = [(robot.footprint, robot.lift)]
        if carried is not None:
            parts.append(carried)
        bodies = [(b.name, b.shape, b.pose) for b in self.scene.fixed]
        bodies += [(name, self.scene.body(name).shape, self.scene.body(name).pose) for name in sorted(obstacles)]
        occupied = self.lattice.occupancy(parts, bodies)  # type: ignore[arg-type]
        res = self.lattice.plan(
            occupied, tuple(map(float, start)), tuple(map(float, goal)), valid, RESOLUTION, YAW_RESOLUTION
        )
        self.stats["path_queries"] += 1
        self.stats["path_checks"] += res.checks
        self.stats["path_seconds"] += res.planning_time
        path = res.path if res.solved else None
        self.paths[key] = path
        return path

    def _sweep(self, path: Path, carried: Carried, candidates: frozenset[str]) -> set[str]:
        """The objects of ``candidates`` that the robot (and what it carries) hits along ``path``."""
        if not candidates:
            return set()
        self.out.collision_checks += len(path)
        return self.world.sweep_hits((self.robot.probe(q, carried) for q in path), against=candidates)

    def _least_blocked(
        self,
        start: np.ndarray,
        goal: np.ndarray,
        carried: Carried,
        carry_key: tuple[str, ...],
        avoid: frozenset[str],
        candidates: frozenset[str],
    ) -> tuple[Path, set[str]] | None:
        """A path avoiding fixed objects and ``avoid``, crossing as few of ``candidates`` as found.

        Tries a path free of every candidate first, then one crossing only objects that earlier facts of
        this robot already name as occluders (so that the facts agree on which of two blocked doorways to
        clear, instead of each query taking its own shortest way), then one crossing any of them; then
        greedily shrinks its hit set (:data:`MAX_REDUCE` attempts).
        """
        path = self._path(start, goal, carried, carry_key, avoid | candidates)
        if path is not None:
            return path, set()
        path = None
        if self.occluders & candidates:
            path = self._path(start, goal, carried, carry_key, avoid | (candidates - self.occluders))
        if path is None:
            path = self._path(start, goal, carried, carry_key, avoid)
        if path is None:
            return None
        hits = self._sweep(path, carried, candidates)
        path, hits = self._reduce(start, goal, carried, carry_key, avoid, candidates, path, hits)
        self.occluders |= hits
        return path, hits

    def _reduce(
        self,
        start: np.ndarray,
        goal: np.ndarray,
        carried: Carried,
        carry_key: tuple[str, ...],
        avoid: frozenset[str],
        candidates: frozenset[str],
        path: Path,
        hits: set[str],
    ) -> tuple[Path, set[str]]:
        tries = 0
        for h in sorted(hits):
            if tries >= MAX_REDUCE:
                break
            if h not in hits:
                continue
            tries += 1
            allowed = hits - {h}
            other = self._path(start, goal, carried, carry_key, avoid | (candidates - allowed))
            if other is not None:
                path, hits = other, self._sweep(other, carried, frozenset(allowed))
        return path, hits

    # ------------------------------------------------------------------------------------ predicates
    def run(self) -> RobotFacts:
        """Every fact of this robot (``reachable-*``, ``occludes-*``; no handovers, see the module doc)."""
        scene, r = self.scene, self.robot.name
        for m in scene.movable:
            for g in scene.grasps[m.name]:
                if not planar_grasp(g):
                    continue
                pick = self._pick(m, g)
                if pick is None:
                    continue
                q_pick, hits = pick
                self.out.facts.append(Fact("reachable-pick", (m.name, g, r)))
                self.out.facts.extend(Fact("occludes-pick", (o, m.name, g, r)) for o in sorted(hits))
                goal = scene.goal.get(m.name)
                for region in sorted({r for r in (goal, self.current.get(m.name)) if r is not None}):
                    place = self._place(m, g, region, q_pick, want_free=region == goal)
                    if place is None:
                        continue
                    self.out.facts.append(Fact("reachable-place", (m.name, region, g, r)))
                    if region == goal:
                        self.out.facts.extend(
                            Fact("occludes-goal-place", (o, m.name, region, g, r)) for o in sorted(place)
                        )
        return self.out

    def _pick(self, m: Body, g: str) -> tuple[np.ndarray, set[str]] | None:
        """The pick base pose of (m, g) and the objects the chosen path to it crosses, or None."""
        q = self.robot.grasp_base(m.pose, m.shape, g)
        if not self._in_bounds(q) or self._collides(self.robot.probe(q), ()):
            return None
        found = self._least_blocked(self.robot.start, q, None, (), frozenset({m.name}), self.movable - {m.name})
        return None if found is None else (q, found[1])

    def _place_candidates(
        self, m: Body, g: str, region: str, carried: tuple[CollisionShape, np.ndarray], others: frozenset[str]
    ) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[tuple[np.ndarray, np.ndarray]]]:
        """(object pose, place base pose) pairs of m in region (grasp g) whose object pose and base pose
        (carrying m) are free of fixed objects: the first ones free of ``others`` too, and a few that are
        not."""
        robot, shape = self.robot, carried[0]
        free: list[tuple[np.ndarray, np.ndarray]] = []
        blocked: list[tuple[np.ndarray, np.ndarray]] = []
        for pose in placements(m, self.scene.body(region)):
            q = robot.grasp_base(pose, m.shape, g)
            if not self._in_bounds(q):
                continue
            at = [(shape, pose)]
            probe = robot.probe(q, carried)
            if self._collides(at, ()) or self._collides(probe, ()):
                continue
            if len(free) < PLACE_FREE_TRIES + PLACE_FIXED_TRIES and not self._collides(at + probe, others):
                free.append((pose, q))
            elif len(blocked) < PLACE_FIXED_TRIES:
                blocked.append((pose, q))
            if len(free) >= PLACE_FREE_TRIES + PLACE_FIXED_TRIES:
                break
        return free, blocked

    def _place(self, m: Body, g: str, region: str, q_pick: np.ndarray, want_free: bool) -> set[str] | None:
        """The objects the chosen placement of m in region (grasp g) and its path hit, or None if none is
        reachable; for ``want_free`` (goal pairs) a placement and path free of movable objects is preferred."""
        robot = self.robot
        shape = collision_shape(m.shape)
        carried = (shape, robot.carry_transform(m.shape, g))
        key = (m.name, g)
        others = self.movable - {m.name}
        if not robot.load_fits(m.shape, g) or self._collides(robot.probe(q_pick, carried), ()):
            return None  # M cannot ride at its carry pose (into the floor or the cart), or be lifted to it here
        free, blocked = self._place_candidates(m, g, region, carried, others)
        if want_free:
            for _, q in free[:PLACE_FREE_TRIES]:
                if self._path(q_pick, q, carried, key, others) is not None:
                    return set()
        best: tuple[Path, set[str], np.ndarray, np.ndarray] | None = None
        for pose, q in (free + blocked)[:PLACE_FIXED_TRIES]:
            path = self._path(q_pick, q, carried, key, frozenset())
            if path is None:
                continue
            if not want_free:
                return set()
            hits = self._sweep(path, carried, others) | self.world.probe_hits([(shape, pose)], against=others)
            if best is None or len(hits) < len(best[1]):
                best = (path, hits, pose, q)
            if not hits:
                break
        if best is None:
            return None
        return self._place_hits(q_pick, best, carried, key, others)

    def _place_hits(
        self,
        q_pick: np.ndarray,
        best: tuple[Path, set[str], np.ndarray, np.ndarray],
        carried: tuple[CollisionShape, np.ndarray],
        key: tuple[str, str],
        others: frozenset[str],
    ) -> set[str]:
        """What the chosen place path (and the object at its placement) hits, the path's hits reduced: as
        :meth:`_least_blocked`, first a path around the known occluders, then greedily."""
        path, hits, pose, q = best
        at_place = self.world.probe_hits([(carried[0], pose)], against=others)
        if hits - at_place - self.occluders and self.occluders & others:
            known = self._path(q_pick, q, carried, key, others - self.occluders - at_place)
            if known is not None:
                path, hits = known, self._sweep(known, carried, others) | at_place
        path, path_hits = self._reduce(q_pick, q, carried, key, frozenset(), others - at_place, path, hits - at_place)
        self.occluders |= path_hits
        return path_hits | at_place
