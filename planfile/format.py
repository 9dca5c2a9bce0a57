"""What a plan file holds, as data types: the schema version, the motion model, actions and steps.

A plan (``docs/plan.schema.json``) is a sequence of steps; in each step every robot performs at most one
action (a pick-and-place, a handover-and-place occupying two robots) or waits.  Geometric plans carry the
placement pose of every moved object and the robots' configurations: for an arm, the approach
configurations of its pick and of its place (pre-grasp first), and at a handover both robots'
exchange configurations; for a planar robot, its SE(2) paths.  Symbolic plans carry no geometry.  A
geometric plan states its :class:`MotionModel`: which motions it holds, and so which motions the validator
requires and how it reads a motion the plan leaves out (docs/validator.md).

:class:`PlannedAction` is the one type of a plan's action on both sides of the file: the planner
(:mod:`mrgc.planner.plan`) fills it in as it grounds a step and writes it (:meth:`PlannedAction.to_json`);
the reader (:mod:`mrgc.planfile.reader`) makes it from a file, inside a :class:`PlanFile` of
:class:`Step` s, and the validator only reads it.  Configurations are lists of floats, as the JSON holds
them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from typing import Any

#: the schema version every plan file states (``schema``); the reader refuses another (E503)
SCHEMA = "mrgc-plan/1"

#: configurations (or a 4×4 matrix), one list of floats each, as the plan's JSON holds them
Configurations = list[list[float]]

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


@dataclass
class PlannedAction:
    """One action of one step (see docs/plan.schema.json for each field's meaning); ``configs`` maps a phase
    (``pick``, ``place``, ``handover``) to configurations, ``paths`` a motion's name to its configurations.

    The planner builds it field by field as it grounds the action; an action read from a file keeps the
    ``kind`` the file states (``stated_kind``), which the validator compares with the one its robots make.
    """

    object: str
    region: str
    pick_robot: str
    place_robot: str
    pick_grasp: str
    place_grasp: str
    place_pose: Configurations | None = None  # 4×4, world frame
    handover_point: str | None = None
    configs: dict[str, Configurations] = field(default_factory=dict)
    paths: dict[str, Configurations] = field(default_factory=dict)
    #: the object is only set down in ``region`` on its way (a relay, beyond the paper: ``enable-relay``);
    #: a later action, the onward move, takes it from there to its goal
    relay: bool = False
    #: the ``kind`` a plan file states (None: the one the robots make, as the planner writes it)
    stated_kind: str | None = None

    @property
    def handover(self) -> bool:
        """Two robots: the object changes hands at ``handover_point``."""
        return self.pick_robot != self.place_robot

    @property
    def kind(self) -> str:
        """``pick-place`` (one robot) or ``handover`` (two); for an action read from a file, what it states."""
        return self.stated_kind or ("handover" if self.handover else "pick-place")

    def robots(self) -> tuple[str, ...]:
        """The robots of the action (one, or the giver and the taker)."""
        return (self.pick_robot,) if not self.handover else (self.pick_robot, self.place_robot)

    def describe(self) -> str:
        """``r1 moves o1 to bin (top)`` / ``r1->r2 moves o1 to bin (top->side-x+)`` / a relay move ``r1 sets
        down o1 in start (top)``."""
        who, grasp = self.pick_robot, self.pick_grasp
        if self.handover:
            who, grasp = f"{who}->{self.place_robot}", f"{grasp}->{self.place_grasp}"
        what = f"sets down {self.object} in" if self.relay else f"moves {self.object} to"
        return f"{who} {what} {self.region} ({grasp})"

    def path_robot(self, name: str) -> str:
        """The robot that moves on path ``name``: the giver on its way to the object, to the exchange and
        home from it (``to-pick``, ``to-handover``, ``giver-home``), the place robot on the others."""
        return self.pick_robot if name in ("to-pick", "to-handover", "giver-home") else self.place_robot

    def waits(self) -> list[tuple[str, int, int]]:
        """The paths on which the robot stands still, at the start or at the end, while another robot of the
        step passes (the validator replays a phase's configurations equally spaced in time: a repeated one is
        time standing still): (path name, configurations repeated at its start, at its end), for the paths
        that repeat any."""
        out = []
        for name, path in self.paths.items():
            first = next((i for i, q in enumerate(path) if q != path[0]), len(path)) - 1
            last = next((i for i, q in enumerate(reversed(path)) if q != path[-1]), len(path)) - 1
            if len(path) > 1 and (first > 0 or last > 0) and first < len(path) - 1:
                out.append((name, first, last))
        return out

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


@dataclass(frozen=True)
class Step:
    """One step of a plan as read: its stated index, its actions and the robots it says wait."""

    index: int
    actions: tuple[PlannedAction, ...]
    waiting: tuple[str, ...]


@dataclass(frozen=True)
class PlanFile:
    """A plan as read: the header fields, the steps, and (geometric plans) the motion model."""

    schema: str
    mrgc_version: str
    problem: str
    problem_file: str
    problem_sha256: str
    backend: str
    encoding: str
    seed: int
    status: str
    symbolic: bool
    makespan: int | None
    motion_cost: int | None
    steps: tuple[Step, ...]
    motion_model: MotionModel | None = None
    problem_digest: str | None = None


def plan_text(doc: Any) -> str:
    """A plan file's text from its JSON value (``PlanResult.to_json()``): indented one space per level, each
    list of scalars (a configuration, a row of a pose, a list of names) on one line, so that a plan reads and
    diffs a configuration per line; the same JSON value as ``json.dumps`` gives (floats as ``repr`` writes
    them), each such line written by the standard library's C encoder."""
    out: list[str] = []
    _write(doc, 0, out)
    out.append("\n")
    return "".join(out)


def _write(value: Any, depth: int, out: list[str]) -> None:
    if isinstance(value, dict) and value:
        for key in value:
            if not (key is None or isinstance(key, (str, int, float))):  # as json.dumps refuses them
                raise TypeError(f"keys must be str, int, float, bool or None, not {type(key).__name__}")
        # keys as json.dumps writes them: a string as it is, a number, bool or null as its JSON text
        entries = [(json.dumps(k if isinstance(k, str) else json.dumps(k)) + ": ", v) for k, v in value.items()]
        brackets = "{}"
    elif isinstance(value, (list, tuple)) and any(isinstance(v, (dict, list, tuple)) for v in value):
        entries, brackets = [("", v) for v in value], "[]"
    else:  # a scalar, an empty container, or a list of scalars: one line
        out.append(json.dumps(value))
        return
    inner = "\n" + " " * (depth + 1)
    for k, (head, item) in enumerate(entries):
        out.append((brackets[0] if k == 0 else ",") + inner + head)
        _write(item, depth + 1, out)
    out.append("\n" + " " * depth + brackets[1])


def file_sha256(path: str) -> str:
    """The sha256 of the file's bytes (hex): a plan's ``problem_sha256``."""
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()
