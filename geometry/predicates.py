"""Phase 1 of the paper: the geometric facts of a scene.  Fixed-base arms use IK mode (the packaging
domain, below); planar mobile robots use path mode (geometry/path_predicates.py, the box-moving domain).

For every robot R (in parallel, one process per robot when there are cores to spare):

- ``reachable-pick M g R``: inverse kinematics puts the tool at M's grasp g and at the pre-grasp pose,
  both configurations collision-free with respect to the fixed objects (M itself is ignored);
- ``reachable-place M Re g R``: the same for a placement of M inside Re (tried in order from the region's
  centre outwards; M at the placement must not hit a fixed object), for Re = M's goal region and M's
  current region;
- ``occludes-pick M1 M g R``: M1 is hit by R's links along the approach (pre-grasp → grasp, sampled) for
  the pick configuration chosen collision-free with respect to the movable objects if possible;
- ``occludes-goal-place M1 M Re g R`` (goal pairs only): M1 is hit by R's links or by M along the
  approach to the placement, or by M at the placement, the placement chosen free of movables if possible;
- ``enable-goal-handover M g1 g2 R1 R2`` (goal objects): at some handover point of M, R1 holding M with
  g1 and R2 holding it with g2 are both collision-free with respect to the fixed objects and to each other
  (up to HANDOVER_CONFIGS distinct IK solutions per arm are tried in pairs: one branch of an arm may reach
  into a waiting arm where another does not).  A configuration reaching into its partner's home is left out
  too: under the default motion model the giver arrives at its exchange while the taker still waits at home
  (it has no path there), and in both models the giver is back home when the taker leaves its exchange for
  the place (docs/validator.md, "What a plan means");
- ``occludes-handover M1 M g1 g2 R1 R2`` (beyond the paper): M1 is hit by R1's or R2's links, or by M held
  at the point, at the exchange of that handover, for the pair of configurations (over every handover point)
  that hits the fewest movable objects; none when a pair hits none (a handover point above the start region
  is in the way of the tall objects standing under it: they must move before the handover);
- ``enable-relay M Re g1 g2 R1 R2`` (beyond the paper; only for goal objects no single action takes to
  their goal): R1 sets M down with g1 at a placement in Re where R2 picks it up with g2
  (:mod:`mrgc.geometry.relays`);
- ``occludes-relay M1 M Re g1 g2 R1 R2`` (beyond the paper): M1 is hit by R1's or R2's links along their
  approaches to that relay's spot, or by M along them and at the spot, for the spot that hits the fewest;
  none when a spot hits none (a relay through a crowded start region needs room there: the objects at its
  spot must move first);

and ``in-region M Re`` from the initial poses.  Everything is deterministic for a seed.
"""

from __future__ import annotations

import itertools
import time
from typing import Callable, Sequence, TypeVar

import numpy as np

from mrgc.geometry.arm import Arm
from mrgc.geometry.collision import Posed, Probes, posed_collide, scene_world
from mrgc.geometry.conventions import APPROACH_SAMPLES, ARM_PLACE_LIFT, REFINE, lattice_offsets, refine, seed_for
from mrgc.geometry.facts import FactsResult, HandoverConfig, RobotFacts
from mrgc.geometry.grasps import finger_opening, fits, grasp_transform, pregrasp_transform
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.kinds import approaches
from mrgc.geometry.relays import Asks, Spots, free_relays, relay_facts, spot_region, stranded
from mrgc.geometry.relays import asks as relay_asks
from mrgc.geometry.scene import Body, SceneSpec, floor_support, half_extents, inside
from mrgc.geometry.transforms import translation
from mrgc.language.model import Box, Fact
from mrgc.workers import map_in_workers, map_until, worker_count

PLACEMENT_GRID = 3  # placements tried per region: a GRID × GRID lattice, centre first
IK_SEEDS = 3  # IK solutions tried per target when looking for one free of movable objects
IK_ITERS = 100  # Levenberg-Marquardt iterations per solve (reachable targets converge in far fewer)
HANDOVER_STARTS = 4  # IK solves per handover target: from home, then from seeded random configurations
HANDOVER_CONFIGS = 3  # distinct handover configurations kept per (object, point, grasp)
DISTINCT_CONFIG = 0.1  # rad: configurations closer than this in every joint count as one

J = TypeVar("J")
R = TypeVar("R")
#: a query of :meth:`RobotEvaluator._solve`: (object, grasp, object pose, held, key)
Query = tuple[str, str, np.ndarray, bool, str]
#: an IK branch of a query: (query, grasp transform, grasp configuration, pre-grasp configuration or None)
Branch = tuple[Query, np.ndarray, np.ndarray, "np.ndarray | None"]
#: a query's answer: the approach path and the movable objects it hits
Answer = tuple[np.ndarray, set[str]]


class RobotEvaluator:
    """Computes one robot's facts of a scene."""

    def __init__(self, scene: SceneSpec, robot: str, seed: int = 0) -> None:
        self.scene = scene
        self.arm = Arm(scene.robot(robot))
        self.world = scene_world(scene)
        # the other arms wait at home while this one picks or places (the validator's execution model): their
        # links at home are obstacles like the fixed objects, named ``@<arm>:<link>``
        for spec in scene.robots:
            if spec.name != robot and approaches(spec.kind):
                other = Arm(spec)
                shapes, _ = other.probes
                for i, (shape, t) in enumerate(zip(shapes, other.link_transforms(other.home[None])[0])):
                    self.world.add(f"@{spec.name}:{i}", shape, t, "fixed")
                for j, (_, shape, t) in enumerate(other.base_hulls):  # bolted in place: there when that arm moves
                    self.world.add(f"^{spec.name}:base:{j}", shape, t, "fixed")
        self.seed = seed
        self.out = RobotFacts()
        self.current = {m.name: r.name for m in scene.movable for r in scene.regions if inside(r, m.shape, m.pose)}
        self._grasp_ts: dict[tuple[str, str], np.ndarray] = {}

    # ------------------------------------------------------------ primitives
    def _ik(
        self,
        tool_poses: list[np.ndarray],
        key: str,
        q_init: np.ndarray | None = None,
        attempt: int = 0,
        restarts: int = 8,
    ) -> list[np.ndarray | None]:
        """IK for many tool poses in one batch (``q_init``: one start for all, or one per pose).  A first
        attempt from one start (or none: home) is analytic for arms with a Panda's kinematics
        (:mod:`mrgc.geometry.ik`); retries (``attempt`` > 0) are numeric with seeded restarts, which reach the
        other branches the analytic answer (nearest the start, whatever the seed) does not.  Solves with a
        start per pose (a pre-grasp from its grasp) are numeric from that start, as grounding solves them:
        the approach between the two stays on its line."""
        if not tool_poses:
            return []
        targets = self.arm.ee_target(np.stack(tool_poses))
        self.out.ik_solves += len(targets)
        start = self.arm.home if q_init is None else q_init
        one_start = np.ndim(start) == 1
        # numeric retries draw the restarts numeric attempts 0, 1, ... drew before the analytic first try
        tries = attempt - 1 if one_start and attempt > 0 else attempt
        res = solve_ik_many(
            self.arm.model,
            targets,
            seed_for(self.arm.name, key, str(tries), seed=self.seed),
            q_init=start,
            restarts=restarts,
            max_iters=IK_ITERS,
            analytic=attempt == 0 and one_start,
        )
        return [r.q if r.solved else None for r in res]

    def usable(self, obj: str, grasp: str) -> bool:
        """Whether this arm can use ``grasp`` on ``obj``: the grasp has geometry and the gripper opens wide
        enough for it (geometry/grasps.py)."""
        spec = self.scene.grasp_specs.get(grasp)
        return spec is not None and fits(spec, self.scene.body(obj).shape, self.arm.spec.kind)

    def grasp_t(self, obj: str, grasp: str) -> np.ndarray:
        """The tool pose in ``obj``'s frame for ``grasp`` (:func:`~mrgc.geometry.grasps.grasp_transform`), made
        once per (object, grasp) and read-only."""
        key = (obj, grasp)
        t = self._grasp_ts.get(key)
        if t is None:
            t = self._grasp_ts[key] = grasp_transform(self.scene.grasp(grasp), self.scene.body(obj).shape)
            t.setflags(write=False)
        return t

    def opening(self, obj: str, grasp: str) -> float:
        """The finger opening while approaching or holding ``obj`` with ``grasp``."""
        return finger_opening(self.scene.grasp(grasp), self.scene.body(obj).shape)

    @staticmethod
    def _approach(q_pre: np.ndarray, q: np.ndarray) -> np.ndarray:
        """The approach from pre-grasp ``q_pre`` to grasp ``q`` ((dof,) each, or (N, dof) for N approaches):
        APPROACH_SAMPLES configurations on the joint-space line, (..., APPROACH_SAMPLES, dof)."""
        s = np.linspace(0.0, 1.0, APPROACH_SAMPLES)[:, None]
        out: np.ndarray = q_pre[..., None, :] * (1 - s) + q[..., None, :] * s
        return out

    def _solve(self, queries: list[Query], want_free: bool) -> dict[int, Answer]:
        """Batched grasp + pre-grasp IK and collision checks for (object, grasp, object pose, held, key)
        queries; the approach path and the movable objects it hits for each query that is reachable.

        Queries whose IK solution collides with a fixed object (or has no pre-grasp) are retried with other
        IK seeds (other solution branches), and so are those whose approach hits movable objects when
        ``want_free`` (the paper's "collision-free, if possible");
        the first clean answer wins, else the first answer.  A query whose hand hits what failed it (a fixed
        body; a movable one when ``want_free``) at its pre-grasp or grasp is not retried (:meth:`_hand_hits`):
        every branch puts the hand there, so a retry gives the same facts; nor is one whose pre-grasp has no
        answer when the analytic solver has no branch for that tool pose either (:meth:`Arm.no_branch
        <mrgc.geometry.arm.Arm.no_branch>`).
        """
        found: dict[int, Answer] = {}
        settled: set[int] = set()  # the hand hits what made the answer fail or unclean: no other branch helps
        todo = list(range(len(queries)))
        blocked: dict[int, bool] = {}  # a placement whose object hits a fixed object there (asked once a query)
        for attempt in range(IK_SEEDS):
            if not todo:
                break
            g_ts = [self.grasp_t(queries[i][0], queries[i][1]) for i in todo]
            qs = self._ik([queries[i][2] @ g for i, g in zip(todo, g_ts)], "grasp", attempt=attempt)
            unsolvable = {i for i, q in zip(todo, qs) if q is None}  # IK with restarts failed: no retry
            for i, q in zip(todo, qs):
                if q is not None and i not in blocked:
                    obj, _, pose, held, _ = queries[i]
                    blocked[i] = held and self.world.probe_collides([(self.scene.body(obj).shape, pose)], "fixed")
            ok = [(i, g, q) for i, g, q in zip(todo, g_ts, qs) if q is not None and not blocked[i]]
            tools = [queries[i][2] @ pregrasp_transform(g) for i, g, _ in ok]
            # a pre-grasp no branch reaches (the analytic search, from the grasp's configuration) is settled
            # without a numeric solve: it would fail, restarts and all, and so would every retry
            none = self.arm.no_branches(tools, np.stack([q for _, _, q in ok]) if ok else None)
            asked = [k for k in range(len(ok)) if not none[k]]
            pres: list[np.ndarray | None] = [None] * len(ok)
            solved = self._ik(
                [tools[k] for k in asked],
                "pre",
                attempt=attempt,
                q_init=np.stack([ok[k][2] for k in asked]) if asked else None,
                restarts=2,
            )
            for k, q_pre in zip(asked, solved):
                pres[k] = q_pre
            branches = [(i, g, q, q_pre) for k, ((i, g, q), q_pre) in enumerate(zip(ok, pres)) if not none[k]]
            settled.update(i for k, (i, _, _) in enumerate(ok) if none[k])
            answers = self._branches([(queries[i], g, q, q_pre) for i, g, q, q_pre in branches], want_free)
            for (i, _, _, _), (answer, final) in zip(branches, answers):
                if final:
                    settled.add(i)
                if answer is not None and (i not in found or (found[i][1] and not answer[1])):
                    found[i] = answer
            # try other IK solutions for queries with no answer yet, or (if asked) one that hits movables
            todo = [
                i
                for i in todo
                if i not in unsolvable and i not in settled and (i not in found or (want_free and found[i][1]))
            ]
        return found

    def _branches(self, items: list[Branch], want_free: bool) -> list[tuple[Answer | None, bool]]:
        """The answers of IK branches to queries of :meth:`_solve`, each item (query, grasp transform ``g``,
        grasp configuration ``q``, pre-grasp ``q_pre`` or None): the approach path and the movable objects it
        hits, or None when the branch fails; and whether no other branch can do better (the query is settled).

        A branch fails when its approach (pre-grasp → grasp, refined to the validator's resolution) hits the arm
        itself or a fixed object, or, with the object in hand (a placement), the object hits a fixed one; else
        its hits are the movable objects the arm's links hit along the approach, and the object in hand hits
        along it and at its placement.  The items are checked together: one forward kinematics, one
        self-collision check, and one kernel query for all of them per world selection and kind of piece (the
        arm's links, the object in hand: :meth:`~mrgc.geometry.collision.CollisionWorld.slot_collides`), the
        answers each would get alone; only the hand checks of the branches that fail or hit something
        (:meth:`_hand_hits`) and the pre-grasps without an answer (:meth:`Arm.no_branch
        <mrgc.geometry.arm.Arm.no_branch>`) are asked branch by branch."""
        out: list[tuple[Answer | None, bool]] = [(None, False)] * len(items)
        for k, (query, g, _, q_pre) in enumerate(items):
            if q_pre is None:  # the pre-grasp, the same tool pose on every branch: settled when no branch reaches it
                out[k] = (None, self.arm.no_branch(query[2] @ pregrasp_transform(g)))
        live = [k for k, item in enumerate(items) if item[3] is not None]
        if not live:
            return out
        queries = [items[k][0] for k in live]
        objs = [query[0] for query in queries]
        openings: list[float | None] = [self.opening(query[0], query[1]) for query in queries]
        pres = [q_pre for _, _, _, q_pre in items if q_pre is not None]
        paths = self._approach(np.stack(pres), np.stack([items[k][2] for k in live]))
        dense = refine(paths, REFINE)  # (n, D, dof): row REFINE * i is the path's configuration i
        transforms = self._link_transforms(dense, openings)  # (n, D, L, 4, 4)
        self.out.collision_checks += len(live)
        clear = self._arm_clear(transforms, objs)
        for x in np.flatnonzero(~clear).tolist():
            out[live[x]] = (None, self._hand_hits(paths[x], (objs[x],), openings[x], "fixed"))
        # the object in hand (placements), along the approach, must stay clear of fixed objects too
        held = [x for x in np.flatnonzero(clear).tolist() if queries[x][3]]
        in_hand = {x: t @ np.linalg.inv(items[live[x]][1]) for x, t in zip(held, self.arm.tool_world(dense[held]))}
        stuck = self.world.slot_collides(self._objects([(objs[x], in_hand[x]) for x in held]), "fixed")
        for x in np.asarray(held, dtype=int)[stuck].tolist():
            clear[x] = False
            out[live[x]] = (None, False)
        ok = np.flatnonzero(clear).tolist()
        if not ok:
            return out
        self.out.collision_checks += len(ok)
        along = transforms[ok, ::REFINE]  # the links at the path's configurations
        probes = Probes.batch(self.arm.probes[0], along, self.world.tolerance)
        hits = self.world.slot_hits(probes, "movable", own=[objs[x] for x in ok])
        carried = [(c, x) for c, x in enumerate(ok) if x in in_hand]  # the object along it and at its placement
        poses = [(objs[x], np.concatenate([in_hand[x][::REFINE], queries[x][2][None]])) for _, x in carried]
        more = self.world.slot_hits(self._objects(poses), "movable", own=[objs[x] for _, x in carried])
        for (c, _), m in zip(carried, more):
            hits[c] |= m
        for c, x in enumerate(ok):
            final = bool(hits[c]) and want_free and self._hand_hits(paths[x], (objs[x],), openings[x], "movable")
            out[live[x]] = ((paths[x], hits[c]), final)
        return out

    def _arm_clear(self, transforms: np.ndarray, objs: list[str]) -> np.ndarray:
        """For each path of probed-link ``transforms`` (n, C, L, 4, 4), whether the arm is free of itself (the
        link pairs :attr:`~mrgc.geometry.kinematics.RobotModel.self_collision_pairs` keeps apart) and of the
        fixed objects at every configuration (object ``objs[i]`` aside): an (n,) bool array."""
        n, _, links = transforms.shape[:3]
        selfhit = self.arm.self_colliding_at(transforms.reshape(-1, links, 4, 4)).reshape(n, -1)
        clear = np.logical_not(selfhit.any(axis=1))
        rest = np.flatnonzero(clear)
        if len(rest):
            probes = Probes.batch(self.arm.probes[0], transforms[rest], self.world.tolerance)
            clear[rest] = ~self.world.slot_collides(probes, "fixed", own=[objs[x] for x in rest.tolist()])
        return clear

    def _objects(self, poses: list[tuple[str, np.ndarray]]) -> Probes:
        """Objects at poses, one probe each ((object, (C, 4, 4) world poses) pairs)."""
        return Probes.of([[(self.scene.body(obj).shape, t) for t in ts] for obj, ts in poses], self.world.tolerance)

    def _link_transforms(self, qs: np.ndarray, openings: Sequence[float | None]) -> np.ndarray:
        """The probed links' world transforms ((Q, C, L, 4, 4)) of Q paths ``qs`` (Q, C, dof), path q with the
        fingers ``openings[q]`` apart: one forward kinematics per distinct opening."""
        out = np.empty(qs.shape[:2] + (len(self.arm.probes[0]), 4, 4))
        for opening in dict.fromkeys(openings):
            rows = [k for k, o in enumerate(openings) if o == opening]
            out[rows] = self.arm.link_transforms(qs[rows], opening)
        return out

    def _hand_hits(self, path: np.ndarray, ignore: tuple[str, ...], opening: float | None, against: str) -> bool:
        """Whether the hand (:attr:`Arm.hand <mrgc.geometry.arm.Arm.hand>`) at the first or last configuration of
        an approach ``path`` (the pre-grasp and the grasp: tool poses every IK branch shares, to the solver's
        0.1 mm) hits an ``against`` object but ``ignore``: then every other branch's approach does too, and a
        retry cannot give a free (or cleaner) answer."""
        hand = self.arm.hand_volume(path[[0, -1]], opening)
        return bool(hand) and self.world.probe_collides(hand, against=against, ignore=ignore)

    def placements(self, obj: str, region: str | Body) -> list[np.ndarray]:
        """Candidate poses of ``obj`` resting inside ``region`` (a name or a region body): a lattice, centre
        first."""
        body, reg = self.scene.body(obj), region if isinstance(region, Body) else self.scene.body(region)
        if not isinstance(reg.shape, Box):
            return []
        h_o, h_r = half_extents(body.shape), half_extents(reg.shape)
        room = h_r[:2] - h_o[:2]
        if np.any(room < 0) or h_o[2] > h_r[2]:
            return []
        held = floor_support(self.scene.fixed, reg) if not isinstance(region, Body) else None  # off the ground
        out = []
        for a, b in lattice_offsets(PLACEMENT_GRID):
            pose = reg.pose @ translation(a * room[0] * 0.9, b * room[1] * 0.9, -h_r[2] + h_o[2] + ARM_PLACE_LIFT)
            if inside(reg, body.shape, pose) and (held is None or held(pose)):
                out.append(pose)
        return out

    # ------------------------------------------------------------ the predicates of one robot
    def run(self) -> RobotFacts:
        """This robot's facts (see the module docstring), its handover configurations and counters."""
        r, scene = self.arm.name, self.scene
        near = {m.name: self.arm.in_reach(m.pose[:3, 3], margin=0.3) for m in scene.movable}
        picks = [
            (m.name, g, m.pose, False, "pick")
            for m in scene.movable
            if near[m.name]
            for g in scene.grasps[m.name]
            if self.usable(m.name, g)
        ]
        for i, (_, hits) in sorted(self._solve(picks, want_free=True).items()):
            obj, g = picks[i][0], picks[i][1]
            self.out.facts.append(Fact("reachable-pick", (obj, g, r)))
            self.out.facts.extend(Fact("occludes-pick", (o, obj, g, r)) for o in sorted(hits))
        # placements: round k tries the k-th candidate pose of every (object, region, grasp) not yet placed
        triples: list[tuple[str, str, str, list[np.ndarray]]] = []
        for m in scene.movable:
            for region in sorted({r for r in (scene.goal.get(m.name), self.current.get(m.name)) if r is not None}):
                poses = [p for p in self.placements(m.name, region) if self.arm.in_reach(p[:3, 3], margin=0.3)]
                triples.extend(
                    (m.name, region, g, poses) for g in scene.grasps[m.name] if self.usable(m.name, g) and poses
                )
        placed: dict[int, set[str]] = {}
        for k in range(PLACEMENT_GRID * PLACEMENT_GRID):
            open_ = [
                i
                for i, t in enumerate(triples)
                if k < len(t[3])
                and (i not in placed or placed[i])
                and (i not in placed or scene.goal.get(t[0]) == t[1])
            ]
            if not open_:
                break
            queries = [(triples[i][0], triples[i][2], triples[i][3][k], True, "place") for i in open_]
            for j, (_, hits) in self._solve(queries, want_free=False).items():
                i = open_[j]
                if i not in placed or (placed[i] and not hits):
                    placed[i] = hits
        for i in sorted(placed):
            obj, region, g, _ = triples[i]
            self.out.facts.append(Fact("reachable-place", (obj, region, g, r)))
            if scene.goal.get(obj) == region:
                self.out.facts.extend(Fact("occludes-goal-place", (o, obj, region, g, r)) for o in sorted(placed[i]))
        self._handover_configs()
        return self.out

    def spots(self, asks: Asks) -> Spots:
        """The relay spots this arm reaches (:mod:`mrgc.geometry.relays`): for each (object, grasp, region)
        asked, the indices of the region's placement lattice where the arm holds the object with the grasp,
        grasp and pre-grasp free of the fixed objects, each with the movable objects the arm's links hit along
        the approach or the object hits at the spot (its IK branches tried for one that hits none, as for a
        pick)."""
        queries, keys = [], []
        for obj, grasp, region in asks:
            if not self.usable(obj, grasp):
                continue
            for k, pose in enumerate(self.placements(obj, spot_region(self.scene, region))):
                if self.arm.in_reach(pose[:3, 3], margin=0.3):
                    queries.append((obj, grasp, pose, True, "relay"))
                    keys.append((obj, grasp, region, k))
        found = self._solve(queries, want_free=True)
        return {keys[i]: frozenset(hits) - {keys[i][0]} for i, (_, hits) in found.items()}

    def _handover_configs(self) -> None:
        """Up to HANDOVER_CONFIGS distinct configurations per (goal object, handover point, grasp), from
        HANDOVER_STARTS IK solves (the first from home, the others from seeded random starts): one solution
        may hit an arm waiting at home or the partner's links where another branch of the arm does not."""
        keys, tools = [], []
        for obj in self.scene.goal:
            for point in self.scene.handover_of.get(obj, ()):
                if point not in self.scene.handover_points:
                    continue
                pose = translation(*self.scene.handover_points[point])
                if not self.arm.in_reach(pose[:3, 3], margin=0.3):
                    continue
                for g in self.scene.grasps[obj]:
                    if self.usable(obj, g):
                        keys.append((obj, point, g))
                        tools.append(pose @ self.grasp_t(obj, g))
        model = self.arm.model
        todo = list(range(len(keys)))
        for attempt in range(HANDOVER_STARTS):
            start = None
            if attempt:  # another branch of the arm: start the solve from a seeded random configuration
                rng = np.random.default_rng(seed_for(self.arm.name, "handover-start", str(attempt), seed=self.seed))
                start = rng.uniform(model.lower, model.upper)
            todo = [i for i in todo if len(self.out.handover.get(keys[i], ())) < HANDOVER_CONFIGS]
            qs = self._ik([tools[i] for i in todo], "handover", q_init=start, attempt=attempt)
            self._keep_handovers([(keys[i], q) for i, q in zip(todo, qs) if q is not None])
            if not attempt:  # no retry for a target no branch reaches (the analytic search: Panda arms only)
                missed = [i for i, q in zip(todo, qs) if q is None]
                none = {i for i, n in zip(missed, self.arm.no_branches([tools[i] for i in missed])) if n}
                todo = [i for i in todo if i not in none]

    def _keep_handovers(self, found: list[tuple[tuple[str, str, str], np.ndarray]]) -> None:
        """Keep each (key, q) of ``found``, in order, as a handover configuration of its key if it differs from
        those kept and is free of itself, of the fixed objects and of the arms at home, with the movable
        objects its links and the object held at the point hit.  The collision checks of all of them run
        together (as :meth:`_branches`'), the answers those of one configuration at a time."""
        kept = {key: self.out.handover.setdefault(key, []) for key, _ in found}
        fresh = [k for k, (key, q) in enumerate(found) if self._distinct(kept[key], q)]
        if not fresh:
            return
        objs = [found[k][0][0] for k in fresh]
        points = [found[k][0][1] for k in fresh]
        openings = [self.opening(obj, found[k][0][2]) for obj, k in zip(objs, fresh)]
        transforms = self._link_transforms(np.stack([found[k][1] for k in fresh])[:, None], openings)[:, 0]
        shapes, tolerance = self.arm.probes[0], self.world.tolerance
        good = ~self.arm.self_colliding_at(transforms)
        clear: set[int] = set()  # fresh indices whose links hit nothing fixed, no arm at home (its partner's too)
        ok = np.flatnonzero(good)
        if len(ok):
            probes = Probes.batch(shapes, transforms[ok], tolerance)
            fixed = self.world.slot_hits(probes, "fixed", own=[objs[x] for x in ok.tolist()])
            clear = {x for x, hits in zip(ok.tolist(), fixed) if not hits}
        movables: dict[int, set[str]] = {}
        if clear:
            rows = sorted(clear)
            own = [objs[x] for x in rows]
            hit = self.world.slot_hits(Probes.batch(shapes, transforms[rows], tolerance), "movable", own=own)
            held = [(objs[x], translation(*self.scene.handover_points[points[x]])[None]) for x in rows]
            more = self.world.slot_hits(self._objects(held), "movable", own=own)
            movables = {x: h | m for x, h, m in zip(rows, hit, more)}
        fresh_at = {k: x for x, k in enumerate(fresh)}
        for k, (key, q) in enumerate(found):
            at = fresh_at.get(k)
            if at is None or not self._distinct(kept[key], q):  # as one at a time: a twin of one kept meanwhile
                continue
            self.out.collision_checks += 1
            if at in clear:
                kept[key].append(HandoverConfig(q, frozenset(movables[at])))

    @staticmethod
    def _distinct(kept: list[HandoverConfig], q: np.ndarray) -> bool:
        """Whether ``q`` differs from every configuration of ``kept`` (by :data:`DISTINCT_CONFIG` in a joint)."""
        return not any(np.max(np.abs(c.q - q)) < DISTINCT_CONFIG for c in kept)


def _robot_worker(args: tuple[SceneSpec, str, int]) -> RobotFacts:
    scene, robot, seed = args
    if not approaches(scene.robot(robot).kind):  # path mode (box-moving)
        from mrgc.geometry.path_predicates import PlanarEvaluator  # coal's lattice: only for planar robots

        return PlanarEvaluator(scene, robot, seed).run()
    return RobotEvaluator(scene, robot, seed).run()


def _spots_worker(args: tuple[SceneSpec, str, int, Asks]) -> tuple[Spots, int, int]:
    scene, robot, seed, asked = args
    ev = RobotEvaluator(scene, robot, seed)
    return ev.spots(asked), ev.out.ik_solves, ev.out.collision_checks


def _relays(
    scene: SceneSpec, facts: set[Fact], seed: int, n: int, deadline: float | None
) -> tuple[set[Fact], int, int] | None:
    """``enable-relay`` facts for the goal objects that need them (:mod:`mrgc.geometry.relays`), with their
    ``occludes-relay`` facts and the IK solves and collision checks they took; None when ``deadline`` passed
    first.  The fixed objects' tops are asked for the objects that got no relay through a region, and for those
    whose every relay through a region has objects in the way at its spot (a crowded start region: a spot on
    the table may be free)."""
    arms = {r.name for r in scene.robots if approaches(r.kind)}
    out: set[Fact] = set()
    ik = checks = 0
    stuck = stranded(scene, facts)
    for surfaces in (False, True):  # the regions first; fixed objects' tops for the objects still stuck
        stuck = [o for o in stuck if o not in free_relays(out)]
        asked = {r: a for r, a in relay_asks(scene, facts, stuck, surfaces).items() if r in arms} if stuck else {}
        if not asked:
            continue
        jobs = [(scene, r, seed, a) for r, a in sorted(asked.items())]
        answers = _map(_spots_worker, jobs, min(n, len(jobs)), deadline)
        if answers is None:
            return None
        spots = {job[1]: ans[0] for job, ans in zip(jobs, answers)}
        out |= relay_facts(scene, facts, spots)
        ik, checks = ik + sum(a[1] for a in answers), checks + sum(a[2] for a in answers)
    return out, ik, checks


def _load_shared(panda: bool) -> None:
    """Load here, before the workers fork, what each of them would otherwise load for itself: numpy's random
    generators (the IK restarts, placements and handover starts draw from them; about 18 ms of CPU an
    import) and, with an arm of a Panda's kinematics (``panda``), the analytic IK's solver module.  Forked
    workers share them; this process needs the generators afterwards anyway (grounding)."""
    import numpy.random  # noqa: F401  (numpy loads it on first use of np.random)

    if panda:
        from mrgc.geometry.ik_analytic import load_solver

        load_solver()


def _map(fn: Callable[[J], R], jobs: list[J], workers: int, deadline: float | None) -> list[R] | None:
    """The jobs in ``workers`` processes (:mod:`mrgc.workers`); with a ``deadline`` (a ``time.perf_counter``
    value), None when it passes first."""
    if deadline is None:
        return map_in_workers(fn, jobs, workers)
    return map_until(fn, jobs, workers, deadline - time.perf_counter())


def compute_facts(
    scene: SceneSpec, seed: int = 0, workers: int | None = None, deadline: float | None = None
) -> FactsResult:
    """Every fact of ``scene`` (see the module docstring); ``workers`` processes (default: one per robot;
    capped at one per robot and one per usable core; 1 runs everything in this process; see
    :mod:`mrgc.workers` for what happens to them on an error or a signal).  With a ``deadline`` (a
    ``time.perf_counter`` value) the work always runs in worker processes and stops when it passes: the
    result is then :attr:`~mrgc.geometry.facts.FactsResult.complete` False with no facts."""
    t0 = time.perf_counter()
    robots = [r.name for r in scene.robots]
    n = worker_count(workers, len(robots))
    jobs = [(scene, r, seed) for r in robots]
    from mrgc.geometry.ik_analytic import panda_chain

    panda = False
    for spec in scene.robots:  # every arm's model, link hulls and Panda reading built here: errors surface once,
        if approaches(spec.kind):  # forked workers share them (and the pybullet check of its URDF), grounding too
            arm = Arm(spec)
            _ = arm.hulls
            panda |= panda_chain(arm.model) is not None
    _load_shared(panda)
    per_robot = _map(_robot_worker, jobs, n, deadline)
    t_robots = time.perf_counter() - t0
    facts: set[Fact] = set()
    handovers = relayed = None
    if per_robot is not None:
        for rf in per_robot:
            facts.update(rf.facts)
        handovers = _handovers(scene, dict(zip(robots, per_robot)), deadline)
    if handovers is not None:
        facts.update(handovers)
        relayed = _relays(scene, facts, seed, n, deadline)
    if per_robot is None or relayed is None:
        return FactsResult([], {"seconds": time.perf_counter() - t0, "workers": n, "facts": 0}, complete=False)
    relays, relay_ik, relay_checks = relayed
    facts.update(relays)
    for m in scene.movable:
        for reg in scene.regions:
            if inside(reg, m.shape, m.pose):
                facts.add(Fact("in-region", (m.name, reg.name)))
    order = {
        "in-region": 0,
        "reachable-pick": 1,
        "reachable-place": 2,
        "occludes-pick": 3,
        "occludes-goal-place": 4,
        "enable-goal-handover": 5,
        "enable-relay": 6,
        "occludes-handover": 7,
        "occludes-relay": 8,
    }
    stats = {
        "seconds": time.perf_counter() - t0,
        "robot_seconds": t_robots,
        "workers": n,
        "ik_solves": sum(rf.ik_solves for rf in per_robot) + relay_ik,
        "collision_checks": sum(rf.collision_checks for rf in per_robot) + relay_checks,
        "facts": len(facts),
    }
    return FactsResult(sorted(facts, key=lambda f: (order[f.predicate], f.args)), stats)


def _handovers(scene: SceneSpec, per_robot: dict[str, RobotFacts], deadline: float | None = None) -> set[Fact] | None:
    """``enable-goal-handover`` from the robots' handover configurations, checking robot–robot collisions, and
    ``occludes-handover`` for the movable objects in the way of the exchange (module docstring); None when
    ``deadline`` passed first (it is read per goal object)."""
    #: (M, g1, g2, R1, R2) -> the movable objects the exchange hits at the pair of configurations (over every
    #: handover point) that hits the fewest
    blocked: dict[tuple[str, str, str, str, str], frozenset[str]] = {}
    arms = _ArmPoses(scene)
    for obj in scene.goal:
        if deadline is not None and time.perf_counter() > deadline:
            return None
        for (r1, (_, point, g1), c1s), (r2, (_, point2, g2), c2s) in itertools.permutations(
            ((r, k, cs) for r, rf in per_robot.items() for k, cs in rf.handover.items() if k[0] == obj), 2
        ):
            key = (obj, g1, g2, r1, r2)
            if r1 == r2 or point2 != point or blocked.get(key, True) == frozenset():
                continue  # the same arm, another point, or a pair already found free of every object
            hits = _exchange_hits(scene, arms, obj, (r1, g1, c1s), (r2, g2, c2s))
            if hits is not None and (key not in blocked or len(hits) < len(blocked[key])):
                blocked[key] = hits
    out: set[Fact] = set()
    for key, hits in blocked.items():
        out.add(Fact("enable-goal-handover", key))
        out.update(Fact("occludes-handover", (o, *key)) for o in sorted(hits))
    return out


def _exchange_hits(
    scene: SceneSpec,
    arms: "_ArmPoses",
    obj: str,
    giver: tuple[str, str, list[HandoverConfig]],
    taker: tuple[str, str, list[HandoverConfig]],
) -> frozenset[str] | None:
    """The movable objects hit at the pair of the two arms' exchange configurations (robot, grasp,
    configurations) that hits the fewest, among the pairs whose arms do not collide; None when every pair
    collides."""
    (r1, g1, c1s), (r2, g2, c2s) = giver, taker
    shape = scene.body(obj).shape
    w1, w2 = finger_opening(scene.grasp(g1), shape), finger_opening(scene.grasp(g2), shape)
    best: frozenset[str] | None = None
    for c1 in c1s:
        for c2 in c2s:
            hits = c1.movables | c2.movables
            if best is not None and (len(hits), sorted(hits)) >= (len(best), sorted(best)):
                continue
            if not posed_collide(arms.at(r1, c1.q, w1), arms.at(r2, c2.q, w2)):
                best = hits
    return best


class _ArmPoses:
    """The probed links of the scene's arms at handover configurations, posed once per (arm, configuration,
    finger opening) however many partners they are checked against."""

    def __init__(self, scene: SceneSpec) -> None:
        self.scene = scene
        self.arms: dict[str, Arm] = {}
        self.posed: dict[tuple[str, bytes, float], Posed] = {}

    def at(self, robot: str, q: np.ndarray, opening: float) -> Posed:
        """The links of ``robot`` at ``q``, its fingers ``opening`` apart."""
        key = (robot, np.asarray(q, dtype=float).tobytes(), opening)
        if key not in self.posed:
            arm = self.arms.get(robot)
            if arm is None:
                arm = self.arms[robot] = Arm(self.scene.robot(robot))
            self.posed[key] = Posed.batch(arm.probes[0], arm.link_transforms(np.asarray(q)[None], opening)[0])
        return self.posed[key]
