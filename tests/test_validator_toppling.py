"""Issue 21, class 6: a box set down so that it touches its neighbour's top only on a corner would topple; the
validator rejects it (``[unstable]``, naming the box and what it stands on), where until issue 21 touching
was enough.  The doctored plan is the stored pa5 plan (tests/data/round2/, see tests/make_round2_plans.py)
with its last placement moved onto the corner of an object placed before it."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import doctor as d
import numpy as np
import pytest

from mrgc import cli


def _on_corner(plan: dict[str, Any], overlap: float) -> tuple[dict[str, Any], str, str]:
    """The plan with its last action's placement standing on the top of the first action's object, shifted
    diagonally so that the two footprints overlap on an ``overlap`` x ``overlap`` square at a corner."""
    problem = d.problem(d.problem_file("pa5"))
    shapes = {m.name: m.shape for m in problem.movable}
    bad = copy.deepcopy(plan)
    first = bad["steps"][0]["actions"][0]
    last = bad["steps"][-1]["actions"][-1]
    under, top = first["object"], last["object"]
    below = np.array(first["place_pose"], dtype=float)
    a, b = shapes[under], shapes[top]
    pose = np.eye(4)
    pose[0, 3] = below[0, 3] + (a.sx + b.sx) / 2 - overlap
    pose[1, 3] = below[1, 3] + (a.sy + b.sy) / 2 - overlap
    pose[2, 3] = below[2, 3] + a.sz / 2 + b.sz / 2 + 0.001
    last["place_pose"] = pose.tolist()
    last["region"] = first["region"]
    return bad, top, under


@pytest.mark.parametrize("overlap", [0.005, 0.015])
def test_a_box_on_its_neighbours_corner_is_rejected_as_unstable(
    overlap: float, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad, top, under = _on_corner(d.load("pa5"), overlap)
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(bad), encoding="utf-8")
    capsys.readouterr()
    rc = cli.main(["validate", d.problem_file("pa5"), str(path), "--format", "json"])
    report = json.loads(capsys.readouterr().out)
    assert rc == 1 and not report["ok"]
    unstable = [v for v in report["violations"] if v["code"] == "unstable"]
    assert unstable, report["violations"]
    assert unstable[0]["subject"] == top and f"{top} would topple" in unstable[0]["message"]
    assert under in unstable[0]["message"]


def test_the_same_box_centred_on_its_neighbour_is_not_unstable(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The control: the doctored plan with full overlap breaks other rules (the arm does not reach there,
    the goal), but the box stands."""
    problem = d.problem(d.problem_file("pa5"))
    shapes = {m.name: m.shape for m in problem.movable}
    plan = d.load("pa5")
    first = plan["steps"][0]["actions"][0]
    bad, top, _ = _on_corner(
        plan, (shapes[first["object"]].sx + shapes[plan["steps"][-1]["actions"][-1]["object"]].sx) / 2
    )
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(bad), encoding="utf-8")
    capsys.readouterr()
    rc = cli.main(["validate", d.problem_file("pa5"), str(path), "--format", "json"])
    report = json.loads(capsys.readouterr().out)
    assert rc == 1
    assert not [v for v in report["violations"] if v["code"] in ("unstable", "floating")], report["violations"]


@pytest.mark.parametrize("case", ["A21", "H13", "A31", "A31-twin"])
def test_the_adversarial_review_s_accepted_plans_are_now_rejected(case: str, tmp_path: Path) -> None:
    """tests/adversarial_round2.py's plans (issue 21's second adversarial review): a tower whose combined
    centre of mass overhangs the box under it (A21) and a support pulled out from under a box and put back
    within one step (A31) are rejected; the centred tower and the same excursion with nothing on top pass."""
    import adversarial_round2 as adv

    name, wrong, _, build, _ = next(c for c in adv.CASES if c[0] == case)
    plan = copy.deepcopy(d.load("pa5"))
    build(plan)
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(plan), encoding="utf-8")
    rc, first = adv.validate(path)
    assert rc == (1 if wrong else 0), first
    if case == "A21":
        assert "[unstable]" in first and "o3 on it" in first
    if case == "A31":
        assert "[floating]" in first and "picks up" in first
