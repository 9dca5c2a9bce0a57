"""The validator's fast path (issue 21, item 8): its own numpy kinematics equal pybullet's, the motion bounds it
derives from them hold over whole intervals, and the certifier proves clear only what is clear
(validator/fk.py, validator/certify.py, validator/phase_bounds.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc.api import load_problem
from mrgc.geometry.bullet import pose_of
from mrgc.geometry.scene import half_extents, scene_from_problem
from mrgc.validator.bounds import arm_bounds
from mrgc.validator.certify import Certifier, Phase, interval_rate
from mrgc.validator.fk import ArmChain, axis_reach, centres, motion_spheres, pack
from mrgc.validator.phase_bounds import face_bound, face_bounds
from mrgc.validator.sweep import CAP, Pair
from mrgc.validator.world import ReplayScene


@pytest.fixture(scope="module")
def panda() -> Any:
    """pa5's Panda r1 in a replay world of its own, its bounds and home (closed after the module)."""
    scene = scene_from_problem(load_problem(str(ROOT / "domains" / "packaging" / "pa5.mrg")))
    with ReplayScene(scene) as rs:
        home = np.array(scene.robots[0].kind.home, dtype=float)
        yield rs, arm_bounds(rs, "r1", home), home


def _frame(rs: ReplayScene, link: int) -> np.ndarray:
    r = rs.robots["r1"]
    if link == -1:
        return r.base
    s = rs.pb.getLinkState(r.body, link, computeForwardKinematics=True, physicsClientId=rs.cid)
    return pose_of(s[4], s[5])


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31 - 1), st.floats(0.0, 0.08))
def test_the_numpy_kinematics_equal_pybullets(
    panda: Any,
    seed: int,
    opening: float,
) -> None:
    """Every link frame and centre of mass of the validator's numpy kinematics equals pybullet's at random
    configurations within the limits, the fingers at a random opening."""
    rs, _, home = panda
    r = rs.robots["r1"]
    rs.set_fingers("r1", opening)
    chain = ArmChain(rs, "r1")
    qs = np.random.default_rng(seed).uniform(r.lower, r.upper, (4, len(r.joints)))
    rot, pos = chain.frames(qs)
    for k, q in enumerate(qs):
        rs.set_config("r1", q)
        for link in range(chain.n):
            f = _frame(rs, link)
            assert np.abs(f[:3, 3] - pos[k, link + 1]).max() < 1e-5
            assert np.abs(f[:3, :3] - rot[k, link + 1]).max() < 1e-5
            com = rs.pb.getLinkState(r.body, link, computeForwardKinematics=True, physicsClientId=rs.cid)[0]
            assert np.abs(np.array(com) - (pos[k, link + 1] + rot[k, link + 1] @ chain.com[link + 1])).max() < 1e-5
    rs.set_fingers("r1", None)
    rs.set_config("r1", home)


def _link_points(rs: ReplayScene, links: tuple[int, ...]) -> dict[int, np.ndarray]:
    r = rs.robots["r1"]
    by_name = {name: index for index, name in r.links.items()}
    return {
        by_name[link.name]: np.asarray(link.points, dtype=float)
        for link in rs.models["r1"].links
        if link.name in by_name and by_name[link.name] in links and len(link.points)
    }


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.floats(0.01, 1.0))
def test_the_interval_bound_holds_over_the_whole_segment(panda: Any, seed: int, scale: float) -> None:
    """The certifier's motion bound over a straight joint-space segment q0 -> q1, built from each link's
    distance from each joint's axis at the two ends only (motion spheres, grown by what the joints beyond
    move the link: :func:`~mrgc.validator.certify.interval_rate`), is at least the largest displacement of any
    collision vertex of the link from where it starts, measured by pybullet at 41 configurations along the
    segment; and never above the global bound."""
    rs, bounds, home = panda
    r = rs.robots["r1"]
    rng = np.random.default_rng(seed)
    q0 = rng.uniform(r.lower, r.upper)
    q1 = np.clip(q0 + scale * rng.uniform(-1, 1, len(q0)) * (r.upper - r.lower), r.lower, r.upper)
    chain = ArmChain(rs, "r1")
    links = list(bounds.links)
    packed = pack(motion_spheres(rs, "r1", bounds, chain), links)
    rot, pos = chain.frames(np.stack([q0, q1]))
    reach = axis_reach(chain, rot, pos, packed)  # (2, links, dof)
    dq = np.abs(q1 - q0)
    rows = bounds.reach.T  # (links, dof)
    rate = interval_rate(rows, reach[0], reach[1], np.tile(dq, (len(links), 1)))
    limit = (rate * dq).sum(axis=1)
    assert np.all(limit <= (rows * dq).sum(axis=1) + 1e-12)
    pts = _link_points(rs, bounds.links)
    rs.set_config("r1", q0)
    start = {link: p @ _frame(rs, link)[:3, :3].T + _frame(rs, link)[:3, 3] for link, p in pts.items()}
    for u in np.linspace(0.0, 1.0, 41)[1:]:
        rs.set_config("r1", q0 + u * (q1 - q0))
        for link, p in pts.items():
            f = _frame(rs, link)
            moved = float(np.linalg.norm(p @ f[:3, :3].T + f[:3, 3] - start[link], axis=1).max())
            assert moved <= limit[links.index(link)] + 1e-6, (link, moved, limit[links.index(link)])
    rs.set_config("r1", home)


def _wall(gap: float, lower: float) -> tuple[Certifier, list[float]]:
    """A point moving along x from -1 to 1 (rate 2 per unit of phase time) past a wall at x = 0 whose near
    face stands ``gap`` off its path (negative: the path cuts ``-gap`` deep into it); its lower bound is the
    distance less ``lower``."""
    x = [0.0]
    asked: list[float] = []

    def distance(s: np.ndarray) -> np.ndarray:
        xs = -1.0 + 2.0 * s
        out: np.ndarray = np.hypot(xs, gap) if gap > 0 else np.abs(xs) + gap
        return out

    def bounds(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (distance(t) - lower)[:, None], np.tile(np.array([[2.0], [0.0]]), (len(t), 1, 1))

    def set_state(s: float) -> None:
        x[0] = s
        asked.append(s)

    def query(p: int) -> dict[tuple[int, int], float]:
        d = float(distance(np.array([x[0]]))[0])
        return {(-1, -1): d} if d < CAP else {}

    phase = Phase(
        np.array([0.0, 0.3, 1.0]),
        np.ones((2, 1)),
        [Pair([(-1, -1)], np.array([[2.0]]))],
        np.array([[0, 1]]),
        np.array([[[1.0], [0.0]]]),
        np.array([[2.0], [0.0]]),
        bounds,
        set_state,
        query,
    )
    return Certifier(phase, 1e-3, 10_000), asked


@pytest.mark.parametrize("lower", [0.0, 0.05, 10.0])
def test_the_certifier_never_clears_a_cut_between_samples(lower: float) -> None:
    """A motion that cuts 4 mm into the wall between clear ends is never certified (the sweep then finds
    it), whatever the lower bounds; one that keeps 2 mm off it is, with few questions to pybullet."""
    cut, _ = _wall(-0.004, lower)
    assert not cut.run()
    clear, asked = _wall(0.002, lower)
    assert clear.run()
    assert len(asked) < 200


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.01, 0.05), st.floats(0.0, 0.2))
def test_a_certified_motion_keeps_within_the_tolerance(gap: float, lower: float) -> None:
    """Whenever the certifier says the motion is clear, the true distance stays above -1 mm everywhere."""
    cert, _ = _wall(gap, lower)
    if cert.run():
        xs = np.linspace(-1.0, 1.0, 20001)
        d = np.hypot(xs, gap) if gap > 0 else np.abs(xs) + gap
        assert d.min() >= -1e-3


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_face_bound_never_exceeds_pybullets_distance(panda: Any, seed: int) -> None:
    """The lower bound of a link's distance from a box that the box's face planes give (its motion spheres
    against each face: :func:`~mrgc.validator.phase_bounds.face_bound`) is never more than pybullet's signed
    distance, at random configurations, for every link and every box of pa5 (the table and five boxes),
    overlapping ones included."""
    rs, bounds, home = panda
    r = rs.robots["r1"]
    chain = ArmChain(rs, "r1")
    links = list(bounds.links)
    packed = pack(motion_spheres(rs, "r1", bounds, chain), links)
    qs = np.random.default_rng(seed).uniform(r.lower, r.upper, (3, len(r.joints)))
    rot, pos = chain.frames(qs)
    world = centres(rot, pos, packed)
    scene = scene_from_problem(load_problem(str(ROOT / "domains" / "packaging" / "pa5.mrg")))
    boxes = {b.name: half_extents(b.shape) for b in (*scene.fixed, *scene.movable)}
    for k, q in enumerate(qs):
        rs.set_config("r1", q)
        for name, half in boxes.items():
            pos_b, rot_b = rs.body_frame(name)
            lb = face_bound(pos_b, rot_b, half, world[k : k + 1], packed[2], packed[3])[0]
            got = rs.link_distances("r1", name, 10.0)
            for i, link in enumerate(links):
                if (link, -1) in got:
                    assert lb[i] <= got[(link, -1)] + 1e-6, (name, r.links[link], lb[i], got[(link, -1)])
    rs.set_config("r1", home)


def _rotation(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 6), st.integers(1, 5), st.integers(1, 12))
def test_the_face_bounds_of_many_boxes_are_each_boxs_own(seed: int, n: int, times: int, spheres: int) -> None:
    """:func:`~mrgc.validator.phase_bounds.face_bounds` (every box at once, the certifier's path) gives for
    each box what the face planes of that box alone give: the spheres in the box's frame, their signed
    distances from its six faces, the least per element and the largest over the faces."""
    rng = np.random.default_rng(seed)
    centre = rng.normal(size=(n, 3))
    rot = np.stack([_rotation(rng.normal(size=4)) for _ in range(n)])
    half = rng.uniform(0.01, 0.5, (n, 3))
    world = rng.normal(size=(times, spheres, 3))
    radius = rng.uniform(0.0, 0.1, spheres)
    first = np.unique(np.concatenate([[0], rng.integers(0, spheres, 3)]))
    got = face_bounds(centre, rot, half, world, radius, first)
    assert got.shape == (times, len(first), n)
    for b in range(n):
        local = (world - centre[b]) @ rot[b]
        faces = np.concatenate([local - half[b], -local - half[b]], axis=2) - radius[None, :, None]
        want = np.array(
            [[faces[t, lo:hi].min(axis=0).max() for lo, hi in zip(first, [*first[1:], spheres])] for t in range(times)]
        )
        assert np.allclose(got[:, :, b], want, atol=1e-12)
        assert np.allclose(face_bound(centre[b], rot[b], half[b], world, radius, first), want, atol=1e-12)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_a_link_is_no_farther_from_the_joint_it_carries_than_its_bound(panda: Any, seed: int) -> None:
    """The certifier's first-joint rate (validator/certify.py, ``_reach``): a link's largest distance from the
    axis of a chain joint that hangs on it, computed once from its motion spheres at one configuration, is at
    least the distance of each of its collision vertices from that axis as pybullet places them at random
    configurations (the axis is fixed in the link's frame, so one configuration serves all)."""
    rs, bounds, home = panda
    r = rs.robots["r1"]
    chain = ArmChain(rs, "r1")
    links = list(bounds.links)
    packed = pack(motion_spheres(rs, "r1", bounds, chain), links)
    rot, pos = chain.frames(home[None])
    once = axis_reach(chain, rot, pos, packed)[0]  # (links, dof)
    carried = {
        (k, column): float(once[k, column])
        for k, link in enumerate(links)
        for column, joint in enumerate(r.joints)
        if chain.joints[joint].parent == link + 1
    }
    assert len(carried) == 7  # link0 carries joint 1, ..., link6 joint 7
    pts = _link_points(rs, bounds.links)
    for q in np.random.default_rng(seed).uniform(r.lower, r.upper, (3, len(r.joints))):
        rs.set_config("r1", q)
        for (k, column), bound in carried.items():
            joint = r.joints[column]
            s = rs.pb.getLinkState(r.body, joint, computeForwardKinematics=True, physicsClientId=rs.cid)
            axis = pose_of(s[4], s[5])[:3, :3] @ chain.joints[joint].axis
            f = _frame(rs, links[k])
            rel = pts[links[k]] @ f[:3, :3].T + f[:3, 3] - np.array(s[4])
            off = np.linalg.norm(np.cross(rel, axis), axis=1).max()
            assert off <= bound + 1e-6, (r.links[links[k]], column, off, bound)
    rs.set_config("r1", home)
