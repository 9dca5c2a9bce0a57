"""Any arm, not only the Panda (issue 27): a conformance test over the arms pybullet_data ships with a gripper
(the xArm6 with its revolute mimic gripper, the Panda) and a 6-DOF arm from a URDF written here (primitive
shapes, a parallel gripper of two prismatic fingers, one mimicking the other).  Each stands on a table at
z = 0, reaches the objects in front of it, plans a two-arm pick-and-place with a handover, and the plan
validates (``mrgc validate``).  The xArm scene is docs/language.md's "Bring your own arm" example, run as
written.  Also: the mount and the gripper as the URDF defines them, the numeric IK on 6-DOF chains, and the
one-line diagnoses of an arm that can reach nothing (W274, W276)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from support import ROOT, run_cli

import mrgc
from mrgc.geometry.fk import ee_pose, fk
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.ik_analytic import panda_chain
from mrgc.geometry.kinematics import gripper_frames, load_robot_model
from mrgc.geometry.tcp import _derive
from mrgc.testing.pybullet_reference import pybullet_fk

XARM = "xarm/xarm6_with_gripper.urdf"

#: a 6-DOF arm of boxes and cylinders, its hand a palm with two prismatic fingers (the right one mimics the
#: left), 0.87 m of reach: (link, its collision geometry and origin z, joint type, joint origin z, axis, limit)
ARM6_LINKS = [
    ("base_link", '<cylinder radius="0.07" length="0.1"/>', 0.05, None, 0.0, "", 0.0),
    ("l1", '<cylinder radius="0.05" length="0.08"/>', 0.05, "revolute", 0.1, "0 0 1", 3.1416),
    ("l2", '<box size="0.06 0.06 0.27"/>', 0.175, "revolute", 0.12, "0 1 0", 2.0),
    ("l3", '<box size="0.05 0.05 0.2"/>', 0.14, "revolute", 0.35, "0 1 0", 2.6),
    ("l4", '<cylinder radius="0.03" length="0.04"/>', 0.0, "revolute", 0.28, "0 0 1", 3.1416),
    ("l5", '<box size="0.04 0.04 0.03"/>', 0.02, "revolute", 0.06, "0 1 0", 2.2),
    ("l6", '<cylinder radius="0.03" length="0.01"/>', 0.005, "revolute", 0.05, "0 0 1", 3.1416),
    ("hand", '<box size="0.04 0.12 0.04"/>', 0.02, "fixed", 0.01, "", 0.0),
]


def arm6_urdf() -> str:
    """The URDF of the 6-DOF arm above, with its fingers (``finger_r`` mimics ``finger_l``)."""
    out = ['<?xml version="1.0"?>', '<robot name="arm6">']
    for k, (name, geometry, z, kind, jz, axis, limit) in enumerate(ARM6_LINKS):
        if kind is not None:
            parent = ARM6_LINKS[k - 1][0]
            out.append(f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="{name}"/>')
            out.append(f'<origin xyz="0 0 {jz}"/>')
            if kind == "revolute":
                out.append(f'<axis xyz="{axis}"/><limit lower="-{limit}" upper="{limit}" effort="10" velocity="2"/>')
            out.append("</joint>")
        out.append(f'<link name="{name}"><collision><origin xyz="0 0 {z}"/><geometry>{geometry}</geometry>')
        out.append("</collision></link>")
    for side, sign, mimic in (("left", "", ""), ("right", "-", '<mimic joint="finger_left"/>')):
        out.append(
            f'<joint name="finger_{side}" type="prismatic"><parent link="hand"/><child link="finger_{side}_link"/>'
        )
        out.append(f'<origin xyz="0 0 0.04"/><axis xyz="0 {sign}1 0"/>')
        out.append(f'<limit lower="0" upper="0.045" effort="10" velocity="0.2"/>{mimic}</joint>')
        out.append(f'<link name="finger_{side}_link"><collision><origin xyz="0 {sign}0.006 0.03"/>')
        out.append('<geometry><box size="0.02 0.012 0.06"/></geometry></collision></link>')
    return "\n".join([*out, "</robot>", ""])


KINDS = {
    "panda": """(:robot-kind panda
    :urdf "franka_panda/panda.urdf"
    :end-effector "panda_hand"
    :home (0 -0.785 0 -2.356 0 1.571 0.785))""",
    "arm6": """(:robot-kind arm6
    :urdf "arm6.urdf"
    :end-effector "hand"
    :home (0 0.4 1.6 0 1.1 0)
    :gripper-opening 0.09)""",
}


def scene(kind: str, base: float, front: float) -> str:
    """Two ``kind`` arms facing each other across a table at ±``base``; a 12 cm stick (o1, the goal) and a
    cube (o2) ``front`` metres in front of a1, the bin as far in front of a2, a handover point between."""
    near = -base + front
    return f"""(define (domain cell)
  (:requirements :handover)
  {KINDS[kind]}
  (:grasps top top-x side-x+ side-x- side-y+ side-y-))

(define (problem handover)
  (:domain cell)
  (:robots
    (a1 :kind {kind} :base ({-base:g} 0 0 0))
    (a2 :kind {kind} :base ({base:g} 0 0 180)))
  (:fixed
    (table :shape (box {2 * base + 0.4:g} 0.8 0.05) :pose (0 0 -0.025 0)))
  (:regions
    (start :shape (box 0.2 0.3 0.2) :pose ({near:g} 0 0.1 0))
    (bin :shape (box 0.16 0.16 0.2) :pose ({-near:g} 0 0.1 0)))
  (:movable
    (o1 :shape (box 0.04 0.04 0.12) :pose ({near:g} -0.06 0.06 0) :grasps (top top-x side-y+ side-y-))
    (o2 :shape (box 0.04 0.04 0.04) :pose ({near:g} 0.06 0.02 0)))
  (:handover-points
    (h1 :position (0 0 0.3)))
  (:goal (in-region o1 bin)))
"""


def docs_example() -> str:
    """The lisp block of docs/language.md's "Bring your own arm"."""
    text = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    section = text.split("### Bring your own arm", 1)[1]
    found = re.search(r"```lisp\n(.*?)```", section, re.S)
    assert found is not None
    return found.group(1)


def write(folder: Path, arm: str) -> Path:
    """The conformance scene of ``arm`` written into ``folder`` (with the URDF it needs)."""
    path = folder / f"{arm}.mrg"
    if arm == "xarm6":
        path.write_text(docs_example(), encoding="utf-8")
    else:
        (folder / "arm6.urdf").write_text(arm6_urdf(), encoding="utf-8")
        path.write_text(scene(arm, 0.7 if arm == "panda" else 0.6, 0.4 if arm == "panda" else 0.3), encoding="utf-8")
    return path


@pytest.mark.parametrize("arm", ["xarm6", "panda", "arm6"])
def test_each_arm_reaches_its_objects_hands_over_and_the_plan_validates(
    arm: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, arm)
    report = mrgc.check(path)
    assert not report.warnings, [str(d) for d in report.warnings]  # no arm that reaches nothing
    problem = report.file.problem()
    found = mrgc.compute_facts(problem)
    facts = set(found.facts)
    for obj in ("o1", "o2"):  # the objects in front of a1
        assert any(f.predicate == "reachable-pick" and f.args[0] == obj and f.args[2] == "a1" for f in facts), obj
    assert any(f.predicate == "reachable-place" and f.args[1:2] == ("bin",) and f.args[3] == "a2" for f in facts)
    assert any(f.predicate == "enable-goal-handover" and f.args[3:] == ("a1", "a2") for f in facts)
    assert not any(f.predicate == "reachable-place" and f.args[1] == "bin" and f.args[3] == "a1" for f in facts)
    plan = mrgc.plan(problem, facts=found.facts, seed=0, time_limit=120)
    assert str(plan.status) == "solved", "\n".join(plan.summary())
    assert any("a1->a2 moves o1 to bin" in line for line in plan.summary()), plan.summary()  # a handover
    text = plan.dumps()
    plan_file = tmp_path / "plan.json"
    plan_file.write_text(text, encoding="utf-8")
    code, out, _ = run_cli(capsys, "validate", path, plan_file)
    assert code == 0, out


def test_the_xarm_is_modelled_from_its_urdf() -> None:
    """The mount is the dummy root and the link fixed to it; the gripper is the drive joint and its five
    mimics, opened by measuring the fingertip gap; forward kinematics at an opening matches pybullet's with
    every mimic joint set by the URDF's rule; the TCP comes from the fingertips."""
    model = load_robot_model(XARM, str(ROOT), "xarm_gripper_base_link")
    assert [model.links[k].name for k in model.mount] == ["world", "link_base"]
    assert model.dof == 6 and panda_chain(model) is None
    gripper = [link for link in model.links if link.finger]
    assert len(gripper) == 6 and sum(link.mimic < 0 for link in gripper) == 1
    assert [model.links[k].name for k in model.fingertips] == ["left_finger", "right_finger"]
    derived = _derive(model.urdf, model.end_effector, ())
    assert derived is not None and derived.text() == "(0 0 0.1621 0)" and "left_finger" in derived.source
    assert model.opening_table is not None
    values, gaps = model.opening_table
    assert np.all(np.diff(gaps) < 0) and 0.085 < gaps[0] < 0.095  # 0 is open
    for opening in (0.02, 0.05, 0.08):
        drive = model.finger_value(opening)
        frames = gripper_frames(model, drive)
        left, right = (frames[k][:3, :3] @ model.links[k].points.T + frames[k][:3, 3:] for k in model.fingertips)
        assert abs((left[1].min() - right[1].max()) - opening) < 1e-3
        q = np.array([0.3, -0.4, -0.9, 0.2, 1.1, -0.5])
        ours = fk(model, q, fingers=drive)
        ref = pybullet_fk(model, q, fingers=drive)
        for link in model.links:
            assert np.allclose(ours[link.index], ref[link.name], atol=1e-5), link.name


def test_the_validator_exempts_the_whole_mount() -> None:
    """pybullet's joint info gives the validator the same mount: its base link -1 and link_base (joint 0)."""
    from mrgc.geometry.scene import scene_from_problem
    from mrgc.validator.world import ReplayScene

    problem = mrgc.parse_file(ROOT / "tests" / "golden" / "errors" / "W274.mrg").problem()
    with ReplayScene(scene_from_problem(problem)) as rs:
        robot = rs.robots["a1"]
        assert robot.mount == frozenset({-1, 0}) and robot.links[0] == "link_base"
        rs.set_fingers("a1", 0.05)  # the drive and its mimics, each by its rule
        import pybullet as pb

        states = [pb.getJointState(robot.body, j, physicsClientId=rs.cid)[0] for j, *_ in robot.fingers]
        assert len(states) == 6 and max(states) - min(states) < 1e-9 and states[0] > 0.3


@pytest.mark.parametrize("arm", ["xarm", "arm6"])
def test_numeric_ik_solves_6_dof_arms(arm: str, tmp_path: Path) -> None:
    """Levenberg-Marquardt with restarts on poses forward kinematics made: 6-DOF chains as 7-DOF ones."""
    if arm == "xarm":
        model = load_robot_model(XARM, str(ROOT), "xarm_gripper_base_link")
    else:
        (tmp_path / "arm6.urdf").write_text(arm6_urdf(), encoding="utf-8")
        model = load_robot_model("arm6.urdf", str(tmp_path), "hand")
        assert panda_chain(model) is None
    rng = np.random.default_rng(7)
    q = rng.uniform(np.maximum(model.lower, -3.0), np.minimum(model.upper, 3.0), size=(150, model.dof))
    results = solve_ik_many(model, ee_pose(model, q), seed=3, restarts=8)
    solved = [r for r in results if r.solved]
    assert len(solved) >= 0.95 * len(results)
    for r, target in zip(results, ee_pose(model, q)):
        if r.solved:
            assert np.linalg.norm(ee_pose(model, r.q)[:3, 3] - target[:3, 3]) < 2e-4


def test_an_arm_whose_ik_never_converges_says_why(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """:end-effector 'link3' leaves the xArm a 3-joint chain: check, facts and plan say so in one line each,
    at the robot's declaration."""
    text = docs_example().replace('"xarm_gripper_base_link"', '"link3" :tcp (0 0 0 0)')
    text = re.sub(r":home \(([^ ]+ [^ ]+ [^ ]+) [^)]*\)", r":home (\1)", text)  # the first three joints
    path = tmp_path / "short.mrg"
    path.write_text(text, encoding="utf-8")
    code, _, err = run_cli(capsys, "check", path)
    lines = [line for line in err.splitlines() if "warning[W276]" in line]
    assert code == 0 and len(lines) == 2 and "is :end-effector right? 'link3' ends a chain of 3 joints" in lines[0]
    assert re.match(r".*short\.mrg:\d+:\d+: warning\[W276\]: IK for a1 found no solution for \d+ targets", lines[0])
    plan = mrgc.plan(path, seed=0, time_limit=60)
    assert str(plan.status) == "infeasible"
    why = "\n".join(plan.summary())
    assert "W276 IK for a1 found no solution" in why and "W276 IK for a2" in why


def test_an_arm_sunk_into_the_table_says_why(tmp_path: Path) -> None:
    """The issue's symptom, now with a true cause: a1 16 cm lower, its mount (exempt) inside the table and
    link1, which turns about the vertical, 5.6 mm into the table top in every configuration: W274 at a1."""
    text = docs_example().replace("(a1 :kind xarm6 :base (-0.55 0 0 0))", "(a1 :kind xarm6 :base (-0.55 0 -0.16 0))")
    path = tmp_path / "low.mrg"
    path.write_text(text, encoding="utf-8")
    warnings = [d for d in mrgc.check(path).warnings if d.code in ("W274", "W275", "W276")]
    assert [d.code for d in warnings] == ["W274"]
    span = warnings[0].span
    assert span is not None and span.line == text[: text.index("(a1 :kind")].count("\n") + 1
    assert warnings[0].message.startswith("every configuration of a1 (64 drawn within its joint limits) collides")
    assert "fixed object 'table': link 'link1' is 5.6 mm inside it" in warnings[0].message


def test_an_end_effector_fixed_to_the_root_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """:end-effector 'link_base' (fixed to the root, a chain of 0 joints): one W276 per robot, no internal
    error."""
    text = docs_example().replace('"xarm_gripper_base_link"', '"link_base" :tcp (0 0 0 0)')
    text = re.sub(r" *:home \([^)]*\)[^\n]*\n", "", text)
    path = tmp_path / "rooted.mrg"
    path.write_text(text, encoding="utf-8")
    code, _, err = run_cli(capsys, "check", path)
    assert code == 0 and err.count("warning[W276]: IK for a") == 2
    assert "'link_base' is fixed to the root link 'world' (a chain of 0 joints)" in err
