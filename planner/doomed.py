"""Doomed actions (beyond the paper): an action whose pick or place cannot be done wherever the skeleton puts it,
found before the later steps are grounded.

The reverse search grounds a skeleton's last step first.  When an earlier step holds an action that fails for
a reason no later step can change -- the arm reaches none of the free placements of the region
(``place by r2: no inverse kinematics``), the region has no free placement at all, or the object's grasp is
out of reach (``pick by r2: no inverse kinematics``) -- every grounding of such a skeleton spends its later
steps first and then fails there.  On a crowded start region (tests/data/park-packaging.mrg) that was 20-45 s
per skeleton, skeleton after skeleton, since the skeletons of a node's children hold the same action again
(with the probes: 9 s for the first such skeleton of a node, nothing for the next ones).

:class:`DoomedActions` remembers the parts of actions (``("place", object, region, robot)``,
``("pick", object, robot)``) that have failed that way in some grounding; before a skeleton holding such a part
is grounded, each of its suspect actions is *probed* in the most permissive context its step can have: alone
(no other robot of the step), keeping clear of the suffix's volume (the steps an ancestor node grounded, the
same for every skeleton of this node) but not of the skeleton's own later steps, not yet grounded, and
avoiding only the objects still at their initial poses then (those the skeleton or the suffix moves later, and
those of its own step).  The
probe asks what never depends on that context -- a pick's inverse kinematics, and for a place whether any free
placement the arm's inverse kinematics reaches exists among the first :data:`~mrgc.planner.ground.PLACEMENT_TRIES`
+ :data:`~mrgc.planner.ground.OUT_OF_REACH_TRIES` free ones within the arm's reach bound (those past it are passed
over, as the grounding passes them; the region's, and for an obstacle the parking regions the grounding would try
next) -- so a failing probe means the step fails in its real context too:
the fixed lattice of placements only shrinks when more is avoided, and a placement's inverse kinematics
answer (no solution from any start) does not depend on what is avoided.  The random placements beyond the
lattice are drawn with the probe's own seed, so the implication holds for the lattice exactly and for the
rest in distribution.  The skeleton then fails at that step without grounding the later ones (its failure
line is the probe's).  Probes are cached per (action, objects in place); they read no clock and draw their
samples from fixed seeds, so the same search makes the same probes.

A pick that failed on what never moves (:attr:`Failure.static <mrgc.planner.outcome.Failure.static>`: every
attempt out of reach, into a fixed body, a robot's base or the arm itself) needs no probe: the object is
picked where it stands at the start (a skeleton moves each object once; relays are left out, and so is a
failure while the object stands elsewhere: a relay's onward half picks it up at the relay's spot) and the
pick's attempts are seeded by robot, object and grasp, so the same pick fails the same way in every skeleton.  A
skeleton holding one fails at once at that step, with the first failure's line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Iterable

import numpy as np

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.planner.outcome import Failure

if TYPE_CHECKING:
    from mrgc.geometry.grounding import Grounder
    from mrgc.geometry.robot import Sweep
    from mrgc.geometry.scene import Body as SceneBody

#: a part of an action that can be doomed: ("pick", object, robot) or ("place", object, region, robot)
Part = tuple[str, ...]

NO_IK = "no inverse kinematics"


def failed_part(a: Action, check: str) -> Part | None:
    """The part of ``a`` that a failure with ``check`` shows doomed in some context, else None."""
    if a.via is not None:
        return None
    if check.startswith("pick by") and check.endswith(NO_IK):
        return ("pick", a.obj, a.pick_robot)
    if (check.startswith("place by") and check.endswith(NO_IK)) or check.startswith("placement: no free pose"):
        return ("place", a.obj, a.region, a.place_robot)
    return None


class DoomedActions:
    """The suspect parts and the cached probes of one search (see the module docstring).  ``grounder`` answers
    the geometric queries; ``regions(a)`` gives the regions a place of ``a`` is tried in, in order (its own,
    then for an obstacle the parking regions and the fixed tops it may be set aside on), each with the body to
    look in (None: the region itself); ``tries`` bounds the placements looked at per region, ``samples``
    the random ones drawn there (as the grounding does); ``dead``
    is the grounding's set of (robot, object, grasp, placement key) whose place has no inverse kinematics, which
    the probes read and add to; ``spot_key`` makes such a key from a pose; ``on_time`` raises when the search's
    deadline has passed; ``label`` names an action as failure lines do."""

    def __init__(
        self,
        grounder: Grounder,
        goal: dict[str, str],
        regions: Callable[[Action], list[tuple[str, SceneBody | None]]],
        tries: int,
        samples: int,
        dead: set[tuple[str, str, str, tuple[float, ...]]],
        spot_key: Callable[[np.ndarray], tuple[float, ...]],
        on_time: Callable[[], None],
        label: Callable[[Action], str],
    ) -> None:
        self.g, self.goal, self.regions, self.tries, self.samples = grounder, goal, regions, tries, samples
        self.dead, self.spot_key, self.on_time, self.label = dead, spot_key, on_time, label
        self.suspects: set[Part] = set()
        #: (robot, object, grasp) of picks that failed on what never moves, with their failure
        self.static_picks: dict[tuple[str, str, str], Failure] = {}
        self.probes: dict[tuple[Action, frozenset[str], tuple[int, ...]], Failure | None] = {}
        self._alive: dict[tuple[int, ...], tuple[Any, ...]] = {}
        self._volume: Sweep = []
        #: probes made and skeletons failed by one (the search's statistics)
        self.probed = 0
        self.doomed = 0

    def failed(self, a: Action, failure: Failure) -> None:
        """Note the failure of action ``a`` in some grounding."""
        if failure.static and a.via is None and failure.check.startswith("pick by") and self._at_start(a.obj):
            self.static_picks.setdefault((a.pick_robot, a.obj, a.pick_grasp), failure)
        part = failed_part(a, failure.check)
        if part is not None and self.g.robot(a.pick_robot).approaches:
            self.suspects.add(part)

    def _suspect(self, a: Action) -> bool:
        if a.via is not None or not self.g.robot(a.pick_robot).approaches:
            return False
        return ("pick", a.obj, a.pick_robot) in self.suspects or ("place", a.obj, a.region, a.place_robot) in (
            self.suspects
        )

    def first(self, skeleton: Skeleton, later: Iterable[str], suffix: list[Any], volume: Sweep) -> Failure | None:
        """The failure of the latest step of ``skeleton`` holding a doomed action (its step and action set),
        when the objects ``later`` (the suffix's) are moved after the skeleton; None when no probe fails."""
        known = self._static(skeleton)
        if known is not None or not self.suspects:
            return known
        still = set(later)
        self._volume = volume
        tag = tuple(id(s) for s in suffix)
        self._alive.setdefault(tag, tuple(suffix))  # the suffix's steps stay alive while their ids key the probes
        for t in range(skeleton.makespan - 1, -1, -1):
            step = skeleton.steps[t]
            same = {a.obj for a in step}
            for a in step:
                if self._suspect(a):
                    f = self._probe(a, frozenset(still | same), tag)
                    if f is not None:
                        self.doomed += 1
                        return Failure(t + 1, self.label(a), f.check, f.bodies, f.detail)
            still |= same
        return None

    def _at_start(self, obj: str) -> bool:
        """Whether ``obj`` stands at its initial pose in the grounder now (not at a relay's spot, where the
        onward half of a relay picks it up)."""
        return bool(np.array_equal(self.g.poses[obj], self.g.scene.body(obj).pose))

    def _static(self, skeleton: Skeleton) -> Failure | None:
        """The failure of the latest step of ``skeleton`` holding a pick known to fail on what never moves."""
        if not self.static_picks:
            return None
        for t in range(skeleton.makespan - 1, -1, -1):
            for a in skeleton.steps[t]:
                f = self.static_picks.get((a.pick_robot, a.obj, a.pick_grasp)) if a.via is None else None
                if f is not None:
                    self.doomed += 1
                    detail = f.detail or "fails on what never moves"
                    return Failure(t + 1, self.label(a), f.check, f.bodies, f"{detail} (known)", static=True)
        return None

    def _probe(self, a: Action, still: frozenset[str], tag: tuple[int, ...]) -> Failure | None:
        key = (a, still, tag)
        if key not in self.probes:
            self.probed += 1
            self.probes[key] = self._ask(a, sorted(still - {a.obj}))
        return self.probes[key]

    def _ask(self, a: Action, avoid: list[str]) -> Failure | None:
        from mrgc.geometry.answers import GroundStatus
        from mrgc.geometry.stances import roles

        g = self.g
        g.step(roles([(a.pick_robot, a.place_robot)]))
        try:
            pick = g.pick(a.pick_robot, a.obj, a.pick_grasp, avoid=avoid)
            if pick.status is GroundStatus.NO_IK:
                return Failure(0, "", f"pick by {a.pick_robot}: {NO_IK}", detail="probed before the later steps")
            last = None
            for region, top in self.regions(a):
                why = self._placeable(a, region, avoid, top)
                if why is None:
                    return None
                last = last or why
            return last
        finally:
            g.step({})

    def _placeable(self, a: Action, region: str, avoid: list[str], top: SceneBody | None = None) -> Failure | None:
        """None when a free placement of ``a``'s object in ``region`` (on the fixed top ``top`` clear of the
        regions, as the grounding sets obstacles aside) has an inverse kinematics answer for the place, else the
        failure saying why not."""
        from mrgc.geometry.answers import GroundStatus
        from mrgc.geometry.placements import off_regions

        g = self.g
        poses = g.placements(
            a.obj,
            region if top is None else top,
            avoid=avoid,
            volume=self._volume,
            key="doomed",
            packed=self.goal.get(a.obj) == region,
            prefer=g.comfortable(a.place_robot, a.obj, a.place_grasp),
            samples=self.samples,
        )
        if top is not None:
            poses = filter(off_regions(g.scene, a.obj), poses)
        far_off = g.out_of_reach(a.place_robot, a.obj, a.place_grasp)
        looked, any_pose = 0, False
        for pose in poses:
            self.on_time()
            any_pose = True
            if looked >= self.tries:
                break
            spot = (a.place_robot, a.obj, a.place_grasp, self.spot_key(pose))
            if spot in self.dead or far_off(pose):  # as the grounding does: costs no try
                continue
            looked += 1
            place = g.place(a.place_robot, a.obj, a.place_grasp, pose, avoid=avoid)
            if place.status is not GroundStatus.NO_IK:
                return None
            self.dead.add(spot)
        detail = "probed before the later steps"
        if not looked and not any_pose:
            return Failure(0, "", f"placement: no free pose of {a.obj} in {region}", detail=detail)
        return Failure(0, "", f"place by {a.place_robot}: {NO_IK}", detail=detail)
