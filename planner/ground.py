"""Task-skeleton grounding by reverse search (the paper's Key Component 2), for fixed-base arms.

Steps are grounded from the last to the first.  At step t, placements avoid the fixed objects, the objects
that are never moved (M_out), the objects moved later (M_fut, still at their initial poses at t), the
objects moved in the same step, and the future volume V_fut (everything later grounded steps sweep,
including objects at their final placements).  Pick, handover and place configurations avoid the same
objects; robots of one step must not collide with each other: the grounder knows where each robot of the
step is in each phase (at home, moving, or standing still where its last motion left it: the execution
model, :meth:`Grounder.step <mrgc.geometry.grounding.Grounder.step>`), each action's motions (approaches,
exchanges, transfers, base paths) keep clear of everything the step's actions grounded before it sweep or
occupy in the same phase (conservative: it ignores when they pass), and the phases are then compared
sample by sample as the validator replays them.  If step t fails, it is retried allowing
collisions with M_out: on success grounding stops and returns the grounded suffix S' and M* = the goal
objects not moved in S' plus the M_out objects that obstruct S'; otherwise it fails.
"""

from __future__ import annotations

import enum
import hashlib
import math
import time
from contextlib import ExitStack
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Iterable

import numpy as np

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.answers import BUSY, SELF, Answer, GroundStatus
from mrgc.geometry.collision import Packed, Posed, grouped_collide, pieces_collide
from mrgc.geometry.conventions import refine
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.placements import aside_tops, nearest_on_top, off_regions
from mrgc.geometry.relays import spot_region
from mrgc.geometry.robot import Volume
from mrgc.geometry.scene import Body as SceneBody
from mrgc.geometry.stances import PHASES, Stance, roles
from mrgc.language.model import Box
from mrgc.planfile.format import PlannedAction
from mrgc.planner.doomed import DoomedActions
from mrgc.planner.outcome import DeadlineReached, Failure

#: tries per place before the step gives up: a placement whose carry was planned, or whose approach the step's
#: other robots blocked (:meth:`ReverseGrounder._place`)
PLACEMENT_TRIES = 6
#: more placements a place may look at whose approaches failed without costing a try: out of the arm's reach (a
#: bin at the edge of the arm's reach: the corners come first when packing, and many are unreachable), or
#: touching an object, a fixed body or the arm itself (a crowded start region; placements past the arm's reach
#: bound are passed over without a look)
OUT_OF_REACH_TRIES = 30
#: random placements drawn per region after the fixed ones (the lattice, a packed bin's grid): a crowded start
#: region has few free poses, most past the arm's reach (6-arm seed 0: 14 free poses of o21 among 200 draws,
#: 98 among 2000); drawing and checking one costs ~0.1 ms, an arm's approach to one ~10 ms
PLACEMENT_SAMPLES = 1000
#: other regions an obstacle with no reachable place in its own may be parked in, nearest first
PARKING_REGIONS = 2
#: carries to a placement blocked by the step's other robots (what they sweep in the same phase) after which
#: a place grounded clear of them gives up: the step is then re-timed or packed, which costs less than more
#: placements each failing its carry the same way (PA7-s1: 17 carries of about 85 ms each, every one
#: blocked by the other arm, before the split that grounded at once)
BUSY_CARRIES = 2
#: packings of a skeleton step whose robots meet (:meth:`ReverseGrounder._packed`), per action of the step: each
#: action may be put first once and last once; the re-timings' nested packings of the step's remaining actions
#: count too (without the bound, a step of 7 actions whose re-timings each packed the rest made up to 19
#: packings, 252 joint groundings, on a reviewer's drawn cases)
PACKINGS_PER_ACTION = 2
#: exchanges tried per handover point when the giver's carry to one fails: another branch of the arms at the
#: same point is often an easy carry where the first (the solution nearest home) is not (6-arm seed 0: r5's
#: first exchange at h5 is reached by no RRTConnect path of 64,000 checks, its second in 0.03 s)
EXCHANGE_TRIES = 3
RELAY_TRIES = 3  # spots tried per relay (the k-th spot both of its robots reach at the k-th try)
#: random placements (beyond the lattice and the packing grid) a goal region is searched with before a suffix is
#: called a dead end for want of room in it (:meth:`ReverseGrounder.dead_end`)
DEAD_END_SAMPLES = 400
#: paths replayed in another path's phase (the validator's execution model): name -> phase
PATH_PHASE = {"taker-to-handover": "to-handover"}
#: the waits an action's robot may make in a phase where it meets another robot of its step, tried in turn
#: (:func:`_waiting`): the share of the phase it stands still, at the path's start (> 0: it sets out late) or
#: at its end (< 0: it arrives early and stands there)
WAITS = (0.5, -0.5, 0.75, -0.75)
#: a skeleton's order constraints: an action's obstacles, (object, strict) (``TaskGraph.obstacles``)
Order = Callable[[Action], list[tuple[str, bool]]]
#: each robot's volume at every sample of every phase of its motions (one volume for a phase it stands still
#: in, away from home): robot -> phase -> volumes
Motions = dict[str, dict[str, list[Volume]]]


class Outcome(str, enum.Enum):
    """How grounding a skeleton ended: every step grounded, a suffix grounded (other objects must move
    first: M*), or a failure."""

    SUCCESS = "success"
    PARTIAL = "partial"
    FAIL = "fail"


@dataclass
class GroundedStep:
    """A grounded joint action: its actions, the volume it sweeps, and the objects it moves."""

    actions: list[PlannedAction]
    #: every sample of every motion of the step, and its objects at their placements, packed (a search holds
    #: the volumes of every step its nodes grounded; :func:`swept` joins them for the kernel)
    volume: Packed
    moved: tuple[str, ...]


@dataclass
class Grounding:
    """The outcome of grounding a skeleton: the grounded steps (a suffix when PARTIAL) and M*."""

    outcome: Outcome
    steps: list[GroundedStep] = field(default_factory=list)
    must_move: set[str] = field(default_factory=set)
    reason: str = ""
    #: why steps failed (the strict attempt of a PARTIAL step, or the failing step of a FAIL)
    failures: list[Failure] = field(default_factory=list)
    #: the step failures of robots in each other's way that a re-timing or a packing got around, in grounding
    #: order (the log and the plan's statistics report them)
    resolved: list[Failure] = field(default_factory=list)
    #: actions re-timed into an earlier skeleton step: (action label, from step, to step)
    retimed: list[tuple[str, int, int]] = field(default_factory=list)
    #: why no skeleton at all can be grounded before the suffix this one failed under ('' when the failure
    #: says nothing of the kind): a goal object it leaves no free pose in its goal region
    dead_end: str = ""
    #: the grounding (its key) whose failure this one repeats without grounding anything ('' when it was
    #: grounded): the same steps from the failing one on, under the same suffix, moving the same objects
    repeats: str = ""


def _matrix(t: np.ndarray) -> list[list[float]]:
    out: list[list[float]] = np.asarray(t, dtype=float).tolist()
    return out


def _configs(c: np.ndarray | None) -> list[list[float]]:
    out: list[list[float]] = [] if c is None else np.atleast_2d(np.asarray(c, dtype=float)).tolist()
    return out


class ReverseGrounder:
    """Grounds skeletons on a scene (see the module docstring)."""

    def __init__(
        self, grounder: Grounder, goal: dict[str, str], full: bool = False, deadline: float | None = None
    ) -> None:
        self.g = grounder
        self.goal = goal
        #: arms' empty-handed motions planned too (``mrgc plan --motions full``): home -> pre-grasp, release
        #: -> home, and for a handover the taker's way to the exchange and the giver's way home
        self.full = full
        self.movable = [b.name for b in grounder.scene.movable]
        #: the fixed tops obstacles may be set aside on (:attr:`_tops`), found when first asked
        self._aside: list[SceneBody] | None = None
        #: the search's time limit (``time.perf_counter()``): the grounder's queries read it in their long
        #: loops and stop at once past it (:attr:`Grounder.cut <mrgc.geometry.grounding.Grounder.cut>`); a
        #: grounding that the deadline cut short anywhere ends with :class:`DeadlineReached` and is discarded,
        #: so the clock ends the search but never decides what a grounding finds
        self.deadline = deadline
        if deadline is not None:
            grounder.deadline = deadline
        #: the objects the steps grounded so far move (later in the plan than the step being grounded)
        self.grounded: set[str] = set()
        #: where the relays being grounded set their objects down (see :meth:`_relay_steps`)
        self._forced: dict[str, np.ndarray] = {}
        #: (robot, object, grasp, placement) whose place failed on what never moves (no IK, fixed bodies):
        #: later groundings pass over them without spending one of their tries
        self._dead_spots: set[tuple[str, str, str, tuple[float, ...]]] = set()
        #: (suffix step ids, object, region) -> (the suffix, whether it leaves the object no free pose there)
        self._full: dict[tuple[tuple[int, ...], str, str], tuple[tuple[GroundedStep, ...], bool]] = {}
        #: failed groundings by what their failure depended on (:meth:`_context`) -> (the suffix, kept so that
        #: its steps' ids stay its own; the failed grounding; its key)
        self._failed: dict[tuple[object, ...], tuple[tuple[GroundedStep, ...], Grounding, str]] = {}
        #: groundings that repeated a failure instead of grounding anything (:meth:`ground`)
        self.repeated = 0
        #: steps packed again, an action that failed on its own put first or last (:meth:`_packed`); the packings
        #: the skeleton step being grounded may still make (:data:`PACKINGS_PER_ACTION`), and the steps whose
        #: packings ran out
        self.repacked = 0
        self._packings = 0
        self.packings_spent = 0
        #: the skeleton being grounded, its actions as re-timed so far (see :class:`_Retiming`)
        self._plan = _Retiming([], None)
        #: actions found doomed before the later steps are grounded (planner/doomed.py)
        self.doomed = DoomedActions(
            grounder,
            goal,
            lambda a: [(a.region, None)] + ([] if a.obj in goal else self._parking(a)),
            PLACEMENT_TRIES + OUT_OF_REACH_TRIES,
            PLACEMENT_SAMPLES,
            self._dead_spots,
            _spot_key,
            self._on_time,
            label,
        )

    def ground(
        self, skeleton: Skeleton, suffix: list[GroundedStep], key: str = "", order: Order | None = None
    ) -> Grounding:
        """Ground ``skeleton``'s steps, last first, before the already grounded ``suffix`` (see the module
        docstring); ``key`` tells this query's seeds from other groundings'.  ``order``: the skeleton's order
        constraints (each action's obstacles, :meth:`TaskGraph.obstacles
        <mrgc.compiler.task_graph.TaskGraph.obstacles>`); with them, an action in the way of another robot
        of its step is first *re-timed* into an earlier step where its robots are free and its obstacles
        already moved (:meth:`_Retiming.retime`), and only then is the step packed; when a grounding with
        re-timings does not succeed, the skeleton is grounded again without them.  Raises
        :class:`DeadlineReached` when the search's deadline cut a query of it short (its answer may then be
        wrong)."""
        self._on_time()
        known = self._repeated(skeleton, suffix)
        if known is not None:
            return known
        result = self._ground(skeleton, suffix, key, order)
        if result.retimed and result.outcome is not Outcome.SUCCESS:
            result = self._ground(skeleton, suffix, key, None)
        if result.outcome is Outcome.FAIL and result.failures:
            result.dead_end = self.dead_end(result.failures[0], skeleton, suffix)
        if self.g.cut:  # a query stopped at the deadline: what it answered decides nothing
            raise DeadlineReached()
        if result.outcome is Outcome.FAIL and result.failures and not result.retimed:
            step = result.failures[0].step
            if 1 <= step <= skeleton.makespan:
                self._failed[self._context(skeleton, suffix, step)] = (tuple(suffix), result, key)
        return result

    @staticmethod
    def _context(skeleton: Skeleton, suffix: list[GroundedStep], step: int) -> tuple[object, ...]:
        """What the reverse search's grounding of ``skeleton``'s step ``step`` (1-based) and of the steps after
        it depends on besides the random draws: the suffix (its steps' ids), the objects the skeleton moves
        (the others never move: M_out) and its steps from ``step`` on."""
        steps = tuple(frozenset(s) for s in skeleton.steps[step - 1 :])
        return (tuple(id(s) for s in suffix), frozenset(skeleton.moved), steps)

    def _repeated(self, skeleton: Skeleton, suffix: list[GroundedStep]) -> Grounding | None:
        """The failure of an earlier grounding whose context (:meth:`_context`) at its failing step is this
        skeleton's at the same step, as this grounding's (nothing grounded); None when there is none.  The
        reverse search grounds the steps from the last one back to that one as it did then; only its random
        draws would differ, which the failure has already had (:data:`PLACEMENT_TRIES` and more), so the
        skeleton is passed over: memoised failures, not a second search of the same steps (a 6-arm skeleton
        grounding takes seconds, and a skeleton source offers many skeletons that differ only before the step
        that failed)."""
        if not self._failed:
            return None
        for step in range(skeleton.makespan, 0, -1):
            known = self._failed.get(self._context(skeleton, suffix, step))
            if known is not None:
                _, failed, key = known
                self.repeated += 1
                return Grounding(
                    Outcome.FAIL,
                    reason=failed.reason,
                    failures=list(failed.failures),
                    dead_end=failed.dead_end,
                    repeats=key,
                )
        return None

    def dead_end(self, failure: Failure, skeleton: Skeleton, suffix: list[GroundedStep]) -> str:
        """Why no skeleton can be grounded before ``suffix`` ('' when ``failure``, of a grounding of ``skeleton``
        under it, does not show it): the failure found no free pose of a goal object in its goal region, and
        the region has none even with nothing avoided but what the suffix sweeps and leaves there (every
        object at its initial pose ignored: a relaxation of every skeleton's context there), among the
        lattice, the packing grid and :data:`DEAD_END_SAMPLES` random placements.  Every plan through the
        suffix puts that object there before the suffix's steps, so none exists.  Cached per (suffix,
        object, region)."""
        for a in (a for step in skeleton.steps for a in step):
            if self.goal.get(a.obj) != a.region or failure.check != f"placement: no free pose of {a.obj} in {a.region}":
                continue
            key = (tuple(id(s) for s in suffix), a.obj, a.region)
            if key not in self._full:  # the suffix is kept with the answer: its steps' ids stay theirs
                volume = swept(suffix)
                free = self.g.placements(
                    a.obj, a.region, volume=volume or None, samples=DEAD_END_SAMPLES, key="dead-end", packed=True
                )
                self._full[key] = (tuple(suffix), next(free, None) is None)
            if self._full[key][1]:
                return f"no free pose of {a.obj} in {a.region} is left by the {len(suffix)} step(s) grounded after it"
        return ""

    def _ground(self, skeleton: Skeleton, suffix: list[GroundedStep], key: str, order: Order | None) -> Grounding:
        fut_objs = {o for s in suffix for o in s.moved}
        skel_objs = set(skeleton.moved)
        out_objs = set(self.movable) - fut_objs - skel_objs
        volume = swept(suffix)
        grounded: list[GroundedStep] = []
        self._plan = _Retiming([list(step) for step in skeleton.steps], order)
        doomed = self.doomed.first(skeleton, fut_objs, suffix, volume)
        if doomed is not None:
            return self._plan.told(Grounding(Outcome.FAIL, reason=doomed.line(), failures=[doomed]))
        for t in range(skeleton.makespan - 1, -1, -1):
            step = tuple(self._plan.steps[t])
            self.grounded = set(fut_objs)
            strict = self._steps(step, fut_objs | out_objs, volume, f"{key}:{t}", t + 1)
            if isinstance(strict, Failure):
                self._plan.rollback()
                relaxed = self._steps(step, fut_objs, volume, f"{key}:{t}:relaxed", t + 1)
                self._plan.commit()
                if isinstance(relaxed, Failure):
                    return self._plan.told(Grounding(Outcome.FAIL, reason=relaxed.line(), failures=[relaxed]))
                grounded[:0] = relaxed
                steps = grounded + suffix
                moved = {o for s in steps for o in s.moved}
                # M* as the paper defines it: every movable object not moved in S' that obstructs the whole
                # grounded sequence S' (this call's steps *and* the older suffix: an object the suffix hits
                # was to be moved by a step of this skeleton that is now discarded)
                blockers = self.g.hits(swept(steps), among=sorted(o for o in self.movable if o not in moved))
                must = {o for o in self.goal if o not in moved} | blockers
                return self._plan.told(
                    Grounding(
                        Outcome.PARTIAL,
                        steps,
                        must,
                        reason=f"step {t + 1} needs {sorted(blockers)} moved",
                        failures=[strict],
                    )
                )
            self._plan.commit()
            grounded[:0] = strict
            volume = swept(strict, volume)
            fut_objs |= moved_objects(strict)  # re-timed actions left for an earlier step
        return self._plan.told(Grounding(Outcome.SUCCESS, grounded + suffix))

    # ------------------------------------------------------------ one joint action
    def _steps(
        self,
        step: tuple[Action, ...],
        avoid: set[str],
        v_fut: Posed,
        key: str,
        index: int,
        same: frozenset[str] = frozenset(),
    ) -> list[GroundedStep] | Failure:
        """Ground one skeleton step; when its robots get in each other's way (an action collides with what
        another robot of the step sweeps in the same phase), ground it again with the failing action first
        (each action keeps clear of the ones grounded before it, so the others then plan around it); then
        re-time (below); then pack it into as few plan steps as it takes (:meth:`_packed`: the failing
        action in the latest, every other one there that grounds with the ones before it, the rest in earlier
        ones).  The skeleton's action set and order constraints are kept (actions of one step constrain each
        other in neither direction); only the plan's makespan grows.

        Every part of a packed step keeps clear of the whole skeleton step's objects at their initial poses
        (``same``: the step's, handed down) and draws with the step's own ``key``, as the unsplit step did:
        an action grounded in the same place of a part as in the step (the same objects and volume to keep
        clear of, what the step's earlier actions sweep) asks the same questions, and the grounder's
        remembered answers give them back instead of a second search (a 6-arm step split again and again
        searched the same hopeless carry 18 times, 41 of the skeleton's 59 s, before the parts drew with the
        step's key)."""
        if any(a.via is not None for a in step):
            return self._relay_steps(step, avoid, v_fut, key, index)
        if not same:  # a skeleton step (or a relay's half), not the rest of a re-timed one: its packings start again
            self._packings = PACKINGS_PER_ACTION * len(step)
        same = same | {a.obj for a in step}
        done = self._step(step, avoid, set(same), v_fut, key, index)
        if not isinstance(done, Failure):
            return [done]
        lead = _lead(step, done)
        if lead is None:
            return done
        known = {step: done}  # the step's orders grounded with these avoid and v_fut, and their failures
        if lead is not step[0]:
            # the failing action grounded first: the others then plan around what it sweeps (PA7-s1)
            order = (lead,) + tuple(a for a in step if a is not lead)
            first = self._step(order, avoid, set(same), v_fut, key, index)
            if not isinstance(first, Failure):
                self._plan.noted.append(done)
                return [first]
            known[order] = first
        # first the same actions over the skeleton's steps: the failing action in an earlier step, else
        # (its robots busy in every earlier step) the action of the robot it met there
        mark = self._plan.mark()
        for moved in _retimable(lead, step, done):
            if not self._plan.retime(moved, index):
                continue
            again = self._steps(tuple(a for a in step if a is not moved), avoid, v_fut, key, index, same)
            if not isinstance(again, Failure):
                self._plan.noted.append(done)
                return again
            self._plan.rollback(mark)
        packed = self._packed(step, lead, known, avoid, v_fut, key, index, same)
        if isinstance(packed, Failure):
            return done
        self._plan.noted.append(done)
        return packed

    def _packed(
        self,
        step: tuple[Action, ...],
        lead: Action,
        known: dict[tuple[Action, ...], Failure],
        avoid: set[str],
        v_fut: Posed,
        key: str,
        index: int,
        same: frozenset[str],
    ) -> list[GroundedStep] | Failure:
        """``step`` over as few plan steps as it takes (see :meth:`_pack`), ``lead`` in the latest.  When an action
        then fails on its own in an earlier one (clear of the later ones' objects and sweeps), it is packed again
        with that action first, in the latest, each action that fails so put after those put first before it;
        an action that fails on its own in the latest (first there: nothing of its step before it) is put last
        instead, once, so that it goes to an earlier plan step (a two-action step so tries what the split of
        sessions 31-42 tried: the failing action alone one step later than the other, else one step earlier).
        That goes on until the step is packed, an action fails again where it was put, an order comes round
        again (at most two packings per action), or the skeleton step's packings are spent
        (:data:`PACKINGS_PER_ACTION` per action of it, the packings of its re-timings' remaining actions
        included).  The failure of the last packing otherwise.  ``known``: the step's joint actions already
        grounded with these ``avoid`` and ``v_fut`` (their order -> what they gave)."""
        first: list[Action] = []  # put first: failed on their own in an earlier plan step
        last: list[Action] = []  # put last: failed on their own in the latest
        order = (lead,) + tuple(a for a in step if a is not lead)
        orders = {order}
        packed: list[GroundedStep] | Failure = known[step]
        while self._packings > 0:
            self._packings -= 1
            packed = self._pack(order, dict(known), avoid, v_fut, key, index, same)
            if not isinstance(packed, Failure):
                return packed
            failing = next((a for a in step if label(a) == packed.action), None)
            if failing is None or failing in first + last:
                return packed
            (last if failing is order[0] else first).append(failing)
            order = tuple(first) + tuple(a for a in step if a not in first + last) + tuple(last)
            if order in orders:
                return packed
            orders.add(order)
            self.repacked += 1
        self.packings_spent += 1
        return packed

    def _pack(
        self,
        order: tuple[Action, ...],
        known: dict[tuple[Action, ...], Failure],
        avoid: set[str],
        v_fut: Posed,
        key: str,
        index: int,
        same: frozenset[str],
    ) -> list[GroundedStep] | Failure:
        """The actions of ``order`` packed greedily into plan steps, grounded latest first (the reverse search):
        the latest is every action, in ``order``, that grounds with the ones kept before it; an action that
        fails (robots of the step in each other's way, or what the ones before it sweep or put down) is dropped
        to the next earlier plan step, which keeps clear of the later steps' objects (at their initial poses)
        and of what they sweep; each drop costs one grounding of the part (the actions before the dropped one
        ask their remembered questions again).  The failure of an action that fails first in its plan step
        (nothing of its step before it) when it does.  Each plan step costs one joint grounding and one more per
        action dropped from it (k(k + 1)/2 at most for k actions, one per action when their robots keep out of
        each other's way), where splitting the step in two again and again, each part split again, multiplied
        them: a 6-arm step's splits failed in cascades of 30-130 s (session 42)."""
        parts: list[GroundedStep] = []
        left = list(order)
        before = self.grounded
        try:
            while left:
                part, dropped = list(left), []
                while True:
                    tried = known.pop(tuple(part), None) if not parts else None  # the latest: as the step was
                    done = tried if tried is not None else self._step(tuple(part), avoid, set(same), v_fut, key, index)
                    if not isinstance(done, Failure):
                        break
                    failing = next((a for a in part if label(a) == done.action), None)
                    if failing is None or failing is part[0]:
                        return done
                    part.remove(failing)
                    dropped.append(failing)
                parts[:0] = [done]
                objects = {a.obj for a in part}
                avoid = avoid | objects
                v_fut = swept([done], v_fut)
                self.grounded = self.grounded | objects
                left = dropped
        finally:
            self.grounded = before
        return parts

    def _relay_steps(
        self, step: tuple[Action, ...], avoid: set[str], v_fut: Posed, key: str, index: int
    ) -> list[GroundedStep] | Failure:
        """:meth:`_relayed`; when a relay finds no spot in its region, the step again with every relay's spot on
        a fixed top instead (:func:`~mrgc.geometry.placements.aside_tops`: the table, in the staging square
        between the relay's two robots, :func:`~mrgc.geometry.relays.spot_region`, clear of every region's
        footprint), as a relay that phase 1 found only there does (session 42: on the 6-arm, 40-object
        instances "relay: no spot in start where both robots reach o37" was the strict failure behind half of
        the partial groundings).  The first attempt's failure is the step's when that fails too (its actions
        are the skeleton's)."""
        done = self._relayed(step, avoid, v_fut, key, index)
        if not isinstance(done, Failure) or not done.check.startswith("relay: no spot"):
            return done
        for top in self._tops:
            moved = tuple(a if a.via in (None, top.name) else replace(a, via=top.name) for a in step)
            if moved == step:
                continue
            again = self._relayed(moved, avoid, v_fut, f"{key}:{top.name}", index, aside=True)
            if not isinstance(again, Failure):
                return again
        return done

    def _relayed(
        self, step: tuple[Action, ...], avoid: set[str], v_fut: Posed, key: str, index: int, aside: bool = False
    ) -> list[GroundedStep] | Failure:
        """A skeleton step holding relays (beyond the paper) as two plan steps: the step's other actions with
        each relay setting its object down at a spot of its ``via`` region, then the relays' onward moves
        (picked up at the spot, placed in the goal).  The reverse search grounds the onward moves first, at
        spots both robots of the relay reach (:meth:`_spots`); the first step then sets each object down at
        its spot.  The k-th try uses each relay's k-th such spot."""
        relays = [a for a in step if a.via is not None]
        onward = tuple(a.halves[1] for a in relays)
        first = tuple(a.halves[0] if a.via is not None else a for a in step)
        last: Failure = Failure(index, label(relays[0]), f"relay: no spot in {relays[0].via} both robots reach")
        for k in range(RELAY_TRIES):
            spots = self._spots(relays, avoid | {a.obj for a in step}, v_fut, f"{key}:relay", k, aside)
            if isinstance(spots, Failure):
                return last if k else replace(spots, step=index)
            with self.g.moved(spots):
                tail = self._steps(onward, avoid, v_fut, f"{key}:onward:{k}", index)
            if isinstance(tail, Failure):
                last = tail
                continue
            before, self.grounded = self.grounded, self.grounded | set(spots)
            self._forced = spots
            try:
                head = self._steps(first, avoid, swept(tail, v_fut), f"{key}:down:{k}", index)
            finally:
                self.grounded, self._forced = before, {}
            if isinstance(head, Failure):
                last = head
                continue
            for s in head:
                for planned in s.actions:
                    planned.relay = planned.object in spots
            return head + tail
        return last

    def _spots(
        self, relays: list[Action], avoid: set[str], v_fut: Posed, key: str, k: int, aside: bool = False
    ) -> dict[str, np.ndarray] | Failure:
        """For each relay, its k-th free spot in its ``via`` region (clear of ``avoid`` at their poses, of
        ``v_fut`` and of the spots chosen before) where its first robot sets the object down with its grasp
        and its second one picks it up with its own (both approaches free; the robots' paths are grounded
        afterwards).  ``aside`` (a relay moved onto a fixed top because its region had no spot): only spots
        clear of every region's footprint, as an obstacle set aside there (no goal bin's room taken)."""
        g, out = self.g, {}
        taken: Volume = []
        for a in relays:
            assert a.via is not None
            others = sorted(avoid - {a.obj})
            found, tried = 0, 0
            where = spot_region(g.scene, a.via, a.pick_robot, a.place_robot)
            both = _both(
                g.comfortable(a.pick_robot, a.obj, a.pick_grasp), g.comfortable(a.place_robot, a.obj, a.place_grasp)
            )
            far_off = (
                g.out_of_reach(a.pick_robot, a.obj, a.pick_grasp),
                g.out_of_reach(a.place_robot, a.obj, a.place_grasp),
            )
            poses = g.placements(
                a.obj, where, avoid=others, volume=_plus(v_fut, taken), key=key, packed=True, prefer=both
            )
            for pose in filter(off_regions(g.scene, a.obj), poses) if aside else poses:
                self._on_time()
                if any(far(pose) for far in far_off):
                    continue  # past one arm's reach bound: neither sets it down and picks it up there
                tried += 1
                if tried > PLACEMENT_TRIES + OUT_OF_REACH_TRIES:
                    break
                if not g.place(a.pick_robot, a.obj, a.pick_grasp, pose, avoid=others).ok:
                    continue
                with g.moved({a.obj: pose}):
                    ok = g.pick(a.place_robot, a.obj, a.place_grasp, avoid=others).ok
                if ok and found == k:
                    out[a.obj] = pose
                    taken.append((g.shape(a.obj), pose))
                    break
                found += ok
            if a.obj not in out:
                return Failure(0, label(a), f"relay: no spot in {a.via} where both robots reach {a.obj}")
        return out

    def ground_step(
        self, step: tuple[Action, ...], avoid: set[str], v_fut: Posed, key: str, index: int = 0
    ) -> GroundedStep | Failure:
        """One joint action grounded on its own (the unit the baselines search over, planner/baselines/): the
        actions of ``step`` in one plan step, clear of the objects ``avoid`` where the grounder has them (their
        initial poses, or those :meth:`Grounder.moved <mrgc.geometry.grounding.Grounder.moved>` gives them),
        of each other and of the volume ``v_fut``; ``key`` seeds its sampling, ``index`` numbers its failure.
        No splitting, re-timing or relays (those are the skeleton grounding's, :meth:`ground`); its robots do
        wait for each other within the step (:func:`_waiting`), as in :meth:`ground`."""
        return self._step(step, avoid, {a.obj for a in step}, v_fut, key, index)

    def _step(
        self, step: tuple[Action, ...], avoid: set[str], same: set[str], v_fut: Posed, key: str, index: int = 0
    ) -> GroundedStep | Failure:
        # where each robot of the step is in each phase follows from its role (the execution model)
        self.g.step(roles((a.pick_robot, a.place_robot) for a in step), self.full)
        try:
            return self._actions(step, avoid, same, v_fut, key, index)
        finally:
            self.g.step({})

    def _actions(
        self, step: tuple[Action, ...], avoid: set[str], same: set[str], v_fut: Posed, key: str, index: int
    ) -> GroundedStep | Failure:
        actions: list[PlannedAction] = []
        step_volume: Volume = []
        motions: Motions = {}  # robot -> phase -> volume at each sample
        owners: Owners = {}  # whose path each motion of a phase is
        placed: dict[str, np.ndarray] = {}  # objects of this step already placed by its earlier actions
        for a in step:
            self._on_time()
            avoid_a = sorted((avoid | same) - {a.obj})
            volume = _plus(v_fut, step_volume)
            # first as if the step's other robots were not there: as they pass, the sample-paired comparison
            # (the validator's) decides
            action = self._action(a, avoid_a, volume, f"{key}:{a.obj}", placed, {})
            if isinstance(action, Failure):
                self.doomed.failed(a, action)
                return replace(action, step=index, action=label(a))
            moves = self._motions(action)
            mine = _joined(moves, self._stood(action))
            # where they meet, first one waiting while the other passes
            clash, mine = _waiting(action, mine, motions, _robots_collide(mine, motions), owners)
            if clash:
                # then keeping clear of the whole of what the others sweep or occupy in each phase
                busy = _swept_by_others(motions, (a.pick_robot, a.place_robot))
                # (its failure is about the others: the action alone grounded, so nothing for the doomed
                # probes to note)
                kept = self._action(a, avoid_a, volume, f"{key}:{a.obj}", placed, busy)
                if not isinstance(kept, Failure):
                    kept_moves = self._motions(kept)
                    again = _joined(kept_moves, self._stood(kept))
                    missed, again = _waiting(kept, again, motions, _robots_collide(again, motions), owners)
                    if missed is None:
                        action, moves, mine, clash = kept, kept_moves, again, None
            if clash:
                phase, robots = clash
                return Failure(index, label(a), f"{phase}: robots of the step collide", robots)
            for robot, phases in mine.items():
                motions.setdefault(robot, {}).update(phases)
            owners.update({(action.path_robot(n), PATH_PHASE.get(n, n)): (action, n) for n in action.paths})
            # the step's volume is every sample of every motion (where a robot stands still is the end of one)
            for phases in moves.values():
                for samples in phases.values():
                    for vol in samples:
                        step_volume.extend(vol)
            assert action.place_pose is not None
            step_volume.append((self.g.shape(a.obj), np.array(action.place_pose)))
            placed[a.obj] = np.array(action.place_pose)
            actions.append(action)
        return GroundedStep(actions, Packed.of(Posed.of(step_volume)), tuple(a.obj for a in step))

    def _motions(self, action: PlannedAction) -> Motions:
        """Each robot's volume at every sample of every phase of a planned action, approaches on the
        validator's finer interpolation (so later placements keep clear between samples too).  A robot that
        picks and places from the one state grasp geometry gives (not :attr:`Robot.approaches
        <mrgc.geometry.robot.Robot.approaches>`: a planar robot) makes no motion in those phases."""
        g, obj = self.g, action.object
        out: Motions = {}
        approach = g.robot(action.pick_robot).approaches
        if approach:
            out.setdefault(action.pick_robot, {})["pick"] = g.volumes(
                action.pick_robot, refine(np.array(action.configs["pick"])), fingers=(obj, action.pick_grasp)
            )
        if "handover" in action.configs:
            giver, taker = np.array(action.configs["handover"])
            out.setdefault(action.pick_robot, {})["handover"] = g.volumes(
                action.pick_robot, giver[None], (obj, action.pick_grasp)
            )
            out.setdefault(action.place_robot, {})["handover"] = g.volumes(
                action.place_robot, taker[None], (obj, action.place_grasp)
            )
        # the paths, in the order grounded (every configuration: they are already at the validator's
        # resolution); holding the object on the transfers, empty-handed otherwise (fingers fully open, a
        # giver's as it let go)
        for phase, path in action.paths.items():
            robot, grasp, holds = _path_of(action, phase)
            grip = (obj, grasp) if grasp is not None else None
            out.setdefault(robot, {})[PATH_PHASE.get(phase, phase)] = g.volumes(
                robot, np.array(path), holding=grip if holds else None, fingers=grip
            )
        if approach:
            out.setdefault(action.place_robot, {})["place"] = g.volumes(
                action.place_robot, refine(np.array(action.configs["place"])), (obj, action.place_grasp)
            )
        return out

    def _standing(self, action: PlannedAction, robot: str) -> dict[Stance, Volume]:
        """Where ``robot`` of ``action`` stands still away from home during the step (the stances
        :meth:`Grounder.stance <mrgc.geometry.grounding.Grounder.stance>` gives it), as far as ``action`` is
        grounded: at its last pick configuration holding the object, at its exchange (a giver having let go, a
        taker holding the object), at its last place configuration with the object released; fingers at the
        grasp's opening."""
        c, obj = action.configs, action.object
        takes = {self.g.stance(robot, phase) for phase in PHASES}
        out: dict[Stance, Volume] = {}
        if Stance.PICKED in takes and c.get("pick"):
            out[Stance.PICKED] = self._volume_at(robot, c["pick"][-1], (obj, action.pick_grasp), True)
        if Stance.EXCHANGE in takes and c.get("handover"):
            out[Stance.EXCHANGE] = self._volume_at(robot, c["handover"][0], (obj, action.pick_grasp), False)
        if Stance.RECEIVED in takes and c.get("handover"):
            out[Stance.RECEIVED] = self._volume_at(robot, c["handover"][1], (obj, action.place_grasp), True)
        if Stance.PLACED in takes and c.get("place"):
            out[Stance.PLACED] = self._volume_at(robot, c["place"][-1], (obj, action.place_grasp), False)
        return out

    def _volume_at(self, robot: str, q: list[float], grip: tuple[str, str], held: bool) -> Volume:
        """``robot`` at configuration (or base pose) ``q``, holding ``grip`` (object, grasp) or, with its
        fingers at the grasp's opening, not."""
        return self.g.volumes(robot, np.array(q)[None], holding=grip if held else None, fingers=grip)[0]

    def _stood(self, action: PlannedAction) -> Motions:
        """Each robot of a planned action standing still away from home: one volume per phase it stands in."""
        out: Motions = {}
        for robot in action.robots():
            where = self._standing(action, robot)
            for phase in PHASES:
                if self.g.stance(robot, phase) in where:
                    out.setdefault(robot, {})[phase] = [where[self.g.stance(robot, phase)]]
        return out

    def _after(self, busy: dict[str, Volume], robot: str, where: Stance) -> Volume:
        """What the step's other robots do (``busy``) in the phases ``robot`` stands still ``where``: its
        configuration there keeps clear of it."""
        return [p for phase in PHASES if self.g.stance(robot, phase) is where for p in busy.get(phase, [])]

    def _on_time(self) -> None:
        """Raise :class:`DeadlineReached` when the search's time limit has passed (or cut a query short)."""
        if self.g.cut or (self.deadline is not None and time.perf_counter() > self.deadline):
            raise DeadlineReached()

    def _action(
        self,
        a: Action,
        avoid: list[str],
        v_fut: Posed,
        key: str,
        placed: dict[str, np.ndarray] | None = None,
        busy: dict[str, Volume] | None = None,
    ) -> PlannedAction | Failure:
        if not self.g.robot(a.pick_robot).approaches:  # it picks from where grasp geometry puts it: it drives
            return self._drive(a, avoid, v_fut, key, placed or {}, busy or {})
        g, busy = self.g, busy or {}
        after = self._after(busy, a.pick_robot, Stance.PICKED)
        pick = g.pick(a.pick_robot, a.obj, a.pick_grasp, avoid=avoid, busy=busy.get("pick", []), after=after)
        if not pick.ok:
            return _failed(f"pick by {a.pick_robot}", pick)
        planned = PlannedAction(a.obj, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp)
        planned.configs["pick"] = _configs(pick.configs)
        assert pick.configs is not None
        start, lift = pick.configs[-1], True  # the place transfer starts at the grasp
        if a.handover:
            exchange = self._hand_over(a, planned, pick.configs[-1], avoid, busy)
            if isinstance(exchange, Failure):
                return exchange
            start, lift = exchange, False  # the taker's transfer starts at the exchange
        with ExitStack() as stack:
            # a handover's two arms stand where its grounded configurations put them, each an obstacle to the
            # other (the taker at its exchange holding the object while the giver withdraws)
            for robot in planned.robots() if a.handover else ():
                stack.enter_context(g.standing(robot, self._standing(planned, robot)))
            done = self._place(a, planned, a.region, start, lift, avoid, v_fut, key, placed, busy)
            if not isinstance(done, Failure) or a.obj in self.goal or a.obj in self._forced:
                return done
            if done.detail == BUSY:  # the step's other robots in the way, not a crowded region: the step
                return done  # is re-timed (or packed) instead
            # beyond the paper: an obstacle with no place in its own region that its arm reaches (a crowded
            # start region, the later steps' sweeps kept clear) is parked in another region the arm reaches
            for region, top in self._parking(a):
                parked = self._place(a, planned, region, start, lift, avoid, v_fut, f"{key}:park", placed, busy, top)
                if not isinstance(parked, Failure):
                    return parked
        return done

    @property
    def _tops(self) -> list[SceneBody]:
        """The tops of fixed boxes obstacles may be set aside on, and relays set down on when their region has no
        spot (:func:`~mrgc.geometry.placements.aside_tops`)."""
        if self._aside is None:
            self._aside = aside_tops(self.g.scene)
        return self._aside

    def _parking(self, a: Action) -> list[tuple[str, SceneBody | None]]:
        """Where an obstacle ``a`` moves may be parked when its own region has no place for it: the other box
        regions whose centre the placing arm reaches, regions nobody's goal first, then nearest the arm (at most
        :data:`PARKING_REGIONS`); then, set aside beyond every region, the tops of the fixed boxes
        (:func:`~mrgc.geometry.placements.aside_tops`: a table) the arm reaches (session 42: the 6-arm,
        40-object instances park in their crowded start region or in the goal bins otherwise).  Each with the
        body to look in (None: the region itself)."""
        g = self.g
        arm = g.arm(a.place_robot)
        goals = set(self.goal.values())
        out = []
        for r in g.scene.regions:
            if r.name != a.region and isinstance(r.shape, Box) and arm.in_reach(r.pose[:3, 3], margin=0.1):
                out.append((r.name in goals, float(np.linalg.norm(r.pose[:2, 3] - arm.base[:2, 3])), r.name))
        where: list[tuple[str, SceneBody | None]] = [(name, None) for _, _, name in sorted(out)[:PARKING_REGIONS]]
        base = arm.base[:3, 3]
        tops = [t for t in self._tops if t.name != a.region and arm.in_reach(nearest_on_top(t, base), margin=0.1)]
        return where + [(top.name, top) for top in tops]

    def _place(
        self,
        a: Action,
        planned: PlannedAction,
        region: str,
        start: np.ndarray,
        lift: bool,
        avoid: list[str],
        v_fut: Posed,
        key: str,
        placed: dict[str, np.ndarray] | None,
        busy: dict[str, Volume],
        top: SceneBody | None = None,
    ) -> PlannedAction | Failure:
        """Put ``a``'s object into ``region``: a placement, the place approach and the carry there from
        ``start``, into ``planned`` (its region too); the failure of the last placement tried otherwise.  With
        ``top`` (a fixed object's top, named ``region``) the object is set aside on it, clear of every region's
        footprint (:func:`~mrgc.geometry.placements.off_regions`)."""
        g = self.g
        last: Failure | None = None
        tried = 0  # placements whose carry was planned, or whose approach the step's other robots blocked
        forced = self._forced.get(a.obj)
        # goal bins are shared by several objects: packed from the corners; elsewhere (moving an obstacle
        # aside) the middle of the region first, nearest the arms that reach it
        spots = (
            iter([forced])
            if forced is not None  # a relay sets its object down where its onward move picks it up
            else g.placements(
                a.obj,
                region if top is None else top,
                avoid=avoid,
                volume=v_fut,
                key=key,
                packed=self.goal.get(a.obj) == region,
                prefer=g.comfortable(a.place_robot, a.obj, a.place_grasp),
                samples=PLACEMENT_SAMPLES,
            )
        )
        if top is not None:
            spots = filter(off_regions(g.scene, a.obj), spots)
        far_off = g.out_of_reach(a.place_robot, a.obj, a.place_grasp)
        looked = far = 0
        crossed = 0  # carries blocked by what the step's other robots sweep meanwhile (``busy``)
        static = True  # every placement tried failed on what never moves (Failure.static)
        while looked < PLACEMENT_TRIES + OUT_OF_REACH_TRIES and tried < PLACEMENT_TRIES:
            self._on_time()
            pose = next(spots, None)
            if pose is None:
                none = Failure(0, "", f"placement: no free pose of {a.obj} in {region}")
                if far and last is None:  # as when every pose tried had no IK (static, as that was)
                    beyond = f"the free poses in {region} not failed at before are beyond its reach"
                    return Failure(0, "", f"place by {a.place_robot}: {GroundStatus.NO_IK.value}", (), beyond, True)
                return _static(last, static) if last else none
            spot = (a.place_robot, a.obj, a.place_grasp, _spot_key(pose))
            if spot in self._dead_spots:
                continue  # failed before on what never moves: fails again, and costs no try
            if forced is None and far_off(pose):
                far += 1
                continue  # no arm configuration reaches it (the reach bound is an upper bound): costs no try
            looked += 1
            place = g.place(
                a.place_robot,
                a.obj,
                a.place_grasp,
                pose,
                avoid=avoid,
                busy=busy.get("place", []),
                after=self._after(busy, a.place_robot, Stance.PLACED),
            )
            if not place.ok:
                last = _failed(f"place by {a.place_robot}", place)
                # an approach costs a try only when the step's other robots are in its way; out of reach, or
                # an object, fixed body or the arm itself in the way, it costs a look (a crowded start region:
                # the free pose next to the others, fingers touching a neighbour, then one with room)
                tried += place.detail == BUSY
                if place.static:
                    self._dead_spots.add(spot)
                static = static and place.static
                continue
            static = False
            tried += 1
            assert place.configs is not None
            carry = g.transfer(
                a.place_robot,
                a.obj,
                a.place_grasp,
                start,
                place.configs[0],
                avoid,
                lift=lift,
                busy=busy.get("to-place", []),
                lower=True,
                phase="to-place",
            )
            if not carry.ok:
                last = _failed(f"carry to the placement by {a.place_robot}", carry)
                crossed += carry.detail == BUSY
                if crossed >= BUSY_CARRIES:
                    return last
                continue
            planned.region = region
            planned.place_pose = _matrix(pose)
            planned.configs["place"] = _configs(place.configs)
            planned.paths["to-place"] = _configs(np.array(carry.path))
            # the arm's empty-handed motions (``full``), and room left in the bin for what comes before
            after = self._transits(a, planned, avoid, busy, {**(placed or {}), a.obj: pose}) if self.full else None
            after = after or self._crowds(a, planned, avoid, v_fut, placed or {}, key)
            if after:
                last = after
                continue
            return planned
        assert last is not None
        return _static(last, static)

    def _crowds(
        self,
        a: Action,
        planned: PlannedAction,
        avoid: list[str],
        v_fut: Posed,
        placed: dict[str, np.ndarray],
        key: str,
    ) -> Failure | None:
        """A failure when the grounded ``planned`` (its motions and the object at its placement) leaves one of
        the goal objects that the earlier steps still have to put into the same bin no free pose there
        (see :meth:`Grounder.crowded_out`); None when each still has one, or none is left to come."""
        later = {a.obj, *placed, *self.grounded}
        still = [o for o in sorted(self.goal) if self.goal[o] == planned.region and o not in later]
        if not still:
            return None
        mine = [p for phases in self._motions(planned).values() for vols in phases.values() for v in vols for p in v]
        crowded = self.g.crowded_out(still, planned.region, avoid, v_fut, key, extra=mine)
        if crowded is None:
            return None
        return Failure(0, "", f"placement: leaves no free pose of {crowded} in {planned.region}")

    def _let_go(self, action: PlannedAction) -> np.ndarray:
        """How a handover's giver backs off the object it lets go at the exchange (the taker holds it there,
        between the giver's fingers at the grasp's opening): along its approach axis, back (world; the tool's
        -z), as a home path backs off along the place approach."""
        tool = self.g.arm(action.pick_robot).tool_world(np.array(action.configs["handover"][0])[None])[0]
        back: np.ndarray = -tool[:3, 2]
        return back

    def _hand_over(
        self, a: Action, planned: PlannedAction, grasped: np.ndarray, avoid: list[str], busy: dict[str, Volume]
    ) -> np.ndarray | Failure:
        """A handover action's exchange (both arms at a handover point) and the giver's carry there from
        ``grasped`` (its pick configuration), into ``planned``; the taker's configuration at the exchange.
        The object's handover points are tried in order until one has both an exchange and a carry to it: a
        point near the edge of the giver's reach can have a free exchange that no carry from the pick gets
        to, where the next point is easy (the 6-arm, 40-object instance of seed 8: one handover failed 40
        times in a row as "carry to the handover: no path" at h1, its other point never tried)."""
        g = self.g
        # each arm then stands at its exchange while the step's other robots do what ``after`` holds
        after = {
            a.pick_robot: self._after(busy, a.pick_robot, Stance.EXCHANGE),
            a.place_robot: self._after(busy, a.place_robot, Stance.RECEIVED),
        }
        failures: list[tuple[Failure, GroundStatus, bool]] = []
        for point in self.g.scene.handover_of.get(a.obj, ()):
            if point not in self.g.scene.handover_points:
                continue
            tried: list[np.ndarray] = []  # the giver's exchange configurations no carry reached
            for k in range(EXCHANGE_TRIES):
                self._on_time()
                hand = self._exchange(a, point, avoid, busy.get("handover", []), after, skip=k)
                if isinstance(hand, tuple):
                    if k == 0:
                        failures.append((*hand, False))
                    break  # no exchange here, or no other pair than those tried
                assert hand.configs is not None
                if any(np.array_equal(hand.configs[0], q) for q in tried):
                    continue  # the same giver configuration with another taker's: the same carry
                giver = g.transfer(
                    a.pick_robot,
                    a.obj,
                    a.pick_grasp,
                    grasped,
                    hand.configs[0],
                    avoid,
                    lift=True,
                    busy=busy.get("to-handover", []),
                    phase="to-handover",
                )
                if not giver.ok:  # each carry's failure kept: another robot of the step may be in one's way only
                    tried.append(hand.configs[0])
                    failures.append((_failed(f"carry to the handover by {a.pick_robot}", giver), giver.status, True))
                    continue
                planned.handover_point = point
                planned.configs["handover"] = _configs(hand.configs)
                planned.paths["to-handover"] = _configs(np.array(giver.path))
                taker: np.ndarray = hand.configs[1]
                return taker
        if not failures:
            return Failure(0, "", f"handover: no handover point usable for {a.obj}")
        return _telling(failures)

    def _transits(
        self, a: Action, planned: PlannedAction, avoid: list[str], busy: dict[str, Volume], new: dict[str, np.ndarray]
    ) -> None | Failure:
        """An arm action's empty-handed motions (``full``), into ``planned.paths``: home to the pre-grasp
        (the object to pick in the way too), the taker home to the exchange, the giver home from the exchange
        (letting go: its fingers at the grasp's opening back off along its approach axis first, the taker
        standing there holding the object); then, with every object of the step at its new pose (``new``, the
        validator's home phase), back off along the place approach and go home."""
        g = self.g
        pick, place = np.array(planned.configs["pick"]), np.array(planned.configs["place"])
        asks: list[tuple[str, str, np.ndarray, np.ndarray, list[str], dict[str, Any]]] = [
            ("to-pick", a.pick_robot, g.arm(a.pick_robot).home, pick[0], [*avoid, a.obj], {})
        ]
        if a.handover:
            giver, taker = np.array(planned.configs["handover"])
            asks.append(("taker-to-handover", a.place_robot, g.arm(a.place_robot).home, taker, avoid, {}))
            let_go = {"fingers": (a.obj, a.pick_grasp), "retreat": self._let_go(planned)}
            asks.append(("giver-home", a.pick_robot, giver, g.arm(a.pick_robot).home, avoid, let_go))
        after = sorted({*avoid, *new})
        asks.append(("home", a.place_robot, place[-1], g.arm(a.place_robot).home, after, {"via": place[::-1]}))
        # the giver's motions share the validator's phases with the taker's: each keeps clear of the other's
        mine: dict[str, Volume] = {}
        if "to-handover" in planned.paths:
            mine["to-handover"] = g.arm_volume(
                a.pick_robot, np.array(planned.paths["to-handover"]), holding=(a.obj, a.pick_grasp)
            )
        home = False
        with ExitStack() as stack:
            for name, robot, start, goal, obstacles, how in asks:
                phase = PATH_PHASE.get(name, name)
                if phase == "home" and not home:  # the home phase comes last: the step's objects placed
                    stack.enter_context(g.moved(new))
                    home = True
                ans = g.transit(
                    robot,
                    start,
                    goal,
                    avoid=obstacles,
                    busy=busy.get(phase, []) + mine.get(phase, []),
                    phase=phase,
                    **how,
                )
                if not ans.ok:
                    return _failed(f"{name} of {robot}", ans)
                planned.paths[name] = _configs(np.array(ans.path))
                mine.setdefault(phase, []).extend(g.arm_volume(robot, np.array(ans.path), grasp=how.get("fingers")))
        return None

    def _drive(
        self,
        a: Action,
        avoid: list[str],
        v_fut: Posed,
        key: str,
        placed: dict[str, np.ndarray],
        busy: dict[str, Volume],
    ) -> PlannedAction | Failure:
        """A planar robot's action (path mode): drive from its start pose to the pick pose, carry the object
        to the place pose, drive back; every path free of fixed objects and of ``avoid``.  The drive home
        sees every object of the step at its new pose (the validator's home phase): the one just placed and
        those ``placed`` by the step's actions grounded before this one (the ones grounded after it keep
        clear of this drive, which is in the step's volume).  Robots of one step move at once, phase by
        phase: each path keeps clear of everything the step's robots grounded before sweep in that phase
        (``busy``: conservative, as it ignores when they pass)."""
        g, robot = self.g, a.pick_robot
        if a.handover:
            return Failure(0, "", "planar robots do not hand over")  # no such facts are computed
        pr = g.planar(robot)
        shape = g.scene.body(a.obj).shape
        home = pr.home
        q_pick = pr.grasp_base(g.poses[a.obj], shape, a.pick_grasp)
        # the drive to the pick keeps clear of the object too: the robot stops in front of it
        to_pick = g.base_path(robot, home, q_pick, avoid=[*avoid, a.obj], busy=busy.get("to-pick", []))
        if not to_pick.ok:
            return _failed("drive to the pick", to_pick)
        last: Failure | None = None
        for k in range(PLACEMENT_TRIES):
            self._on_time()
            spot = g.placement(a.obj, a.region, avoid=avoid, volume=v_fut, key=key, skip=k)
            if not spot.ok:
                return last or Failure(0, "", f"placement: no free pose of {a.obj} in {a.region}")
            assert spot.pose is not None
            q_place = pr.grasp_base(spot.pose, shape, a.place_grasp)
            carry = g.base_path(
                robot, q_pick, q_place, holding=(a.obj, a.pick_grasp), avoid=avoid, busy=busy.get("to-place", [])
            )
            if not carry.ok:
                last = _failed("carry to the placement", carry)
                continue
            new = {**placed, a.obj: spot.pose}
            with g.moved(new):
                back = g.base_path(robot, q_place, home, avoid=sorted({*avoid, *new}), busy=busy.get("home", []))
            if not back.ok:
                last = _failed("drive home", back)
                continue
            planned = PlannedAction(
                a.obj, a.region, robot, robot, a.pick_grasp, a.place_grasp, place_pose=_matrix(spot.pose)
            )
            planned.configs = {"pick": _configs(q_pick), "place": _configs(q_place)}
            planned.paths = {
                "to-pick": _configs(np.array(to_pick.path)),
                "to-place": _configs(np.array(carry.path)),
                "home": _configs(np.array(back.path)),
            }
            return planned
        assert last is not None
        return last

    def _exchange(
        self, a: Action, point: str, avoid: list[str], busy: Volume, after: dict[str, Volume], skip: int = 0
    ) -> Answer | tuple[Failure, GroundStatus]:
        """Both arms' exchange configurations for ``a`` at handover point ``point`` (giver, taker), the pair
        after the first ``skip`` free ones (:meth:`Grounder.handover <mrgc.geometry.approaches.Approaches.handover>`),
        or the failure there with its query's status (two arms colliding named as such)."""
        ans = self.g.handover(
            a.obj,
            point,
            a.pick_robot,
            a.pick_grasp,
            a.place_robot,
            a.place_grasp,
            avoid=avoid,
            busy=busy,
            after=after,
            skip=skip,
        )
        if ans.ok:
            return ans
        failure = _failed(f"handover at {point}", ans)
        if (
            ans.status is GroundStatus.COLLISION
            and not ans.blockers
            and not ans.detail.startswith(("hits", BUSY, SELF))
        ):
            failure = replace(
                failure,
                check=f"handover at {point}: the two arms collide",
                bodies=tuple(sorted((a.pick_robot, a.place_robot))),
            )
        return failure, ans.status


class _Retiming:
    """A skeleton's steps as the reverse search re-times its actions (beyond the paper): an action in the way
    of another robot of its step goes to the latest earlier step (not grounded yet: the reverse search
    grounds later steps first) where its robots are free, that holds no relay, and where the skeleton's order
    constraints (``order``: the action's obstacles, (object, strict)) still hold: each obstacle moved by the
    skeleton strictly before that step, or no later for a non-strict one.  The actions that wait for the
    re-timed one's object (it is their obstacle) only gain: it now moves earlier.  A step with a handover
    takes no second one (a single handover point: the skeleton model's rule, kept for any number).  Geometry
    agrees: the objects of earlier steps are at their initial poses for the later ones, which ignore them,
    and their placements avoid what the later steps sweep, whatever step they are in.  Moves (and the
    failures they or a packing got around) are pending until the step that made them is grounded
    (:meth:`commit`); :meth:`rollback` takes back those made since a :meth:`mark`."""

    def __init__(self, steps: list[list[Action]], order: Order | None) -> None:
        self.steps, self.order = steps, order
        self.pending: list[tuple[Action, int, int]] = []  # (action, from step, to step), 1-based
        self.noted: list[Failure] = []
        self.done: list[tuple[str, int, int]] = []
        self.resolved: list[Failure] = []

    def retime(self, a: Action, index: int) -> bool:
        """Move ``a`` from step ``index`` to an earlier one where it may go (pending); False when none."""
        if self.order is None or a.via is not None or a not in self.steps[index - 1]:
            return False
        to = self._target(a, index)
        if to is None:
            return False
        self.steps[index - 1].remove(a)
        self.steps[to - 1].append(a)
        self.pending.append((a, index, to))
        return True

    def _target(self, a: Action, index: int) -> int | None:
        assert self.order is not None
        when = {b.obj: t for t, step in enumerate(self.steps, 1) for b in step}
        obstacles = self.order(a)
        for to in range(index - 1, 0, -1):
            step = self.steps[to - 1]
            if any(set(b.robots) & set(a.robots) or b.via is not None for b in step):
                continue
            if a.handover and any(b.handover for b in step):
                continue
            if all(o in when and (when[o] < to if strict else when[o] <= to) for o, strict in obstacles):
                return to
        return None

    def mark(self) -> tuple[int, int]:
        """Where the pending moves and notes stand now."""
        return len(self.pending), len(self.noted)

    def rollback(self, mark: tuple[int, int] = (0, 0)) -> None:
        """Take back the moves and notes made since ``mark`` (default: all pending ones)."""
        while len(self.pending) > mark[0]:
            a, at, to = self.pending.pop()
            self.steps[to - 1].remove(a)
            self.steps[at - 1].append(a)
        del self.noted[mark[1] :]

    def commit(self) -> None:
        """The pending moves hold: the step that made them is grounded."""
        self.done += [(label(a), at, to) for a, at, to in self.pending]
        self.resolved += self.noted
        self.pending.clear()
        self.noted.clear()

    def told(self, grounding: Grounding) -> Grounding:
        """``grounding`` with the re-timings and the resolved failures of robots in each other's way."""
        grounding.retimed = list(self.done)
        grounding.resolved = list(self.resolved)
        return grounding


def label(a: Action) -> str:
    """An action as a failure line names it: ``r1 moves o3 to bin-a (top)``, ``r1->r2 hands o3 to bin-a ...``,
    ``r1->r2 relay o3 to bin-a via start (top->top)``."""
    if a.via is not None:
        return (
            f"{a.pick_robot}->{a.place_robot} relay {a.obj} to {a.region} via {a.via} ({a.pick_grasp}->{a.place_grasp})"
        )
    if a.pick_robot == a.place_robot:
        return f"{a.pick_robot} moves {a.obj} to {a.region} ({a.pick_grasp})"
    return f"{a.pick_robot}->{a.place_robot} hand {a.obj} over to {a.region} ({a.pick_grasp}->{a.place_grasp})"


def _both(
    rank_a: Callable[[np.ndarray], np.ndarray], rank_b: Callable[[np.ndarray], np.ndarray]
) -> Callable[[np.ndarray], np.ndarray]:
    """A rank of relay spots by two robots' :meth:`comfortable <mrgc.geometry.placements.Placements.comfortable>`
    ranks: 0 where both reach comfortably, else the worse of the two (nearer first).  A region both robots
    reach only in a corner (a crowded start region between two arms) is searched there first, not over its
    whole area."""
    return lambda poses: np.maximum(rank_a(poses), rank_b(poses))


def _spot_key(pose: np.ndarray) -> tuple[float, ...]:
    """A placement as a set key: its rotation and position rounded to 1e-6 (the same candidate drawn again by
    another grounding is the same key)."""
    return tuple(float(v) + 0.0 for v in np.round(pose[:3], 6).ravel())


def _static(failure: Failure, static: bool) -> Failure:
    """``failure`` marked static exactly when ``static``: every try behind it failed on what never moves."""
    return failure if failure.static == static else replace(failure, static=static)


def _telling(failures: list[tuple[Failure, GroundStatus, bool]]) -> Failure:
    """Of an action's failures at each of its handover points (the exchange's there, or the giver's carry to
    it; each with its query's status and whether the exchange there was found), the one that says most about
    what would let it through: another robot of the step in the way (the step's robots' passes are then
    compared sample by sample, or the step is packed), else bodies in the way (objects to move first, or the
    two arms), else the carry to a point whose exchange was found (the only point that got that far), else
    anything but a point out of the arms' reach, else the last.  The last point's failure alone hid the
    others': on the 6-arm, 40-object instance one handover failed 42 times as "handover at h5: no inverse
    kinematics" (h5 is out of reach for that grasp pair) where another robot of the step was in the way at
    h1, the point in reach; the step was never split.  And an exchange that fails at a point hid the carry
    that failed at the point where the exchange exists: seed 0's first skeleton failed as "handover at h3:
    collision: hits r6 at home" (no exchange at h3 in phase 1 either) where the giver's carry to h5 found no
    path."""
    for telling in (
        lambda f, _, __: f.detail == BUSY,
        lambda f, _, __: bool(f.bodies),
        lambda _, __, exchanged: exchanged,
        lambda _, status, __: status is not GroundStatus.NO_IK,
    ):
        for f, status, exchanged in failures:
            if telling(f, status, exchanged):
                return f
    return failures[-1][0]


def _lead(step: tuple[Action, ...], failure: Failure) -> Action | None:
    """The action of ``step`` to ground first when the step's robots got in each other's way grounded in the
    order given (``failure``): the failing one, so that the others plan around it; None for another
    failure."""
    if len(step) < 2 or not (failure.detail == BUSY or failure.check.endswith("robots of the step collide")):
        return None
    return next((a for a in step if label(a) == failure.action), None)


def _failed(what: str, answer: Answer) -> Failure:
    """A failure of a geometric query: its status as the check, the objects that were in the way as bodies."""
    return Failure(
        0, "", f"{what}: {answer.status.value}", tuple(sorted(answer.blockers)), answer.detail, answer.static
    )


def _path_of(action: PlannedAction, phase: str) -> tuple[str, str | None, bool]:
    """Whose a path of ``action`` is, the grasp its fingers are at (None: fully open) and whether it holds the
    object: the transfers hold it, the transits are empty-handed (a giver's fingers as it let go)."""
    table = {
        "to-handover": (action.pick_grasp, True),
        "to-place": (action.place_grasp, True),
        "to-pick": (None, False),
        "taker-to-handover": (None, False),
        "home": (None, False),
        "giver-home": (action.pick_grasp, False),
    }
    return (action.path_robot(phase), *table[phase])


def swept(steps: Iterable[GroundedStep], before: Posed | None = None) -> Posed:
    """The volume ``steps`` sweep (their volumes one after the other: V_fut of the step before them), after
    ``before``'s pieces when given; a new set, whatever caches the queries of it grow stay with it."""
    return Posed.join([*([before] if before is not None else []), *(s.volume for s in steps)])


def _plus(volume: Posed, pieces: Volume) -> Posed:
    """``volume`` and then ``pieces`` (``volume`` itself when there are none: its caches go on)."""
    return Posed.join([volume, Posed.of(pieces, volume.pad)]) if pieces else volume


def _swept_by_others(motions: Motions, robots: tuple[str, ...]) -> dict[str, Volume]:
    """What the step's robots other than ``robots`` sweep in each phase (every sample of their motions)."""
    busy: dict[str, Volume] = {}
    for robot, phases in motions.items():
        if robot not in robots:
            for phase, samples in phases.items():
                busy.setdefault(phase, []).extend(p for vol in samples for p in vol)
    return busy


def _joined(moves: Motions, stood: Motions) -> Motions:
    """An action's motions with the phases its robots stand still in (where they make no motion)."""
    out = {robot: dict(phases) for robot, phases in moves.items()}
    for robot, phases in stood.items():
        for phase, volumes in phases.items():
            out.setdefault(robot, {}).setdefault(phase, volumes)
    return out


#: whose path made a robot's motion in a phase of the step: (robot, phase) -> (the action, the path's name)
Owners = dict[tuple[str, str], tuple[PlannedAction, str]]


def _pad(path: list[Any], n: int) -> list[Any]:
    """``path`` standing still ``n`` configurations at its start (n > 0) or ``-n`` at its end (n < 0)."""
    still = [path[0] if n > 0 else path[-1]] * abs(n)
    return still + path if n > 0 else path + still


def _waiting(
    action: PlannedAction,
    mine: Motions,
    motions: Motions,
    clash: tuple[str, tuple[str, ...]] | None,
    owners: Owners | None = None,
) -> tuple[tuple[str, tuple[str, ...]] | None, Motions]:
    """Where ``action``'s motions ``mine`` meet another robot of the step (``clash``, :func:`_robots_collide`'s
    answer), the robot of the action that moves in that phase waits (:data:`WAITS`): it stands still at the
    path's first configuration before setting out, or at its last after arriving, for a share of the phase,
    so that the two pass one after the other (the validator replays a phase's configurations equally spaced
    in time: a repeated configuration is time standing still).  When no share clears the phase and the
    other robot moves there on a path of an earlier action of the step (``owners``), the two take the phase
    one after the other: the other hurries through the first half and stands at its path's end, this one
    stands at its start meanwhile and takes the second half, or the other way round; every other robot of the
    step is compared with both again.  Phase by phase until none clashes; a wait is kept only when it clears
    the phase it is made in.  The clash left (None when every one was waited out) and the motions as they
    are then; the paths (``action``'s, and the earlier actions' with ``motions`` in step) get the waits only
    when they cleared every clash.  A phase in which both robots of a handover move, or the action moves on
    no path of its own (an approach, an exchange), is not waited in."""
    if clash is None:
        return None, mine
    mine = {robot: dict(phases) for robot, phases in mine.items()}
    theirs = {robot: dict(phases) for robot, phases in motions.items()}
    pads: dict[str, int] = {}  # path name -> configurations added (> 0 before it, < 0 after it)
    their_pads: dict[tuple[str, str], int] = {}  # (robot, phase) of an earlier action -> the same
    while clash is not None:
        phase = clash[0]
        names = [n for n in action.paths if PATH_PHASE.get(n, n) == phase]
        if len(names) != 1 or names[0] in pads:
            return clash, mine
        robot = action.path_robot(names[0])
        samples = mine[robot][phase]
        if len(samples) < 2:
            return clash, mine
        for share in WAITS:
            n = math.ceil(abs(share) * (len(samples) - 1) / (1 - abs(share)))
            waited = _pad(samples, n if share > 0 else -n)
            if not any(_phases_collide({phase: waited}, their) for o, their in theirs.items() if o != robot):
                pads[names[0]] = n if share > 0 else -n
                mine[robot][phase] = waited
                break
        else:
            turns = _in_turn(robot, samples, phase, clash[1], theirs, owners or {}, their_pads)
            if turns is None:
                return clash, mine
            pads[names[0]], (other, n_other) = turns
            mine[robot][phase] = _pad(samples, pads[names[0]])
            theirs[other][phase] = _pad(theirs[other][phase], n_other)
            their_pads[(other, phase)] = n_other
        clash = _robots_collide(mine, theirs)
    for name, n in pads.items():
        action.paths[name] = [list(q) for q in _pad(action.paths[name], n)]
    for (other, phase), n in their_pads.items():
        owner, name = (owners or {})[(other, phase)]
        owner.paths[name] = [list(q) for q in _pad(owner.paths[name], n)]
        motions[other][phase] = theirs[other][phase]
    return None, mine


def _in_turn(
    robot: str,
    samples: list[Volume],
    phase: str,
    robots: tuple[str, ...],
    theirs: Motions,
    owners: Owners,
    done: dict[tuple[str, str], int],
) -> tuple[int, tuple[str, int]] | None:
    """:func:`_waiting`'s last resort: ``robot`` (its ``samples`` in ``phase``) and the other robot of the
    clash (``robots``) take the phase in turn, each standing still while the other moves; the pads of the
    two paths (``robot``'s, then (the other, its)), or None when the other's motion there is no path of an
    earlier action of the step (or is padded already, or shared with its partner in a handover), or neither
    order clears the phase against every robot of the step."""
    other = next((r for r in robots if r != robot), None)
    if other is None or (other, phase) not in owners or (other, phase) in done:
        return None
    owner, name = owners[(other, phase)]
    if sum(PATH_PHASE.get(n, n) == phase for n in owner.paths) != 1:
        return None
    their = theirs[other][phase]
    if len(their) < 2:
        return None
    rest = [m for o, m in theirs.items() if o not in (robot, other)]
    for mine_n, their_n in ((len(their) - 1, -(len(samples) - 1)), (-(len(their) - 1), len(samples) - 1)):
        me, it = _pad(samples, mine_n), _pad(their, their_n)
        if _phases_collide({phase: me}, {phase: it}):
            continue
        if any(_phases_collide({phase: me}, m) or _phases_collide({phase: it}, m) for m in rest):
            continue
        return mine_n, (other, their_n)
    return None


def _robots_collide(mine: Motions, motions: Motions) -> tuple[str, tuple[str, ...]] | None:
    """Robots of one step move at once: phase by phase (pick, handover, place; drives), samples paired by
    index as the validator replays them, they must not collide with each other.  The first phase where a
    robot of ``mine`` (an action's motions) collides with another robot of ``motions`` (the step's actions
    grounded before), and the two robots; None when none does."""
    for robot, phases in mine.items():
        for other, their in motions.items():
            phase = _phases_collide(phases, their)
            if other != robot and phase:
                return phase, tuple(sorted((robot, other)))
    return None


def _phases_collide(mine: dict[str, list[Volume]], theirs: dict[str, list[Volume]]) -> str:
    """The first phase both robots move in where they collide, their samples paired by index (resampled);
    "" when they never do.  Each phase is one query of the collision kernel: every pair of samples at once,
    only pieces of paired samples tested against each other."""
    for phase, samples in mine.items():
        other = theirs.get(phase)
        if not other:
            continue
        if len(samples) == 1 or len(other) == 1:  # one stands still: against every sample of the other at once
            still, moves = (samples, other) if len(samples) == 1 else (other, samples)
            if pieces_collide([p for vol in moves for p in vol], still[0]):
                return phase
            continue
        if _paired(samples, other):
            return phase
    return ""


def _paired(a: list[Volume], b: list[Volume]) -> bool:
    """Whether sample ``i * len(a) // n`` of ``a`` collides with sample ``i * len(b) // n`` of ``b`` for some
    ``i < n = max(len(a), len(b))`` (the validator's pairing of two motions).  One query of the kernel
    (:func:`~mrgc.geometry.collision.grouped_collide`): each distinct volume of either motion in it once (a
    volume repeated, a robot standing still while it waits, is one group), the pairs of volumes that meet in
    time, and of those only the pairs whose volumes' boxes meet opened piece by piece."""
    n = max(len(a), len(b))
    groups: tuple[dict[int, int], dict[int, int]] = ({}, {})  # id of a volume -> its group, per motion
    volumes: tuple[list[Volume], list[Volume]] = ([], [])
    pairs: dict[tuple[int, int], None] = {}
    for i in range(n):
        va, vb = a[i * len(a) // n], b[i * len(b) // n]
        if not va or not vb:
            continue
        ka, kb = (_group(v, groups[s], volumes[s]) for s, v in ((0, va), (1, vb)))
        pairs[(ka, kb)] = None
    if not pairs:
        return False
    (pa, sa), (pb, sb) = (
        (Posed.of([p for v in vs for p in v]), np.cumsum([0] + [len(v) for v in vs])) for vs in volumes
    )
    return grouped_collide(pa, sa, pb, sb, np.array(list(pairs), dtype=np.intp))


def _group(volume: Volume, groups: dict[int, int], volumes: list[Volume]) -> int:
    """The group of ``volume`` in :func:`_paired`'s query, a new one for a volume not seen before."""
    k = groups.get(id(volume))
    if k is None:
        k = groups[id(volume)] = len(volumes)
        volumes.append(volume)
    return k


def _retimable(alone: Action, step: tuple[Action, ...], failure: Failure) -> list[Action]:
    """The actions of ``step`` that :meth:`ReverseGrounder._steps` tries to re-time into an earlier step when
    ``alone`` failed on another robot of the step (``failure``): ``alone``, then the actions of the robots
    the failure names that ``alone`` does not use (the two robots of a clash: moving either apart settles it;
    PA5-s15's `r2 moves o3` had no earlier step with r2 free, `r1 moves o2` had)."""
    met = set(failure.bodies) - set(alone.robots)
    return [alone] + [b for b in step if b is not alone and met & set(b.robots)]


def draw_key(skeleton: Skeleton, suffix: Iterable[GroundedStep]) -> str:
    """The key a grounding of ``skeleton`` under ``suffix`` draws its random placements and relay spots from
    (:meth:`ReverseGrounder.ground`'s ``key``): made of what is grounded -- the skeleton's steps and the suffix's
    moves, step by step (objects, regions, robots, grasps, relays) -- not of when, so the same skeleton under the
    same moves draws the same way however many groundings came before it, and a change to the search re-draws
    only the groundings it changes (docs/planner.md, "Draws keyed by what is grounded").  16 hex digits of a
    SHA-1, the same on every machine and in every process."""
    lines = [" | ".join(f"{a}" for a in step) for step in skeleton.steps] + ["--"]
    for s in suffix:
        lines.append(
            " | ".join(
                f"{a.object} {a.region} {a.pick_robot} {a.place_robot} {a.pick_grasp} {a.place_grasp}"
                + (" relay" if a.relay else "")
                for a in s.actions
            )
        )
    return hashlib.sha1("\n".join(lines).encode()).hexdigest()[:16]


def moved_objects(steps: Iterable[GroundedStep]) -> set[str]:
    """The objects the grounded steps move."""
    return {o for s in steps for o in s.moved}
