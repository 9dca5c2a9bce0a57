"""The world a step is grounded in: the scene as the grounding has moved it, the robots, the run's deadline.

The :class:`~mrgc.geometry.grounding.Grounder` is one stateful service built on :class:`StepWorld`; each
of its jobs is a module of its own (placements, approaches and handovers, arm paths, base paths, swept
volumes).  This module holds what they share:

- **the scene** with the movable objects where the grounding has put them (:meth:`StepWorld.move`,
  :meth:`StepWorld.moved`: the reverse search moves objects as it grounds steps), as a collision world;
- **the robots**, each made once through the kinds' table (:meth:`StepWorld.robot`: a
  :class:`~mrgc.geometry.robot.Robot`, asked, never tested for its kind) and what it leaves in the world
  (:meth:`Robot.rest <mrgc.geometry.robot.Robot.rest>`): a robot that parks (a planar robot) waits at home,
  group ``robots``, an obstacle to every query; any other (an arm) is at home (group ``home:<robot>``) in the
  phases the execution model puts it there, its mount (``base:<robot>``) always; where each arm of the step
  being grounded is in each phase (:meth:`StepWorld.step`, the execution model of
  :mod:`mrgc.geometry.stances`, and :meth:`StepWorld.standing`) is what every query keeps clear of
  (:meth:`StepWorld._others`);
- **the run's deadline** (:attr:`StepWorld.deadline`, a ``time.perf_counter()`` value;
  ``benchmarks/cpu_plan.py`` swaps that clock for CPU time): every long loop reads it (placements, IK
  attempts, handover pairs, lifts, transfers, transits, RRT solves, lattice searches), and past it the query
  stops at once with what it has (status ``TIME_LIMIT`` where a status is the answer) and
  :attr:`StepWorld.cut` turns True.  An answer made after the cut may be wrong, so the caller discards
  everything grounded since (the planner ends its search with ``time limit``); no clock decides an answer
  otherwise;
- **the caches** the queries share: volumes as the collision kernel reads them, and the path answers
  (transfers, base paths) remembered per grounder (:data:`REMEMBERED`).

Seeds derive from the query, so the same queries in the same order give the same answers.
"""

from __future__ import annotations

import hashlib
import operator
import time
from contextlib import contextmanager
from typing import Any, Callable, Iterable, Iterator, Mapping

import numpy as np

from mrgc.geometry.answers import Answer
from mrgc.geometry.arm import Arm
from mrgc.geometry.collision import CollisionShape, Posed, collision_shape, scene_world
from mrgc.geometry.kinds import robot_for
from mrgc.geometry.planar import PlanarRobot
from mrgc.geometry.robot import Pieces, Robot, Volume
from mrgc.geometry.scene import SceneSpec
from mrgc.geometry.stances import Stance, stance

#: path answers (transfers, base paths) remembered per grounder
REMEMBERED = 4096


class StepWorld:
    """The state the grounder's queries share (see the module docstring)."""

    def __init__(self, scene: SceneSpec, seed: int = 0) -> None:
        self.scene = scene
        self.seed = seed
        self.world = scene_world(scene)
        self.poses = {b.name: b.pose.copy() for b in scene.movable}
        self._robots: dict[str, Robot] = {}
        self._paths: dict[tuple[object, ...], Answer] = {}
        #: volumes (V_fut, what the step's other robots sweep, ``after``) as the collision kernel reads them
        self._volumes = _VolumeCache()
        #: the free placements :meth:`Placements.crowded_out <mrgc.geometry.placements.Placements.crowded_out>`
        #: found, by object, region, what to avoid (and where), the content of the volume's part the region
        #: can meet, and key (most recent last)
        self._rooms: dict[tuple[object, ...], Any] = {}
        #: each region's floor support test (:func:`~mrgc.geometry.scene.floor_support`), made once per region
        self._floor_held: dict[str, Any] = {}
        #: robots that park (:attr:`Robot.parks <mrgc.geometry.robot.Robot.parks>`: planar robots) wait at home
        #: (their start pose, as the validator assumes), obstacles for the others: robot -> its world bodies
        #: there, group ``robots``
        self.parked: dict[str, tuple[str, ...]] = {}
        for spec in scene.robots:
            robot = self.robot(spec.name)
            if robot.parks:
                home = robot.rest().home
                names = tuple(f"@{spec.name}" + (f":{i}" if i else "") for i in range(len(home)))
                for name, (shape, pose) in zip(names, home):
                    self.world.add(name, shape, pose, "robots")
                self.parked[spec.name] = names
        self.queries = 0
        #: the run's deadline (``time.perf_counter()``; None: none), and whether it has cut a query short
        self.deadline: float | None = None
        self.cut = False
        #: the other robots (arms) wait at home while others move (the validator's rule): each one's volume at
        #: home, group ``home:<robot>``, an obstacle to the other arms' motions in the phases it is there
        self.homes: tuple[str, ...] = ()
        #: each arm's mount links (its base), group ``base:<arm>``: an obstacle to the other arms, home or not
        self._bases: tuple[str, ...] = ()
        #: the step being grounded (see :meth:`step`): each of its robots' role, and the arms' motion model
        self._roles: dict[str, str] = {}
        self._full = False
        #: arms of the step standing still away from home where they are known (:meth:`standing`): robot ->
        #: stance -> (world group, digest of its transforms)
        self._stands: dict[str, dict[Stance, tuple[str, bytes]]] = {}

    def late(self) -> bool:
        """Whether the run's :attr:`deadline` has passed (then :attr:`cut` is True: queries stop at once)."""
        if not self.cut and self.deadline is not None and time.perf_counter() > self.deadline:
            self.cut = True
        return self.cut

    def _homes(self) -> tuple[str, ...]:
        """Put every robot that does not park at home into the world (once; its :meth:`Robot.rest
        <mrgc.geometry.robot.Robot.rest>`: an arm's links) and name their groups."""
        if not self.homes:
            staying = [s.name for s in self.scene.robots if not self.robot(s.name).parks]
            for name in staying:
                rest = self.robot(name).rest()
                for i, (shape, t) in enumerate(rest.home):
                    self.world.add(f"@{name}:{i}", shape, t, f"home:{name}")
                for j, (_, shape, t) in enumerate(rest.mount):  # bolted in place: there, home or not
                    self.world.add(f"@{name}:base" + (f":{j}" if j else ""), shape, t, f"base:{name}")
                if rest.mount:
                    self._bases += (f"base:{name}",)
            self.homes = tuple(f"home:{name}" for name in staying)
        return self.homes

    def step(self, roles: Mapping[str, str], full: bool = False) -> None:
        """Declare the step whose actions are grounded next: each of its robots' role in its action
        (``pick-place``, ``giver`` or ``taker``) and whether arms' empty-handed transits are paths (``full``,
        ``mrgc plan --motions full``).  The grounder then knows, per phase, where every arm is (the execution
        model a plan means, :data:`STANCES`; docs/validator.md, docs/planner.md):

        - every arm starts the step at home; an arm in no action of the step stays there;
        - between its own motions an arm stands where its last motion left it, its fingers as that motion
          left them: a pick-and-place arm at its last pick configuration holding its object while the step's
          handovers run (to-handover, handover, giver-home), a taker at its exchange holding the object while
          the giver withdraws (giver-home), an arm without a home path at its last place configuration in
          the home phase;
        - a missing transit (no path under ``configurations``) is a jump at the end of its phase: a taker is
          at home until the handover phase (unless it has a ``taker-to-handover`` path), a giver at its
          exchange until the end of the giver-home phase, then at home (to-place, place, home);
        - planar robots always drive their paths (as ``full``).

        Each query of a phase keeps clear of the other arms at home then and of those standing still where
        :meth:`standing` has put them (:meth:`_others`); what the step's other robots do meanwhile, moving or
        standing, comes as the query's ``busy``.  ``step({})`` forgets the step."""
        self._roles, self._full = dict(roles), full

    def stance(self, robot: str, phase: str) -> Stance:
        """Where ``robot`` is during ``phase`` of the declared step (:meth:`step`); at home when it has no
        action in it."""
        role = self._roles.get(robot)
        if role is None:
            return Stance.HOME
        return stance(role, phase, self._full or self.robot(robot).parks)

    @contextmanager
    def standing(self, robot: str, where: Mapping[Stance, Volume]) -> Iterator[None]:
        """``robot`` standing still at ``where`` (a volume per stance: its links, and the object it holds
        there) for the queries inside the ``with`` block: an obstacle to the other arms in the phases the
        execution model puts it there (:meth:`stance`); taken out again after the block."""
        before = self._stands.get(robot, {})
        added: list[str] = []
        mine = dict(before)
        try:
            for where_, volume in where.items():
                if where_ in before:
                    continue
                group = f"stand:{robot}:{where_.name}"
                for i, (shape, t) in enumerate(volume):
                    added.append(f"~{robot}:{where_.name}:{i}")
                    self.world.add(added[-1], shape, t, group)
                mine[where_] = (group, fingerprint((), volume)[1])
            self._stands[robot] = mine
            yield
        finally:
            for name in added:
                self.world.remove(name)
            if before:
                self._stands[robot] = before
            else:
                self._stands.pop(robot, None)

    def _presence(self) -> tuple[object, ...]:
        """What :meth:`_others` answers depend on (a path cache's key): the step's roles, its motion model
        and where its arms stand."""
        stands = sorted((r, s.name, d) for r, m in self._stands.items() for s, (_, d) in m.items())
        return (tuple(sorted(self._roles.items())), self._full, tuple(stands))

    def _others(self, robot: str, phase: str) -> tuple[str, ...]:
        """The world groups of the other arms standing still in ``phase`` of the current step (:meth:`step`):
        at home, or where :meth:`standing` put them (an arm that moves then is in the query's ``busy``; one
        whose place is not known yet is left out), and every other arm's base link."""
        out = []
        for home in self._homes():
            other = home[5:]
            if other == robot:
                continue
            where = self.stance(other, phase)
            if where is Stance.HOME:
                out.append(home)
            elif where in self._stands.get(other, {}):
                out.append(self._stands[other][where][0])
        return tuple(out) + tuple(b for b in self._bases if b != f"base:{robot}")

    def robot(self, robot: str) -> Robot:
        """The robot ``robot`` (:class:`~mrgc.geometry.robot.Robot`, of its kind's class), made once."""
        if robot not in self._robots:
            self._robots[robot] = robot_for(self.scene.robot(robot))
        return self._robots[robot]

    def arm(self, robot: str) -> Arm:
        """The arm ``robot``, for the arms' own queries (approaches, arm paths: :meth:`robot` as an
        :class:`~mrgc.geometry.arm.Arm`)."""
        out = self.robot(robot)
        if not isinstance(out, Arm):
            raise TypeError(f"robot {robot!r} is not an arm")
        return out

    def planar(self, robot: str) -> PlanarRobot:
        """The planar robot ``robot``, for the planar robots' own queries (base paths, drives: :meth:`robot` as
        a :class:`~mrgc.geometry.planar.PlanarRobot`)."""
        out = self.robot(robot)
        if not isinstance(out, PlanarRobot):
            raise TypeError(f"robot {robot!r} is not a planar robot")
        return out

    def move(self, obj: str, pose: np.ndarray) -> None:
        """Put ``obj`` at ``pose`` (world) for all later queries."""
        self.poses[obj] = pose.copy()
        self.world.set_transform(obj, pose)

    @contextmanager
    def moved(self, poses: Mapping[str, np.ndarray]) -> Iterator[None]:
        """The objects at ``poses`` for the queries inside the ``with`` block, back where they were after it
        (also when it raises)."""
        before = {o: self.poses[o] for o in poses}
        try:
            for o, pose in poses.items():
                self.move(o, pose)
            yield
        finally:
            for o, pose in before.items():
                self.move(o, pose)

    def shape(self, obj: str) -> CollisionShape:
        """The collision shape of body ``obj``."""
        return collision_shape(self.scene.body(obj).shape)

    def _busy(self, volume: Pieces) -> Posed | None:
        """What other robots of a step sweep meanwhile (``busy``) as the kernel reads it (None: nothing)."""
        return self._volumes.posed(volume) if volume else None

    def fingerprint(self, arrays: Iterable[np.ndarray], busy: Pieces) -> tuple[tuple[int, ...], bytes]:
        """What a path query's answer depends on besides its names: the shapes of ``busy`` and a digest of
        ``arrays`` (configurations, object poses) and of ``busy``'s pieces (the path caches' keys), read from
        ``busy`` as the kernel reads it (:meth:`_busy`: converted once however often it is asked)."""
        posed = self._busy(busy)
        if posed is None:
            return fingerprint(arrays, ())
        _, digest = fingerprint([*arrays, posed.kind, posed.transforms], ())
        return tuple(id(s) for s in posed.shapes), digest

    def _remembered(self, key: tuple[object, ...], ask: Callable[[], Answer]) -> Answer:
        """The path answer remembered for ``key`` (a query's names and :func:`fingerprint`), else ``ask()``'s,
        remembered (:meth:`_remember`): the same question gets the same answer without a second search."""
        if key not in self._paths:
            answer = ask()
            self._remember(key, answer)
            return answer
        return self._paths[key]

    def _remember(self, key: tuple[object, ...], answer: Answer) -> None:
        """Keep a path answer, forgetting the oldest beyond :data:`REMEMBERED` (insertion order: the same
        run forgets the same ones)."""
        if self.cut:
            return  # made after the deadline: not an answer to keep (the caller discards it too)
        if len(self._paths) >= REMEMBERED:
            del self._paths[next(iter(self._paths))]
        self._paths[key] = answer


class _VolumeCache:
    """Volumes as the collision kernel reads them (:class:`~mrgc.geometry.collision.Posed`), converted once
    per list: the last few lists asked for (the same list object, unchanged) are kept with their conversion;
    a volume given as a ``Posed`` already is the kernel's (a grounded suffix's V_fut: :meth:`Posed.join
    <mrgc.geometry.collision.Posed.join>`).  Lists that grow by concatenation into new lists (what a step's
    other robots sweep, as its actions are grounded one after the other; until session 23 also V_fut, then
    a list): a list that begins with the pieces of a kept one (the same piece objects, as many as it had
    then) converts only the rest (:meth:`Posed.extended <mrgc.geometry.collision.Posed.extended>`, equal to
    the bit to converting the whole list; on the 6-arm, 40-object instance, converting whole suffix volumes
    again was 12 % of the grounding's time).  Nothing is copied into coal."""

    SIZE = 8
    #: a kept list this long or longer is worth looking for at the front of a new one
    PREFIX_MIN = 64

    def __init__(self) -> None:
        #: (the list, its length then, its conversion, its pieces then)
        self.kept: list[tuple[Pieces, int, Posed, tuple[tuple[CollisionShape, np.ndarray], ...]]] = []

    def posed(self, volume: Pieces | Posed) -> Posed:
        if isinstance(volume, Posed):
            return volume  # already the kernel's (a grounded suffix's volume: :meth:`Posed.join`)
        for k, (held, n, posed, _) in enumerate(self.kept):
            if held is volume and n == len(volume):
                if k:
                    self.kept.insert(0, self.kept.pop(k))
                return posed
        made = self._extended(volume)
        posed = made if made is not None else Posed.of(volume)
        # held, so that its id is not reused meanwhile
        self.kept.insert(0, (volume, len(volume), posed, tuple(volume)))
        del self.kept[self.SIZE :]
        return posed

    def _extended(self, volume: Pieces) -> Posed | None:
        """The conversion of ``volume`` from the longest kept list its pieces begin with, or None."""
        best: tuple[int, Posed] | None = None
        for _, n, posed, pieces in self.kept:
            if self.PREFIX_MIN <= n < len(volume) and (best is None or n > best[0]):
                if pieces[0] is volume[0] and pieces[-1] is volume[n - 1] and all(map(operator.is_, pieces, volume)):
                    best = (n, posed)
        return best[1].extended(volume[best[0] :]) if best is not None else None


def fingerprint(arrays: Iterable[np.ndarray], busy: Pieces) -> tuple[tuple[int, ...], bytes]:
    """What a path query's answer depends on besides its names: the shapes of ``busy`` and a digest of
    ``arrays`` (configurations, object poses) and of ``busy``'s transforms (the path caches' keys)."""
    digest = hashlib.sha1()
    for part in (*arrays, *(t for _, t in busy)):
        digest.update(np.ascontiguousarray(np.asarray(part, dtype=float)).tobytes())
    return tuple(id(shape) for shape, _ in busy), digest.digest()


def named_body(hit: str) -> str:
    """A body of the grounder's world as a failure line names it: ``r2 at home`` for an arm's link at home
    (``@r2:<i>``, its base link ``@r2:base``), ``r1 at its exchange`` for one standing still
    (``~r1:EXCHANGE:<i>``, :meth:`Grounder.standing`), else its name."""
    if hit.startswith("@"):
        return f"{hit[1:].split(':')[0]} at home"
    if hit.startswith("~"):
        robot, where = hit[1:].split(":")[:2]
        return f"{robot} {Stance[where].value}"
    return hit
