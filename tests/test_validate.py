"""The independent plan validator: valid plans pass; every kind of broken plan is rejected in one clear line.

Valid geometric plans come from tests/validator_plans.py (pa3-handover, built with the geometry layer's
grounding service and IK, and a planar room); symbolic plans for chain-3 are written by hand from the
file's own comment (its three feasible action sets).  Each doctored plan of issue 9 is a named test here;
tests/test_validator_fuzz.py edits the same plans at random.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
import validator_plans as vp
from hypothesis import given, settings
from hypothesis import strategies as st

from mrgc import cli
from mrgc.errors import InputError
from mrgc.geometry.grasps import grasp_transform
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.transforms import translation
from mrgc.language.loader import parse_file
from mrgc.planfile.format import PlannedAction
from mrgc.planfile.reader import load_plan, read_plan
from mrgc.validator.validate import ValidationReport, validate

ROOT = vp.ROOT
PA3 = vp.PA3
CHAIN3 = str(ROOT / "domains" / "symbolic" / "chain-3.mrg")
_l, _line, _plan, _action = vp.rows, vp.line, vp.as_file, vp.action


# ------------------------------------------------------------------------------------- pa3-handover
@pytest.fixture(scope="module")
def pa3() -> Any:
    return vp.pa3()


@pytest.fixture(scope="module")
def grounder(pa3: Any) -> Grounder:
    return vp.grounder()


@pytest.fixture
def one_step() -> dict[str, Any]:
    return vp.one_step()


@pytest.fixture
def two_steps() -> dict[str, Any]:
    return vp.two_steps()


def _codes(report: ValidationReport) -> set[str]:
    return {v.code for v in report.violations}


def test_hand_built_plans_are_valid(pa3: Any, one_step: dict[str, Any], two_steps: dict[str, Any]) -> None:
    for plan in (one_step, two_steps):
        report = validate(pa3, plan, PA3)
        assert report.ok, report.lines()
        assert report.lines()[0].startswith("valid: plan for pa3-handover")
        assert report.stats["configurations"] > 40 and report.stats["distance_queries"] > 100


def _drop_last_step(p: dict[str, Any]) -> None:
    p["steps"].pop()
    p["makespan"] -= 1
    p["motion_cost"] -= 1


def _move_twice(p: dict[str, Any]) -> None:
    p["steps"].append({"index": 3, "actions": [copy.deepcopy(_action(p, 1))], "waiting": ["r2"]})
    p["makespan"], p["motion_cost"] = 3, 3


def _nudge(p: dict[str, Any]) -> None:  # o2's placement pushed into its neighbour o1 (still inside start)
    pose = _action(p, 1)["place_pose"]
    pose[0][3], pose[1][3] = 0.03, -0.25


def _swap_grasp(p: dict[str, Any]) -> None:
    _action(p, 2)["pick_grasp"] = "side-x+"


def _beyond_limits(p: dict[str, Any]) -> None:
    _action(p, 1)["configs"]["pick"][2][3] = 0.5  # panda_joint4 lies in [-3.1416, 0]


def _busy(p: dict[str, Any]) -> None:
    p["steps"][1]["actions"].insert(0, p["steps"][0]["actions"].pop())
    p["steps"].pop(0)
    p["makespan"] = 1
    for i, s in enumerate(p["steps"], 1):
        s["index"] = i


def _rename(p: dict[str, Any]) -> None:
    _action(p, 1)["pick_robot"] = _action(p, 1)["place_robot"] = "r9"


def _short_config(p: dict[str, Any]) -> None:
    _action(p, 1)["configs"]["place"][0].pop()


def _no_configs(p: dict[str, Any]) -> None:
    del _action(p, 2)["configs"]["handover"]


def _out_of_region(p: dict[str, Any]) -> None:
    _action(p, 1)["region"] = "bin-a"


def _handover_moved(p: dict[str, Any]) -> None:
    _action(p, 2)["configs"]["handover"][1][0] += 0.2


def _other_file(p: dict[str, Any]) -> None:
    p["problem_sha256"] = "0" * 64


def _other_problem(p: dict[str, Any]) -> None:
    p["problem"] = "pa5"


def _regrasp(p: dict[str, Any]) -> None:
    _action(p, 1)["place_grasp"] = "side-x+"


def _not_solved(p: dict[str, Any]) -> None:
    p["status"], p["steps"], p["makespan"], p["motion_cost"] = "no plan", [], None, None


MUTATIONS: dict[str, tuple[Callable[[dict[str, Any]], None], str, str]] = {
    # name: (mutation, expected code, a fragment of its message)
    "nudged into a neighbour": (_nudge, "collision-object-object", "o2 placed and o1 overlap by"),
    "step removed": (_drop_last_step, "goal", "goal (in-region o1 bin-b) does not hold at the end"),
    "object moved twice": (_move_twice, "moved-twice", "o2 is moved again (first at step 1)"),
    "grasp swapped": (_swap_grasp, "grasp", "puts the tool 40.3 mm, 1.571 rad from grasp 'side-x+' of o1"),
    "outside joint limits": (_beyond_limits, "joint-limits", "panda_joint4 = 0.5000 is outside [-3.1416, 0.0000]"),
    "robot in two actions": (_busy, "robot-busy", "r1 is in two actions of the step"),
    "unknown robot": (_rename, "unknown-name", "no robot 'r9'"),
    "configuration too short": (_short_config, "config", "has 6 values; r1 has 7 joints"),
    "handover configurations missing": (_no_configs, "missing", "no handover configurations"),
    "placement outside its region": (_out_of_region, "outside-region", "is not entirely inside region bin-a"),
    "taker away from the handover point": (_handover_moved, "handover", "from handover point h1"),
    "problem file changed": (_other_file, "problem-changed", "the problem file changed since the plan was made"),
    "plan of another problem": (_other_problem, "problem", "the plan is for problem 'pa5', not 'pa3-handover'"),
    "regrasp in hand": (_regrasp, "action", "a robot cannot regrasp in hand"),
    "no plan": (_not_solved, "status", "the plan's status is 'no plan'"),
}


@pytest.mark.parametrize("name", list(MUTATIONS))
def test_mutated_plans_are_rejected(name: str, pa3: Any, two_steps: dict[str, Any]) -> None:
    mutate, code, fragment = MUTATIONS[name]
    plan = copy.deepcopy(two_steps)
    mutate(plan)
    report = validate(pa3, plan, PA3)
    assert not report.ok
    hits = [str(v) for v in report.violations if v.code == code]
    assert any(fragment in h for h in hits), report.lines()
    for line in report.lines():
        assert "\n" not in line and "Traceback" not in line
    assert report.lines()[-1].startswith("invalid: ")


def test_a_pick_through_a_neighbour_is_a_robot_object_collision(
    pa3: Any, one_step: dict[str, Any], grounder: Grounder
) -> None:
    pick = grounder.pick("r1", "o1", "side-x+")  # avoiding nothing: the hand goes through o2
    assert pick.ok
    plan = copy.deepcopy(one_step)
    _action(plan, 1)["configs"]["pick"] = _l(pick.configs)
    report = validate(pa3, plan, PA3)
    hits = [str(v) for v in report.violations if v.code == "collision-robot-object"]
    assert any("pick: panda_hand of r1 (" in h and "of 5) and o2 overlap by" in h for h in hits), report.lines()


def test_two_hands_at_one_handover_collide(pa3: Any, one_step: dict[str, Any], grounder: Grounder) -> None:
    arm = grounder.arm("r2")
    top = grasp_transform(grounder.scene.grasp("top"), grounder.scene.body("o1").shape)
    target = arm.ee_target(translation(0, 0, 0.4) @ top)
    res = solve_ik_many(arm.model, target[None], 0, q_init=arm.home)[0]
    assert res.solved
    plan = copy.deepcopy(one_step)
    a = _action(plan, 1)
    a["place_grasp"] = "top"  # the taker also grasps from the top: the two hands meet
    a["configs"]["handover"][1] = [float(v) for v in res.q]
    report = validate(pa3, plan, PA3)
    hits = [str(v) for v in report.violations if v.code == "collision-robot-robot"]
    assert any(
        h.startswith("step 1: r1: handover: ") and "of r2 (at its handover (taker) configuration)" in h for h in hits
    ), report.lines()


def test_paths_are_checked_and_must_connect(pa3: Any, one_step: dict[str, Any]) -> None:
    plan = copy.deepcopy(one_step)
    a = _action(plan, 1)
    home = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
    pre = a["configs"]["pick"][0]
    a["paths"]["to-pick"] = [home, [(x + y) / 2 for x, y in zip(home, pre)], pre]
    assert validate(pa3, plan, PA3).ok
    a["paths"]["to-pick"] = a["paths"]["to-pick"][:-1]
    lines = validate(pa3, plan, PA3).lines()
    assert any("path 'to-pick' (moving o1) ends" in x and "away from the first pick configuration" in x for x in lines)
    a["paths"]["fly"] = [home]  # a path the schema does not know: the plan cannot be checked (E502)
    with pytest.raises(InputError) as err:
        validate(pa3, plan, PA3)
    assert "plan.steps[0].actions[0].paths has an unknown field 'fly'" in err.value.diagnostics[0].message


# ------------------------------------------------------------------------------------- issue 9's doctored plans
def _cli(
    tmp_path: Path, problem_path: str, plan: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> tuple[int, list[str]]:
    """``mrgc validate`` on ``plan``: exit code and output lines (one per violation, then the verdict)."""
    path = tmp_path / "doctored.json"
    path.write_text(json.dumps(plan), encoding="utf-8")
    rc = cli.main(["validate", problem_path, str(path)])
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err
    return rc, cap.out.splitlines()


def _rejected(rc: int, lines: list[str], code: str, *fragments: str) -> None:
    assert rc == 1 and lines[-1].startswith("invalid: "), lines
    hits = [x for x in lines if x.endswith(f"[{code}]")]
    assert any(all(f in x for f in fragments) for x in hits), lines


def test_doctored_every_planar_path_deleted(
    room: tuple[str, Any, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _, plan = room
    assert _cli(tmp_path, path, plan, capsys)[0] == 0
    del _action(plan, 1)["paths"]
    rc, lines = _cli(tmp_path, path, plan, capsys)
    for name in ("to-pick", "to-place", "home"):
        _rejected(
            rc,
            lines,
            "missing",
            f"r1: the action moving b has no '{name}' path, which the motion model (planar 'paths') requires",
        )


def test_doctored_only_the_to_place_path_deleted(
    room: tuple[str, Any, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _, plan = room
    del _action(plan, 1)["paths"]["to-place"]
    rc, lines = _cli(tmp_path, path, plan, capsys)
    _rejected(rc, lines, "missing", "has no 'to-place' path")
    assert len(lines) == 2, lines


def test_doctored_approach_cut_to_the_grasp(
    one_step: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _action(one_step, 1)
    a["configs"]["pick"] = a["configs"]["pick"][-1:]
    a["paths"]["to-handover"][0] = a["configs"]["pick"][0]
    rc, lines = _cli(tmp_path, PA3, one_step, capsys)
    _rejected(
        rc,
        lines,
        "approach",
        "step 1: r1: the pick approach of r1 (moving o1) holds 1 configuration; the "
        "motion model's approaches hold 5, pre-grasp first",
    )
    _rejected(rc, lines, "approach", "the first pick configuration of r1 puts the tool 80.0 mm")


def test_doctored_approach_through_the_object(
    one_step: dict[str, Any], grounder: Grounder, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The middle approach configuration puts the tool at the grasp depth 31 mm along the finger axis: a
    finger drives through o1 before the contact segment (configurations 4 to 5), where o1 is not exempt."""
    a = _action(one_step, 1)
    qs = a["configs"]["pick"]
    grasp = vp.tool_at(grounder, "o1", "top", grounder.poses["o1"])
    qs[2] = [float(v) for v in vp.ik(grounder, "r1", grasp @ translation(0, 0.031, 0), np.array(qs[2]))]
    rc, lines = _cli(tmp_path, PA3, one_step, capsys)
    _rejected(rc, lines, "collision-robot-object", "step 1: r1: pick: ", " of r1 (", " of 5) and o1 overlap by")
    hits = [x for x in lines if "[collision-robot-object]" in x and "and o1 overlap" in x]
    assert all("configurations 4 and 5" not in x for x in hits), hits


def test_doctored_object_released_in_the_air(
    one_step: dict[str, Any], grounder: Grounder, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """o1 released 12 cm above bin-b's floor, its place approach recomputed to match: only support fails."""
    a = _action(one_step, 1)
    pose = translation(0, 0, 0.12) @ np.array(a["place_pose"])
    a["place_pose"] = _l(pose)
    old = np.array(a["configs"]["place"])
    pre = vp.ik(grounder, "r2", vp.tool_at(grounder, "o1", "side-x+", pose, 0.08), old[0])
    at = vp.ik(grounder, "r2", vp.tool_at(grounder, "o1", "side-x+", pose), old[-1])
    a["configs"]["place"] = _line(pre, at)
    rc, lines = _cli(tmp_path, PA3, one_step, capsys)
    _rejected(
        rc,
        lines,
        "floating",
        "step 1: o1: o1 is released at (",
        "resting on nothing: its lowest point is "
        "126.0 mm above the floor of bin-b, and nothing is within 10 mm under it",
    )
    assert len(lines) == 2, lines


def test_an_object_may_rest_on_another_until_that_one_moves(grounder: Grounder) -> None:
    """Step 1 stacks o2 on o1 (supported by a movable object: valid); step 2 takes o1 from under it: o2
    would fall, so the plan is invalid (besides the hand that now meets o2 on its way to o1)."""
    g = vp.grounder()
    pick = g.pick("r1", "o2", "top", avoid=["o1", "o3"])
    assert pick.ok and pick.configs is not None
    on_o1 = translation(0, 0, 0.12 + 0.006) @ g.poses["o1"]
    place = g.place("r1", "o2", "top", on_o1)
    assert place.ok and place.configs is not None
    up = vp.lifted(g, "r1", "o2", "top", g.poses["o2"], pick.configs[-1])
    down = vp.lifted(g, "r1", "o2", "top", on_o1, place.configs[0])[::-1]
    stack = PlannedAction(
        "o2",
        "start",
        "r1",
        "r1",
        "top",
        "top",
        place_pose=_l(on_o1),
        configs={"pick": _l(pick.configs), "place": _l(place.configs)},
        paths={"to-place": _l([pick.configs[-1], *up, *down, place.configs[0]])},
    )
    g.move("o2", on_o1)
    hand = vp.handover(g, ["o3"])
    report = validate(vp.pa3(), _plan(vp.pa3(), PA3, [[stack], [hand]]), PA3)
    assert not any(v.step == 1 for v in report.violations), report.lines()
    assert (
        "step 2: o2: o2 rested on o1, which the step moves away: nothing holds it up now [floating]" in report.lines()
    ), report.lines()


def test_doctored_unknown_robot_waiting(
    two_steps: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    two_steps["steps"][0]["waiting"].append("r9")
    rc, lines = _cli(tmp_path, PA3, two_steps, capsys)
    _rejected(rc, lines, "unknown-name", "step 1: r9: no robot 'r9' (waiting)")
    two_steps["steps"][0]["waiting"] = []
    rc, lines = _cli(tmp_path, PA3, two_steps, capsys)
    _rejected(rc, lines, "waiting", "step 1: r2: r2 is in no action of the step and not listed as waiting")


def test_doctored_unknown_fields_are_refused(
    two_steps: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An unknown field may carry meaning the validator cannot check: the plan is refused as bad input
    (exit 2, E502 naming the field), like a plan missing a field."""
    _action(two_steps, 2)["configs"]["retreat"] = [[0.0] * 7]
    path = tmp_path / "doctored.json"
    path.write_text(json.dumps(two_steps), encoding="utf-8")
    assert cli.main(["validate", PA3, str(path)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert (
        len(err) == 1
        and "error[E502]" in err[0]
        and "plan.steps[1].actions[0].configs has an unknown field 'retreat'" in err[0]
    ), err


def test_doctored_transfer_left_out_is_a_straight_move(
    one_step: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without its to-handover path, r1 carries o1 from the grasp to the exchange in a straight joint-space
    line (the paper's packaging model), through its neighbour o3."""
    del _action(one_step, 1)["paths"]
    rc, lines = _cli(tmp_path, PA3, one_step, capsys)
    _rejected(
        rc,
        lines,
        "collision-object-object",
        "to-handover: o1 held by r1 (between straight to-handover "
        "transfer configurations 1 and 2 of 2) and o3 overlap by",
    )


def test_a_transfer_path_is_checked(
    one_step: dict[str, Any], grounder: Grounder, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A given transfer path is followed: lifted only 5 cm before it turns, o1 sweeps through o3."""
    a = _action(one_step, 1)
    path = a["paths"]["to-handover"]
    a["paths"]["to-handover"] = path[:2] + path[-1:]
    rc, lines = _cli(tmp_path, PA3, one_step, capsys)
    _rejected(
        rc,
        lines,
        "collision-object-object",
        "to-handover: o1 held by r1 (between to-handover path configurations 2 and 3 of 3) and o3 overlap by",
    )


def test_the_motion_model_must_be_one_the_validator_checks(one_step: dict[str, Any]) -> None:
    one_step["motion_model"]["approach"] = {"configurations": 2, "back_off": 0.01}
    lines = validate(vp.pa3(), one_step, PA3).lines()
    assert (
        "the motion model's approach back-off is 0.01 m; the grasp specification's pre-grasp stands 0.08 m back "
        "[motion-model]" in lines
    ), lines
    assert any("the motion model's approaches hold 2 configurations; at least 5 are needed" in x for x in lines)


def test_full_motions_require_every_path(one_step: dict[str, Any]) -> None:
    one_step["motion_model"]["arms"] = "full"
    lines = validate(vp.pa3(), one_step, PA3).lines()
    for name in ("to-pick", "taker-to-handover", "to-place", "home", "giver-home"):
        assert any(
            f"has no '{name}' path, which the motion model (arms 'full') requires [missing]" in x for x in lines
        ), lines
    assert not any("'to-handover' path" in x for x in lines)


def test_the_documented_motion_model_is_the_planners() -> None:
    import re

    from mrgc.planner.plan import planner_motion_model

    text = (ROOT / "docs" / "validator.md").read_text(encoding="utf-8")
    block = re.search(r"```json\n(\"motion_model\": .*?)```", text, re.S)
    assert block is not None
    assert json.loads("{" + block.group(1) + "}")["motion_model"] == planner_motion_model().to_json()


# ------------------------------------------------------------------------------------- the CLI
def test_cli_valid_and_invalid(tmp_path: Path, two_steps: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    good = tmp_path / "good.json"
    good.write_text(json.dumps(two_steps), encoding="utf-8")
    assert cli.main(["validate", PA3, str(good)]) == 0
    assert capsys.readouterr().out.startswith("valid: plan for pa3-handover: 2 steps, 2 objects moved")
    bad_plan = copy.deepcopy(two_steps)
    _drop_last_step(bad_plan)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(bad_plan), encoding="utf-8")
    assert cli.main(["validate", PA3, str(bad)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "o1: goal (in-region o1 bin-b) does not hold at the end: o1 is at (0.000, -0.250, 0.060), not "
        "entirely inside bin-b [goal]",
        "invalid: 1 violation",
    ]
    assert cli.main(["validate", PA3, str(bad), "--format", "json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["ok"] is False and data["violations"][0]["code"] == "goal"


def _truncated(text: str) -> str:
    return text[: len(text) // 2]


def _edit(change: Callable[[dict[str, Any]], None]) -> Callable[[str], str]:
    def make(text: str) -> str:
        plan = json.loads(text)
        change(plan)
        return json.dumps(plan, indent=1)

    return make


def _del_grasp(p: dict[str, Any]) -> None:
    del _action(p, 1)["pick_grasp"]


def _set(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    return lambda p: p.__setitem__(key, value)


def _small_matrix(p: dict[str, Any]) -> None:
    _action(p, 1)["place_pose"] = [[1.0, 0.0, 0.0]]


def _unknown_kind(p: dict[str, Any]) -> None:
    _action(p, 1)["kind"] = "throw"


MALFORMED: dict[str, tuple[Callable[[str], str | bytes] | None, str, str]] = {
    "truncated": (_truncated, "E501", "plan is not JSON: it ends early (truncated?)"),
    "empty": (lambda t: "", "E501", "plan is not JSON: it is empty"),
    "not JSON": (lambda t: "steps: [1, 2]\n", "E501", "plan is not JSON: Expecting value"),
    "NaN": (lambda t: t.replace('"seed": 0', '"seed": NaN'), "E501", "NaN is not a JSON number"),
    "binary": (lambda t: b"\x89PNG\r\n\x1a\n\x00\xff", "E500", "it is not UTF-8 text"),
    "a list": (lambda t: "[1, 2]", "E502", "plan should be an object, not [1, 2]"),
    "field missing": (_edit(_del_grasp), "E502", "plan.steps[0].actions[0] lacks 'pick_grasp'"),
    "wrong type": (_edit(_set("seed", "zero")), "E502", 'plan.seed should be an integer, not "zero"'),
    "unknown kind": (_edit(_unknown_kind), "E502", "plan.steps[0].actions[0].kind should be one of"),
    "bad matrix": (_edit(_small_matrix), "E502", "plan.steps[0].actions[0].place_pose should hold 4 items, not 1"),
    "wrong schema": (
        _edit(_set("schema", "mrgc-plan/7")),
        "E503",
        "schema 'mrgc-plan/7' is not supported (this mrgc reads 'mrgc-plan/1')",
    ),
    "missing file": (None, "E500", "No such file or directory"),
    # issue 9: unknown fields, limits checked before the JSON parser can explode
    "unknown field": (
        _edit(lambda p: _action(p, 1).__setitem__("teleport", True)),
        "E502",
        "plan.steps[0].actions[0] has an unknown field 'teleport'",
    ),
    "unknown top-level field": (_edit(_set("trust_me", 1)), "E502", "plan has an unknown field 'trust_me'"),
    "relay not a boolean": (
        _edit(lambda p: _action(p, 1).__setitem__("relay", "yes")),
        "E502",
        'plan.steps[0].actions[0].relay should be true or false, not "yes"',
    ),
    "motion model missing": (_edit(lambda p: p.pop("motion_model")), "E502", "plan lacks 'motion_model'"),
    "unknown motion model": (
        _edit(lambda p: p["motion_model"].__setitem__("arms", "teleport")),
        "E502",
        "plan.motion_model.arms should be one of",
    ),
    "nested 100k deep": (
        lambda t: t.replace('"stats": {', '"stats": {"x": ' + "[" * 100_000 + "]" * 100_000 + ", ", 1),
        "E504",
        "plan nests arrays and objects more than 32 deep",
    ),
    "400-digit integer": (
        lambda t: t.replace('"seed": 0', '"seed": ' + "9" * 400),
        "E504",
        "plan holds an integer of 400 digits (at most 20)",
    ),
    "400-digit integer in a configuration": (
        _edit(lambda p: _action(p, 1)["configs"]["pick"][0].__setitem__(0, int("9" * 400))),
        "E504",
        "an integer of 400 digits",
    ),
    "beyond double precision": (
        lambda t: t.replace('"seed": 0', '"seed": 1e999'),
        "E504",
        "the number 1e999 lies beyond double precision",
    ),
    "key twice": (
        lambda t: t.replace('"seed": 0', '"seed": 0, "seed": 1'),
        "E501",
        "the key 'seed' appears twice in one object",
    ),
}


@pytest.mark.parametrize("name", list(MALFORMED))
def test_malformed_plan_files_are_input_errors(
    name: str, tmp_path: Path, two_steps: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    make, code, fragment = MALFORMED[name]
    text = json.dumps(two_steps, indent=1)
    path = tmp_path / "plan.json"
    if make is not None:
        data = make(text)
        path.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
    assert cli.main(["validate", PA3, str(path)]) == 2
    cap = capsys.readouterr()
    first = cap.err.splitlines()[0]
    assert f"error[{code}]" in first and fragment in first, cap.err
    assert "Traceback" not in cap.err and cap.out == ""
    if make is not None and code != "E500":
        with pytest.raises(InputError) as err:
            load_plan(str(path))
        assert err.value.diagnostics[0].code == code


def test_validate_raises_on_a_schema_violation(pa3: Any, two_steps: dict[str, Any]) -> None:
    plan = copy.deepcopy(two_steps)
    del plan["steps"][0]["actions"][0]["object"]
    with pytest.raises(InputError) as err:
        validate(pa3, plan, PA3)
    assert err.value.diagnostics[0].code == "E502"


def test_the_installed_script_validates(tmp_path: Path, one_step: dict[str, Any]) -> None:
    """End to end in a fresh process: nothing but the report on stdout, and coal (the planner's collision
    engine) is never loaded: the validator's collisions are pybullet's alone."""
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(one_step), encoding="utf-8")
    code = (
        "import sys; from mrgc import cli; rc = cli.main(['validate', %r, %r]); "
        "print('coal' in sys.modules, 'mrgc.geometry.grounding' in sys.modules, rc)" % (PA3, str(path))
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=tmp_path)
    lines = out.stdout.splitlines()
    assert len(lines) == 2 and lines[0].startswith("valid: ") and lines[1] == "False False 0", out
    assert out.stderr == ""


# ------------------------------------------------------------------------------------- the replay scene
def test_replay_scene_distances_and_kinematics(pa3: Any, grounder: Grounder, tmp_path: Path) -> None:
    from mrgc.geometry.fk import ee_pose
    from mrgc.language.model import Box, Mesh
    from mrgc.validator.world import ReplayScene

    cube = tmp_path / "cube.obj"
    corners = "".join(f"v {x} {y} {z}\n" for x in (-0.05, 0.05) for y in (-0.05, 0.05) for z in (-0.05, 0.05))
    faces = ["1 2 4", "1 4 3", "5 7 8", "5 8 6", "1 5 6", "1 6 2", "3 4 8", "3 8 7", "1 3 7", "1 7 5", "2 6 8", "2 8 4"]
    cube.write_text(corners + "".join(f"f {f}\n" for f in faces), encoding="utf-8")
    scene = grounder.scene
    with ReplayScene(scene) as rs:
        rs.add_object("mesh", Mesh(str(cube)), translation(2, 0, 0))
        rs.add_object("box", Box(0.1, 0.1, 0.1), translation(2.13, 0, 0))
        c = rs.closest("mesh", "box", 0.1)  # pybullet's 1 mm mesh margin is added back
        assert c is not None and abs(c.distance - 0.03) < 1e-6
        rs.set_pose("box", translation(2.09, 0, 0))
        c = rs.closest("mesh", "box")
        assert c is not None and abs(c.distance + 0.01) < 1e-6
        arm = grounder.arm("r1")
        q = np.array([0.3, 0.2, -0.1, -2.0, 0.1, 1.9, 0.4])
        rs.set_config("r1", q)
        assert np.abs(rs.ee_pose("r1") - arm.base @ ee_pose(arm.model, q)).max() < 1e-6
        rs.set_config("r1", arm.home)
        assert rs.closest("r1", "table") is None  # its base link stands on the table: ignored
        assert rs.closest("r1", "r2", 10.0) is not None


@given(gap=st.floats(0.0005, 0.03), diagonal=st.booleans())
@settings(max_examples=25, deadline=None, derandomize=True)
def test_replay_boxes_are_exact_at_edges(gap: float, diagonal: bool) -> None:
    """Boxes are 8-vertex hulls in the replay world: their distances are exact at edges and corners too,
    where GEOM_BOX's rounded margin read up to 1.1 mm wrong (docs/geometry.md)."""
    from mrgc.geometry.scene import SceneSpec
    from mrgc.language.model import Box
    from mrgc.validator.world import ReplayScene

    with ReplayScene(SceneSpec("edges", (), (), (), (), {}, {}, {}, {})) as rs:
        rs.add_object("a", Box(0.1, 0.1, 0.1), np.eye(4))
        # edge to edge across the diagonal of x-y, or corner to corner across the body diagonal
        d = np.array([0.1, 0.1, 0.0 if not diagonal else 0.1]) + gap * np.array([1, 1, int(diagonal)])
        rs.add_object("b", Box(0.1, 0.1, 0.1), translation(*d))
        exact = gap * (np.sqrt(3) if diagonal else np.sqrt(2))
        c = rs.closest("a", "b", 0.1)
        assert c is not None and abs(c.distance - exact) < 5e-5, (c, exact)


@given(
    st.lists(st.lists(st.floats(-3, 3), min_size=3, max_size=3), min_size=2, max_size=40),
    st.sampled_from([0.01, 0.003]),
    st.booleans(),
)
@settings(max_examples=60, deadline=None, derandomize=True)
def test_samples_are_never_farther_apart_than_the_resolution(
    configs: list[list[float]], resolution: float, planar: bool
) -> None:
    """Between two consecutive samples of a motion no coordinate moves more than the resolution, whether the
    motion has few configurations (every one sampled) or many (equal steps along its length)."""
    from mrgc.validator.sampling import config_at, deltas, sample_count, sample_times

    qs = np.array(configs)
    times = sample_times(qs, planar, resolution)
    assert times[0] == 0.0 and times[-1] == 1.0 and np.all(np.diff(times) > 0)
    assert len(times) <= sample_count(qs, planar, resolution)
    m = len(qs)
    for s0, s1 in zip(times[:-1], times[1:]):
        # every point of the polyline between the two samples: the configurations in between and the ends
        inner = [k / (m - 1) for k in range(m) if s0 < k / (m - 1) < s1]
        pts = np.array([config_at(qs, float(s), planar) for s in [s0, *inner, s1]])
        travel = float(np.abs(deltas(pts, planar)).max(axis=1).sum())
        assert travel <= resolution + 1e-9, (s0, s1, travel)


# ------------------------------------------------------------------------------------- symbolic: chain-3
@pytest.fixture(scope="module")
def chain3() -> Any:
    return parse_file(CHAIN3).problem(None)


def _act(obj: str, region: str, r1: str, g1: str, r2: str | None = None, g2: str | None = None) -> PlannedAction:
    return PlannedAction(obj, region, r1, r2 or r1, g1, g2 or g1)


A1 = ("o1", "goal", "r1", "top")
A2 = ("o1", "goal", "r2", "side")
A3 = ("o1", "goal", "r1", "top", "r2", "side")
B = ("o2", "start", "r1", "top")
C = ("o3", "start", "r2", "side")

VALID_SYMBOLIC = {
    "{A2}": [[A2]],
    "{B, A3}": [[B], [A3]],
    "{B, C, A1}": [[B, C], [A1]],
    "{B, C, A1}, C beside A1": [[B], [C, A1]],
}


@pytest.mark.parametrize("name", list(VALID_SYMBOLIC))
def test_symbolic_plans_of_chain3_are_valid(name: str, chain3: Any) -> None:
    steps = [[_act(*a) for a in step] for step in VALID_SYMBOLIC[name]]
    report = validate(chain3, _plan(chain3, CHAIN3, steps, symbolic=True), CHAIN3)
    assert report.ok, report.lines()
    assert report.stats["mode"] == "symbolic"


INVALID_SYMBOLIC: dict[str, tuple[list[list[tuple[str, ...]]], str, str]] = {
    "pick obstacle in the same step": (
        [[B, A1], [C]],
        "pick-obstacle",
        "o2 blocks r1 picking o1 with top and moves at step 1; it must move at an earlier step",
    ),
    "place obstacle later": (
        [[B], [A1], [C]],
        "place-obstacle",
        "o3 blocks r1 placing o1 in goal with top and moves at step 3; it must move by step 2",
    ),
    "place obstacle never moved": (
        [[B], [A1]],
        "place-obstacle",
        "o3 blocks r1 placing o1 in goal with top and never moves",
    ),
    "handover before its pick obstacle": ([[A3], [B]], "pick-obstacle", "o2 blocks r1 picking o1 with top"),
    "unsupported grasp": (
        [[("o1", "goal", "r1", "side")]],
        "unsupported",
        "no fact (reachable-pick o1 side r1) supports 'r1 moves o1 to goal (side)'",
    ),
    "unsupported handover": (
        [[("o1", "goal", "r2", "side", "r1", "top")]],
        "unsupported",
        "no fact (enable-goal-handover o1 side top r2 r1)",
    ),
    "obstacle to the goal": (
        [[("o2", "goal", "r1", "top")], [A2]],
        "region",
        "o2 goes to 'goal', but the model moves it only into 'start'",
    ),
    "goal missed": ([[B]], "goal", "goal (in-region o1 goal) does not hold at the end: o1 is in 'start'"),
    "moved twice": ([[A2], [A2]], "moved-twice", "o1 is moved again (first at step 1)"),
    "robot busy": ([[B, A3]], "robot-busy", "r1 is in two actions of the step (moving o2 and o1)"),
}


@pytest.mark.parametrize("name", list(INVALID_SYMBOLIC))
def test_broken_symbolic_plans_are_rejected(name: str, chain3: Any) -> None:
    spec, code, fragment = INVALID_SYMBOLIC[name]
    steps = [[_act(*a) for a in step] for step in spec]
    report = validate(chain3, _plan(chain3, CHAIN3, steps, symbolic=True), CHAIN3)
    hits = [str(v) for v in report.violations if v.code == code]
    assert any(fragment in h for h in hits), report.lines()


def test_symbolic_cli(tmp_path: Path, chain3: Any, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(_plan(chain3, CHAIN3, [[_act(*A2)]], symbolic=True)), encoding="utf-8")
    assert cli.main(["validate", CHAIN3, str(path)]) == 0
    assert capsys.readouterr().out == "valid: plan for chain-3: 1 step, 1 object moved (symbolic checks)\n"
    # a geometric plan's file given for the wrong problem file: every mismatch is reported, nothing crashes
    assert cli.main(["validate", PA3, str(path)]) == 1
    out = capsys.readouterr().out
    assert "the plan is for problem 'chain-3', not 'pa3-handover' [problem]" in out
    assert "[plan-kind]" in out and "[unknown-name]" in out


# ------------------------------------------------------------------------------------- symbolic: relays
RELAY = str(ROOT / "tests" / "data" / "relay.mrg")


@pytest.fixture(scope="module")
def relay() -> Any:
    return parse_file(RELAY).problem(None)


def _moves(*spec: tuple[str, ...]) -> list[PlannedAction]:
    """Actions ``(object, region, robot, grasp[, robot2, grasp2][, "relay"])``."""
    out = []
    for a in spec:
        relay, a = a[-1] == "relay", a[:-1] if a[-1] == "relay" else a
        out.append(PlannedAction(a[0], a[1], a[2], a[4] if len(a) > 4 else a[2], a[3], a[5] if len(a) > 4 else a[3]))
        out[-1].relay = relay
    return out


O2, O3 = ("o2", "start", "r1", "top"), ("o3", "goal", "r2", "side")
SET_DOWN = ("o1", "mid", "r1", "top", "relay")  # the relay move: r1 sets o1 down in mid
ON = ("o1", "goal", "r2", "side")  # the onward move: r2 picks o1 in mid and puts it into goal


def _relay_report(problem: Any, *steps: list[tuple[str, ...]]) -> ValidationReport:
    return validate(problem, _plan(problem, RELAY, [_moves(*step) for step in steps], symbolic=True), RELAY)


def test_a_relay_plan_is_valid(relay: Any) -> None:
    """o2 first (it blocks r1's pick), then o1 set down in mid, then r2 takes it on (o3, which blocks that
    place, moved by then); no reachable-pick fact for r2's pick in mid, the relay fact covers it; o4's pick
    obstacle (r2 picking o1 side) and its place fact for mid play no part."""
    assert ("reachable-pick", ("o1", "side", "r2")) not in {(f.predicate, f.args) for f in relay.init}
    for steps in ([[O2, O3], [SET_DOWN], [ON]], [[O2], [SET_DOWN, O3], [ON]]):
        report = _relay_report(relay, *steps)
        assert report.ok, report.lines()
        assert report.lines()[0] == "valid: plan for relay: 3 steps, 3 objects moved (symbolic checks)"
    # a regrasp (r1 sets o1 down and picks it again with side), the onward move a handover to r2
    regrasp = _relay_report(relay, [O2, O3], [SET_DOWN], [("o1", "goal", "r1", "side", "r2", "side")])
    assert regrasp.ok, regrasp.lines()
    top_top = _relay_report(relay, [O2, O3], [SET_DOWN], [("o1", "goal", "r1", "side", "r2", "top")])
    assert [str(v) for v in top_top.violations] == [
        "step 3: o1: no fact (enable-goal-handover o1 side top r1 r2) supports 'r1->r2 moves o1 to goal "
        "(side->top)' [unsupported]"
    ]
    plan = read_plan(_plan(relay, RELAY, [_moves(O2, O3), _moves(SET_DOWN), _moves(ON)], symbolic=True))
    (moved,) = plan.steps[1].actions
    assert moved.relay and moved.describe() == "r1 sets down o1 in mid (top)"
    assert not plan.steps[2].actions[0].relay


INVALID_RELAYS: dict[str, tuple[list[list[tuple[str, ...]]], str, str]] = {
    "moved twice without the relay flag": (
        [[O2, O3], [SET_DOWN[:-1]], [ON]],
        "moved-twice",
        "step 3: o1: o1 is moved again (first at step 2); each object moves at most once [moved-twice]",
    ),
    "set down and never moved on": (
        [[O2, O3], [SET_DOWN]],
        "relay",
        "step 2: o1: o1 is set down at step 2 and never moved on [relay]",
    ),
    "moved on in the same step": (
        [[O2, O3], [SET_DOWN, ON]],
        "moved-twice",
        "o1 is moved again in step 2, where it is set down; its onward move comes at a later step",
    ),
    "set down twice": (
        [[O2, O3], [SET_DOWN], [("o1", "mid", "r1", "top", "relay")], [ON]],
        "moved-twice",
        "o1 is set down again (first at step 2); a relay move is followed by its onward move, not a relay",
    ),
    "moved a third time": (
        [[O2, O3], [SET_DOWN], [ON], [ON]],
        "moved-twice",
        "o1 is moved a third time (set down at step 2, moved on at step 3)",
    ),
    "relay of an object without a goal": (
        [[("o2", "mid", "r1", "top", "relay")], [("o2", "start", "r1", "top"), O3], [SET_DOWN], [ON]],
        "region",
        "step 1: o2: o2 is not a goal object: only goal objects are relayed (enable-relay) [region]",
    ),
    "relay into the goal region": (
        [[O2, O3], [("o1", "goal", "r1", "top", "relay")], [ON]],
        "region",
        "o1 is set down in its goal region 'goal': a relay move sets it down on its way, in another region",
    ),
    "relay as a handover": (
        [[O2, O3], [("o1", "mid", "r1", "top", "r2", "side", "relay")], [ON]],
        "region",
        "a relay move is a pick-and-place: r1 sets o1 down itself, not a handover to r2",
    ),
    "no relay fact for the onward pick": (
        [[O2, O3], [SET_DOWN], [("o1", "goal", "r2", "top")]],
        "unsupported",
        "no fact (enable-relay o1 mid top top r1 r2) supports 'r1 sets down o1 in mid (top)'",
    ),
    "no relay fact at all": (
        [[O2, O3], [("o1", "start", "r1", "top", "relay")]],
        "unsupported",
        "no fact (enable-relay o1 start top _ r1 _) supports 'r1 sets down o1 in start (top)'",
    ),
    "relay move before its pick obstacle": (
        [[SET_DOWN, O3], [O2], [ON]],
        "pick-obstacle",
        "o2 blocks r1 picking o1 with top and moves at step 2; it must move at an earlier step",
    ),
    "onward move before its place obstacle": (
        [[O2], [SET_DOWN], [ON], [O3]],
        "place-obstacle",
        "o3 blocks r2 placing o1 in goal with side and moves at step 4; it must move by step 3",
    ),
}


@pytest.mark.parametrize("name", list(INVALID_RELAYS))
def test_broken_relay_plans_are_rejected(name: str, relay: Any) -> None:
    spec, code, fragment = INVALID_RELAYS[name]
    report = _relay_report(relay, *spec)
    hits = [str(v) for v in report.violations if v.code == code]
    assert any(fragment in h for h in hits), report.lines()


# ------------------------------------------------------------------------------------- geometric relays
@pytest.fixture
def relay_plan() -> dict[str, Any]:
    return vp.relay()


def test_a_geometric_relay_plan_is_valid(pa3: Any, relay_plan: dict[str, Any]) -> None:
    """o1 set down in bin-a (not its goal) at step 1 stands there between the steps: placed inside its
    action's region, resting on the bin's floor; step 2 picks it there and hands it on into bin-b."""
    assert _action(relay_plan, 1)["relay"] is True and "relay" not in _action(relay_plan, 2)
    report = validate(pa3, relay_plan, PA3)
    assert report.ok, report.lines()
    assert report.lines()[0].startswith("valid: plan for pa3-handover: 2 steps, 1 object moved (geometric")


def test_the_onward_pick_is_checked_where_the_relay_move_put_the_object(
    pa3: Any, relay_plan: dict[str, Any], one_step: dict[str, Any]
) -> None:
    """The same onward move, but picking o1 where it stood at the start (one_step's handover): the replay
    knows o1 is in bin-a now, 364 mm away."""
    plan = copy.deepcopy(relay_plan)
    plan["steps"][1]["actions"] = one_step["steps"][0]["actions"]
    report = validate(pa3, plan, PA3)
    assert {(v.step, v.code) for v in report.violations} == {(2, "grasp"), (2, "approach")}, report.lines()
    grasp = next(str(v) for v in report.violations if v.code == "grasp")
    assert grasp.startswith("step 2: r1: the last pick configuration of r1 puts the tool 364.1 mm")


def _no_relay_flag(p: dict[str, Any]) -> None:
    del _action(p, 1)["relay"]


def _never_moved_on(p: dict[str, Any]) -> None:
    _drop_last_step(p)


GEOMETRIC_RELAYS: dict[str, tuple[Callable[[dict[str, Any]], None], list[str]]] = {
    "moved twice without the flag": (
        _no_relay_flag,
        ["step 2: o1: o1 is moved again (first at step 1); each object moves at most once [moved-twice]"],
    ),
    "set down and never moved on": (
        _never_moved_on,
        [
            "step 1: o1: o1 is set down at step 1 and never moved on [relay]",
            "o1: goal (in-region o1 bin-b) does not hold at the end: o1 is at (",
        ],
    ),
}


@pytest.mark.parametrize("name", list(GEOMETRIC_RELAYS))
def test_broken_geometric_relays_are_rejected(name: str, pa3: Any, relay_plan: dict[str, Any]) -> None:
    change, lines = GEOMETRIC_RELAYS[name]
    change(relay_plan)
    found = [str(v) for v in validate(pa3, relay_plan, PA3).violations]
    assert len(found) == len(lines) and all(f.startswith(line) for f, line in zip(found, lines)), found


def test_geometric_relays_only_of_goal_objects_on_their_way(
    pa3: Any, one_step: dict[str, Any], two_steps: dict[str, Any]
) -> None:
    _action(two_steps, 1)["relay"] = True  # o2, not a goal object, within start
    assert [str(v) for v in validate(pa3, two_steps, PA3).violations] == [
        "step 1: o2: o2 is not a goal object: only goal objects are relayed (enable-relay) [region]",
        "step 1: o2: o2 is set down at step 1 and never moved on [relay]",
    ]
    _action(one_step, 1)["relay"] = True  # o1 handed over into bin-b, its goal
    assert [str(v) for v in validate(pa3, one_step, PA3).violations] == [
        "step 1: o1: a relay move is a pick-and-place: r1 sets o1 down itself, not a handover to r2 [region]",
        "step 1: o1: o1 is set down in its goal region 'bin-b': a relay move sets it down on its way, in another "
        "region [region]",
        "step 1: o1: o1 is set down at step 1 and never moved on [relay]",
    ]


# ------------------------------------------------------------------------------------- planar robots
@pytest.fixture
def room(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Any, dict[str, Any]]:
    """r1 drives from (-1, 0) to the box's -x side, carries it east into the goal region, and drives back."""
    return vp.room(str(tmp_path_factory.getbasetemp()))


def test_a_planar_plan_is_valid_and_its_mutations_are_not(room: tuple[str, Any, dict[str, Any]]) -> None:
    path, problem, plan = room
    report = validate(problem, plan, path)
    assert report.ok, report.lines()
    bad = copy.deepcopy(plan)
    a = _action(bad, 1)
    a["configs"]["pick"] = [[-0.5, 0.0, 0.0]]  # 5 cm short of the box, where the to-pick path does not go
    a["paths"]["home"] = _line([1.25, 0, 0], [0, 1.2, 0], 10) + _line([0, 1.2, 0], [-1, 0, 0], 10)  # through the wall
    lines = validate(problem, bad, path).lines()
    assert any(
        "the last pick base pose of r1 is 50.0 mm, 0.000 rad from where grasp 'side-x-' of b puts it" in x
        for x in lines
    ), lines
    assert any(
        "[collision-robot-fixed]" in x and "footprint of r1 (" in x and "and wall overlap by" in x for x in lines
    ), lines
    assert any(
        "path 'to-pick' (moving b) ends 50.0 mm, 0.000 rad away from the first pick configuration" in x for x in lines
    ), lines
    bad = copy.deepcopy(plan)
    detour = [-1.3, -1.5, 0]  # carrying the box through r2, standing at home
    _action(bad, 1)["paths"]["to-place"] = _line([-0.45, 0, 0], detour) + _line(detour, [1.25, 0, 0])
    lines = validate(problem, bad, path).lines()
    assert any("[collision-robot-robot]" in x and "footprint of r2 (at home)" in x for x in lines), lines
    assert any("[collision-robot-object]" in x and "b held by r1" in x and "r2" in x for x in lines), lines


def test_random_damage_never_crashes_the_validator(pa3: Any, two_steps: dict[str, Any]) -> None:
    """Values swapped for others of the same JSON type (so the schema still holds): always a report."""
    import random

    rng = random.Random(0)
    names = ["o1", "o2", "o3", "r1", "r2", "h1", "start", "bin-a", "bin-b", "table", "top", "side-y-", "", "zz"]
    numbers = [0.0, -1.0, 1e6, -1e300, 3.2, 1e-12, 7]

    def leaves(node: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        if isinstance(node, dict):
            return [p for k, v in node.items() for p in leaves(v, path + (k,))]
        if isinstance(node, list):
            return [p for i, v in enumerate(node) for p in leaves(v, path + (i,))]
        return [path]

    steps_only = [p for p in leaves(two_steps) if p[0] == "steps" and p[-1] not in ("index",)]
    for _ in range(25):
        plan = copy.deepcopy(two_steps)
        for path in rng.sample(steps_only, 3):
            node = plan
            for k in path[:-1]:
                node = node[k]
            old = node[path[-1]]
            if isinstance(old, str):
                node[path[-1]] = rng.choice(names)
            elif isinstance(old, float):
                node[path[-1]] = rng.choice(numbers)
        try:
            report = validate(pa3, plan, PA3)
        except InputError as exc:  # e.g. a kind no longer in the schema's enum
            assert exc.diagnostics[0].code == "E502"
            continue
        for line in report.lines():
            assert "\n" not in line
