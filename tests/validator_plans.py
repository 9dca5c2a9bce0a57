"""Valid plans for the validator's tests, built once per session (tests/test_validate.py and
tests/test_validator_fuzz.py mutate copies of them).

Geometric plans for pa3-handover are built with the geometry layer's grounding service and IK (tests may
use them; the validator itself may not): approaches from the grounder, and every transfer that holds an
object lifted straight up out of its neighbours (IK every 5 cm) before it moves on, so that the plans are
valid under the paper's packaging motion model as the validator reads it (docs/validator.md).  The
box-moving plan is a small room with one box, its SE(2) paths written out as straight drives.
"""

from __future__ import annotations

import copy
import json
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from support import ROOT

from mrgc.geometry.grasps import grasp_transform, pregrasp_transform
from mrgc.geometry.transforms import translation
from mrgc.language.loader import parse_file
from mrgc.planfile.format import PlannedAction, file_sha256
from mrgc.planner.plan import Plan

if TYPE_CHECKING:  # the grounding service (coal, IK) loads only when a plan is built
    from mrgc.geometry.grounding import Grounder

PA3 = str(ROOT / "domains" / "packaging" / "pa3-handover.mrg")
LIFT_TO = 0.25  # m above the grasp a held object is lifted before it travels
LIFT_STEP = 0.05

ROOM = """(define (domain movers)
  (:requirements :planar-base)
  (:robot-kind mover :base planar :footprint (box 0.5 0.4 0.3) :carry (0.45 0 0.2 0))
  (:grasps side-x+ side-x- side-y+ side-y-))
(define (problem room)
  (:domain movers)
  (:robots (r1 :kind mover :base (-1 0 0 0)) (r2 :kind mover :base (-1 -1.5 0 0)))
  (:fixed (wall :shape (box 0.1 1 0.5) :pose (0 1.2 0.25 0)))
  (:regions (start :shape (box 1 1 0.5) :pose (0 0 0.25 0)) (goal :shape (box 1 1 0.5) :pose (1.5 0 0.25 0)))
  (:movable (b :shape (box 0.3 0.3 0.3) :pose (0 0 0.15 0)))
  (:goal (in-region b goal)))
"""


def rows(a: Any) -> list[list[float]]:
    return [[float(v) for v in row] for row in np.atleast_2d(a)]


def line(a: Any, b: Any, n: int = 5) -> list[list[float]]:
    """``n`` configurations from ``a`` to ``b``, straight."""
    return rows(np.linspace(np.asarray(a, dtype=float), np.asarray(b, dtype=float), n))


def as_file(problem: Any, path: str, steps: list[list[PlannedAction]], symbolic: bool = False) -> dict[str, Any]:
    """The plan JSON a file would hold for ``steps`` (status solved)."""
    plan = Plan(
        problem.name,
        path,
        file_sha256(path),
        "0.1.0",
        "cpsat",
        "time-of-move",
        0,
        "solved",
        steps,
        symbolic=symbolic,
        stats={"robots": [r.name for r in problem.robots]},
    )
    return json.loads(plan.dumps())  # type: ignore[no-any-return]


def action(plan: dict[str, Any], step: int, k: int = 0) -> dict[str, Any]:
    return plan["steps"][step - 1]["actions"][k]  # type: ignore[no-any-return]


# ------------------------------------------------------------------------------------- pa3-handover
@lru_cache(maxsize=1)
def pa3() -> Any:
    return parse_file(PA3).problem(None)


def grounder() -> Grounder:
    from mrgc.geometry.grounding import Grounder
    from mrgc.geometry.scene import scene_from_problem

    return Grounder(scene_from_problem(pa3()), seed=0)


def ik(g: Grounder, robot: str, tool_world: np.ndarray, q_init: np.ndarray) -> np.ndarray:
    """The configuration of ``robot`` nearest ``q_init`` (IK seeded there) putting the tool at ``tool_world``."""
    from mrgc.geometry.ik import solve_ik_many

    arm = g.arm(robot)
    res = solve_ik_many(arm.model, arm.ee_target(tool_world)[None], 0, q_init=np.asarray(q_init))[0]
    assert res.solved, f"no IK for {robot}"
    return np.asarray(res.q, dtype=float)


def tool_at(g: Grounder, obj: str, grasp: str, pose: np.ndarray, back_off: float = 0.0) -> np.ndarray:
    """The tool pose of ``grasp`` of ``obj`` at ``pose``, backed off along the approach by ``back_off``."""
    gt = grasp_transform(g.scene.grasp(grasp), g.scene.body(obj).shape)
    return pose @ (pregrasp_transform(gt, back_off) if back_off else gt)  # type: ignore[no-any-return]


def lifted(g: Grounder, robot: str, obj: str, grasp: str, pose: np.ndarray, q: np.ndarray) -> list[np.ndarray]:
    """Configurations holding ``obj`` (grasped with ``grasp`` while it is at ``pose``) lifted 5 cm at a time
    up to LIFT_TO, starting from ``q``."""
    out = []
    for h in np.arange(LIFT_STEP, LIFT_TO + 1e-9, LIFT_STEP):
        q = ik(g, robot, translation(0, 0, float(h)) @ tool_at(g, obj, grasp, pose), q)
        out.append(q)
    return out


def handover(g: Grounder, avoid: list[str]) -> PlannedAction:
    """r1 picks o1 from the top, lifts it and hands it to r2 at h1 (r2 grasps side-x+), r2 puts it into
    bin-b (straight from the exchange)."""
    pick = g.pick("r1", "o1", "top", avoid=avoid)
    hand = g.handover("o1", "h1", "r1", "top", "r2", "side-x+", avoid=avoid)
    spot = g.placement("o1", "bin-b", avoid=avoid)
    assert pick.ok and hand.ok and spot.ok and spot.pose is not None
    place = g.place("r2", "o1", "side-x+", spot.pose, avoid=avoid)
    assert place.ok and pick.configs is not None and hand.configs is not None
    up = lifted(g, "r1", "o1", "top", g.poses["o1"], pick.configs[-1])
    return PlannedAction(
        "o1",
        "bin-b",
        "r1",
        "r2",
        "top",
        "side-x+",
        place_pose=rows(spot.pose),
        handover_point="h1",
        configs={"pick": rows(pick.configs), "handover": rows(hand.configs), "place": rows(place.configs)},
        paths={"to-handover": rows([pick.configs[-1], *up, hand.configs[0]])},
    )


@lru_cache(maxsize=1)
def _one_step() -> str:
    g = grounder()
    return json.dumps(as_file(pa3(), PA3, [[handover(g, ["o2", "o3"])]]))


def lifted_move(g: Grounder, obj: str, region: str, avoid: list[str], relay: bool = False) -> PlannedAction:
    """r1 picks ``obj`` from the top, lifts it straight up out of its neighbours, lowers it into ``region``
    and puts it down there (the grounder's placement); the grounder then has it there."""
    pick = g.pick("r1", obj, "top", avoid=avoid)
    spot = g.placement(obj, region, avoid=avoid)
    assert pick.ok and spot.ok and spot.pose is not None and pick.configs is not None
    place = g.place("r1", obj, "top", spot.pose, avoid=avoid)
    assert place.ok and place.configs is not None
    up = lifted(g, "r1", obj, "top", g.poses[obj], pick.configs[-1])
    down = lifted(g, "r1", obj, "top", spot.pose, place.configs[0])[::-1]
    g.move(obj, spot.pose)
    return PlannedAction(
        obj,
        region,
        "r1",
        "r1",
        "top",
        "top",
        place_pose=rows(spot.pose),
        configs={"pick": rows(pick.configs), "place": rows(place.configs)},
        paths={"to-place": rows([pick.configs[-1], *up, *down, place.configs[0]])},
        relay=relay,
    )


@lru_cache(maxsize=1)
def _two_steps() -> str:
    """Step 1: r1 moves o2 within start (top), lifted out and lowered in; step 2: the handover of o1."""
    g = grounder()
    first = lifted_move(g, "o2", "start", ["o1", "o3"])
    return json.dumps(as_file(pa3(), PA3, [[first], [handover(g, ["o2", "o3"])]]))


@lru_cache(maxsize=1)
def _relay() -> str:
    """Step 1, the relay move: r1 picks o1 from the top, lifts it out of its neighbours and sets it down in
    bin-a; step 2, the onward move: r1 picks it there and hands it over to r2, who puts it into bin-b."""
    g = grounder()
    first = lifted_move(g, "o1", "bin-a", ["o2", "o3"], relay=True)
    return json.dumps(as_file(pa3(), PA3, [[first], [handover(g, ["o2", "o3"])]]))


def relay() -> dict[str, Any]:
    """A valid relay plan for pa3-handover: r1 sets o1 down in bin-a, then picks it there and hands it to r2
    (the onward move), who puts it into bin-b."""
    return json.loads(_relay())  # type: ignore[no-any-return]


def one_step() -> dict[str, Any]:
    """A valid one-step plan for pa3-handover: r1 hands o1 over to r2 at h1, r2 puts it into bin-b."""
    return json.loads(_one_step())  # type: ignore[no-any-return]


def two_steps() -> dict[str, Any]:
    """A valid two-step plan for pa3-handover: r1 moves o2 within start, then the handover of o1."""
    return json.loads(_two_steps())  # type: ignore[no-any-return]


# ------------------------------------------------------------------------------------- a planar room
@lru_cache(maxsize=1)
def _room(folder: str) -> tuple[str, str]:
    path = Path(folder) / "room.mrg"
    path.write_text(ROOM, encoding="utf-8")
    problem = parse_file(str(path)).problem(None)
    # the planar model (geometry/planar.py): facing the grasped face, the front 5 cm from it; the base origin
    # 0.25 (half length) + 0.05 + 0.15 (half the box) = 0.45 m from the box's centre
    q_pick, place = [-0.45, 0.0, 0.0], translation(1.7, 0.0, 0.151)
    q_place = [1.25, 0.0, 0.0]
    act = PlannedAction(
        "b",
        "goal",
        "r1",
        "r1",
        "side-x-",
        "side-x-",
        place_pose=rows(place),
        configs={"pick": [q_pick], "place": [q_place]},
        paths={
            "to-pick": line([-1, 0, 0], q_pick),
            "to-place": line(q_pick, q_place, 20),
            "home": line(q_place, [-1, 0, 0], 30),
        },
    )
    return str(path), json.dumps(as_file(problem, str(path), [[act]]))


def room(folder: str) -> tuple[str, Any, dict[str, Any]]:
    """(path, problem, valid plan) of the room: r1 drives to the box's -x side, carries it east into the
    goal region and drives back.  ``folder`` is where the problem file is written (once per session)."""
    path, text = _room(folder)
    return path, parse_file(path).problem(None), copy.deepcopy(json.loads(text))
