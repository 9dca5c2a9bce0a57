"""CollisionWorld on coal: known answers for primitives and hulls, queries by group/name, probes, sweeps."""

from __future__ import annotations

import itertools
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc import parse_file
from mrgc.errors import InputError
from mrgc.geometry.arm import Arm
from mrgc.geometry.collision import TOLERANCE, CollisionWorld, ConvexHull, collision_shape
from mrgc.geometry.ik import solve_ik_many
from mrgc.geometry.scene import SceneSpec, scene_from_problem
from mrgc.geometry.transforms import rot_z, rpy_matrix, translation
from mrgc.language.model import Box, Cylinder, Mesh, Sphere
from mrgc.validator.world import ReplayScene


def at(x: float, y: float = 0.0, z: float = 0.0, yaw: float = 0.0) -> np.ndarray:
    t = rot_z(yaw)
    t[:3, 3] = (x, y, z)
    return t


def pair(a, ta, b, tb) -> bool:
    w = CollisionWorld()
    w.add("a", a, ta)
    w.add("b", b, tb)
    return w.collides("a")


CUBE_POINTS = np.array(list(itertools.product([-0.5, 0.5], repeat=3)))
#: the unit cube's twelve triangles, two a side, as an OBJ file lists them (1-based indices into CUBE_POINTS)
CUBE_FACES = [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2)]
CUBE_FACES += [(3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4)]


# --------------------------------------------------------------------------------------- pairs


@pytest.mark.parametrize("x, expected", [(0.0, True), (0.5, True), (0.99, True), (1.01, False), (3.0, False)])
def test_two_unit_boxes(x: float, expected: bool) -> None:
    assert pair(Box(1, 1, 1), at(0), Box(1, 1, 1), at(x)) is expected


def test_box_side_lengths_are_full_lengths() -> None:
    # a 2 × 0.2 × 0.2 bar reaches x = ±1
    assert pair(Box(2, 0.2, 0.2), at(0), Sphere(0.1), at(1.05))
    assert not pair(Box(2, 0.2, 0.2), at(0), Sphere(0.1), at(1.15))


def test_yaw_rotation() -> None:
    bar = Box(2.0, 0.2, 0.2)
    probe = Box(0.2, 0.2, 0.2)
    # probe at (0, 0.9): misses the bar along x, hits it when the bar is turned 90° about z
    assert not pair(bar, at(0), probe, at(0, 0.9))
    assert pair(bar, at(0, yaw=math.pi / 2), probe, at(0, 0.9))
    # a unit cube turned 45° reaches sqrt(2)/2 ≈ 0.707 along x
    assert pair(Box(1, 1, 1), at(0, yaw=math.pi / 4), Box(1, 1, 1), at(1.2, 0.0))
    assert not pair(Box(1, 1, 1), at(0, yaw=math.pi / 4), Box(1, 1, 1), at(1.25, 0.0))


def test_cylinder_axis_is_local_z() -> None:
    cyl = Cylinder(radius=0.1, height=1.0)  # reaches z = ±0.5, radius 0.1
    small = Box(0.1, 0.1, 0.1)
    assert pair(cyl, at(0), small, at(0, 0, 0.52))
    assert not pair(cyl, at(0), small, at(0, 0, 0.56))
    assert pair(cyl, at(0), small, at(0.14, 0, 0))
    assert not pair(cyl, at(0), small, at(0.16, 0, 0))
    # round: a box corner near the diagonal misses where the bounding square would hit
    assert not pair(cyl, at(0), Box(0.01, 0.01, 0.01), at(0.08, 0.08, 0))  # corner 0.106 from the axis


def test_sphere() -> None:
    assert pair(Sphere(0.5), at(0), Sphere(0.5), at(0.99))
    assert not pair(Sphere(0.5), at(0), Sphere(0.5), at(1.01))
    assert pair(Sphere(0.2), at(0), Box(1, 1, 1), at(0.65))
    assert not pair(Sphere(0.2), at(0), Box(1, 1, 1), at(0.75))
    # the box's corner region: an AABB test would say yes, the sphere says no
    assert not pair(Sphere(0.2), at(0), Box(1, 1, 1), at(0.65, 0.65, 0.65))  # corner 0.26 away


def test_touching_counts_as_collision_and_clearance_does_not() -> None:
    assert pair(Box(1, 1, 1), at(0), Box(1, 1, 1), at(0, 0, 1.0))
    assert not pair(Box(1, 1, 1), at(0), Box(1, 1, 1), at(0, 0, 1.001))


@pytest.mark.parametrize("x", [0.0, 0.3, 0.5, 0.9, 0.99, 1.01, 1.2, 2.0])
@pytest.mark.parametrize("yaw", [0.0, math.pi / 2, math.pi / 4])
def test_hull_of_cube_vertices_behaves_like_the_box(x: float, yaw: float) -> None:
    hull = ConvexHull(CUBE_POINTS)
    for other, t in [(Box(1, 1, 1), at(x, yaw=yaw)), (Sphere(0.5), at(x, 0.2)), (Box(0.4, 2, 0.4), at(x))]:
        assert pair(hull, at(0), other, t) == pair(Box(1, 1, 1), at(0), other, t), (other, x, yaw)
    assert collision_shape(hull).half.tolist() == [0.5, 0.5, 0.5]


def test_hull_of_random_points_contains_them() -> None:
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(50, 3)) * 0.2
    w = CollisionWorld()
    w.add("h", ConvexHull(pts), at(1, 2, 3))
    tiny = collision_shape(Sphere(1e-4))
    for p in pts:  # every input point is inside (or on) the hull
        assert w.probe_collides([(tiny, at(1 + p[0], 2 + p[1], 3 + p[2]))])
    assert not w.probe_collides([(tiny, at(1 + 0.2 * 10, 2, 3))])


def test_degenerate_clouds_become_thin_hulls() -> None:
    flat = ConvexHull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float))
    assert 0 < collision_shape(flat).half[2] < 2e-5
    assert pair(flat, at(0), Sphere(0.01), at(0.5, 0.5, 0.005))
    assert not pair(flat, at(0), Sphere(0.01), at(0.5, 0.5, 0.02))
    point = collision_shape(ConvexHull(np.zeros((1, 3))))
    assert np.all(point.half <= 2e-6)
    with pytest.raises(ValueError):
        collision_shape(ConvexHull(np.array([[0.0, 0.0, np.nan]] * 4)))


NEARLY_FLAT = """
import numpy as np
from mrgc.geometry.collision import ConvexHull, collision_shape
rng = np.random.default_rng(0)
for thickness, size in [(2e-8, 1), (1e-7, 10), (1e-6, 100), (0, 1), (1e-12, 1000)]:
    for offset in (0.0, 3.0 * size):
        pts = rng.uniform(-1, 1, (50, 3)) * size
        pts[:, 2] *= thickness / size
        pts[:, 0] += offset
        assert collision_shape(ConvexHull(pts)).coal_geometry.num_points >= 4
line = np.zeros((20, 3)); line[:, 0] = np.linspace(-1, 1, 20)
for pts in (line, np.ones((10, 3)), np.eye(3), np.array([[0.0, 0, 0], [1, 1, 1]])):
    collision_shape(ConvexHull(pts))
print("ok")
"""


def test_nearly_flat_clouds_do_not_crash_qhull() -> None:
    """coal's qhull segfaults on clouds flatter than ~3e-8 of their size: run in a child process."""
    out = subprocess.run([sys.executable, "-c", NEARLY_FLAT], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "ok", (out.returncode, out.stderr[-2000:])


def test_mesh_file(tmp_path: Path) -> None:
    corners = list(itertools.product([-0.5, 0.5], repeat=3))
    faces = CUBE_FACES
    obj = tmp_path / "cube.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in corners] + [f"f {a} {b} {c}" for a, b, c in faces]
    obj.write_text("\n".join(lines) + "\n")
    mesh = Mesh(str(obj), scale=2.0)  # a 2 m cube
    assert collision_shape(mesh).half.tolist() == [1.0, 1.0, 1.0]
    assert pair(mesh, at(0), Box(0.2, 0.2, 0.2), at(1.05))
    assert not pair(mesh, at(0), Box(0.2, 0.2, 0.2), at(1.15))
    hull = ConvexHull.of_mesh(mesh)
    assert pair(hull, at(0), Box(0.2, 0.2, 0.2), at(0, 0, 0))  # a hull is solid, a mesh is a surface
    assert not pair(hull, at(0), Box(0.2, 0.2, 0.2), at(1.15))
    with pytest.raises(InputError) as err:
        collision_shape(Mesh(str(tmp_path / "missing.obj")))
    assert err.value.diagnostics[0].code == "E258"


# ----------------------------------------------------------------------------- world queries


def scene() -> CollisionWorld:
    """A table, three objects on a row, one far away, and a robot link."""
    w = CollisionWorld()
    w.add("table", Box(2, 1, 0.1), at(0, 0, -0.05), "fixed")
    for i, x in enumerate([-0.6, 0.0, 0.6]):
        w.add(f"o{i + 1}", Box(0.1, 0.1, 0.2), at(x, 0, 0.101), "movable")
    w.add("far", Sphere(0.1), at(5, 5, 5), "movable")
    w.add("link", Cylinder(0.05, 0.4), at(2, 0, 0.5), "robot:r1")
    return w


def test_colliding_with_names_exactly_the_hit_objects() -> None:
    w = scene()
    assert w.colliding_with("o1") == set()  # 1 mm above the table, far from the others
    w.add("bar", Box(1.3, 0.05, 0.05), at(0.3, 0, 0.15), "movable")  # through o2 and o3, not o1
    assert w.colliding_with("bar") == {"o2", "o3"}
    assert w.colliding_with("bar", against="fixed") == set()
    w.set_transform("bar", at(0.3, 0, 0.0))  # now also through the table
    assert w.colliding_with("bar") == {"o2", "o3", "table"}
    assert w.colliding_with("bar", ignore={"o3", "fixed"}) == {"o2"}
    assert w.colliding_with("bar", against=["o1", "o2"]) == {"o2"}
    assert w.collides("bar") and not w.collides("bar", against=["o1", "far"])
    # several query objects act as one body: the union of their hits, never each other
    assert w.colliding_with(["bar", "o2"]) == {"o3", "table"}


def test_set_transform_moves_objects() -> None:
    w = scene()
    assert not w.collides("link")
    w.set_transform("link", at(0.6, 0, 0.3))  # down onto o3
    assert w.colliding_with("link") == {"o3"}
    assert np.allclose(w.transform("link"), at(0.6, 0, 0.3))
    w.set_transform("link", at(2, 0, 0.5))
    assert not w.collides("link")


def test_add_and_remove() -> None:
    w = scene()
    w.add("lid", Box(0.2, 0.2, 0.02), at(0, 0, 0.21), "movable")
    assert w.colliding_with("lid") == {"o2"}
    w.remove("o2")
    assert "o2" not in w and w.colliding_with("lid") == set()
    assert w.names("movable") == ["o1", "o3", "far", "lid"]
    with pytest.raises(ValueError):
        w.add("o1", Sphere(1), at(0))
    with pytest.raises(ValueError):
        w.add("movable", Sphere(1), at(0))
    with pytest.raises(KeyError):
        w.collides("nope")


def test_groups_and_ignore() -> None:
    w = scene()
    w.set_transform("link", at(0, 0, 0.1))  # through the table and o2
    assert w.colliding_with("link") == {"table", "o2"}
    assert w.colliding_with("link", against="movable") == {"o2"}
    assert w.colliding_with("link", against=("fixed", "movable"), ignore="table") == {"o2"}
    assert not w.collides("link", ignore=["fixed", "movable"])
    assert w.colliding_with("o2", against="robot:r1") == {"link"}
    assert w.colliding_with("link", against="no-such-group") == set()


def test_distance() -> None:
    w = scene()
    assert w.distance("o1", "o2") == pytest.approx(0.5, abs=1e-6)
    assert w.distance("o1", "table") == pytest.approx(0.001, abs=1e-6)
    w.set_transform("o2", at(-0.55, 0, 0.101))
    assert w.distance("o1", "o2") == pytest.approx(-0.05, abs=1e-6)


# ------------------------------------------------------------------------------------ probes


def test_probe_reports_hits_and_leaves_the_world_alone() -> None:
    w = scene()
    before = {n: w.transform(n) for n in w.names()}
    hull = collision_shape(ConvexHull(CUBE_POINTS * 0.2))  # a 0.2 m cube
    probe = [(hull, at(0.0, 0, 0.1)), (collision_shape(Sphere(0.05)), at(0.6, 0, 0.25))]
    assert w.probe_hits(probe) == {"o2", "o3", "table"}
    assert w.probe_hits(probe, against="movable", ignore="o3") == {"o2"}
    assert w.probe_collides(probe)
    assert not w.probe_collides(probe, against=["o1", "far"])
    assert not w.probe_collides([(hull, at(0, 0, 1.0))])
    assert w.probe_hits([]) == set()
    # the probe did not add anything or move anything
    assert len(w) == len(before) and all(np.array_equal(w.transform(n), t) for n, t in before.items())
    assert w.colliding_with("o2") == set()
    # geometries are accepted directly, too
    assert w.probe_hits([(Box(0.1, 0.1, 0.1), at(-0.6, 0, 0.04))]) == {"o1", "table"}


def test_same_shape_handle_in_many_places() -> None:
    w = scene()
    ball = collision_shape(Sphere(0.06))
    probe = [(ball, at(x, 0, 0.25)) for x in (-0.6, 0.0, 0.6)]
    assert w.probe_hits(probe) == {"o1", "o2", "o3"}


def test_sweep_is_the_union_of_its_probes() -> None:
    w = scene()
    link = collision_shape(Cylinder(0.03, 0.3))
    # a vertical link moving along x above the row, dipping into o2 only mid-way
    xs = np.linspace(-0.6, 0.6, 25)
    probes = [[(link, at(x, 0, 0.2 + 0.2 * abs(x) / 0.6 + 0.15))] for x in xs]
    assert w.sweep_hits(probes) == {"o2"}
    assert w.sweep_hits(probes) == set().union(*(w.probe_hits(p) for p in probes))
    # the batched form: (C configurations, L links, 4, 4)
    transforms = np.stack([[t for _, t in p] for p in probes])
    assert w.batch_hits([link], transforms) == {"o2"}
    assert w.batch_collides([link], transforms)
    assert not w.batch_collides([link], transforms, ignore="o2")
    with pytest.raises(ValueError):
        w.batch_hits([link, link], transforms)


# ------------------------------------------------------------------ agreement with an exact test

sizes = st.tuples(*[st.integers(1, 10)] * 3)
centres = st.tuples(*[st.integers(-12, 12)] * 3)


@settings(max_examples=300, deadline=None)
@given(sizes, centres, sizes, centres, st.booleans(), st.sampled_from(["box", "hull"]))
def test_axis_aligned_boxes_agree_with_the_exact_test(sa, ca, sb, cb, quarter_turn, kind) -> None:
    """Sizes and centres on a 5 cm grid (so faces often line up exactly, the hard case for GJK)."""
    a = np.array(sa) * 0.05
    b = np.array(sb) * 0.05
    pa = np.array(ca) * 0.025
    pb = np.array(cb) * 0.025
    extent_b = b[[1, 0, 2]] if quarter_turn else b
    gap = np.abs(pa - pb) - (a + extent_b) / 2
    if np.any(np.abs(gap) < 1e-9):
        return  # exactly touching: coal says yes, but floating point decides; not a fair question
    exact = bool(np.all(gap < 0))
    shape_b = Box(*b) if kind == "box" else ConvexHull(CUBE_POINTS * b)
    w = CollisionWorld()
    w.add("a", Box(*a), at(*pa))
    w.add("b", shape_b, at(*pb, yaw=math.pi / 2 if quarter_turn else 0.0))
    assert w.collides("a") is exact
    assert w.collides("b") is exact
    assert w.probe_collides([(Box(*a), at(*pa))], against="b") is exact
    assert w.colliding_with("a") == ({"b"} if exact else set())
    assert w.colliding_with("b") == ({"a"} if exact else set())
    assert w.probe_hits([(Box(*a), at(*pa))], ignore="a") == ({"b"} if exact else set())


# ------------------------------------------------- near contact: yes/no, coal's distance and pybullet agree
#
# Three answers to "do these two shapes overlap?": the yes/no query (GJK against the security margin), coal's
# signed distance (GJK + EPA) and pybullet's getClosestPoints (bullet's own GJK/EPA, through the validator's
# ReplayScene).  Outside a band of BAND around contact all three must agree: no "free" for an overlap deeper
# than BAND, no "collides" for a gap wider than BAND + TOLERANCE.  pybullet gets boxes as 8-vertex meshes:
# its GEOM_BOX rounds edges and corners by its collision margin (1 mm), which moves its distances near
# edges by up to 1.1 mm (measured), while ReplayScene removes the margin of a mesh exactly (measured
# agreement with coal on meshes: 0.05 mm at most).

BAND = 1e-4  # metres
ANGLES = st.one_of(
    st.sampled_from([0.0, math.pi / 2, math.pi, -math.pi / 2, math.pi / 4]), st.floats(-math.pi, math.pi)
)


def rotation(rpy: tuple[float, float, float]) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = rpy_matrix(*rpy)
    return t


def agree(name: str, collides: bool, d_coal: float, d_bullet: float | None = None) -> None:
    """The yes/no answer, coal's signed distance and pybullet's distance tell the same story."""
    if d_coal < -BAND:
        assert collides, f"{name}: overlap of {-d_coal * 1e3:.3f} mm reported free"
    if d_coal > BAND + TOLERANCE:
        assert not collides, f"{name}: gap of {d_coal * 1e3:.3f} mm reported colliding"
    if d_bullet is not None and abs(d_coal) > BAND:
        assert (d_bullet < 0) == (d_coal < 0), f"{name}: coal {d_coal * 1e3:.3f} mm, pybullet {d_bullet * 1e3:.3f} mm"


class MeshFiles:
    """Convex shapes for both engines: coal gets the Box or ConvexHull, pybullet a mesh file of its vertices."""

    def __init__(self, folder: Path) -> None:
        self.folder, self.count = folder, 0

    def write(self, points: np.ndarray, faces: list[tuple[int, int, int]]) -> Mesh:
        self.count += 1  # pybullet caches meshes by file name: one file per shape
        path = self.folder / f"shape{self.count}.obj"
        lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in points]
        path.write_text("\n".join(lines + [f"f {a} {b} {c}" for a, b, c in faces]) + "\n")
        return Mesh(str(path))

    def box(self, size: np.ndarray) -> tuple[Box, Mesh, np.ndarray]:
        corners = CUBE_POINTS * size
        faces = CUBE_FACES
        return Box(*size), self.write(corners, faces), corners

    def hull(self, seed: int, axes: np.ndarray) -> tuple[ConvexHull, Mesh, np.ndarray]:
        pts = np.random.default_rng(seed).normal(size=(40, 3))
        pts = pts / np.linalg.norm(pts, axis=1, keepdims=True) * axes  # every point on the hull
        # pybullet takes the convex hull of the vertices the faces use: a fan through all of them will do
        return ConvexHull(pts), self.write(pts, [(1, i, i + 1) for i in range(2, len(pts))]), pts


@pytest.fixture(scope="module")
def bullet(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    replay = ReplayScene(SceneSpec("near-contact", (), (), (), (), {}, {}, {}, {}))
    yield replay, MeshFiles(tmp_path_factory.mktemp("near-contact"))
    replay.close()


sides = st.tuples(*[st.integers(5, 300)] * 3).map(lambda mm: np.array(mm) / 1000)
hull_axes = st.tuples(*[st.integers(10, 150)] * 3).map(lambda mm: np.array(mm) / 1000)


@settings(max_examples=300, deadline=None)
@given(
    st.sampled_from(["box-box", "hull-box", "hull-hull", "same-hull"]),
    sides,
    sides,
    hull_axes,
    st.integers(0, 2**16),
    st.tuples(ANGLES, ANGLES, ANGLES),
    st.tuples(ANGLES, ANGLES, ANGLES),
    st.tuples(ANGLES, ANGLES),
    st.floats(-0.02, 0.02),
)
def test_near_contact_pairs_agree(  # type: ignore[no-untyped-def]
    bullet,
    kind: str,
    size_a,
    size_b,
    axes,
    seed: int,
    rpy_a,
    rpy_b,
    direction,
    s: float,
) -> None:
    """Two convex shapes placed so that their extents along a direction ``u`` overlap by ``-s`` (gap ``s``
    along u, |s| <= 20 mm): a near-contact pose, often with faces lined up (angles of 0, 90°, 45°).
    "same-hull" is one hull against a copy of itself, turned (or not), the hard case for GJK."""
    replay, files = bullet
    a = files.hull(seed, axes) if kind != "box-box" else files.box(size_a)
    b = (
        files.box(size_b)
        if kind in ("box-box", "hull-box")
        else files.hull(seed if kind == "same-hull" else seed + 1, axes)
    )
    ta, tb = rotation(rpy_a), rotation(rpy_b)
    u = rpy_matrix(0.0, direction[0], direction[1])[:, 0]
    reach_a = max((ta[:3, :3] @ a[2].T).T @ u)
    reach_b = max(-(tb[:3, :3] @ b[2].T).T @ u)
    tb[:3, 3] = (reach_a + reach_b + s) * u
    world = CollisionWorld()
    world.add("a", a[0], ta)
    world.add("b", b[0], tb)
    d = world.distance("a", "b")
    name = f"n{files.count}"
    replay.add_object(name + "a", a[1], ta)
    replay.add_object(name + "b", b[1], tb)
    try:
        near = replay.closest(name + "a", name + "b", 0.1)
    finally:
        replay.set_pose(name + "a", None)
        replay.set_pose(name + "b", None)
    agree(kind, world.collides("a"), d, near.distance if near is not None else 0.1)
    agree(kind + " (probe)", world.probe_collides([(a[0], ta)], against="b"), d)


# Two Pandas facing each other across a table (pa3-handover's r1 and r2), both holding an object at one
# point: each hand takes one of the classic grasps (approach axis, finger axis in the object frame), its tool
# centre point 5 mm short of the object's centre, and the second hand is pushed along its approach axis by
# up to 20 mm.  Fingers then overlap tip to tip or just miss each other.

GRASP_AXES = {
    "top": ((0, 0, -1), (0, 1, 0)),
    "side-x+": ((-1, 0, 0), (0, 1, 0)),
    "side-x-": ((1, 0, 0), (0, 1, 0)),
    "side-y+": ((0, -1, 0), (1, 0, 0)),
    "side-y-": ((0, 1, 0), (1, 0, 0)),
}
GRIPPER_LINKS = ("panda_hand", "panda_leftfinger", "panda_rightfinger")


def hand_pose(grasp: str, standoff: float) -> np.ndarray:
    """The tool pose in the object frame (+z the approach axis, +y the finger axis)."""
    z, y = (np.array(v, dtype=float) for v in GRASP_AXES[grasp])
    t = np.eye(4)
    t[:3, 0], t[:3, 1], t[:3, 2] = np.cross(y, z), y, z
    t[:3, 3] = -z * standoff
    return t


@pytest.fixture(scope="module")
def facing_pandas():  # type: ignore[no-untyped-def]
    scene = scene_from_problem(parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem())
    arms = Arm(scene.robot("r1")), Arm(scene.robot("r2"))
    replay = ReplayScene(scene)
    for body in (*scene.fixed, *scene.movable):
        replay.set_pose(body.name, None)
    yield arms, replay
    replay.close()


@settings(max_examples=150, deadline=None)
@given(
    st.one_of(st.sampled_from([math.radians(d) for d in range(0, 180, 5)]), st.floats(-math.pi, math.pi)),
    st.sampled_from(sorted(GRASP_AXES)),
    st.sampled_from(sorted(GRASP_AXES)),
    st.one_of(st.just(0.0), st.floats(-0.02, 0.02)),
    st.one_of(st.just(0.0), st.floats(-0.1, 0.1)),
    st.one_of(st.just(0.4), st.floats(0.3, 0.5)),
)
@example(math.radians(120), "side-x-", "side-x+", 0.0, 0.0, 0.4)  # fingers overlap 4.4 mm: "free" at 1e-9
@example(math.radians(105), "side-y-", "side-y+", 0.0, 0.0, 0.4)  # the same, along the other axis
@example(math.radians(120), "top", "top", 0.0, 0.0, 0.4)  # both hands in one place: hand pair "free" at 1e-9
def test_panda_grippers_in_handover_poses_agree(  # type: ignore[no-untyped-def]
    facing_pandas,
    yaw: float,
    g1: str,
    g2: str,
    push: float,
    x: float,
    z: float,
) -> None:
    (r1, r2), replay = facing_pandas
    obj = translation(x, 0.0, z) @ rot_z(yaw)
    tools = obj @ hand_pose(g1, 0.005), obj @ hand_pose(g2, 0.005) @ translation(0.0, 0.0, push)
    qs = [solve_ik_many(arm.model, arm.ee_target(t)[None], 0, q_init=arm.home)[0] for arm, t in zip((r1, r2), tools)]
    assume(all(q.solved for q in qs))
    shapes, index = r1.probes
    names = [r1.model.links[i].name for i in index]
    t1, t2 = r1.link_transforms(qs[0].q), r2.link_transforms(qs[1].q)
    # every link pair of the two grippers, one pair at a time
    nearest = math.inf
    for i, j in itertools.product(range(len(shapes)), repeat=2):
        pair_world = CollisionWorld()
        pair_world.add("a", shapes[i], t1[i])
        pair_world.add("b", shapes[j], t2[j])
        d = pair_world.distance("a", "b")
        nearest = min(nearest, d)
        if names[i] in GRIPPER_LINKS and names[j] in GRIPPER_LINKS:
            agree(f"{names[i]} of r1 / {names[j]} of r2", pair_world.collides("a"), d)
    # the whole arms, as phase 1 checks a handover (r1's link hulls probed against r2's), and the validator
    world = CollisionWorld()
    for k, (shape, t) in enumerate(zip(shapes, t2)):
        world.add(f"r2#{k}", shape, t, "r2")
    replay.set_config("r1", qs[0].q)
    replay.set_config("r2", qs[1].q)
    near = replay.closest("r1", "r2", 0.1)
    agree("r1 / r2", world.batch_collides(shapes, t1, against="r2"), nearest, near.distance if near else 0.1)


def _random_pieces(rng: np.random.Generator, n: int, spread: float) -> list[tuple[object, np.ndarray]]:
    shapes = [
        collision_shape(Box(0.05, 0.08, 0.03)),
        collision_shape(Sphere(0.03)),
        collision_shape(ConvexHull(rng.normal(size=(30, 3)) * 0.03)),
    ]
    out = []
    for k in range(n):
        t = np.eye(4)
        t[:3, :3] = rpy_matrix(*rng.uniform(-math.pi, math.pi, 3))[:3, :3]
        t[:3, 3] = rng.uniform(-spread, spread, 3)
        out.append((shapes[k % 3], t))
    return out


def _pairwise(a: list[tuple[object, np.ndarray]], b: list[tuple[object, np.ndarray]]) -> bool:
    """The reference: every pair through a world of one object (coal's own broadphase and narrowphase)."""
    for shape, t in b:
        world = CollisionWorld()
        world.add("x", shape, t)  # type: ignore[arg-type]
        if any(world.probe_collides([p]) for p in a):  # type: ignore[list-item]
            return True
    return False


@pytest.mark.parametrize("n_a, n_b", [(1, 5), (12, 30), (40, 600), (8, 3000), (3000, 8), (200, 1000)])
def test_the_kernel_agrees_with_pairwise_coal(n_a: int, n_b: int) -> None:
    """The kernel's answers (numpy broadphase, direct or grouped, or a few pieces against a large set; a
    yes/no query of two sets direct up to DIRECT_YES_NO pairs (40 x 600), grouped above (200 x 1000); coal's
    narrowphase on the pairs left) are those of testing every pair with coal, on random boxes, spheres and
    hulls near each other."""
    from mrgc.geometry.collision import Posed, overlaps, pieces_collide, posed_collide

    rng = np.random.default_rng(n_a * 1000 + n_b)
    for spread in (0.15, 0.4, 1.0):
        a, b = _random_pieces(rng, n_a, spread), _random_pieces(rng, n_b, spread)
        pa, pb = Posed.of(a), Posed.of(b)  # type: ignore[arg-type]
        i, j = overlaps(pa, pb)
        meet = {(int(x), int(y)) for x, y in zip(i, j)}
        every = np.all(pa.lo[:, None] <= pb.hi[None], axis=2) & np.all(pb.lo[None] <= pa.hi[:, None], axis=2)
        assert meet == {(int(x), int(y)) for x, y in zip(*np.nonzero(every))}  # grouping drops no pair
        expected = _pairwise(a, b)
        assert posed_collide(pa, pb) == expected
        assert pieces_collide(a, b) == expected  # type: ignore[arg-type]
        if n_b <= 30:  # which-objects: the world's numpy path against coal's, object by object
            world = CollisionWorld()
            for k, (shape, t) in enumerate(b):
                world.add(f"b{k}", shape, t)  # type: ignore[arg-type]
            hits = world.probe_hits(pa)
            assert hits == {f"b{k}" for k, piece in enumerate(b) if _pairwise(a, [piece])}
            assert world.probe_collides(pa) == expected == world.probe_collides(a)  # type: ignore[arg-type]


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from([1.5, 2.0]), st.sampled_from([13, 16, 120]))
def test_a_large_set_probed_often_answers_as_before_through_its_tree(seed: int, reach: float, n_probe: int) -> None:
    """A large set probed often enough (more than TREE_AFTER times, and than its size / TREE_AMORTISED) answers
    through coal's broadphase tree (its boxes grown by the tolerance): the same answers as the numpy path (a
    fresh copy of the set, never probed before; that path agrees with pairwise coal: the test above), for
    probes of one configuration (a few pieces, up to GROUP) and of a batch, each a cluster somewhere in the
    set (about half of them collide).  The part of it within a box is the same object when asked again."""
    from mrgc.geometry import collision
    from mrgc.geometry.collision import Posed, posed_collide

    rng = np.random.default_rng(seed)
    large = _random_pieces(rng, collision.DIRECT_PAIRS // 12 + 50, reach)
    reused = Posed.of(large)  # type: ignore[arg-type]
    seen = set()
    for k in range(max(collision.TREE_AFTER, len(large) // collision.TREE_AMORTISED) + 12):
        centre = translation(*rng.uniform(-reach, reach, 3))
        probe = Posed.of([(s, centre @ t) for s, t in _random_pieces(rng, n_probe, 0.1)])  # type: ignore[misc]
        answer = posed_collide(probe, reused)
        assert answer == posed_collide(probe, Posed.of(large)), k  # type: ignore[arg-type]
        seen.add(answer)
    assert reused._tree is not None  # the later probes went through the tree
    lo, hi = np.full(3, -0.3), np.full(3, 0.3)
    part = reused.within(lo, hi)
    assert part is reused.within(lo, hi) and 0 < len(part) < len(reused)
    assert len(seen) == 2 or n_probe == 120  # both answers occur (a batch of 120 pieces mostly collides)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1), st.lists(st.integers(0, 40), min_size=1, max_size=4), st.booleans())
def test_a_packed_set_reads_back_bit_for_bit(seed: int, sizes: list[int], skewed: bool) -> None:
    """A grounded step's volume is kept packed (its transforms' top rows, no boxes): read back, and joined
    with others as a suffix's volume is, it gives the very arrays the unpacked sets give (kinds, transforms
    and the boxes made again from them, bit for bit), so packing changes no answer; a transform whose last
    row is not (0, 0, 0, 1) is kept whole.  It takes less memory than the set it packs."""
    from mrgc.geometry.collision import Packed, Posed

    rng = np.random.default_rng(seed)
    sets = []
    for n in sizes:
        pieces = _random_pieces(rng, n, 1.0)
        if skewed and pieces:
            pieces[0][1][3, :3] = 1e-3  # not affine
        sets.append(Posed.of(pieces))  # type: ignore[arg-type]
    packed = [Packed.of(p) for p in sets]
    for p, k in zip(sets, packed):
        back = k.posed()
        for name in ("kind", "transforms", "lo", "hi"):
            assert np.array_equal(getattr(back, name), getattr(p, name)), name
        assert back.shapes == p.shapes and back.pad == p.pad and len(k) == len(p)
        if len(p) > 1 and not skewed:
            assert k.kind.nbytes + k.rows.nbytes < 0.6 * sum(
                getattr(p, n).nbytes for n in ("kind", "transforms", "lo", "hi")
            )
    joined, again = Posed.join(sets), Posed.join(packed)
    for name in ("kind", "transforms", "lo", "hi"):
        assert np.array_equal(getattr(joined, name), getattr(again, name)), name
    assert [id(s) for s in joined.shapes] == [id(s) for s in again.shapes]


def test_a_small_probe_tests_every_pose_of_a_shape_it_holds_twice() -> None:
    """A small probe (up to SMALL_PROBE pieces, through the selection's coal tree) with one shape at several
    poses (an object along a path): the pose that collides is found wherever it is in the probe, as a list
    and as a Posed (a shape's probe object moved to all of them at once answered for the last pose only)."""
    from mrgc.geometry.collision import Posed

    world = CollisionWorld()
    world.add("wall", Box(0.1, 1.0, 1.0), translation(0, 0, 0))
    box = collision_shape(Box(0.05, 0.05, 0.05))
    for k in range(3):  # the colliding pose first, in the middle, last
        poses = [translation(0.5 + 0.1 * i, 0, 0) for i in range(3)]
        poses[k] = translation(0.02, 0, 0)
        probe = [(box, t) for t in poses]
        assert world.probe_collides(probe), k  # type: ignore[arg-type]
        assert world.probe_collides(Posed.of(probe)), k  # type: ignore[arg-type]
    assert not world.probe_collides([(box, translation(0.5 + 0.1 * i, 0, 0)) for i in range(3)])  # type: ignore[misc]


def test_grouped_collide_tests_only_pieces_of_the_paired_groups() -> None:
    """Two motions compared sample by sample: pieces of groups that are not paired never count."""
    from mrgc.geometry.collision import Posed, grouped_collide

    box = collision_shape(Box(0.1, 0.1, 0.1))
    a = Posed.of([(box, translation(0, 0, 0)), (box, translation(1, 0, 0))])
    b = Posed.of([(box, translation(1, 0, 0)), (box, translation(0, 0, 0))])
    one_each = np.array([0, 1, 2])
    assert not grouped_collide(a, one_each, b, one_each, np.array([[0, 0], [1, 1]]))  # each apart from its pair
    assert grouped_collide(a, one_each, b, one_each, np.array([[1, 0], [1, 1]]))  # a's second against both
    assert grouped_collide(a, np.array([0, 2]), b, np.array([0, 2]), np.array([[0, 0]]))  # one group each
    assert not grouped_collide(a, one_each, b, one_each, np.zeros((0, 2), dtype=int))
    for bad in ([0, 0, 2], [0, 1], [1, 2], [0]):  # an empty group, pieces left out, a group before 0, none
        with pytest.raises(ValueError, match="every group a piece"):
            grouped_collide(a, np.array(bad), b, one_each, np.array([[0, 0]]))


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.lists(st.tuples(st.integers(0, 6), st.integers(0, 3)), min_size=1, max_size=4), min_size=1, max_size=5),
    st.lists(st.lists(st.tuples(st.integers(0, 6), st.integers(0, 3)), min_size=1, max_size=4), min_size=1, max_size=5),
    st.data(),
)
def test_grouped_collide_answers_as_each_pair_of_groups_on_its_own(
    groups_a: list[list[tuple[int, int]]], groups_b: list[list[tuple[int, int]]], data: st.DataObject
) -> None:
    """One query of paired groups says what testing each pair of groups alone says (pieces_collide)."""
    from mrgc.geometry.collision import Posed, grouped_collide, pieces_collide

    shapes = [collision_shape(Box(0.1, 0.1, 0.1)), collision_shape(Sphere(0.06))]

    def pieces(group: list[tuple[int, int]]) -> list:  # type: ignore[type-arg]
        return [(shapes[y % 2], translation(0.09 * x, 0.07 * y, 0.0)) for x, y in group]

    va, vb = [pieces(g) for g in groups_a], [pieces(g) for g in groups_b]
    pairs = data.draw(
        st.lists(st.tuples(st.integers(0, len(va) - 1), st.integers(0, len(vb) - 1)), max_size=8, unique=True)
    )
    expected = any(pieces_collide(va[k], vb[m]) for k, m in pairs)
    starts = [np.cumsum([0] + [len(v) for v in vs]) for vs in (va, vb)]
    got = grouped_collide(
        Posed.of([p for v in va for p in v]),
        starts[0],
        Posed.of([p for v in vb for p in v]),
        starts[1],
        np.array(pairs, dtype=int).reshape(-1, 2),
    )
    assert got is expected


def _same_posed(a: object, b: object) -> bool:
    """Two kernel sets equal to the bit: the same shape objects in the same order, rows and boxes."""
    return (
        [id(s) for s in a.shapes] == [id(s) for s in b.shapes]  # type: ignore[attr-defined]
        and all(
            np.array_equal(getattr(a, f), getattr(b, f)) and getattr(a, f).dtype == getattr(b, f).dtype
            for f in ("kind", "transforms", "lo", "hi")
        )
        and a.pad == b.pad  # type: ignore[attr-defined]
    )


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 200), st.integers(1, 200), st.sampled_from([1, 2, 3]))
def test_a_set_extended_by_pieces_is_the_set_of_all_its_pieces(seed: int, n_a: int, n_b: int, kinds: int) -> None:
    """``Posed.extended`` (a set followed by more pieces, its own not converted again) is, to the bit, the set
    ``Posed.of`` makes of all the pieces: shapes in order of first appearance, rows, boxes (or None where
    ``of`` would take its one-shape way).  The volume cache of the grounding converts a list that begins with
    the pieces of a list it kept that way: the same set as converting it whole, and the kept one's rows are
    not converted again."""
    from mrgc.geometry import step_world
    from mrgc.geometry.collision import Posed

    rng = np.random.default_rng(seed)
    pool = _random_pieces(rng, max(n_a, n_b), 0.5)
    a = [pool[k] for k in rng.integers(0, len(pool), n_a) if k % 3 < kinds]
    b = [(pool[k][0], translation(0.1, 0, 0) @ pool[k][1]) for k in rng.integers(0, len(pool), n_b) if k % 3 < kinds]
    assume(a and b)
    whole = Posed.of(a + b)  # type: ignore[operator]
    made = Posed.of(a).extended(b)  # type: ignore[arg-type]
    assert (made is None) == (len(whole.shapes) == 1)
    if made is not None:
        assert _same_posed(made, whole)
    cache = step_world._VolumeCache()
    cache.PREFIX_MIN = 1
    first = cache.posed(a)  # type: ignore[arg-type]
    converted: list[int] = []
    real = step_world.Posed.of
    try:
        step_world.Posed.of = lambda pieces, pad=TOLERANCE: converted.append(len(pieces)) or real(pieces, pad)  # type: ignore[method-assign,func-returns-value]
        longer = cache.posed(a + b)  # type: ignore[operator]
    finally:
        step_world.Posed.of = real  # type: ignore[method-assign]
    assert _same_posed(longer, whole) and _same_posed(first, Posed.of(a))  # type: ignore[arg-type]
    assert converted == ([] if made is not None else [len(a) + len(b)])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.lists(st.integers(0, 80), min_size=0, max_size=4), st.sampled_from([1, 2, 3]))
def test_joined_sets_are_the_set_of_all_their_pieces(seed: int, sizes: list[int], kinds: int) -> None:
    """``Posed.join`` (a grounded suffix's volume from its steps' sets) holds the pieces of its parts in order:
    the distinct shapes in order of first appearance, the same rows, the boxes ``Posed.of`` makes of all the
    pieces (to rounding: a part of one shape bounds it another way), and the same answers against a probe; it
    is a new set whose queries grow no cache on its parts, and the parts are left as they were."""
    from mrgc.geometry.collision import Posed, posed_collide

    rng = np.random.default_rng(seed)
    pool = _random_pieces(rng, 12, 0.5)
    pieces = [[pool[k] for k in rng.integers(0, len(pool), n) if k % 3 < kinds] for n in sizes]
    parts = [Posed.of(p) for p in pieces]  # type: ignore[arg-type]
    before = [(p.kind.copy(), p.transforms.copy(), p.lo.copy()) for p in parts]
    joined = Posed.join(parts)
    whole = Posed.of([x for p in pieces for x in p])  # type: ignore[misc]
    assert joined is not whole and all(joined is not p for p in parts)
    assert [id(s) for s in joined.shapes] == [id(s) for s in whole.shapes]
    assert np.array_equal(joined.kind, whole.kind) and np.array_equal(joined.transforms, whole.transforms)
    assert np.allclose(joined.lo, whole.lo, atol=1e-12) and np.allclose(joined.hi, whole.hi, atol=1e-12)
    probe = Posed.of(_random_pieces(rng, 5, 0.5))  # type: ignore[arg-type]
    assert posed_collide(joined, probe) == posed_collide(whole, probe)
    assert posed_collide(probe, joined) == posed_collide(probe, whole)
    joined.within(np.full(3, -0.2), np.full(3, 0.2))
    for p, (kind, transforms, lo) in zip(parts, before):
        assert not p._parts and p._tree is None  # the union's caches are its own
        assert np.array_equal(p.kind, kind) and np.array_equal(p.transforms, transforms)
        assert np.array_equal(p.lo, lo)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from([0.1, 0.25, 0.6]), st.booleans())
def test_the_oriented_box_cut_keeps_every_colliding_pair(seed: int, spread: float, skipping: bool) -> None:
    """Past its first pairs the narrowphase hands coal only the pairs whose oriented boxes meet: the pairs
    that collide, in order, are those coal finds among all the candidate pairs (which-objects with a skip
    mark per piece, and yes/no stopping at the first), on rotated boxes, spheres and thin hulls."""
    from mrgc.geometry import collision
    from mrgc.geometry.collision import Posed, overlaps

    rng = np.random.default_rng(seed)
    thin = collision_shape(ConvexHull(rng.normal(size=(20, 3)) * [0.12, 0.01, 0.01]))
    a = [(thin, t) for _, t in _random_pieces(rng, 40, spread)] + _random_pieces(rng, 20, spread)
    b = _random_pieces(rng, 60, spread)
    pa, pb = Posed.of(a), Posed.of(b)  # type: ignore[arg-type]
    i, j = overlaps(pa, pb)
    assume(len(i) > collision.EXACT_PLAIN + 10)
    marks = (lambda: (np.zeros(len(pb), dtype=bool), None)) if skipping else (lambda: None)
    every = collision._narrow(pa, pb, i, j, TOLERANCE, False, marks())
    assert collision._exact(pa, pb, i, j, TOLERANCE, False, marks()) == every
    assert collision._exact(pa, pb, i, j, TOLERANCE, True) == every[:1]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 12), st.sampled_from([0.15, 0.4, 1.0]), st.booleans())
def test_many_probes_at_once_get_the_answers_each_gets_alone(seed: int, count: int, spread: float, own: bool) -> None:
    """``slot_collides`` and ``slot_hits`` (the pieces of ``count`` probes in one set, each piece tagged with its
    probe) answer each probe as ``probe_collides`` and ``probe_hits`` of its pieces alone, with the probe's own
    object (when it has one) ignored: random boxes, spheres and hulls against a world of fixed and movable
    ones, large probes among small (the broadphase's grouped path and its direct one)."""
    from mrgc.geometry.collision import Posed, Probes

    rng = np.random.default_rng(seed)
    world = CollisionWorld()
    for k, (shape, t) in enumerate(_random_pieces(rng, 30, spread)):
        world.add(f"b{k}", shape, t, "fixed" if k % 3 == 0 else "movable")  # type: ignore[arg-type]
    probes = [_random_pieces(rng, int(rng.integers(1, 60)), spread) for _ in range(count)]
    mine = [f"b{int(rng.integers(0, 30))}" if own and rng.random() < 0.7 else None for _ in probes]
    together = Probes.of(probes)  # type: ignore[arg-type]
    for against in ("fixed", "movable", None):
        yes = world.slot_collides(together, against, ignore="b1", own=mine)
        which = world.slot_hits(together, against, ignore="b1", own=mine)
        for k, probe in enumerate(probes):
            ignore = ("b1",) if mine[k] is None else ("b1", mine[k])
            assert yes[k] == world.probe_collides(Posed.of(probe), against, ignore), (against, k)  # type: ignore[arg-type]
            assert which[k] == world.probe_hits(probe, against, ignore), (against, k)  # type: ignore[arg-type]
    assert not world.slot_collides(together, "nothing").any()
