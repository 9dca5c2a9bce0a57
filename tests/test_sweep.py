"""The validator's continuous check: motion bounds that hold, self-collision pairs derived from the URDF, and a
sweep that finds what passes between two samples (validator/sweep.py, validator/bounds.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc.api import load_problem
from mrgc.geometry.scene import scene_from_problem
from mrgc.validator.bounds import ArmBounds, arm_bounds
from mrgc.validator.sweep import CAP, Pair, Sweep
from mrgc.validator.world import ReplayScene

PA5 = str(ROOT / "domains" / "packaging" / "pa5.mrg")


@pytest.fixture(scope="module")
def panda() -> Any:
    scene = scene_from_problem(load_problem(PA5))
    rs = ReplayScene(scene)
    home = np.array(scene.robots[0].kind.home, dtype=float)
    yield rs, arm_bounds(rs, "r1", home), home
    rs.close()


def _link_points(rs: ReplayScene, bounds: ArmBounds) -> dict[int, np.ndarray]:
    """Each shaped link's collision vertices (link frame) from the URDF model, by pybullet link index."""
    r = rs.robots["r1"]
    by_name = {name: index for index, name in r.links.items()}
    return {
        by_name[link.name]: np.asarray(link.points, dtype=float)
        for link in rs.models["r1"].links
        if link.name in by_name and by_name[link.name] in bounds.links and len(link.points)
    }


def _world_points(rs: ReplayScene, link: int, pts: np.ndarray) -> np.ndarray:
    from mrgc.geometry.bullet import pose_of

    r = rs.robots["r1"]
    if link == -1:
        frame = r.base
    else:
        s = rs.pb.getLinkState(r.body, link, computeForwardKinematics=True, physicsClientId=rs.cid)
        frame = pose_of(s[4], s[5])
    return pts @ frame[:3, :3].T + frame[:3, 3]  # type: ignore[no-any-return]


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.floats(0.01, 1.0))
def test_no_point_of_a_link_moves_farther_than_its_bound(panda: Any, seed: int, scale: float) -> None:
    """Along a straight joint-space motion from q0 to q1, every collision vertex of every link stays within
    sum_j |dq_j| R[j, link] of where it started (the Schwarzer-Saha-Latombe bound the sweep relies on)."""
    rs, bounds, home = panda
    r = rs.robots["r1"]
    rng = np.random.default_rng(seed)
    q0 = rng.uniform(r.lower, r.upper)
    q1 = np.clip(q0 + scale * rng.uniform(-1, 1, len(q0)) * (r.upper - r.lower), r.lower, r.upper)
    pts = _link_points(rs, bounds)
    rs.set_config("r1", q0)
    start = {link: _world_points(rs, link, p) for link, p in pts.items()}
    limit = {link: float(np.abs(q1 - q0) @ bounds.reach[:, bounds.column(link)]) for link in pts}
    for u in np.linspace(0.0, 1.0, 11)[1:]:
        rs.set_config("r1", q0 + u * (q1 - q0))
        for link, p in pts.items():
            moved = float(np.linalg.norm(_world_points(rs, link, p) - start[link], axis=1).max())
            assert moved <= limit[link] + 1e-6, (link, moved, limit[link])
    rs.set_config("r1", home)


def test_self_collision_pairs_are_the_links_more_than_one_chain_joint_apart(panda: Any) -> None:
    """Derived from the joint tree: rigidly attached links and the gripper are exempt among themselves, and
    neighbours across one chain joint; every other pair of collision-bearing links is checked."""
    rs, bounds, _ = panda
    name = rs.robots["r1"].links
    pairs = {frozenset((name[a], name[b])) for a, b in bounds.self_pairs}
    assert frozenset(("panda_link5", "panda_link7")) in pairs
    assert frozenset(("panda_link0", "panda_hand")) in pairs
    assert frozenset(("panda_link1", "panda_leftfinger")) in pairs
    for exempt in [
        ("panda_link0", "panda_link1"),
        ("panda_link6", "panda_link7"),
        ("panda_link6", "panda_hand"),  # across joint 7 only (link8 and the hand are fixed to link7)
        ("panda_link7", "panda_hand"),
        ("panda_hand", "panda_leftfinger"),
        ("panda_leftfinger", "panda_rightfinger"),
    ]:
        assert frozenset(exempt) not in pairs, exempt
    shaped = len(bounds.links)  # 8 links of the chain and base, the hand, two fingers
    assert shaped == 11 and len(pairs) == len(bounds.self_pairs) == 39
    assert {name[f] for f in bounds.fingers} == {"panda_leftfinger", "panda_rightfinger"}
    assert {"panda_hand", "panda_leftfinger", "panda_rightfinger"} <= {name.get(g, "") for g in bounds.gripper}


def _line_sweep(gap: float, breaks: int) -> tuple[list[tuple[float, float]], Sweep]:
    """A point moving along x from -1 to 1 (rate 2 per unit of phase time) past a wall at x = 0 whose
    near face stands ``gap`` off its path (negative: the path cuts ``-gap`` deep into it)."""
    hits: list[tuple[float, float]] = []
    x = [0.0]

    def set_state(s: float) -> None:
        x[0] = -1.0 + 2.0 * s

    def query(p: int, s: float) -> dict[tuple[int, int], float]:
        d = float(np.hypot(x[0], gap)) if gap > 0 else abs(x[0]) + gap
        return {(-1, -1): d} if d < CAP else {}

    def report(p: int, sub: tuple[int, int], d: float, s: float) -> None:
        hits.append((s, d))

    pair = Pair([(-1, -1)], np.array([[2.0]]))
    bp = np.linspace(0.0, 1.0, breaks)
    sweep = Sweep(bp, lambda k: np.ones(1), [pair], set_state, query, report, 1e-3, 10_000)
    return hits, sweep


@pytest.mark.parametrize("breaks", [2, 3, 8])
def test_the_sweep_finds_an_overlap_between_two_configurations(breaks: int) -> None:
    """Configurations at x = -1 and x = 1 (or any number between that never lands on the wall's 4 mm) are
    clear; the motion between them cuts 4 mm into the wall: reported, at its deepest within the floor."""
    hits, sweep = _line_sweep(-0.004, breaks)
    sweep.run()
    assert hits, "an overlap between samples went unseen"
    deepest = min(d for _, d in hits)
    assert deepest <= -0.002


def test_the_sweep_passes_a_clear_motion_with_few_checks() -> None:
    """A motion that keeps 2 mm off the wall is clear; far from it the sweep takes long steps."""
    hits, sweep = _line_sweep(0.002, 2)
    sweep.run()
    assert not hits
    assert 5 < sweep.events < 200


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_the_spheres_hold_every_link(panda: Any, seed: int) -> None:
    """The sphere about each link's centre of mass (the sweep's lower bounds: a pair farther apart than its
    spheres is not asked of pybullet) holds the link: pybullet's distance between two links, and between a
    link and a box, is never less than the bound at random configurations within the limits."""
    rs, bounds, _ = panda
    r = rs.robots["r1"]
    rng = np.random.default_rng(seed)
    rs.set_config("r1", rng.uniform(r.lower, r.upper))
    links = list(bounds.links)
    centres = rs.link_centres("r1", links)
    pos, rot = rs.body_frame("o1")
    half = np.array([0.02, 0.02, 0.05])  # o1 of pa5: a box 0.04 x 0.04 x 0.1
    near = rs.link_distances("r1", "o1", 10.0)
    for k, a in enumerate(links):
        local = np.maximum(np.abs(rot.T @ (centres[k] - pos)) - half, 0.0)
        assert near.get((a, -1), 10.0) >= float(np.linalg.norm(local)) - bounds.spheres[k] - 1e-6
        for m in range(k + 1, len(links)):
            b = links[m]
            d = rs.link_distances("r1", "r1", 10.0, (a, b)).get((a, b), 10.0)
            assert d >= float(np.linalg.norm(centres[k] - centres[m])) - bounds.spheres[k] - bounds.spheres[m] - 1e-6
