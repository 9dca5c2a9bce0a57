"""Approaches and handovers: an arm's configurations for a grasp of an object at a pose, found by IK.

To pick (or place) an object with a grasp, the arm's tool goes to the grasp pose along the grasp's approach
axis: the *approach* is the pre-grasp (backed off by :data:`~mrgc.geometry.grasps.APPROACH`) and
:data:`~mrgc.geometry.conventions.APPROACH_SAMPLES` configurations to the grasp, pre-grasp first, both ends by
IK from one branch (:meth:`Approaches._approach_configs`).  An approach is kept when, checked at every
:data:`APPROACH_CHECK` of joint motion, it collides with nothing: not with itself, fixed bodies, the other arms
where they stand in the phase, the objects to avoid, what the step's other robots sweep meanwhile (``busy``),
and, at its last configuration, what they do in the later phases it stands there (``after``).  Attempts start
from home, then from seeded random starts; a pose no start solves is out of reach after :data:`IK_GIVE_UP`, or
after the first when the analytic solver has no branch for it either (:meth:`Arm.no_branch
<mrgc.geometry.arm.Arm.no_branch>`); an approach whose pre-grasp (the same tool pose in every attempt) has no
numeric answer and no analytic branch either is out of reach at once.
A *handover* is both arms at their exchange configurations holding the object at a handover point, not
colliding with each other (:data:`HANDOVER_PAIRS` rounds of drawing).
"""

from __future__ import annotations

from typing import Callable, Iterable, Iterator, Mapping

import numpy as np

from mrgc.geometry.answers import BUSY, SELF, Answer, GroundStatus
from mrgc.geometry.arm import Arm
from mrgc.geometry.arm_paths import joint_line
from mrgc.geometry.collision import Posed, posed_collide
from mrgc.geometry.conventions import APPROACH_SAMPLES, PATH_RESOLUTION, seed_for
from mrgc.geometry.grasps import APPROACH, fits, grasp_transform, pregrasp_transform
from mrgc.geometry.ik import IKResult, solve_ik_many
from mrgc.geometry.robot import Pieces, Volume
from mrgc.geometry.stances import Stance
from mrgc.geometry.step_world import named_body
from mrgc.geometry.transforms import translation
from mrgc.geometry.volumes import Volumes

#: largest joint motion (rad) between the configurations of an approach that are checked: half the
#: validator's resolution, so that the validator, sampling at other times, does not find the fingers deeper
#: in a neighbour than the 1 mm it tolerates where the planner found them clear (a 5-sample approach checked
#: at 4 times its samples let the validator reject whole plans for 1.1 mm finger overlaps)
APPROACH_CHECK = PATH_RESOLUTION / 2
#: IK attempts (each with its restarts) after which a pose none of them solved is called out of reach, as
#: phase 1 does (predicates.IK_SEEDS); attempts that solve it but collide go on to other branches
IK_GIVE_UP = 3
#: what :meth:`Approaches._attempt` answers when no IK attempt of an approach can succeed
OUT_OF_REACH = "out of reach"
#: pairs of exchange configurations tried for a handover before the two arms are said to collide
HANDOVER_PAIRS = 6
#: an approach's last segment starts at most this many equal shares of the back-off from the grasp (the
#: validator allows 2)
CONTACT_START = 1.5
#: the contact segment (an approach's last) keeps the tool within this of the grasp's approach line (its z
#: axis through the grasp position) and of its orientation, at :data:`CONTACT_CHECKS` equally spaced
#: configurations (the validator's rule: 10 mm and 0.05 rad at 17; a joint-space line between a pre-grasp and
#: a grasp from different IK branches can swing the tool 14 mm off it: 10 complete plans of a generated 6-arm
#: scene were rejected for one such place)
CONTACT_OFF = 0.008
CONTACT_TURN = 0.04
CONTACT_CHECKS = 17


def _out_of_reach(ik: str, attempt: int, status: GroundStatus, no_branch: Callable[[], bool]) -> bool:
    """Whether an approach whose IK attempt ``attempt`` failed (``ik``: the solver's status) gives up: the pose
    is provably out of reach (no other seed helps), or no attempt so far converged (none collided) and either
    :data:`IK_GIVE_UP` attempts have (phase 1 gives up there too) or ``no_branch()`` says the analytic solver
    has no branch for it either (:meth:`Arm.no_branch <mrgc.geometry.arm.Arm.no_branch>`)."""
    if ik == "unreachable":
        return True
    return status is GroundStatus.NO_IK and (attempt + 1 >= IK_GIVE_UP or no_branch())


def on_the_line(arm: Arm, tool: np.ndarray, start: np.ndarray, end: np.ndarray) -> bool:
    """Whether the joint-space line from ``start`` to ``end`` (an approach's contact segment) keeps the tool
    within :data:`CONTACT_OFF` of the line along ``tool``'s z axis through its position and within
    :data:`CONTACT_TURN` of its orientation, at :data:`CONTACT_CHECKS` equally spaced configurations."""
    s = np.linspace(0.0, 1.0, CONTACT_CHECKS)[:, None]
    poses = arm.tool_world(start[None] * (1 - s) + end[None] * s)
    d = poses[:, :3, 3] - tool[:3, 3]
    axis = tool[:3, 2]
    off = np.linalg.norm(d - (d @ axis)[:, None] * axis[None], axis=1)
    cos = (np.einsum("kij,ij->k", poses[:, :3, :3], tool[:3, :3]) - 1.0) / 2.0  # trace(R_grasp^T R) = 1 + 2 cos
    turn = np.arccos(np.clip(cos, -1.0, 1.0))
    return bool(off.max() <= CONTACT_OFF and turn.max() <= CONTACT_TURN)


class Approaches(Volumes):
    """An arm's pick, place and handover configurations (see the module docstring)."""

    def _approach(
        self,
        robot: str,
        obj: str,
        grasp: str,
        pose: np.ndarray,
        key: str,
        avoid: Iterable[str],
        attempts: int = 8,
        approach: bool = True,
        held: bool = False,
        busy: Pieces = (),
        from_home: bool = True,
        after: Pieces = (),
        partner: tuple[str, ...] = (),
    ) -> Answer:
        spec = self.scene.grasp_specs.get(grasp)
        arm = self.arm(robot)
        if spec is None or not fits(spec, self.scene.body(obj).shape, arm.spec.kind):
            return Answer(GroundStatus.NO_IK)  # no geometry, or the gripper does not open wide enough
        g_t = grasp_transform(spec, self.scene.body(obj).shape)
        avoid = tuple(a for a in avoid if a != obj)
        blockers: set[str] = set()
        status = GroundStatus.NO_IK
        moving = self._busy(busy)
        clash: tuple[str, Volume] | None = None  # the last attempt's collision not with ``avoid``: told at the end
        phase = key.split(":")[0]  # "pick", "place" or "handover"
        static = True  # every attempt so far failed on what never moves (IK, fixed bodies, bases)
        asked: dict[str, bool] = {}  # the analytic solver's answers for this approach's poses (asked once)
        for attempt in range(attempts):
            seed = seed_for(robot, obj, grasp, key, str(attempt), seed=self.seed)
            # the first attempt starts from home (the solution nearest it); the others from a start drawn from
            # their seed, or every attempt would converge to that same solution again
            start = (
                arm.home
                if attempt == 0 and from_home
                else np.random.default_rng(seed).uniform(arm.model.lower, arm.model.upper)
            )
            configs = self._attempt(arm, pose @ g_t, start, seed, attempt, status, approach, asked)
            if configs is OUT_OF_REACH:
                return Answer(GroundStatus.NO_IK, static=True)
            if not isinstance(configs, np.ndarray):
                continue
            # checked at every APPROACH_CHECK of joint motion (finer than the validator samples), with the
            # object in hand when placing
            dense = joint_line(configs, APPROACH_CHECK)
            volume = self.free_volume(robot, dense, holding=(obj, grasp) if held else None, grasp=(obj, grasp))
            if volume is None:  # the arm collides with itself: another branch may not (what never moves)
                status, clash = GroundStatus.COLLISION, ("self", [])
                continue
            self.queries += 1
            posed = Posed.of(volume)
            if self._fixed_clash(robot, obj, grasp, configs, posed, held, self._others(robot, phase)):
                status, clash = GroundStatus.COLLISION, ("fixed", volume)
                static = static and self._static_clash(robot, obj, posed, held)
                continue
            static = False  # this attempt failed (if it did) on what moves
            hit = self.world.probe_hits(posed, against=avoid) if avoid else set()
            if hit:
                blockers |= hit
                status = GroundStatus.COLLISION
                if self._hand_hits(robot, configs, (obj, grasp), avoid):
                    break  # the hand, where the grasp puts it in every attempt: no other branch helps
                continue
            clash = self._step_clash(robot, (obj, grasp), configs, posed, moving, after, partner)
            if clash is not None:
                status = GroundStatus.COLLISION
                continue
            return Answer(GroundStatus.OK, pose=pose, configs=configs)
        detail = ""
        if clash is not None and not blockers:
            detail = self._clash_detail(robot, phase, clash, ignore=() if held else (obj,), partner=partner)
        return Answer(status, blockers=blockers, detail=detail, static=static)

    def _hand_hits(self, robot: str, configs: np.ndarray, grip: tuple[str, str], avoid: tuple[str, ...]) -> bool:
        """Whether ``robot``'s hand (:attr:`Arm.hand <mrgc.geometry.arm.Arm.hand>`), at the pre-grasp or the grasp
        of an approach ``configs`` with the fingers at ``grip``'s opening, hits one of ``avoid``: those two tool
        poses are the grasp's, the same in every IK attempt (to the solver's 0.1 mm), so no other attempt
        clears it."""
        opening = self._grip(robot, *grip)[0]
        hand = self.arm(robot).hand_volume(configs[[0, -1]], opening)
        return bool(hand) and self.world.probe_collides(Posed.of(hand), against=avoid)

    def _step_clash(
        self,
        robot: str,
        grip: tuple[str, str],
        configs: np.ndarray,
        posed: Posed,
        moving: Posed | None,
        after: Pieces,
        partner: tuple[str, ...],
    ) -> tuple[str, Volume] | None:
        """What an approach ``configs`` (swept as ``posed``) of ``robot`` to ``grip`` (object, grasp) meets of the
        step's other robots, as ``(kind, volume)``: ``moving`` when another robot of the step moves there
        meanwhile, or moves or stands where the arm stands afterwards (``after``); ``partner`` when the arm at
        its exchange, holding the object, hits its handover partner at home then (``partner``: that arm's world
        group, :meth:`_at_home_then`); None when neither.  Where it stands, the arm is checked holding the object
        (where it has let the object go, the object is there too then: placed, or held by the taker), its volume
        made once for both checks."""
        if moving is not None and posed_collide(posed, moving):
            return "moving", []
        if not (after or partner):
            return None
        standing = self.arm_volume(robot, configs[-1:], holding=grip)
        here = Posed.of(standing)
        if after and posed_collide(here, self._volumes.posed(after)):
            return "moving", []
        if partner and self.world.probe_collides(here, against=partner):
            return "partner", standing
        return None

    def _at_home_then(self, partner: str, phase: str) -> tuple[str, ...]:
        """The world group of ``partner``'s home links when the execution model has it at home in ``phase`` of
        the declared step (:meth:`step`), else nothing."""
        if self.stance(partner, phase) is not Stance.HOME or self.robot(partner).parks:
            return ()
        self._homes()
        return (f"home:{partner}",)

    def _static_clash(self, robot: str, obj: str, volume: Posed, held: bool) -> bool:
        """Whether an approach volume hits what never moves: a fixed body or another arm's base link."""
        bases = tuple(b for b in self._bases if b != f"base:{robot}")
        return self.world.probe_collides(volume, against=("fixed", *bases), ignore=() if held else (obj,))

    def _fixed_clash(
        self, robot: str, obj: str, grasp: str, configs: np.ndarray, volume: Posed, held: bool, homes: tuple[str, ...]
    ) -> bool:
        """Whether an approach (``configs``, swept as ``volume``) hits a fixed object or an arm at home
        (``homes``), or, picking, the object it picks before its contact segment (the last one: the validator
        exempts the picked object there only)."""
        if self.world.probe_collides(volume, against=("fixed", *homes), ignore=() if held else (obj,)):
            return True
        if held or len(configs) < 3:
            return False
        early = self.arm_volume(robot, joint_line(configs[:-1], APPROACH_CHECK), grasp=(obj, grasp))
        return self.world.probe_collides(early, against=(obj,))

    def _attempt(
        self,
        arm: Arm,
        tool: np.ndarray,
        start: np.ndarray,
        seed: int,
        attempt: int,
        status: GroundStatus,
        approach: bool,
        asked: dict[str, bool],
    ) -> np.ndarray | str | None:
        """One IK attempt of an approach to tool pose ``tool`` from ``start``: its configurations (the grasp
        alone without ``approach``), None when it failed, :data:`OUT_OF_REACH` when no attempt can succeed.
        That is when the grasp has no answer and :func:`_out_of_reach` says so, or when no attempt so far has
        got past the pre-grasp (``status`` still no IK), this one's pre-grasp has no numeric answer from its
        branch and the analytic solver has no branch for it either: it is the same tool pose in every attempt
        (``asked`` keeps the analytic answers of this approach)."""
        q = solve_ik_many(arm.model, arm.ee_target(tool)[None], seed, q_init=start)[0]
        if not q.solved or q.q is None:  # (q is None exactly when the solve failed)
            gone = _out_of_reach(q.status.value, attempt, status, lambda: self._asked(asked, "grasp", arm, tool))
            return OUT_OF_REACH if gone else None
        if not approach:
            return np.asarray(q.q)[None]
        configs = self._approach_configs(arm, tool, q.q, seed)
        if configs is None and status is GroundStatus.NO_IK and not self._pre(arm, tool, q.q, seed).solved:
            return OUT_OF_REACH if self._asked(asked, "pre", arm, tool @ pregrasp_transform(np.eye(4))) else None
        return configs

    @staticmethod
    def _asked(asked: dict[str, bool], what: str, arm: Arm, tool: np.ndarray) -> bool:
        """:meth:`Arm.no_branch <mrgc.geometry.arm.Arm.no_branch>` for ``tool``, asked once per ``what``."""
        if what not in asked:
            asked[what] = arm.no_branch(tool)
        return asked[what]

    @staticmethod
    def _pre(arm: Arm, tool: np.ndarray, q: np.ndarray, seed: int) -> IKResult:
        """The pre-grasp of grasp configuration ``q`` (tool at ``tool``): numeric IK from ``q`` (cached by
        :func:`~mrgc.geometry.ik.solve_ik_many`, so asking twice solves once)."""
        target = arm.ee_target(tool @ pregrasp_transform(np.eye(4)))[None]
        return solve_ik_many(arm.model, target, seed, q_init=q[None], restarts=2)[0]

    @classmethod
    def _approach_configs(cls, arm: Arm, tool: np.ndarray, q: np.ndarray, seed: int) -> np.ndarray | None:
        """The approach to grasp configuration ``q`` (tool at ``tool``): the pre-grasp by IK from ``q``, then
        :data:`APPROACH_SAMPLES` configurations to ``q``; None when the pre-grasp has no solution, or when
        pre-grasp and grasp come from different IK branches and swing the tool off the approach line (the
        contact segment must start near the grasp: the validator's rule, with a margin)."""
        pre = cls._pre(arm, tool, q, seed)
        if not pre.solved or pre.q is None:
            return None
        s = np.linspace(0.0, 1.0, APPROACH_SAMPLES)[:, None]
        configs: np.ndarray = pre.q[None] * (1 - s) + q[None] * s
        near = arm.tool_world(configs[-2][None])[0][:3, 3]
        if np.linalg.norm(near - tool[:3, 3]) > CONTACT_START * APPROACH / (APPROACH_SAMPLES - 1):
            return None
        return configs if on_the_line(arm, tool, configs[-2], configs[-1]) else None

    def _clash_detail(
        self, robot: str, phase: str, clash: tuple[str, Volume], ignore: tuple[str, ...], partner: tuple[str, ...] = ()
    ) -> str:
        """Name what a volume collided with besides the avoided objects: fixed bodies, other arms at home
        (their links are named ``@<arm>:<i>``) or standing still (``~<arm>:<stance>:<i>``), the handover
        partner at home (``partner``: its group), or the other robots of the step."""
        kind, volume = clash
        if kind == "moving":
            return BUSY
        if kind == "self":
            return SELF
        if kind == "partner":
            hit = self.world.probe_hits(Posed.of(volume), against=partner)
            names = sorted({named_body(h) for h in hit}) or [f"{g.split(':', 1)[1]} at home" for g in partner]
            return "hits " + ", ".join(names) + ", its handover partner"
        hit = self.world.probe_hits(volume, against=("fixed", *self._others(robot, phase)), ignore=ignore)
        named = sorted({named_body(h) for h in hit})
        return "hits " + ", ".join(named) if named else ""

    def pick(
        self, robot: str, obj: str, grasp: str, avoid: Iterable[str] = (), busy: Pieces = (), after: Pieces = ()
    ) -> Answer:
        """Approach configurations for ``robot`` to grasp ``obj`` (at its current pose) with ``grasp``,
        free of fixed objects, of ``avoid`` and of ``busy`` (what other robots sweep meanwhile), the last one
        holding the object also free of ``after`` (what they do in the later phases the arm stands there,
        :meth:`step`); ``blockers`` names the avoided objects that were in the way."""
        return self._approach(robot, obj, grasp, self.poses[obj], "pick", avoid, busy=busy, after=after)

    def place(
        self,
        robot: str,
        obj: str,
        grasp: str,
        pose: np.ndarray,
        avoid: Iterable[str] = (),
        busy: Pieces = (),
        after: Pieces = (),
    ) -> Answer:
        """Approach configurations for ``robot`` holding ``obj`` with ``grasp`` to put it at ``pose`` (``busy``
        and ``after`` as for :meth:`pick`)."""
        return self._approach(robot, obj, grasp, pose, "place", avoid, held=True, busy=busy, after=after)

    def handover(
        self,
        obj: str,
        point: str,
        giver: str,
        g1: str,
        taker: str,
        g2: str,
        avoid: Iterable[str] = (),
        busy: Pieces = (),
        after: Mapping[str, Pieces] | None = None,
        skip: int = 0,
    ) -> Answer:
        """Both arms' configurations holding ``obj`` at handover point ``point`` (configs: giver, taker), free
        of ``busy`` (what the step's other robots do in the handover phase), each arm's also of ``after[arm]``
        (what they do in the later phases it stands at its exchange: :meth:`step`).  ``skip``: the pair after
        the first ``skip`` free pairs, in the order they are drawn (other branches of the arms at the same
        point, for a carry that cannot reach the first); the failure when there are no more."""
        pose = translation(*self.scene.handover_points[point])
        ended: list[Answer] = []  # why the pairs ran out
        pairs = self._exchange_pairs(obj, pose, point, (giver, g1), (taker, g2), avoid, busy, after or {}, ended)
        for n, pair in enumerate(pairs):
            if n == skip:
                return Answer(GroundStatus.OK, pose=pose, configs=pair)
        return ended[0]

    def _exchange_pairs(
        self,
        obj: str,
        pose: np.ndarray,
        point: str,
        giving: tuple[str, str],
        taking: tuple[str, str],
        avoid: Iterable[str],
        busy: Pieces,
        later: Mapping[str, Pieces],
        ended: list[Answer],
    ) -> Iterator[np.ndarray]:
        """The free pairs of exchange configurations (giver, taker) for :meth:`handover`, in the order they are
        drawn; when they run out, why (the deadline, one arm never getting there, the two arms colliding at
        every exchange drawn) is appended to ``ended``."""
        (giver, g1), (taker, g2) = giving, taking
        # as in phase 1, a handover is checked at the exchange configurations (no approach).  Each round draws
        # one more free exchange configuration of each arm (the first from home, the others from seeded
        # random starts: from home IK finds the same solution every time) and tries it against every
        # configuration of the other arm drawn so far
        found: dict[str, list[np.ndarray]] = {giver: [], taker: []}
        failed = Answer(GroundStatus.COLLISION)
        worlds: list[Posed] = []  # the taker's configurations, as the kernel reads them
        free = 0

        # each arm at its exchange while its partner is still (or already) at home: the giver arrives at the
        # end of to-handover, where a taker without a path to its exchange (``--motions configurations``) waits
        # at home; the taker leaves for its place at the start of to-place, the giver home by then
        partner = {giver: self._at_home_then(taker, "to-handover"), taker: self._at_home_then(giver, "to-place")}

        def exchange(arm: str, grasp: str, attempt: int) -> Answer:
            key = f"handover:{point}" + (f":{attempt}" if attempt else "")
            return self._approach(
                arm,
                obj,
                grasp,
                pose,
                key,
                avoid,
                approach=False,
                busy=busy,
                from_home=attempt == 0,
                after=later.get(arm, ()),
                partner=partner[arm],
            )

        for attempt in range(HANDOVER_PAIRS):
            if self.late():
                ended.append(Answer(GroundStatus.TIME_LIMIT))
                return
            a, b = exchange(giver, g1, attempt), exchange(taker, g2, attempt)
            if not b.ok:
                failed = b
            else:
                assert b.configs is not None
                found[taker].append(b.configs[-1])
                world = Posed.of(self.arm_volume(taker, b.configs[-1:], grasp=(obj, g2)))
                worlds.append(world)
                for q in found[giver]:  # the new taker configuration against the giver's earlier ones
                    if not posed_collide(Posed.of(self.arm_volume(giver, q[None], grasp=(obj, g1))), world):
                        free += 1
                        yield np.stack([q, b.configs[-1]])
            if not a.ok:
                failed = a
            else:
                assert a.configs is not None
                found[giver].append(a.configs[-1])
                volume = Posed.of(self.arm_volume(giver, a.configs[-1:], grasp=(obj, g1)))
                for q, world in zip(found[taker], worlds):  # the new giver configuration against every taker's
                    if not posed_collide(volume, world):
                        free += 1
                        yield np.stack([a.configs[-1], q])
        if free:
            ended.append(Answer(GroundStatus.COLLISION, detail=f"no free exchange but the {free} drawn before"))
        elif not (found[giver] and found[taker]):  # one arm never got there: why (its last attempt)
            ended.append(Answer(failed.status, blockers=failed.blockers, detail=failed.detail))
        else:
            ended.append(Answer(GroundStatus.COLLISION, detail="the two arms collide at every exchange drawn"))
