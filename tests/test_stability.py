"""Stable placements (validator/stability.py) and upright cart placements (issue 21, items 6 and 7).

The support polygon is checked against closed forms: boxes on boxes (centred, shifted past the edge, bridged
over two supports, yawed), boxes on region floors, cylinders, spheres and meshes; tilted and floating objects
get a verdict, never an exception.  The cart's set-down is checked through ``mrgc validate`` on the room of
tests/validator_plans.py: its place pose tilted 3 degrees on its edge, or 2 cm off the floor, is rejected.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import validator_plans as vp
from hypothesis import example, given, settings
from hypothesis import strategies as st
from support import run_cli

from mrgc.geometry.transforms import from_xyz_rpy, rot_z, translation
from mrgc.language.model import Box, Cylinder, Mesh, Sphere
from mrgc.validator.stability import (
    CIRCLE_POINTS,
    FLAT_TOL,
    MARGIN,
    MARGIN_SHARE,
    SUPPORT_TOL,
    cart_set_down,
    lowest,
    stability,
)

sides = st.floats(0.02, 1.0)
yaws = st.floats(-math.pi, math.pi)
gaps = st.floats(-SUPPORT_TOL * 0.99, SUPPORT_TOL * 0.99)
places = st.floats(-5.0, 5.0)
PROPERTY = settings(max_examples=150, deadline=None)


def required(a: float, b: float) -> float:
    return min(MARGIN, MARGIN_SHARE * min(a, b))


def scene(yaw: float, x0: float, y0: float) -> np.ndarray:
    """The frame every body of a drawn scene is placed in: turned by ``yaw`` and moved to (x0, y0)."""
    frame: np.ndarray = translation(x0, y0, 0.0) @ rot_z(yaw)
    return frame


# ------------------------------------------------------------------------------------- boxes on boxes
@PROPERTY
@given(a=sides, b=sides, h=sides, grow=st.tuples(st.floats(0, 1), st.floats(0, 1)), H=sides, gap=gaps, yaw=yaws)
def test_a_box_centred_on_a_larger_box_is_stable(
    a: float, b: float, h: float, grow: tuple[float, float], H: float, gap: float, yaw: float
) -> None:
    frame = scene(yaw, 1.0, -2.0)
    below = (Box(a + grow[0], b + grow[1], H), frame @ translation(0, 0, H / 2))
    s = stability("o", Box(a, b, h), frame @ translation(0, 0, H + gap + h / 2), {"s": below})
    assert s.stable and s.flat and s.supporters == ("s",)
    assert s.margin == pytest.approx(min(a, b) / 2, abs=1e-9)  # its whole bottom face rests on s
    assert s.required == pytest.approx(required(a, b))


@PROPERTY
@given(a=sides, b=sides, A=sides, B=sides, share=st.floats(0.0, 0.999), yaw=yaws, x0=places, y0=places)
@example(a=0.020000000000000004, b=1.0, A=0.02, B=1.0, share=0.5, yaw=0.0, x0=1.0, y0=0.0)  # 1 ulp past the edge
def test_a_box_shifted_over_the_edge_topples_exactly_there(
    a: float, b: float, A: float, B: float, share: float, yaw: float, x0: float, y0: float
) -> None:
    """Shifted by dx along its supporter's x: the contact patch is the overlap of the two footprints and the
    margin the centre's distance to its edge; past the supporter's edge (dx > A/2) the centre is outside."""
    dx = share * (A + a) / 2
    frame = scene(yaw, x0, y0)
    s = stability(
        "o", Box(a, b, 0.1), frame @ translation(dx, 0, 0.35), {"s": (Box(A, B, 0.3), frame @ translation(0, 0, 0.15))}
    )
    lo, hi = max(dx - a / 2, -A / 2), min(dx + a / 2, A / 2)
    half_y = min(b, B) / 2
    want = min(dx - lo, hi - dx, half_y) if dx <= hi else -(dx - hi)
    assert s.supporters == ("s",)
    assert s.margin == pytest.approx(want, abs=1e-9)
    if abs(want - s.required) > 1e-9:
        assert s.stable == (want >= s.required)
    if dx > A / 2:  # past the edge: toppling (a centre a rounding error past it has a margin of 0, not < 0)
        assert not s.stable and (s.margin < 0 or dx - A / 2 <= 1e-9)


@pytest.mark.parametrize(("dx", "stable"), [(0.5 - MARGIN - 1e-6, True), (0.5 - MARGIN + 1e-6, False), (0.5, False)])
def test_the_verdict_flips_at_the_margin(dx: float, stable: bool) -> None:
    """A 0.4 m box on a 1 m one, shifted so its centre of mass nears the supporter's edge at x = 0.5."""
    s = stability("o", Box(0.4, 0.4, 0.2), translation(dx, 0, 0.4), {"s": (Box(1, 1, 0.6), translation(0, 0, 0))})
    assert s.stable == stable
    assert s.margin == pytest.approx(0.5 - dx, abs=1e-9)


@PROPERTY
@given(w=sides, g=sides, over=st.floats(0.01, 1.0), b=sides, yaw=yaws, x0=places, y0=places)
def test_two_half_supports_make_a_stable_bridge(
    w: float, g: float, over: float, b: float, yaw: float, x0: float, y0: float
) -> None:
    """Two supports of width ``w`` a gap ``g`` apart; the object spans the gap and reaches ``over`` of each."""
    frame = scene(yaw, x0, y0)
    a = g + 2 * over * w
    support = Box(w, b + 0.1, 0.3)
    bodies = {
        "left": (support, frame @ translation(-(g + w) / 2, 0, 0.15)),
        "right": (support, frame @ translation((g + w) / 2, 0, 0.15)),
    }
    obj, pose = Box(a, b, 0.2), frame @ translation(0, 0, 0.4)
    s = stability("o", obj, pose, bodies)
    assert s.supporters == ("left", "right")
    assert s.margin == pytest.approx(min(a / 2, b / 2), abs=1e-9)  # the hull spans the gap
    assert s.stable == (min(a, b) / 2 >= required(a, b))
    half = stability("o", obj, pose, {"left": bodies["left"]})
    assert not half.stable and half.supporters == ("left",)
    assert half.margin == pytest.approx(-g / 2, abs=1e-9)  # the centre lies over the middle of the gap


def test_a_box_touching_its_neighbours_top_on_a_corner_topples() -> None:
    """Issue 21's case: a box set down touching its neighbour's top only on a 5 x 5 mm corner."""
    cube = Box(0.1, 0.1, 0.1)
    s = stability("o2", cube, translation(0.095, 0.095, 0.151), {"o1": (cube, translation(0, 0, 0.05))})
    assert not s.stable and s.flat and s.supporters == ("o1",)
    assert sorted(s.polygon) == [(0.045, 0.045), (0.045, 0.05), (0.05, 0.045), (0.05, 0.05)]
    assert s.margin == pytest.approx(-math.hypot(0.045, 0.045))
    assert s.message() == (
        "o2 would topple: its centre of mass lies 63.6 mm outside the support polygon of its contacts with o1 "
        "(it must lie at least 5.0 mm inside)"
    )
    near = stability("o2", cube, translation(0.048, 0, 0.151), {"o1": (cube, translation(0, 0, 0.05))})
    assert near.message() == (
        "o2 would topple: its centre of mass lies only 2.0 mm inside the support polygon of its contacts with o1 "
        "(it must lie at least 5.0 mm inside)"
    )


@PROPERTY
@given(a=sides, b=sides, h=sides, lift=st.floats(0, SUPPORT_TOL * 0.99), yaw=yaws, x0=places, y0=places)
def test_a_box_on_the_floor_of_a_region_is_stable(
    a: float, b: float, h: float, lift: float, yaw: float, x0: float, y0: float
) -> None:
    frame = scene(yaw, x0, y0)
    region = ("bin", Box(a + 0.2, b + 0.2, 0.5), frame @ translation(0, 0, 0.95))  # its floor at z = 0.7
    s = stability("o", Box(a, b, h), frame @ translation(0.05, -0.05, 0.7 + lift + h / 2), {}, [region])
    assert s.stable and s.supporters == ("floor of bin",)
    assert s.margin == pytest.approx(min(a, b) / 2, abs=1e-9)
    assert s.message().startswith("o stands on floor of bin, its centre of mass ")


def test_what_lies_farther_than_the_tolerance_does_not_support() -> None:
    cube = Box(0.1, 0.1, 0.1)
    bodies = {"o1": (cube, translation(0, 0, 0.05))}
    assert stability("o2", cube, translation(0, 0, 0.15 + SUPPORT_TOL * 0.99), bodies).stable
    far = stability("o2", cube, translation(0, 0, 0.15 + SUPPORT_TOL * 1.01), bodies)
    assert not far.stable and far.supporters == () and far.margin == -math.inf and far.polygon == ()
    assert far.message() == "o2 rests on nothing: nothing lies within 10 mm under its lowest face"
    beside = stability("o2", cube, translation(0.1, 0, 0.05), bodies)  # touching o1's side, not its top
    assert beside.supporters == ()


# ------------------------------------------------------------------------------------- tilted poses
@PROPERTY
@given(rpy=st.tuples(yaws, yaws, yaws), z=st.floats(0.0, 0.3), shape=st.sampled_from(["box", "cylinder", "sphere"]))
def test_a_tilted_pose_gets_a_verdict(rpy: tuple[float, float, float], z: float, shape: str) -> None:
    """Any rotation of the object, and of a box under it: a verdict, consistent with itself."""
    obj = {"box": Box(0.2, 0.1, 0.3), "cylinder": Cylinder(0.05, 0.2), "sphere": Sphere(0.1)}[shape]
    pose = from_xyz_rpy((0.0, 0.0, z), rpy)
    under = from_xyz_rpy((0.02, -0.01, lowest(obj, pose) - 0.1), (rpy[1], rpy[2], rpy[0]))
    bodies = {"table": (Box(1, 1, 0.1), translation(0, 0, -0.05)), "tilted": (Box(0.15, 0.1, 0.12), under)}
    s = stability("o", obj, pose, bodies, [("r", Box(2, 2, 1), translation(0, 0, 0.5))])
    assert s.flat == (shape == "sphere" or s.tilt <= FLAT_TOL)
    if not s.flat or not s.supporters:
        assert not s.stable
    if not s.supporters:
        assert s.margin == -math.inf and s.polygon == ()
    assert s.message().startswith(("o ", "o would"))


def test_a_box_tilted_on_its_edge_is_not_flat() -> None:
    pose = translation(0, -0.15, 0) @ from_xyz_rpy((0, 0, 0), (math.radians(3), 0, 0)) @ translation(0, 0.15, 0.15)
    s = stability("b", Box(0.3, 0.3, 0.3), pose, {}, [("goal", Box(1, 1, 0.5), translation(0, 0, 0.25))])
    assert not s.flat and not s.stable and s.supporters == ("floor of goal",)
    assert len(s.polygon) == 2  # it touches the floor on its edge
    assert s.message() == (
        "b is set down tilted 3.0 degrees from upright on floor of goal: it touches them on an edge or a corner, "
        "not flat on its lowest face (tolerance 0.01 rad)"
    )


# ------------------------------------------------------------------------------------- other shapes
@PROPERTY
@given(r=st.floats(0.01, 0.5), shift=st.floats(0.0, 1.0), yaw=yaws)
def test_a_cylinder_rests_on_its_disc(r: float, shift: float, yaw: float) -> None:
    """The disc is a regular polygon inscribed in it: its edge lies r cos(pi / n) from the centre."""
    inscribed = r * math.cos(math.pi / CIRCLE_POINTS)
    top = stability("c", Cylinder(r, 0.2), rot_z(yaw) @ translation(0, 0, 0.4), {"s": (Box(2, 2, 0.6), np.eye(4))})
    assert top.stable and top.margin == pytest.approx(inscribed, abs=1e-9)
    assert top.required == pytest.approx(min(MARGIN, MARGIN_SHARE * 2 * r))
    # on a 2 m box whose edge is at x = 1: the margin is 1 - x once the edge cuts the disc's polygon
    x = 1 - r + shift * 2 * r * 0.999
    s = stability("c", Cylinder(r, 0.2), translation(x, 0, 0.4), {"s": (Box(2, 2, 0.6), np.eye(4))})
    assert s.margin == pytest.approx(min(1 - x, inscribed), abs=1e-9)
    assert s.stable == (min(1 - x, inscribed) >= s.required) or abs(min(1 - x, inscribed) - s.required) < 1e-9


def test_spheres_touch_at_a_point() -> None:
    table = {"t": (Box(1, 1, 0.1), translation(0, 0, 0.05))}
    ball = stability("ball", Sphere(0.05), translation(0.3, 0.1, 0.151), table)
    assert ball.stable and ball.polygon == ((0.3, 0.1),) and ball.required == 0.0 and ball.margin == 0.0
    off = stability("ball", Sphere(0.05), translation(0.52, 0, 0.151), table)  # its lowest point is off the top
    assert not off.stable and off.supporters == ()
    on_ball = stability(
        "o", Box(0.1, 0.1, 0.1), translation(0, 0, 0.15), {"ball": (Sphere(0.05), translation(0, 0, 0.05))}
    )
    assert not on_ball.stable and on_ball.supporters == ("ball",) and on_ball.polygon == ((0.0, 0.0),)
    assert "lies on the edge of the support polygon of its contacts with ball" in on_ball.message()


@PROPERTY
@given(r=st.floats(0.005, 0.3), x=st.floats(-0.49, 0.49), y=st.floats(-0.49, 0.49), lift=st.floats(0, 0.009))
@example(r=0.025, x=-0.2000000000003, y=0.0, lift=0.0)  # the contact point rounded, the centre not: -3e-13 m
def test_a_ball_on_a_top_is_stable_wherever_it_touches(r: float, x: float, y: float, lift: float) -> None:
    """A ball's centre is above its contact point (neutral equilibrium, required margin 0): the margin is 0
    up to rounding, which must not make every ball placement "topple" (it did, 3e-13 m "outside")."""
    table = {"t": (Box(1, 1, 0.1), translation(0, 0, 0.05))}
    ball = stability("ball", Sphere(r), translation(x, y, 0.1 + lift + r), table)
    assert ball.stable and ball.supporters == ("t",) and abs(ball.margin) < 1e-9


def _write_obj(path: Path, vertices: list[tuple[float, float, float]], faces: list[tuple[int, ...]]) -> str:
    lines = [f"v {x} {y} {z}" for x, y, z in vertices] + ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


def _revolved(path: Path, profile: list[tuple[float, float]], n: int = 48) -> Mesh:
    """A closed surface of revolution about z: ``profile`` (radius, z) from the bottom up, its ends on the axis
    (radius 0), centred on its bounding box's centre."""
    zs = [z for _, z in profile]
    mid = (min(zs) + max(zs)) / 2
    verts: list[tuple[float, float, float]] = []
    rings: list[list[int]] = []
    for r, z in profile:
        if r == 0.0:
            verts.append((0.0, 0.0, z - mid))
            rings.append([len(verts) - 1] * n)
            continue
        rings.append(list(range(len(verts), len(verts) + n)))
        verts += [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), z - mid) for k in range(n)]
    faces = []
    for lo, hi in zip(rings, rings[1:]):
        for k in range(n):
            a, b, c, d = lo[k], lo[(k + 1) % n], hi[(k + 1) % n], hi[k]
            faces += [t for t in ((a, b, c), (a, c, d)) if len(set(t)) == 3]
    return Mesh(_write_obj(path, verts, faces))


@pytest.mark.parametrize(("tall", "rolls"), [(0.17, True), (0.03, True), (0.002, False)])
def test_a_mesh_on_a_rounded_bottom_rolls_over_when_its_centre_of_mass_is_high(
    tmp_path: Path, tall: float, rolls: bool
) -> None:
    """A 12 mm hemispherical bottom under a 17 cm tube (a test tube on its round end) rolls over, whatever the
    1 mm lowest face says (a 4.9 mm disc, the centre of mass 1.2 mm inside it was "stable", and pybullet's
    tube fell flat from a 0.002 rad tilt), and so does a 3 cm one; under a 2 mm one (a bowl's shape) the centre
    of mass is below the hemisphere's centre, and it rights itself."""
    r = 0.012
    bottom = [(r * math.sin(a), r - r * math.cos(a)) for a in np.linspace(0.0, math.pi / 2, 13)]
    tube = _revolved(tmp_path / "tube.obj", [*bottom, (r, r + tall), (0.0, r + tall)])
    half = (r + tall) / 2
    table = {"t": (Box(1, 1, 0.1), translation(0, 0, 0.05))}
    s = stability("tube", tube, translation(0.2, 0.1, 0.1 + half), table)
    assert s.flat and s.supporters == ("t",) and s.stable != rolls
    assert (s.rolls is not None) == rolls
    if rolls:
        assert "would roll over on t: tilted toward" in s.message()
    # a flat-bottomed mesh of the same size stands, and tilts back onto its bottom's edge every way
    can = _revolved(tmp_path / "can.obj", [(0.0, 0.0), (r, 0.0), (r, r + tall), (0.0, r + tall)])
    flat = stability("can", can, translation(0.2, 0.1, 0.1 + half), table)
    assert flat.stable and flat.rolls is None


def test_a_mesh_stands_on_its_lowest_vertices_with_its_volume_centroid(tmp_path: Path) -> None:
    """A wedge (a right triangle 0.3 long and 0.2 high, 0.1 deep, outward faces): its centroid lies a third
    of the way along, not in the middle of its bounding box."""
    v = [(0, -0.05, 0), (0.3, -0.05, 0), (0, -0.05, 0.2), (0, 0.05, 0), (0.3, 0.05, 0), (0, 0.05, 0.2)]
    faces = [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (0, 3, 5, 2), (1, 2, 5, 4)]
    wedge = Mesh(_write_obj(tmp_path / "wedge.obj", [tuple(map(float, p)) for p in v], faces))
    s = stability("w", wedge, translation(1, 2, 0.3), {"t": (Box(2, 2, 0.3), translation(1, 2, 0.15))})
    assert s.stable and s.com == pytest.approx((1.1, 2.0))
    assert s.margin == pytest.approx(0.05) and s.required == pytest.approx(min(MARGIN, MARGIN_SHARE * 0.1))
    # its thin end over the table's edge at x = 2: the centroid at x = 2.05 is past it
    over = stability("w", wedge, translation(1.95, 2, 0.3), {"t": (Box(2, 2, 0.3), translation(1, 2, 0.15))})
    assert not over.stable and over.margin == pytest.approx(-0.05)


# ------------------------------------------------------------------------------------- carts (unit)
def test_a_cart_sets_its_box_down_upright_on_its_floor() -> None:
    box = Box(0.3, 0.3, 0.3)
    for lift in (0.0, 0.001, 0.006, SUPPORT_TOL * 0.99):
        assert cart_set_down("b", box, translation(1, 0, 0.15 + lift), "r1", 0.01, 1e-3) == []
    tilted = from_xyz_rpy((1, 0, 0.16), (math.radians(3), 0, 0))
    assert lowest(box, tilted) == pytest.approx(0.16 - 0.15 * (math.cos(math.radians(3)) + math.sin(math.radians(3))))
    (tilt,) = [m for m in cart_set_down("b", box, tilted, "r1", 0.01, 1e-3) if "tilted" in m]
    assert tilt == (
        "r1 sets b down tilted 3.0 degrees (0.052 rad) from upright; it carries it upright and lowers it so onto "
        "the floor (tolerance 0.01 rad)"
    )
    assert cart_set_down("b", box, translation(1, 0, 0.171), "r1", 0.01, 1e-3) == [
        "r1 sets b down with its lowest point 21.0 mm above the floor it drives on (z = 0); a cart lowers what it "
        "carries onto that floor: 0 to 10 mm above it (tolerance 1 mm below)"
    ]
    assert "19.0 mm below the floor" in cart_set_down("b", box, translation(1, 0, 0.131), "r1", 0.01, 1e-3)[0]
    assert lowest(Cylinder(0.1, 0.4), from_xyz_rpy((0, 0, 1), (math.pi / 2, 0, 0))) == pytest.approx(0.9)


# ------------------------------------------------------------------------------------- carts (mrgc validate)
@pytest.fixture
def room(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Any, dict[str, Any]]:
    """r1 drives to box b's -x side, carries it east into the goal region (placed at z = 0.151, 1 mm up)."""
    return vp.room(str(tmp_path_factory.getbasetemp()))


def _validate(
    tmp_path: Path, path: str, plan: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> tuple[int, list[str]]:
    file = tmp_path / "doctored.json"
    file.write_text(json.dumps(plan), encoding="utf-8")
    code, out, _ = run_cli(capsys, "validate", path, file)
    return code, out.splitlines()


def _place(plan: dict[str, Any], change: np.ndarray) -> dict[str, Any]:
    """``plan`` with its place pose P replaced by ``change`` @ P (a world-frame change)."""
    out = copy.deepcopy(plan)
    a = vp.action(out, 1)
    a["place_pose"] = vp.rows(change @ np.array(a["place_pose"]))
    return out


def test_a_cart_placement_tilted_on_its_edge_is_rejected(
    room: tuple[str, Any, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _, plan = room
    assert _validate(tmp_path, path, plan, capsys)[0] == 0
    # 3 degrees about x, standing on its lower -y edge 1 mm above the floor, its centre where it was (so r1's
    # base pose still matches it): inside the goal region and resting; only the tilt is wrong
    c, s = math.cos(math.radians(3)), math.sin(math.radians(3))
    centre = np.array([1.7, 0.0, 0.151])
    turn = from_xyz_rpy((0, 0, 0), (math.radians(3), 0, 0))
    tilt = translation(0, 0, 0.15 * (c + s) - 0.15) @ translation(*centre) @ turn @ translation(*-centre)
    code, lines = _validate(tmp_path, path, _place(plan, tilt), capsys)
    assert code == 1 and lines[-1].startswith("invalid: ")
    tilted = (
        "step 1: r1: r1 sets b down tilted 3.0 degrees (0.052 rad) from upright; it carries it upright and lowers "
        "it so onto the floor (tolerance 0.01 rad) [placement]"
    )
    assert tilted in lines, lines
    assert all(x == tilted or x.endswith("[unstable]") for x in lines[:-1]), lines  # the replay's stability may too
    # about its centre, as a plan might write it: the corner dips below the floor, reported too
    about_centre = translation(*centre) @ turn @ translation(*-centre)
    code, lines = _validate(tmp_path, path, _place(plan, about_centre), capsys)
    assert code == 1 and any("tilted 3.0 degrees" in x and x.endswith("[placement]") for x in lines), lines


@pytest.mark.parametrize(("dz", "where"), [(0.02, "21.0 mm above"), (-0.02, "19.0 mm below")])
def test_a_cart_placement_off_the_floor_is_rejected(
    room: tuple[str, Any, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str], dz: float, where: str
) -> None:
    path, _, plan = room
    code, lines = _validate(tmp_path, path, _place(plan, translation(0, 0, dz)), capsys)
    assert code == 1 and lines[-1].startswith("invalid: ")
    assert (
        f"step 1: r1: r1 sets b down with its lowest point {where} the floor it drives on (z = 0); a cart lowers "
        "what it carries onto that floor: 0 to 10 mm above it (tolerance 1 mm below) [placement]"
    ) in lines


def test_a_cart_placement_as_the_planner_writes_it_is_valid(
    room: tuple[str, Any, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The planner's grounding sets boxes down 6 mm up (ARM_PLACE_LIFT), the planar model 1 mm: both rest."""
    path, _, plan = room
    assert _validate(tmp_path, path, _place(plan, translation(0, 0, 0.005)), capsys)[0] == 0


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(st.integers(-3, 3), st.integers(-3, 3)), max_size=16))
def test_distinct_rows_are_numpys_unique_rows(points: list[tuple[int, int]]) -> None:
    """The support polygon's points, deduplicated and sorted by x then y without numpy.ma: what
    ``np.unique(axis=0)`` gives, zeros of either sign one point."""
    from mrgc.validator.stability import _distinct_rows

    pts = np.array(points, dtype=float).reshape(-1, 2) * 0.5
    pts[pts == 0.0] = np.where(np.arange((pts == 0.0).sum()) % 2, -0.0, 0.0)
    assert np.array_equal(_distinct_rows(pts), np.unique(pts, axis=0).reshape(-1, 2))
