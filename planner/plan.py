"""Plans: the planner's output, as versioned JSON (schema ``docs/plan.schema.json``).

A plan is a sequence of steps; in each step every robot performs at most one action (a pick-and-place, a
handover-and-place occupying two robots) or waits.  Geometric plans carry the placement pose of every
moved object and the robots' configurations: for an arm, the approach configurations of its pick and of
its place (pre-grasp first), and at a handover both robots' exchange configurations; for a planar robot,
its SE(2) paths.  Symbolic plans carry no geometry.

A geometric plan states its :class:`MotionModel`: which motions it holds, and so which motions the
validator requires and how it reads a motion the plan leaves out (docs/validator.md).  This module writes
plans; :mod:`mrgc.planner.plan_reader` reads them back (limits, JSON Schema, typed actions).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field, replace
from typing import Any

from mrgc.planner.outcome import PlanStatus, Why

SCHEMA = "mrgc-plan/1"

#: ``motion_model.arms`` -> what an arm's motions in the plan are
ARM_MODELS: dict[str, str] = {
    "configurations": "the paper's packaging model: pick and place approaches (pre-grasp to grasp) and the "
    "handover configurations; a transfer holding the object is a straight joint-space move "
    "unless the plan gives its path; empty-handed transit is not modelled",
    "full": "every motion is a path: to-pick, to-handover, taker-to-handover, to-place, home, giver-home, "
    "besides the approaches and handover configurations",
}
#: ``motion_model.planar`` -> what a planar robot's motions in the plan are
PLANAR_MODELS: dict[str, str] = {
    "paths": "every motion is an SE(2) path: to-pick, to-place, home",
}


@dataclass(frozen=True)
class MotionModel:
    """Which motions a geometric plan holds.

    ``arms`` and ``planar`` name entries of :data:`ARM_MODELS` and :data:`PLANAR_MODELS`;
    ``approach_configurations`` is how many configurations each pick and place approach holds (pre-grasp
    first, grasp last, in joint space), ``approach_back_off`` how far (m) the pre-grasp stands back from the
    grasp along the approach axis; ``resolution`` the largest motion (rad per joint; m or rad for a planar
    base) between two states at which the planner checked its motions.
    """

    arms: str = "configurations"
    planar: str = "paths"
    approach_configurations: int = 5
    approach_back_off: float = 0.08
    resolution: float = 0.01

    def to_json(self) -> dict[str, Any]:
        """The motion model as the plan's ``motion_model``."""
        return {
            "arms": self.arms,
            "planar": self.planar,
            "approach": {"configurations": self.approach_configurations, "back_off": self.approach_back_off},
            "resolution": self.resolution,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> "MotionModel":
        """The model of a schema-checked ``motion_model`` object."""
        approach = data["approach"]
        return cls(
            data["arms"],
            data["planar"],
            approach["configurations"],
            float(approach["back_off"]),
            float(data["resolution"]),
        )


def planner_motion_model(arms: str = "configurations") -> MotionModel:
    """The motion model of the plans ``mrgc plan`` writes: approaches of the geometry layer's
    ``APPROACH_SAMPLES`` configurations backed off by the grasp specification's ``APPROACH``, planar paths
    checked every ``PATH_RESOLUTION``."""
    from mrgc.geometry.conventions import APPROACH_SAMPLES, PATH_RESOLUTION
    from mrgc.geometry.grasps import APPROACH

    return MotionModel(arms, "paths", APPROACH_SAMPLES, APPROACH, PATH_RESOLUTION)


@dataclass
class PlannedAction:
    """One action of one step; ``configs`` maps a phase (``pick``, ``place``, ``handover``) to configurations."""

    object: str
    region: str
    pick_robot: str
    place_robot: str
    pick_grasp: str
    place_grasp: str
    place_pose: list[list[float]] | None = None  # 4×4, world frame
    handover_point: str | None = None
    configs: dict[str, list[list[float]]] = field(default_factory=dict)
    paths: dict[str, list[list[float]]] = field(default_factory=dict)
    #: the object is only set down in ``region`` on its way (a relay, beyond the paper: ``enable-relay``);
    #: a later action, the onward move, takes it from there to its goal
    relay: bool = False

    @property
    def kind(self) -> str:
        """``pick-place`` (one robot) or ``handover`` (two)."""
        return "handover" if self.pick_robot != self.place_robot else "pick-place"

    def robots(self) -> list[str]:
        """The robots of the action (one, or the giver and the taker)."""
        return [self.pick_robot] if self.pick_robot == self.place_robot else [self.pick_robot, self.place_robot]

    def to_json(self) -> dict[str, Any]:
        """The action as the plan's JSON holds it."""
        out: dict[str, Any] = {
            "kind": self.kind,
            "object": self.object,
            "region": self.region,
            "pick_robot": self.pick_robot,
            "place_robot": self.place_robot,
            "pick_grasp": self.pick_grasp,
            "place_grasp": self.place_grasp,
        }
        if self.place_pose is not None:
            out["place_pose"] = self.place_pose
        if self.handover_point is not None:
            out["handover_point"] = self.handover_point
        if self.relay:
            out["relay"] = True
        if self.configs:
            out["configs"] = self.configs
        if self.paths:
            out["paths"] = self.paths
        return out


@dataclass
class Plan:
    """A plan and how it was found."""

    problem: str
    problem_file: str
    problem_sha256: str
    mrgc_version: str
    backend: str
    encoding: str
    seed: int
    #: how the run ended (a status's value, as the JSON holds it, is turned into the status)
    status: PlanStatus
    steps: list[list[PlannedAction]] = field(default_factory=list)
    symbolic: bool = False
    stats: dict[str, Any] = field(default_factory=dict)
    #: why the run ended as it did (reasons for "no plan", failures met on the way)
    why: Why | None = None
    #: the independent validator's verdict on the returned plan (geometric plans)
    validation: dict[str, Any] | None = None
    #: the motions a geometric plan holds (None: :func:`planner_motion_model`); symbolic plans have none
    motion_model: MotionModel | None = None
    #: the content digest of the checked problem (:func:`mrgc.language.digest.problem_digest`): the plan is
    #: for any file holding this problem (its facts file too), whatever its bytes
    problem_digest: str | None = None

    def __post_init__(self) -> None:
        self.status = PlanStatus(self.status)

    @property
    def makespan(self) -> int:
        """The number of steps."""
        return len(self.steps)

    @property
    def motion_cost(self) -> int:
        """The number of moves (the paper's cost, objects moved; an object a relay sets down moves twice)."""
        return sum(len(step) for step in self.steps)

    def candidate(self, steps: list[list[PlannedAction]], robots: list[str], symbolic: bool = False) -> "Plan":
        """This run's plan with ``steps`` as a complete, solved plan, for the validator to judge (the
        referee of the search and of the Ap1 baseline), under the motion model the plan will state."""
        return replace(
            self,
            status=PlanStatus.SOLVED,
            steps=steps,
            symbolic=symbolic,
            stats={"robots": robots},
            why=None,
            validation=None,
            problem_digest=None,
        )

    def to_json(self) -> dict[str, Any]:
        """The plan as its JSON file holds it (docs/plan.schema.json)."""
        return {
            "schema": SCHEMA,
            "mrgc_version": self.mrgc_version,
            "problem": self.problem,
            "problem_file": self.problem_file,
            "problem_sha256": self.problem_sha256,
            **({"problem_digest": self.problem_digest} if self.problem_digest is not None else {}),
            "backend": self.backend,
            "encoding": self.encoding,
            "seed": self.seed,
            "status": str(self.status),
            "symbolic": self.symbolic,
            **({} if self.symbolic else {"motion_model": (self.motion_model or planner_motion_model()).to_json()}),
            "makespan": self.makespan if self.steps else None,
            "motion_cost": self.motion_cost if self.steps else None,
            "steps": [
                {"index": i, "actions": [a.to_json() for a in step], "waiting": self._waiting(step)}
                for i, step in enumerate(self.steps, 1)
            ],
            **({"validation": self.validation} if self.validation is not None else {}),
            **({"why": self.why.to_json()} if self.why is not None else {}),
            "stats": self.stats,
        }

    def _waiting(self, step: list[PlannedAction]) -> list[str]:
        busy = {r for a in step for r in a.robots()}
        return sorted(set(self.stats.get("robots", [])) - busy)

    def dumps(self) -> str:
        """The plan file's text."""
        return json.dumps(self.to_json(), indent=1, sort_keys=False) + "\n"

    def summary(self) -> list[str]:
        """The plan in a few lines, as ``mrgc plan`` prints it."""
        lines = [
            f"plan for {self.problem}: {self.status}"
            + (
                f", makespan {self.makespan}, {moved_text([[a.object for a in step] for step in self.steps])}"
                if self.steps
                else ""
            )
        ]
        for i, step in enumerate(self.steps, 1):
            parts = []
            for a in step:
                who = a.pick_robot if a.kind == "pick-place" else f"{a.pick_robot}->{a.place_robot}"
                grasp = a.pick_grasp if a.kind == "pick-place" else f"{a.pick_grasp}->{a.place_grasp}"
                verb = "sets down" if a.relay else "moves"
                parts.append(f"{who} {verb} {a.object} {'in' if a.relay else 'to'} {a.region} ({grasp})")
            lines.append(f"  step {i}: " + "; ".join(parts))
        if self.why is not None and self.status is not PlanStatus.SOLVED:
            lines += self.why.lines()
        return lines


def moved_text(steps: list[list[str]]) -> str:
    """``3 objects moved`` (``in 4 moves`` when a relay moves one twice) for the objects each step moves."""
    objects, moves = len({o for step in steps for o in step}), sum(len(step) for step in steps)
    text = f"{objects} object{'s' * (objects != 1)} moved"
    return text + (f" in {moves} moves" if moves != objects else "")


def file_sha256(path: str) -> str:
    """The sha256 of the file's bytes (hex)."""
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()
