"""A robot arm placed in a scene: its kinematic model, base pose, tool centre point and link hulls.

Everything the predicates and grounding ask of a robot goes through here: where the end effector must be
for a tool pose, where the links are at a configuration (as collision probes), where a held object is, and
whether the arm collides with itself (:meth:`Arm.self_collides`: the link pairs of
:attr:`RobotModel.self_collision_pairs` kept :data:`SELF_CLEARANCE` apart; docs/geometry.md).
"""

from __future__ import annotations

from functools import cached_property
from typing import Mapping

import numpy as np

from mrgc.geometry.collision import TOLERANCE, CollisionShape, ConvexHull, PairCheck, Posed, collision_shape
from mrgc.geometry.fk import ee_pose, fk_world
from mrgc.geometry.grasps import finger_opening, grasp_transform
from mrgc.geometry.kinematics import RobotModel, gripper_frames, model_for_kind
from mrgc.geometry.robot import Held, Rest, Volume
from mrgc.geometry.scene import RobotSpec
from mrgc.geometry.transforms import from_pose, inverse
from mrgc.language.model import GraspSpec, Shape

#: how far apart (m) the planner keeps two links of one arm that the self-collision rule does not exempt
#: (:attr:`RobotModel.self_collision_pairs`).  The validator calls a self-collision a penetration deeper than
#: 1 mm in pybullet, whose link meshes (convex hulls, their 1 mm margin removed) agree with these hulls to
#: about 0.05 mm; the clearance covers that and what moves between two configurations the planner checks
SELF_CLEARANCE = 0.003

#: link hulls by model key (shared collision shapes: immutable once built)
_HULLS: dict[str, dict[int, CollisionShape]] = {}


class Arm:
    """A fixed-base arm of a scene (one per robot; built once per process): the ``fixed`` kind of
    :class:`~mrgc.geometry.robot.Robot`.  Its configurations are joint vectors; it holds an object in its tool
    frame, its fingers at the grasp's opening; it picks and places along an approach found by IK, and between
    its motions stands where the execution model puts it."""

    #: its pick and place are approaches found by IK (:attr:`Robot.approaches <mrgc.geometry.robot.Robot.approaches>`)
    approaches = True
    #: it stands where the execution model puts it, phase by phase (:attr:`Robot.parks
    #: <mrgc.geometry.robot.Robot.parks>`)
    parks = False

    def __init__(self, spec: RobotSpec) -> None:
        self.spec = spec
        self.name = spec.name
        self.model: RobotModel = model_for_kind(spec.kind, spec.base_dir)
        self.base = spec.base
        self.base_inv = inverse(spec.base)
        self.tcp = from_pose(spec.kind.tcp) if spec.kind.tcp is not None else np.eye(4)
        self.tcp_inv = inverse(self.tcp)
        home = np.array(spec.kind.home, dtype=float) if spec.kind.home else None
        self.home = (
            self.model.clamp(home[: self.model.dof])
            if home is not None and len(home) >= self.model.dof
            else self.model.clamp((self.model.lower + self.model.upper) / 2)
        )

    @cached_property
    def hulls(self) -> dict[int, CollisionShape]:
        """The collision hull of every :attr:`~mrgc.geometry.kinematics.Link.solid` link, by link index
        (built once per model and process: the arms of one kind share them)."""
        hulls = _HULLS.get(self.model.key)
        if hulls is None:
            hulls = _HULLS[self.model.key] = {
                link.index: collision_shape(ConvexHull(np.asarray(link.points, dtype=float)))
                for link in self.model.links
                if link.solid
            }
        return hulls

    @cached_property
    def probes(self) -> tuple[list[CollisionShape], list[int]]:
        """Collision hulls of the links that can hit anything: every solid link but the mount
        (:attr:`RobotModel.mount`: the root link and the links fixed to it, bolted in place, whatever they are
        called), which stands on what the arm is mounted on."""
        mount = set(self.model.mount)
        index = [k for k in self.hulls if k not in mount]
        return [self.hulls[k] for k in index], index

    @cached_property
    def hand(self) -> list[int]:
        """Positions in :attr:`probes` of the end-effector link and the links below it (the hand and its
        fingers): where they are follows from the tool pose and the finger opening alone, whatever the joints."""
        below = set(gripper_frames(self.model))
        return [i for i, k in enumerate(self.probes[1]) if k in below]

    def hand_volume(self, q: np.ndarray, opening: float | None = None) -> Volume:
        """The :attr:`hand`'s hulls at each of configurations ``q`` (C, dof), the fingers ``opening`` apart."""
        shapes = self.probes[0]
        transforms = self.link_transforms(np.atleast_2d(q), opening)
        return [(shapes[i], t[i]) for t in transforms for i in self.hand]

    @cached_property
    def base_hulls(self) -> tuple[tuple[str, CollisionShape, np.ndarray], ...]:
        """The mount's solid links (name, hull, world pose): left out of :attr:`probes` (they cannot move,
        and this arm's own links start on them), they are obstacles to every other arm."""
        mount = [k for k in self.model.mount if k in self.hulls]
        if not mount:
            return ()
        poses = fk_world(self.model, self.home[None], self.base)[0]
        return tuple((self.model.links[k].name, self.hulls[k], poses[k]) for k in mount)

    @cached_property
    def _self_check(self) -> PairCheck:
        """The self-collision check over the solid links: the mount's solid links first, then the
        :attr:`probes` in their order."""
        index = [k for k in self.model.mount if k in self.hulls] + self.probes[1]
        at = {k: i for i, k in enumerate(index)}
        pairs = [(at[a], at[b]) for a, b in self.model.self_collision_pairs]
        return PairCheck([self.hulls[k] for k in index], pairs, SELF_CLEARANCE)

    def self_colliding(self, q: np.ndarray, opening: float | None = None) -> np.ndarray:
        """Whether the arm collides with itself at each configuration of ``q`` (C, dof): two links of
        :attr:`RobotModel.self_collision_pairs` within :data:`SELF_CLEARANCE`, the fingers ``opening`` apart
        (None: fully open).  A (C,) bool array."""
        return self.self_colliding_at(self.link_transforms(np.atleast_2d(q), opening))

    def self_colliding_at(self, transforms: np.ndarray) -> np.ndarray:
        """:meth:`self_colliding` for the probed links' world transforms ((C, L, 4, 4), as
        :meth:`link_transforms` gives them): a (C,) bool array."""
        out: np.ndarray = self._self_check.colliding(self._with_base(transforms))
        return out

    def self_collides(self, q: np.ndarray, opening: float | None = None) -> bool:
        """Whether the arm collides with itself at some configuration of ``q`` ((C, dof) or (dof,)); stops at
        the first that does."""
        return self.self_collides_at(self.link_transforms(np.atleast_2d(q), opening))

    def self_collides_at(self, transforms: np.ndarray) -> bool:
        """:meth:`self_collides` for the probed links' world transforms as :meth:`link_transforms` gives them
        ((C, L, 4, 4)): a caller that has them already (collision probes) saves the forward kinematics."""
        return self._self_check.collides(self._with_base(transforms))

    def held_collides_at(self, transforms: np.ndarray, shape: CollisionShape, poses: np.ndarray) -> bool:
        """Whether an object of ``shape`` this arm holds, at world ``poses`` (C, 4, 4), comes within
        :data:`SELF_CLEARANCE` of one of the arm's own solid links (the mount's included) at the probed links'
        ``transforms`` (C, L, 4, 4), the :attr:`hand`'s excepted: the hand and its fingers hold it where the
        grasp puts them, the same all along a motion (the validator's ``collision-self-held``: a carry that
        swings the object into the arm's base or shoulder)."""
        check = self._held_check(shape, self._held_checks, with_links=False)
        return check.collides(self._with_base(transforms, poses))

    def collides_with_itself_at(
        self, transforms: np.ndarray, shape: CollisionShape | None = None, poses: np.ndarray | None = None
    ) -> bool:
        """:meth:`self_collides_at` or, holding an object of ``shape`` at ``poses``, :meth:`held_collides_at`:
        the same answer from one check of both sets of pairs (the links' pairs, then the held object's; one
        clearance), whose bounding spheres are placed once for both."""
        if shape is None or poses is None:
            return self.self_collides_at(transforms)
        check = self._held_check(shape, self._both_checks, with_links=True)
        return check.collides(self._with_base(transforms, poses))

    def _held_check(
        self, shape: CollisionShape, kept: dict[int, tuple[CollisionShape, PairCheck]], with_links: bool
    ) -> PairCheck:
        """The pair check of the solid links ([mount] + probes, :attr:`_self_check`'s order) and a held object
        of ``shape`` after them: the held object's pairs (every link but the :attr:`hand`'s), after the links'
        own pairs when ``with_links``; made once per shape into ``kept``."""
        made = kept.get(id(shape))
        if made is None:
            hand = {self.probes[1][i] for i in self.hand}
            links = [k for k in self.model.mount if k in self.hulls] + self.probes[1]
            pairs = [(len(links), j) for j, k in enumerate(links) if k not in hand]
            if with_links:
                pairs = [(int(a), int(b)) for a, b in self._self_check.pairs.tolist()] + pairs
            check = PairCheck([self.hulls[k] for k in links] + [shape], pairs, SELF_CLEARANCE)
            made = kept[id(shape)] = (shape, check)  # the shape kept alive: its id stays its own
        return made[1]

    @cached_property
    def _no_branch_memo(self) -> dict[bytes, bool]:
        """:meth:`no_branches`' answers from home, by end-effector target (its bytes)."""
        return {}

    @cached_property
    def _held_checks(self) -> dict[int, tuple[CollisionShape, PairCheck]]:
        """The :meth:`held_collides_at` checks made so far, by held shape."""
        return {}

    @cached_property
    def _both_checks(self) -> dict[int, tuple[CollisionShape, PairCheck]]:
        """The :meth:`collides_with_itself_at` checks made so far, by held shape."""
        return {}

    @cached_property
    def _base_poses(self) -> np.ndarray:
        """The world poses of the mount's solid links (:attr:`base_hulls`), (B, 4, 4)."""
        return np.stack([pose for _, _, pose in self.base_hulls]) if self.base_hulls else np.zeros((0, 4, 4))

    def _with_base(self, transforms: np.ndarray, poses: np.ndarray | None = None) -> np.ndarray:
        """The probed links' transforms (C, L, 4, 4) with the mount's solid links' (fixed) in front, and a
        held object's ``poses`` (C, 4, 4) after them when given."""
        t = np.asarray(transforms, dtype=float).reshape(-1, len(self.probes[1]), 4, 4)
        base = self._base_poses
        parts = [np.broadcast_to(base, (len(t),) + base.shape)] if len(base) else []
        parts.append(t)
        if poses is not None:
            parts.append(np.asarray(poses, dtype=float).reshape(len(t), 1, 4, 4))
        return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1)

    def ee_target(self, tool_world: np.ndarray) -> np.ndarray:
        """The end-effector pose (base frame) that puts the tool centre point at ``tool_world`` (a 4×4, or
        (..., 4, 4) for many)."""
        target: np.ndarray = self.base_inv @ tool_world @ self.tcp_inv
        return target

    def tool_world(self, q: np.ndarray) -> np.ndarray:
        """Tool centre point pose(s) in the world at configuration(s) ``q``."""
        tool: np.ndarray = self.base @ ee_pose(self.model, q) @ self.tcp
        return tool

    def link_transforms(self, q: np.ndarray, opening: float | None = None) -> np.ndarray:
        """World transforms of the probed links: ``q.shape[:-1] + (L, 4, 4)``, the fingers ``opening``
        metres apart (None: fully open, as the URDF's upper limits)."""
        return self._frames(q, opening)[..., self.probes[1], :, :]

    def _frames(self, q: np.ndarray, opening: float | None) -> np.ndarray:
        """World frames of every link at ``q`` (``q.shape[:-1] + (links, 4, 4)``), the fingers ``opening`` apart."""
        fingers = None if opening is None else self.model.finger_value(opening)
        return fk_world(self.model, q, self.base, fingers)

    def no_branch(self, tool_world: np.ndarray) -> bool:
        """Whether the analytic solver (:mod:`mrgc.geometry.ik_analytic`; arms with a Panda's kinematics only,
        else False) finds no configuration within the joint limits putting the tool at ``tool_world``: over
        the q7 grid, every branch out of the limits or off the target (:func:`~mrgc.geometry.ik_analytic.
        reaches`).  A numeric solve that failed from its start need then not be retried from others, nor one
        asked at all (the analytic search covers what their random starts would, but for solutions at q7
        between its grid values or in q7's own margin: measured, docs/geometry.md)."""
        return self.no_branches([tool_world])[0]

    def no_branches(self, tool_worlds: list[np.ndarray], starts: np.ndarray | None = None) -> list[bool]:
        """:meth:`no_branch` for each of ``tool_worlds``, solved in one batch; ``starts`` (one configuration
        per tool pose; home by default) only say where the search begins, which is all the cost of a
        reachable pose's answer: from a configuration near it, one call of the solver (whether a branch
        exists over the q7 grid does not depend on the start)."""
        from mrgc.geometry.ik import TOL_POS, TOL_ROT
        from mrgc.geometry.ik_analytic import panda_chain, reaches

        chain = panda_chain(self.model)
        if chain is None or not tool_worlds:
            return [False] * len(tool_worlds)
        targets = self.ee_target(np.stack(tool_worlds))
        if starts is not None:
            return [not ok for ok in reaches(self.model, chain, targets, starts, TOL_POS, TOL_ROT)]
        # from home, remembered per target (grounding asks again for the same poses, skeleton after skeleton)
        memo = self._no_branch_memo
        keys = [t.tobytes() for t in targets]
        todo = [k for k, key in enumerate(keys) if key not in memo]
        if todo:
            refs = np.tile(self.home, (len(todo), 1))
            for k, ok in zip(todo, reaches(self.model, chain, targets[todo], refs, TOL_POS, TOL_ROT)):
                memo[keys[k]] = not ok
        return [memo[key] for key in keys]

    def in_reach(self, point: np.ndarray, margin: float = 0.0) -> bool:
        """Whether a world point can be within reach of the tool (cheap pre-filter)."""
        local = self.base_inv[:3, :3] @ point + self.base_inv[:3, 3]
        return bool(
            np.linalg.norm(local - self.model.shoulder) <= self.model.reach + np.linalg.norm(self.tcp[:3, 3]) + margin
        )

    def comfort(self, tools: np.ndarray, share: float) -> np.ndarray:
        """For each world tool pose of ``tools`` (..., 4, 4): 0 when the end effector lies within ``share`` of
        the reach bound from the shoulder, else its distance from the shoulder (m): the far corners of a bin at
        the edge of the reach fail IK after every restart."""
        far = np.linalg.norm(self.ee_target(tools)[..., :3, 3] - self.model.shoulder, axis=-1)
        out: np.ndarray = np.where(far <= share * self.model.reach, 0.0, far)
        return out

    # ------------------------------------------------------------------ volumes (the Robot protocol)
    def hold(self, shape: Shape, grasp: str, grasps: Mapping[str, GraspSpec]) -> tuple[float | None, np.ndarray]:
        """The finger opening holding an object of ``shape`` with ``grasp`` and the object's pose in the tool
        frame (the inverse grasp transform); KeyError for a grasp without geometry."""
        spec = grasps[grasp]
        return finger_opening(spec, shape), np.linalg.inv(grasp_transform(spec, shape))

    def volume(
        self, configs: np.ndarray, held: Held | None = None, opening: float | None = None
    ) -> tuple[Volume, np.ndarray]:
        """The probed link hulls at each of ``configs`` (C, dof), the fingers ``opening`` apart (None: fully
        open), then the held object (shape, pose in the tool frame) at each; and the links' world transforms
        ((C, L, 4, 4), for :meth:`self_collides_at`)."""
        shapes, kind, flat, transforms, _ = self._pieces(configs, held, opening)
        return list(zip(map(shapes.__getitem__, kind.tolist()), list(flat))), transforms

    def posed(
        self, configs: np.ndarray, held: Held | None = None, opening: float | None = None
    ) -> tuple[Posed, np.ndarray, np.ndarray | None]:
        """:meth:`volume` as the collision kernel reads it (:class:`~mrgc.geometry.collision.Posed`: the same
        pieces in the same order, made from the arrays without a list of pieces between), the links' world
        transforms (C, L, 4, 4), and the held object's world poses (C, 4, 4; None when it holds nothing)."""
        shapes, kind, flat, transforms, poses = self._pieces(configs, held, opening)
        boxes = self._boxes(held[0] if held is not None else None)
        return Posed(shapes, kind, flat, TOLERANCE, boxes=boxes), transforms, poses

    def _pieces(
        self, configs: np.ndarray, held: Held | None, opening: float | None
    ) -> tuple[list[CollisionShape], np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """The pieces of :meth:`volume` as arrays: the distinct shapes, each piece's shape index and world
        transform (links of each configuration in turn, then the held object at each), the links' transforms
        (C, L, 4, 4) and the held object's poses (C, 4, 4; None when it holds nothing)."""
        configs = np.atleast_2d(configs)
        shapes: list[CollisionShape] = list(self.probes[0])
        frames = self._frames(configs, opening)  # every link's: the end effector's too
        transforms = frames[:, self.probes[1]]
        kind = self._kind(len(configs), held is not None)
        flat = transforms.reshape(-1, 4, 4)
        poses = None
        if held is not None:
            shape, in_tool = held
            poses = frames[:, self.model.ee_link] @ self.tcp @ in_tool  # the tool pose (:meth:`tool_world`)
            shapes.append(shape)
            flat = np.concatenate([flat, poses])
        return shapes, kind, flat, transforms, poses

    def _kind(self, configs: int, holding: bool) -> np.ndarray:
        """Which shape each piece of :meth:`_pieces` is: the probes' indices at each of ``configs``
        configurations in turn, then (``holding``) the held object's index (after the probes') at each; kept
        read-only for the few counts motion checks ask for (one configuration, a motion's batches)."""
        key = (configs, holding)
        kind = self._kinds.get(key)
        if kind is None:
            links = len(self.probes[0])
            kind = np.tile(np.arange(links), configs)
            if holding:
                kind = np.concatenate([kind, np.full(configs, links)])
            kind.setflags(write=False)
            if len(self._kinds) < 256:
                self._kinds[key] = kind
        return kind

    @cached_property
    def _kinds(self) -> dict[tuple[int, bool], np.ndarray]:
        """:meth:`_kind`'s arrays by (configurations, holding)."""
        return {}

    def _boxes(self, held: CollisionShape | None) -> np.ndarray:
        """The :attr:`CollisionShape.box` of each shape of :meth:`_pieces` stacked ((S, 2, 3)): the probes', then
        the held object's; made once per held shape."""
        key = id(held) if held is not None else None
        kept = self._boxes_of.get(key)
        if kept is None:
            boxes = np.stack([s.box for s in self.probes[0]] + ([held.box] if held is not None else []))
            kept = self._boxes_of[key] = (held, boxes)  # the shape kept alive: its id stays its own
        return kept[1]

    @cached_property
    def _boxes_of(self) -> dict[int | None, tuple[CollisionShape | None, np.ndarray]]:
        """:meth:`_boxes`' arrays by held shape (its id; None: nothing held)."""
        return {}

    def volumes(self, configs: np.ndarray, held: Held | None = None, opening: float | None = None) -> list[Volume]:
        """:meth:`volume` at each of ``configs`` separately (one volume per configuration: a motion's samples,
        the held object after the links), from one batched forward kinematics."""
        configs = np.atleast_2d(configs)
        volume = self.volume(configs, held, opening)[0]
        links = len(self.probes[0])
        out = [volume[k * links : (k + 1) * links] for k in range(len(configs))]
        if held is not None:  # the held object's pieces follow the links' (one per configuration)
            for k, piece in enumerate(volume[links * len(configs) :]):
                out[k].append(piece)
        return out

    def rest(self) -> Rest:
        """The probed links at home (fingers fully open) and the mount's solid links (:attr:`base_hulls`)."""
        return Rest(self.volume(self.home[None])[0], self.base_hulls)
