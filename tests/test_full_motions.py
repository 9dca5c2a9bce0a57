"""`mrgc plan --motions full` (issue 9, beyond the paper): arms' empty-handed motions planned as paths too,
and the validator, which then requires every path, accepts the plan."""

from __future__ import annotations

import pytest
from support import ROOT

from mrgc import __version__, parse_file
from mrgc.errors import InputError
from mrgc.planfile.format import file_sha256
from mrgc.planner.search import plan_problem
from mrgc.validator.validate import validate

HANDOVER = ROOT / "domains" / "packaging" / "pa3-handover.mrg"


def test_full_motions_plan_every_path_and_validate() -> None:
    problem = parse_file(HANDOVER).problem()
    plan = plan_problem(
        problem, str(HANDOVER), file_sha256(str(HANDOVER)), __version__, seed=0, time_limit=120, motions="full"
    )
    assert plan.status == "solved", plan.why.lines() if plan.why else plan.stats
    doc = plan.to_json()
    assert doc["motion_model"]["arms"] == "full"
    for step in plan.steps:
        for action in step:
            want = {"to-pick", "to-place", "home"}
            if action.pick_robot != action.place_robot:
                want |= {"to-handover", "taker-to-handover", "giver-home"}
            assert want <= set(action.paths)
    assert validate(problem, doc, str(HANDOVER)).ok
    # a full plan missing one of its paths is not valid
    first = doc["steps"][0]["actions"][0]
    del first["paths"]["home"]
    report = validate(problem, doc, str(HANDOVER))
    assert not report.ok and any(v.code == "missing" for v in report.violations)


def test_unknown_motion_model_is_misuse() -> None:
    problem = parse_file(HANDOVER).problem()
    with pytest.raises(InputError, match="motions='teleport': must be one of configurations, full"):
        plan_problem(problem, str(HANDOVER), "0" * 64, __version__, motions="teleport")
