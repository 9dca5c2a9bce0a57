"""Robot models, forward and inverse kinematics: numpy against pybullet, IK round trips, errors as diagnostics."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mrgc.errors import InputError
from mrgc.geometry import fk as F
from mrgc.geometry import ik as I
from mrgc.geometry import transforms as tf
from mrgc.geometry.conventions import pose_error, rotation_log
from mrgc.geometry.kinematics import load_robot_model, model_for_kind, read_mesh
from mrgc.language.model import Pose, RobotKind
from mrgc.testing.pybullet_reference import pybullet_fk, pybullet_ik

PANDA = "franka_panda/panda.urdf"


def unit_floats(n: int) -> st.SearchStrategy:
    return st.lists(st.floats(0.0, 1.0), min_size=n, max_size=n)


def in_limits(model, u) -> np.ndarray:
    return model.lower + np.asarray(u) * (model.upper - model.lower)


def assert_same_frames(ref: dict[str, np.ndarray], ours: np.ndarray, model, tol: float = 1e-6) -> None:
    for link in model.links:
        pe, re = pose_error(ours[link.index], ref[link.name])
        assert pe <= tol, (link.name, float(pe))
        assert re <= tol, (link.name, float(re))


# ---------------------------------------------------------------------------------------------- models


def test_panda_model(panda) -> None:
    assert panda.dof == 7
    assert panda.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    assert panda.link_names[0] == "panda_link0"
    assert {"panda_hand", "panda_leftfinger", "panda_rightfinger", "panda_grasptarget"} <= set(panda.link_names)
    assert panda.links[panda.ee_link].name == "panda_hand"
    assert np.allclose(panda.ee_offset[:3, 3], [0, 0, 0.107])
    assert panda.lower[3] == pytest.approx(-3.1416) and panda.upper[3] == 0.0
    assert panda.max_velocity[0] == pytest.approx(2.175)
    left = panda.links[panda.link_index("panda_leftfinger")]
    assert left.joint_kind == "prismatic" and left.chain_index == -1 and left.frozen_value == pytest.approx(0.04)
    # every Panda link with a collision mesh has its OBJ vertices in the link frame
    link4 = panda.links[panda.link_index("panda_link4")]
    (col,) = link4.collisions
    assert col.kind == "mesh" and col.mesh_path.endswith("meshes/collision/link4.obj")
    assert link4.points.shape == (900, 3) and col.faces.shape[1] == 3
    assert panda.links[panda.link_index("panda_link8")].points.shape == (0, 3)
    assert 0.9 < panda.reach < 1.0 and np.allclose(panda.shoulder, [0, 0, 0.333])


def test_models_are_cached_and_pickle(panda) -> None:
    assert load_robot_model(PANDA, "/elsewhere", "panda_hand") is panda
    copy = pickle.loads(pickle.dumps(panda))
    q = np.linspace(0.1, 0.7, 7)
    assert np.array_equal(F.fk(copy, q), F.fk(panda, q))
    assert I.solve_ik(copy, F.ee_pose(panda, q), seed=3).solved


def test_model_for_kind(panda) -> None:
    kind = RobotKind("arm", urdf=PANDA, end_effector="panda_hand")
    assert model_for_kind(kind, "/tmp") is panda
    with pytest.raises(InputError) as err:
        model_for_kind(RobotKind("arm", urdf=None), "/tmp")
    assert err.value.diagnostics[0].code == "E400"


def test_missing_urdf_is_a_diagnostic(tmp_path: Path) -> None:
    with pytest.raises(InputError) as err:
        load_robot_model("robots/nope.urdf", str(tmp_path), "hand")
    (diag,) = err.value.diagnostics
    assert diag.code == "E400" and "robots/nope.urdf" in diag.message and str(tmp_path) in diag.message


def test_malformed_urdf_is_a_diagnostic(tmp_path: Path) -> None:
    (tmp_path / "bad.urdf").write_text("<robot name='x'><link name='a'></robot", encoding="utf-8")
    with pytest.raises(InputError) as err:
        load_robot_model("bad.urdf", str(tmp_path), "a")
    assert err.value.diagnostics[0].code == "E400" and "bad.urdf" in err.value.diagnostics[0].message


def test_missing_end_effector_is_a_diagnostic() -> None:
    with pytest.raises(InputError) as err:
        load_robot_model(PANDA, "/tmp", "panda_gripper")
    (diag,) = err.value.diagnostics
    assert diag.code == "E401" and "panda_gripper" in diag.message and "panda_hand" in diag.message


def test_loading_prints_nothing() -> None:
    code = (
        "from mrgc.geometry.kinematics import load_robot_model; "
        "from mrgc.testing.pybullet_reference import pybullet_fk; "
        f"m = load_robot_model({PANDA!r}, '.', 'panda_hand'); pybullet_fk(m, [0.0] * 7); print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout == "ok\n"
    assert "pybullet" not in out.stderr


# -------------------------------------------------------------------------- a URDF exercising the corners

TOY = """<?xml version="1.0"?>
<robot name="toy">
  <link name="base">
    <inertial><origin xyz="0.1 0 0.05" rpy="0.3 0 0"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><origin xyz="0 0 0.05" rpy="0 0 0.2"/><geometry><box size="0.2 0.3 0.1"/></geometry></collision>
  </link>
  <link name="l1">
    <inertial><origin xyz="0 0.02 0.1" rpy="0.1 0.2 0.3"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><origin xyz="0 0 0.1" rpy="0.5 0 0"/>
      <geometry><cylinder radius="0.04" length="0.2"/></geometry></collision>
  </link>
  <link name="l2">
    <inertial><origin xyz="0.05 0 0" rpy="0 0.4 0"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><mesh filename="package://meshes/tri.obj" scale="2 2 2"/></geometry></collision>
  </link>
  <link name="l3">
    <inertial><origin xyz="0 0 0.03"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="mount"/>
  <link name="l4"><inertial><origin xyz="0.01 0 0"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tool"/>
  <link name="side"><collision><geometry><box size="0.01 0.01 0.01"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.1 -0.2 0.3"/><axis xyz="1 1 0"/>
    <limit lower="-2" upper="2" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.2" rpy="0 0.5 0"/><axis xyz="0 -1 0"/>
    <limit lower="-0.1" upper="0.3" velocity="0.5"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.3 0 0" rpy="1.2 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="fixed_mount" type="fixed"><parent link="l3"/><child link="mount"/>
    <origin xyz="0 0.1 0" rpy="0 0 0.7"/></joint>
  <joint name="j4" type="revolute"><parent link="mount"/><child link="l4"/>
    <origin xyz="0.05 0 0.1"/><axis xyz="1 0 0"/><limit lower="-1" upper="1.5" velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l4"/><child link="tool"/>
    <origin xyz="0 0 0.12" rpy="0.3 0 0"/></joint>
  <joint name="side_joint" type="revolute"><parent link="l2"/><child link="side"/>
    <origin xyz="0 0.1 0"/><axis xyz="0 0 1"/><limit lower="0.2" upper="0.6" velocity="1"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("toy")
    (folder / "meshes").mkdir()
    (folder / "meshes" / "tri.obj").write_text(
        "# tri\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3 4\n", encoding="utf-8"
    )
    (folder / "toy.urdf").write_text(TOY, encoding="utf-8")
    return load_robot_model("toy.urdf", str(folder), "tool")


def test_toy_model(toy) -> None:
    assert toy.joint_names == ("j1", "j2", "j3", "j4")
    assert [j.kind for j in toy.joints] == ["revolute", "prismatic", "revolute", "revolute"]
    assert toy.joints[2].continuous and toy.lower[2] == pytest.approx(-np.pi)
    side = toy.links[toy.link_index("side")]
    assert side.chain_index == -1 and side.frozen_value == pytest.approx(0.2)
    kinds = {link.name: [c.kind for c in link.collisions] for link in toy.links}
    assert kinds["base"] == ["box"] and kinds["l1"] == ["cylinder"] and kinds["l2"] == ["mesh"]
    (mesh,) = toy.links[toy.link_index("l2")].collisions
    assert np.allclose(mesh.vertices[1], [0.2, 0, 0]) and mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    box = toy.links[0]
    assert np.allclose(np.ptp(box.collisions[0].vertices, axis=0), [0.2, 0.3, 0.1])


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    u=unit_floats(4),
    xyz=st.lists(st.floats(-1, 1), min_size=3, max_size=3),
    rpy=st.lists(st.floats(-3.1, 3.1), min_size=3, max_size=3),
)
def test_toy_fk_matches_pybullet(toy, u, xyz, rpy) -> None:
    q = in_limits(toy, u)
    base = tf.from_xyz_rpy(xyz, rpy)
    assert_same_frames(pybullet_fk(toy, q, base), F.fk(toy, q, base), toy)


# ---------------------------------------------------------------------------------------------- FK


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(u=unit_floats(7))
def test_fk_matches_pybullet(panda, u) -> None:
    q = in_limits(panda, u)
    ours = F.fk(panda, q)
    assert_same_frames(pybullet_fk(panda, q), ours, panda)
    assert np.allclose(F.ee_pose(panda, q), ours[panda.ee_link], atol=1e-12)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(u=unit_floats(7), x=st.floats(-1, 1), y=st.floats(-1, 1), z=st.floats(0, 1), yaw=st.floats(-180, 180))
def test_fk_with_a_base_pose_matches_pybullet(panda, u, x, y, z, yaw) -> None:
    q = in_limits(panda, u)
    base = Pose(x, y, z, yaw)
    ours = F.fk_world(panda, q, base)
    assert_same_frames(pybullet_fk(panda, q, tf.from_pose(base)), ours, panda)
    assert np.allclose(ours, tf.from_pose(base) @ F.fk(panda, q), atol=1e-12)
    assert np.allclose(F.ee_pose(panda, q, base), ours[panda.ee_link], atol=1e-12)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(u=unit_floats(7), opening=st.floats(0.0, 0.1))
def test_fk_with_the_fingers_at_an_opening_matches_pybullet(panda, u, opening) -> None:
    q = in_limits(panda, u)
    value = panda.finger_value(opening)
    ours = F.fk(panda, q, fingers=value)
    assert_same_frames(pybullet_fk(panda, q, fingers=value), ours, panda)
    left, right = panda.link_index("panda_leftfinger"), panda.link_index("panda_rightfinger")
    gap = np.linalg.norm(ours[left][:3, 3] - ours[right][:3, 3])
    assert gap == pytest.approx(min(opening, 0.08), abs=1e-9)  # the finger frames stand the opening apart
    # only the fingers move; at the upper limit they are where the frozen (open) model puts them
    assert np.allclose(np.delete(ours, [left, right], axis=0), np.delete(F.fk(panda, q), [left, right], axis=0))
    assert np.allclose(F.fk(panda, q, fingers=panda.finger_value(0.08)), F.fk(panda, q), atol=1e-15)


def test_fk_batches(panda) -> None:
    rng = np.random.default_rng(0)
    q = rng.uniform(panda.lower, panda.upper, size=(4, 3, 7))
    batch = F.fk(panda, q)
    assert batch.shape == (4, 3, len(panda.links), 4, 4)
    assert np.allclose(batch[2, 1], F.fk(panda, q[2, 1]), atol=1e-14)
    assert F.ee_pose(panda, q).shape == (4, 3, 4, 4)
    with pytest.raises(ValueError):
        F.fk(panda, np.zeros(6))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(u=st.lists(unit_floats(7), min_size=2, max_size=6), opening=st.none() | st.floats(0.0, 0.1))
def test_fk_of_one_configuration_is_its_row_of_a_batch_to_the_bit(panda, toy, u, opening) -> None:
    """geometry/fk.py: one configuration takes 4x4 products (a motion check's case) where a batch takes stacked
    ones; the frames are the same numbers to the last bit, with a base pose and the fingers at an opening."""
    base = np.eye(4)
    base[:3, 3] = [0.3, -0.2, 0.1]
    for model in (panda, toy):
        qs = np.stack([in_limits(model, v[: model.dof]) for v in u])
        fingers = None if opening is None or model is toy else model.finger_value(opening)
        batch = F.fk(model, qs, base, fingers)
        for k, q in enumerate(qs):
            assert np.array_equal(F.fk(model, q[None], base, fingers)[0], batch[k])
            assert np.array_equal(F.fk(model, q, base, fingers), batch[k])


def test_jacobian_matches_finite_differences(panda, toy) -> None:
    rng = np.random.default_rng(1)
    for model in (panda, toy):
        q = rng.uniform(model.lower, model.upper)
        jac = F.jacobian(model, q)
        t0 = F.ee_pose(model, q)
        h = 1e-6
        for i in range(model.dof):
            dq = np.zeros(model.dof)
            dq[i] = h
            t1 = F.ee_pose(model, q + dq)
            lin = (t1[:3, 3] - t0[:3, 3]) / h
            ang = rotation_log(t1[:3, :3] @ t0[:3, :3].T) / h
            assert np.allclose(jac[:3, i], lin, atol=1e-5) and np.allclose(jac[3:, i], ang, atol=1e-5)


def test_collision_points(panda) -> None:
    q = np.array([0.3, -0.5, 0.2, -2.0, 0.1, 1.8, 0.5])
    base = Pose(1.0, 2.0, 0.5, 90)
    pts = F.collision_points(panda, q, base)
    frames = F.fk(panda, q, base)
    hand = panda.links[panda.link_index("panda_hand")]
    expected = hand.points @ frames[hand.index, :3, :3].T + frames[hand.index, :3, 3]
    assert np.allclose(pts["panda_hand"], expected)
    assert "panda_link8" not in pts and pts["panda_link4"].shape == (900, 3)
    assert F.collision_points(panda, np.stack([q, q]))["panda_link1"].shape == (2, 152, 3)


def test_obj_reader(tmp_path: Path) -> None:
    path = tmp_path / "quad.obj"
    path.write_text(
        "v 0 0 0\nv 1 0 0\nvn 0 0 1\nv 1 1 0\nv 0 1 0\nf 1//1 2//1 3//1 4//1\nf -1 -2 -3\n", encoding="utf-8"
    )
    v, f = read_mesh(str(path))
    assert v.shape == (4, 3) and f.tolist() == [[0, 1, 2], [0, 2, 3], [3, 2, 1]]


# ---------------------------------------------------------------------------------------------- IK


@pytest.fixture(scope="module")
def round_trip(panda):
    rng = np.random.default_rng(2024)
    q = rng.uniform(panda.lower, panda.upper, size=(200, 7))
    targets = F.ee_pose(panda, q)
    I.clear_ik_cache()
    return targets, I.solve_ik_many(panda, targets, seed=0)


def test_ik_round_trip(panda, round_trip) -> None:
    targets, results = round_trip
    solved = [r for r in results if r.status is I.IKStatus.SOLVED]
    assert len(solved) >= 0.95 * len(results)
    for target, res in zip(targets, results):
        if res.solved:
            assert panda.within_limits(res.q)
            pe, re = pose_error(F.ee_pose(panda, res.q), target)
            assert pe <= 1e-4 and re <= 1e-3
            assert res.pos_error == pytest.approx(float(pe), abs=1e-12)
        else:
            assert res.status is I.IKStatus.NO_CONVERGENCE and res.q is None


def test_single_solves_agree_with_the_batch(panda, round_trip) -> None:
    targets, results = round_trip
    I.clear_ik_cache()
    for target, res in zip(targets[:15], results[:15]):
        one = I.solve_ik(panda, target, seed=0)
        assert one.status == res.status
        if one.solved:
            assert np.allclose(one.q, res.q, atol=1e-9)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(picks=st.lists(st.integers(0, 5), min_size=2, max_size=12), per_target=st.booleans())
def test_a_target_asked_twice_in_a_batch_gets_the_answer_of_one_asked_once(panda, round_trip, picks, per_target):
    """ik.py: a batch holding the same target (with the same start) more than once solves it once and gives
    every copy that answer: the same answers, each the same as a batch without the copies (the numeric rows
    of a target run the same whatever else is in the batch), unsolved ones too."""
    targets, _ = round_trip
    hard = tf.from_xyz_rpy([0.0, 0.0, -0.5], [0.0, 0.0, 0.0])  # within the reach bound, no solution
    pool = np.concatenate([targets[:5], hard[None]])
    batch = pool[picks]
    starts = np.tile(panda.clamp((panda.lower + panda.upper) / 2), (len(batch), 1)) if per_target else None
    I.clear_ik_cache()
    together = I.solve_ik_many(panda, batch, seed=3, q_init=starts)
    for i, res in enumerate(together):
        I.clear_ik_cache()
        alone = I.solve_ik_many(panda, batch[i : i + 1], seed=3, q_init=None if starts is None else starts[i : i + 1])[
            0
        ]
        assert res.status == alone.status
        assert (res.q is None) == (alone.q is None) and (res.q is None or np.allclose(res.q, alone.q, atol=1e-9))
        first = picks.index(picks[i])
        assert together[first] is res  # solved once


def test_ik_is_deterministic(panda) -> None:
    target = F.ee_pose(panda, np.array([0.5, 0.3, -0.4, -1.8, 0.2, 2.2, -0.3]))
    I.clear_ik_cache()
    a = I.solve_ik(panda, target, seed=7)
    I.clear_ik_cache()
    b = I.solve_ik(panda, target, seed=7)
    assert a.solved and np.array_equal(a.q, b.q)
    assert I.solve_ik(panda, target, seed=7) is I.solve_ik(panda, target, seed=7)  # cached


def test_ik_honours_q_init(panda) -> None:
    q0 = np.array([0.1, 0.2, 0.1, -1.5, 0.1, 1.6, 0.7])
    target = F.ee_pose(panda, q0 + 0.02)
    res = I.solve_ik(panda, target, seed=0, q_init=q0)
    assert res.solved and np.abs(res.q - q0).max() < 0.1


def test_unreachable_targets(panda) -> None:
    far = tf.translation(5.0, 0.0, 0.5)
    res = I.solve_ik(panda, far, seed=0)
    assert res.status is I.IKStatus.UNREACHABLE and res.q is None and res.iterations == 0
    # within the reach bound but impossible: the hand inside the base pointing into the floor
    res = I.solve_ik(panda, tf.from_xyz_rpy([0.0, 0.0, -0.5], [0.0, 0.0, 0.0]), seed=0)
    assert res.status is I.IKStatus.NO_CONVERGENCE and res.iterations <= 100


def test_rotation_log_at_pi() -> None:
    for axis in np.eye(3):
        r = tf.from_xyz_rpy([0, 0, 0], np.pi * axis)[:3, :3]
        v = rotation_log(r)
        assert np.isclose(np.linalg.norm(v), np.pi) and np.allclose(np.abs(v), np.pi * axis)
    assert np.allclose(rotation_log(np.eye(3)), 0.0)


def test_pybullet_ik_reference(panda) -> None:
    rng = np.random.default_rng(5)
    targets = F.ee_pose(panda, rng.uniform(panda.lower, panda.upper, size=(5, 7)))
    for t in targets:
        res = pybullet_ik(panda, t, seed=0)
        if res.solved:
            assert pose_error(F.ee_pose(panda, res.q), t)[0] <= 1e-4 and panda.within_limits(res.q)


def _checks_in_a_worker(folder: str) -> bool:
    """In a forked worker: load the toy's model again and say whether that started a pybullet client."""
    from mrgc.geometry import bullet

    load_robot_model("toy.urdf", folder, "tool")
    return bullet._CLIENT.get("pid") == os.getpid()


def test_a_urdf_accepted_once_is_not_loaded_again_by_forked_workers(toy) -> None:
    from mrgc.geometry import bullet
    from mrgc.workers import map_in_workers

    folder = os.path.dirname(toy.urdf)
    assert bullet.check_urdf(toy.urdf) is None and bullet._file_key(toy.urdf) in bullet._ACCEPTED  # pybullet's
    assert map_in_workers(_checks_in_a_worker, [folder, folder], 2) == [False, False]


def _panda_in_a_worker(_: int) -> tuple[bool, bool]:
    """In a forked worker: whether checking pybullet_data's Panda started a pybullet client, and whether it
    loads in one (pybullet's own files are not loaded to be checked, but they must load)."""
    from mrgc.geometry import bullet
    from mrgc.geometry.kinematics import resolve_urdf

    path = resolve_urdf(PANDA, "/tmp")
    refused = bullet.check_urdf(path)
    started = bullet._CLIENT.get("pid") == os.getpid()
    return refused is None and not started, isinstance(bullet.shared_body(path), int)


def test_pybullets_own_urdfs_are_not_loaded_to_be_checked() -> None:
    from mrgc.workers import map_in_workers

    assert map_in_workers(_panda_in_a_worker, [0, 1], 2) == [(True, True), (True, True)]
