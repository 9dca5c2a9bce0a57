"""The tool centre point of a robot kind without ``:tcp``, derived from its URDF (geometry/tcp.py, issue 24):
a grasp-target link first, else the fingertips; ``mrgc check`` says which; a Panda without ``:tcp`` gets the
shipped domain's facts and plans."""

from __future__ import annotations

import os
from pathlib import Path

import pybullet_data
import pytest
from support import ROOT, run_cli

import mrgc
from mrgc.geometry.scene import scene_from_problem
from mrgc.geometry.tcp import _derive, derive_tcp
from mrgc.language.loader import parse_file
from mrgc.language.model import Pose

PANDA = os.path.join(pybullet_data.getDataPath(), "franka_panda", "panda.urdf")
TCP_LINE = ":tcp (0 0 0.105 0) ; the point between the fingertips, on the hand's z axis"


def domain_without_tcp(folder: Path) -> Path:
    """The packaging domain with its ``:tcp`` line removed, and pa3-handover beside it."""
    text = (ROOT / "domains" / "packaging" / "domain.mrg").read_text()
    assert TCP_LINE in text
    (folder / "domain.mrg").write_text(text.replace(TCP_LINE, ""))
    (folder / "pa3-handover.mrg").write_text((ROOT / "domains" / "packaging" / "pa3-handover.mrg").read_text())
    return folder / "pa3-handover.mrg"


def test_the_panda_tcp_comes_from_its_grasp_target_link(tmp_path: Path) -> None:
    problem = parse_file(domain_without_tcp(tmp_path)).problem()
    kind = problem.domain.robot_kinds[0]
    assert kind.tcp is None
    derived = derive_tcp(kind)
    assert derived is not None and derived.pose == Pose(0.0, 0.0, 0.105, 0.0)
    assert derived.source == "link 'panda_grasptarget'" and derived.text() == "(0 0 0.105 0)"
    shipped = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem().domain.robot_kinds[0]
    assert derived.pose == shipped.tcp
    # the scene, which phase 1, the grounding, the validator and the pictures read, holds the derived value
    assert {r.kind.tcp for r in scene_from_problem(problem).robots} == {shipped.tcp}


def test_without_a_grasp_target_link_the_tcp_lies_between_the_fingertips(tmp_path: Path) -> None:
    folder = tmp_path / "franka_panda"
    folder.mkdir()
    os.symlink(os.path.join(os.path.dirname(PANDA), "meshes"), folder / "meshes")
    text = Path(PANDA).read_text()
    start, end = text.index('<link name="panda_grasptarget">'), text.index("</robot>")
    (folder / "panda.urdf").write_text(text[:start] + text[end:])
    derived = _derive(str(folder / "panda.urdf"), "panda_hand", ())
    assert derived is not None and derived.source == "fingertips of 'panda_leftfinger', 'panda_rightfinger'"
    # the finger joints sit 0.0584 m along the hand's z; the collision mesh reaches 0.0539 m further
    assert (derived.pose.x, derived.pose.y, derived.pose.yaw) == (0.0, 0.0, 0.0)
    assert derived.pose.z == pytest.approx(0.1122, abs=5e-4)


def test_a_kind_without_fingers_or_grasp_target_gets_none() -> None:
    assert _derive(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa", "model.urdf"), "lbr_iiwa_link_7", ()) is None


def test_check_reports_the_derived_tcp_with_its_source(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = domain_without_tcp(tmp_path)
    code, out, err = run_cli(capsys, "check", path)
    assert code == 0 and err == ""
    note = f"{tmp_path / 'domain.mrg'}:5:3: note: robot kind 'panda' has no :tcp: using (0 0 0.105 0) from the "
    assert note + "link 'panda_grasptarget' of 'franka_panda/panda.urdf'" in out.splitlines()
    assert f"ok: domain packaging from {tmp_path / 'domain.mrg'}" in out
    code, out, _ = run_cli(capsys, "check", ROOT / "domains" / "packaging" / "pa3-handover.mrg")
    assert code == 0 and "note:" not in out  # the shipped domain states its :tcp


@pytest.mark.slow
def test_a_panda_without_tcp_gets_the_same_facts_and_plans(tmp_path: Path) -> None:
    path = domain_without_tcp(tmp_path)
    shipped = ROOT / "domains" / "packaging" / "pa3-handover.mrg"
    facts = mrgc.compute_facts(path).facts
    assert facts == mrgc.compute_facts(shipped).facts and len(facts) > 40
    plan = mrgc.plan(path, time_limit=120)
    assert plan.status.value == "solved", plan.why
    report = mrgc.validate(path, plan)  # the validator's scene derives the same grasp point
    assert report.ok, report.violations
