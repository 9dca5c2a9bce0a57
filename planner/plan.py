"""Plans: the planner's output, as versioned JSON (schema ``docs/plan.schema.json``).

A plan is a sequence of steps; in each step every robot performs at most one action (a pick-and-place, a
handover-and-place occupying two robots) or waits.  Geometric plans carry the placement pose of every
moved object and the robots' configurations: for an arm, the approach configurations of its pick and of
its place (pre-grasp first), and at a handover both robots' exchange configurations; for a planar robot,
its SE(2) paths.  Symbolic plans carry no geometry.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from typing import Any

from mrgc.planner.outcome import PlanStatus, Why

SCHEMA = "mrgc-plan/1"


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

    @property
    def kind(self) -> str:
        return "handover" if self.pick_robot != self.place_robot else "pick-place"

    def robots(self) -> list[str]:
        return [self.pick_robot] if self.pick_robot == self.place_robot else [self.pick_robot, self.place_robot]

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "kind": self.kind, "object": self.object, "region": self.region,
            "pick_robot": self.pick_robot, "place_robot": self.place_robot,
            "pick_grasp": self.pick_grasp, "place_grasp": self.place_grasp,
        }
        if self.place_pose is not None:
            out["place_pose"] = self.place_pose
        if self.handover_point is not None:
            out["handover_point"] = self.handover_point
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
    status: PlanStatus | str  # a PlanStatus (its value is what the JSON holds)
    steps: list[list[PlannedAction]] = field(default_factory=list)
    symbolic: bool = False
    stats: dict[str, Any] = field(default_factory=dict)
    #: why the run ended as it did (reasons for "no plan", failures met on the way)
    why: Why | None = None
    #: the independent validator's verdict on the returned plan (geometric plans)
    validation: dict[str, Any] | None = None

    @property
    def makespan(self) -> int:
        return len(self.steps)

    @property
    def motion_cost(self) -> int:
        """The number of objects moved (the paper's cost)."""
        return sum(len(step) for step in self.steps)

    def to_json(self) -> dict[str, Any]:
        return {
            "schema": SCHEMA,
            "mrgc_version": self.mrgc_version,
            "problem": self.problem,
            "problem_file": self.problem_file,
            "problem_sha256": self.problem_sha256,
            "backend": self.backend,
            "encoding": self.encoding,
            "seed": self.seed,
            "status": str(PlanStatus(self.status)),
            "symbolic": self.symbolic,
            "makespan": self.makespan if self.steps else None,
            "motion_cost": self.motion_cost if self.steps else None,
            "steps": [{"index": i, "actions": [a.to_json() for a in step],
                       "waiting": self._waiting(step)} for i, step in enumerate(self.steps, 1)],
            **({"validation": self.validation} if self.validation is not None else {}),
            **({"why": self.why.to_json()} if self.why is not None else {}),
            "stats": self.stats,
        }

    def _waiting(self, step: list[PlannedAction]) -> list[str]:
        busy = {r for a in step for r in a.robots()}
        return sorted(set(self.stats.get("robots", [])) - busy)

    def dumps(self) -> str:
        return json.dumps(self.to_json(), indent=1, sort_keys=False) + "\n"

    def summary(self) -> list[str]:
        lines = [f"plan for {self.problem}: {PlanStatus(self.status)}"
                 + (f", makespan {self.makespan}, {self.motion_cost} objects moved" if self.steps else "")]
        for i, step in enumerate(self.steps, 1):
            parts = []
            for a in step:
                who = a.pick_robot if a.kind == "pick-place" else f"{a.pick_robot}->{a.place_robot}"
                grasp = a.pick_grasp if a.kind == "pick-place" else f"{a.pick_grasp}->{a.place_grasp}"
                parts.append(f"{who} moves {a.object} to {a.region} ({grasp})")
            lines.append(f"  step {i}: " + "; ".join(parts))
        if self.why is not None and PlanStatus(self.status) is not PlanStatus.SOLVED:
            lines += self.why.lines()
        return lines


def file_sha256(path: str) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()
