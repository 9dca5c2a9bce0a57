"""Deferred actions (beyond the paper): what keeps failing in grounding comes last in the skeletons.

Skeletons come in (makespan, objects moved) order, and many share an action: when that action cannot be
grounded (a bin at the edge of the arm's reach, an obstacle with no free place the arm reaches), the
search fails on it skeleton after skeleton while the skeletons without it, one step longer, never come.
:class:`Deferrals` counts, for each failed grounding, the *part* of the skeleton action it failed at:

- a place out of the arm's reach (``place by r1: no inverse kinematics``, ``carry to the placement by
  r1: no inverse kinematics``): the object, the region and the placing robot, whatever the grasps
  (``r1 places o6 in bin-b``): where the hand must go is out of reach with most grasps alike;
- a pick out of reach (``pick by r1: no inverse kinematics``): the object and the picking robot
  (``r1 picks o6``);
- anything else (collisions, crowded regions, handovers, relays, robots of a step colliding): the action
  itself, grasps included: those depend on the grasp and on what else the skeleton moves.

A pick that failed on what never moves (every attempt out of reach, into a fixed body, a robot's base or the
arm itself: :attr:`Failure.static <mrgc.planner.outcome.Failure.static>`) also counts against the pick with
its grasp (``r1 picks o1 with side-x-``), and that part is deferred at once: the object is picked where it
stands at the start (a skeleton moves each object once; relays are counted as themselves), the pick's
attempts are seeded by robot, object and grasp, so every skeleton holding that pick fails on it again.  On
PA10-s15 (``mrgc generate packaging --preset pa10 --seed 15``) eight skeletons in a row failed on
``pick by r1: collision: hits table`` with one grasp of a handover, deferred three at a time per pair of grasps.
A place whose every placement tried failed that way (``r4 places o2 in bin-b with side-y-``: the fingers of a
side grasp into the table wherever the bin's floor puts the object) is deferred at once too: the placements a
later grounding tries are others (the failed ones are remembered and skipped), but the grasp is what fails.

On nine generated runs that hit the time limit before deferral, this split solved 7, counting every
failure by the action 6, and every place and pick failure by its part 5 (docs/planner.md, "Deferred
actions").

At :data:`DEFER_AFTER` failures of one part every skeleton action with that part is deferred: the skeleton
sources give the skeletons without such actions first (:meth:`mrgc.compiler.enumerate.SkeletonGenerator.defer`),
and the rest once those are used up, so no skeleton is lost.  The counts depend only on what the
groundings found, never on time.
"""

from __future__ import annotations

from typing import Iterable

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.planner.outcome import Failure

#: failures of one part (see the module docstring) before the actions with it are deferred
DEFER_AFTER = 3

#: a part of an action: ("place", object, region, robot), ("pick", object, robot) or ("action", action)
Part = tuple[object, ...]


def parts(a: Action) -> list[Part]:
    """The parts of ``a`` a failure may be counted against (a relay only as itself)."""
    whole: Part = ("action", a)
    if a.via is not None:
        return [whole]
    return [("place", a.obj, a.region, a.place_robot), ("pick", a.obj, a.pick_robot), _grasped(a), _put(a), whole]


def _grasped(a: Action) -> Part:
    """The pick of ``a`` with its grasp: the part a static pick failure is counted against."""
    return ("grasp", a.obj, a.pick_robot, a.pick_grasp)


def _put(a: Action) -> Part:
    """The place of ``a`` in its region with its grasp: the part a static place failure is counted against."""
    return ("put", a.obj, a.region, a.place_robot, a.place_grasp)


def _held(a: Action, failure: Failure) -> Part | None:
    """The part a static ``failure`` of ``a`` defers at once (a pick or a place with its grasp), else None."""
    if not failure.static or a.via is not None:
        return None
    if failure.check.startswith("pick by"):
        return _grasped(a)
    if failure.check.startswith("place by"):
        return _put(a)
    return None


def describe(part: Part) -> str:
    """A part in words: ``r1 places o6 in bin-b``, ``r1 picks o6``, ``r1 picks o6 with top``, or the action."""
    if part[0] == "place":
        return f"{part[3]} places {part[1]} in {part[2]}"
    if part[0] == "pick":
        return f"{part[2]} picks {part[1]}"
    if part[0] == "grasp":
        return f"{part[2]} picks {part[1]} with {part[3]}"
    if part[0] == "put":
        return f"{part[3]} places {part[1]} in {part[2]} with {part[4]}"
    return str(part[1])


class Deferrals:
    """The search's failure counts and deferred parts, shared by every skeleton source."""

    def __init__(self, after: int = DEFER_AFTER) -> None:
        self.after = after
        self.counts: dict[Part, int] = {}
        self.deferred: set[Part] = set()

    def failed(self, skeleton: Skeleton, failure: Failure) -> Part | None:
        """Count the part of ``skeleton``'s action that ``failure`` (the first failure of a failed
        grounding) names; returns the part when this failure defers it."""
        from mrgc.planner.ground import label

        if not 1 <= failure.step <= skeleton.makespan:
            return None  # the validator's verdict on a whole plan, or no step
        for a in skeleton.steps[failure.step - 1]:
            names = (label(a), *(label(h) for h in (a.halves if a.via is not None else ())))
            if failure.action in names:
                counted = [(_part(a, failure.check), 1)]
                held = _held(a, failure)
                if held is not None:
                    counted.insert(0, (held, self.after))  # fails wherever it is tried: at once
                found: Part | None = None
                for part, weight in counted:
                    self.counts[part] = self.counts.get(part, 0) + weight
                    if part not in self.deferred and self.counts[part] >= self.after:
                        self.deferred.add(part)
                        found = found or part
                return found
        return None

    def reason(self, part: Part) -> str:
        """Why ``part`` was deferred, in words (the search's ``--verbose`` line)."""
        if part[0] in ("grasp", "put"):
            return "at its first failure, on what never moves"
        return f"after {self.after} failures"

    def covers(self, a: Action) -> bool:
        """Whether ``a`` has a deferred part."""
        return any(p in self.deferred for p in parts(a))

    def among(self, actions: Iterable[Action]) -> list[Action]:
        """The deferred ones of ``actions``."""
        return [a for a in actions if self.covers(a)] if self.deferred else []


def _part(a: Action, check: str) -> Part:
    """The part of ``a`` a failure with ``check`` is counted against."""
    if a.via is not None or not check.endswith("no inverse kinematics"):
        return ("action", a)
    if check.startswith(("place", "carry to the placement")):
        return ("place", a.obj, a.region, a.place_robot)
    if check.startswith("pick"):
        return ("pick", a.obj, a.pick_robot)
    return ("action", a)
