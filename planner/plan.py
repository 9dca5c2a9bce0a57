"""Plans: the planner's output, written as versioned JSON in the plan format of :mod:`mrgc.planfile`.

A :class:`Plan` is the record of one planning run: the steps of :class:`~mrgc.planfile.format.PlannedAction`
s it found (the plan format's one action type), how the run ended (status, why), the validator's verdict on
it and the statistics; :meth:`Plan.dumps` writes it.  :func:`planner_motion_model` is the motion model of
the plans ``mrgc plan`` writes.  :mod:`mrgc.planfile.reader` reads plans back (limits, JSON Schema, typed
actions).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from mrgc.planfile.format import SCHEMA, MotionModel, PlanFile, PlannedAction, Step, plan_text
from mrgc.planner.outcome import PlanStatus, Why


def planner_motion_model(arms: str = "configurations") -> MotionModel:
    """The motion model of the plans ``mrgc plan`` writes: approaches of the geometry layer's
    ``APPROACH_SAMPLES`` configurations backed off by the grasp specification's ``APPROACH``, planar paths
    checked every ``PATH_RESOLUTION``."""
    from mrgc.geometry.conventions import APPROACH_SAMPLES, PATH_RESOLUTION
    from mrgc.geometry.grasps import APPROACH

    return MotionModel(arms, "paths", APPROACH_SAMPLES, APPROACH, PATH_RESOLUTION)


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
    def has_plan(self) -> bool:
        """Whether this holds a plan: one with steps, or a solved one without (the goals held at the start,
        makespan 0); a run without a plan states neither makespan nor motion cost (null in its file)."""
        return bool(self.steps) or self.status is PlanStatus.SOLVED

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
            "makespan": self.makespan if self.has_plan else None,
            "motion_cost": self.motion_cost if self.has_plan else None,
            "steps": [
                {"index": i, "actions": [a.to_json() for a in step], "waiting": self._waiting(step)}
                for i, step in enumerate(self.steps, 1)
            ],
            **({"validation": self.validation} if self.validation is not None else {}),
            **({"why": self.why.to_json()} if self.why is not None else {}),
            "stats": self.stats,
        }

    def as_file(self) -> PlanFile:
        """The plan as the typed values its file holds -- what reading :meth:`to_json` back gives
        (:func:`mrgc.planfile.reader.read_plan`), without the JSON text or the schema check: how the referee
        hands a candidate plan to the validator inside a search (the file, written once at the end, is
        checked against the schema where it is written and read)."""
        return PlanFile(
            schema=SCHEMA,
            mrgc_version=self.mrgc_version,
            problem=self.problem,
            problem_file=self.problem_file,
            problem_sha256=self.problem_sha256,
            backend=self.backend,
            encoding=self.encoding,
            seed=self.seed,
            status=str(self.status),
            symbolic=self.symbolic,
            makespan=self.makespan if self.has_plan else None,
            motion_cost=self.motion_cost if self.has_plan else None,
            steps=tuple(Step(i, tuple(step), tuple(self._waiting(step))) for i, step in enumerate(self.steps, 1)),
            motion_model=None if self.symbolic else (self.motion_model or planner_motion_model()),
            problem_digest=self.problem_digest,
        )

    def _waiting(self, step: list[PlannedAction]) -> list[str]:
        busy = {r for a in step for r in a.robots()}
        return sorted(set(self.stats.get("robots", [])) - busy)

    def dumps(self) -> str:
        """The plan file's text (:func:`~mrgc.planfile.format.plan_text`: a configuration per line)."""
        return plan_text(self.to_json())

    def summary(self) -> list[str]:
        """The plan in a few lines, as ``mrgc plan`` prints it."""
        lines = [
            f"plan for {self.problem}: {self.status}"
            + (
                f", makespan {self.makespan}, {moved_text([[a.object for a in step] for step in self.steps])}"
                if self.has_plan
                else ""
            )
        ]
        for i, step in enumerate(self.steps, 1):
            lines.append(f"  step {i}: " + "; ".join(a.describe() + _waits_text(a) for a in step))
        if self.why is not None and self.status is not PlanStatus.SOLVED:
            lines += self.why.lines()
        return lines


def _waits_text(action: PlannedAction) -> str:
    """`` (r2 waits at the start of to-place, 75 % of it)`` for an action whose robot waits for another of its
    step (:meth:`~mrgc.planfile.format.PlannedAction.waits`); '' when none does."""
    parts = []
    for name, first, last in action.waits():
        where, k = ("start", first) if first else ("end", last)
        share = round(100 * k / (len(action.paths[name]) - 1))
        parts.append(f"{action.path_robot(name)} waits at the {where} of {name}, {share} % of it")
    return f" ({'; '.join(parts)})" if parts else ""


def moved_text(steps: list[list[str]]) -> str:
    """``3 objects moved`` (``in 4 moves`` when a relay moves one twice) for the objects each step moves."""
    objects, moves = len({o for step in steps for o in step}), sum(len(step) for step in steps)
    text = f"{objects} object{'s' * (objects != 1)} moved"
    return text + (f" in {moves} moves" if moves != objects else "")
