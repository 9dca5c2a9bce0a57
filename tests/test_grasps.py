"""Grasps as data: the (:grasps ...) syntax, its checks, the frames and finger openings geometry/grasps.py
derives from a spec, and two scenes the declared grasps make feasible (a handover of a small box held at
its two ends; a box picked between close neighbours with the wrist turned)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

from mrgc import cli, parse_file
from mrgc.errors import InputError
from mrgc.geometry.grasps import FINGER_CLEARANCE, finger_opening, fits, grasp_transform, grasp_warnings, width
from mrgc.geometry.predicates import compute_facts
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.ast import Grasps
from mrgc.language.loader import parse_string
from mrgc.language.model import AXES, BUILTIN_GRASPS, Box, Cylinder, Fact, GraspSpec, RobotKind
from mrgc.language.parser import parse_text
from mrgc.language.printer import format_source

PACKAGING = ROOT / "domains" / "packaging"

KIND = '(:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand")'
DOMAIN = f"""(define (domain cell)
  {KIND}
  ; built-in names and declared grasps, mixed
  (:grasps top (top-x :approach -z :fingers x) ; wrist turned
    (side-x+ :approach -x :fingers z :depth 0.015 :offset (0 0 0.03))))
"""


def check_codes(text: str) -> list[tuple[str, str]]:
    """(code, message) of every diagnostic ``text`` gets from the checker (none: [])."""
    try:
        parse_string(text, "g.mrg")
    except InputError as exc:
        return [(d.code, d.message) for d in exc.diagnostics]
    return []


# ---------------------------------------------------------------------------------------------- syntax
def test_declared_and_bare_grasps_parse_into_specs() -> None:
    domain = parse_string(DOMAIN, "g.mrg").domains[0]
    assert domain.grasps == ("top", "top-x", "side-x+")
    assert domain.grasp_spec("top") == BUILTIN_GRASPS["top"]
    assert domain.grasp_spec("top-x") == GraspSpec("top-x", (0.0, 0.0, -1.0), (1.0, 0.0, 0.0))
    side = domain.grasp_spec("side-x+")
    assert side == GraspSpec("side-x+", (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.015, (0.0, 0.0, 0.03))
    assert side != BUILTIN_GRASPS["side-x+"]  # a domain's own declaration takes precedence over the built-in
    assert domain.robot_kinds[0].gripper_opening == 0.08  # the default: a Panda's


def test_fmt_round_trips_keeps_comments_and_is_idempotent() -> None:
    tree = parse_text(DOMAIN, "g.mrg")
    assert not isinstance(tree, Exception) and isinstance(tree.definitions[0].sections[1], Grasps)
    once = format_source(tree, DOMAIN)
    assert "; built-in names and declared grasps, mixed" in once and "; wrist turned" in once
    assert "    (top-x :approach -z :fingers x) ; wrist turned\n" in once
    again = parse_text(once, "g.mrg")
    assert again == tree
    assert format_source(again, once) == once


def test_mrgc_fmt_check_accepts_the_canonical_form(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "d.mrg"
    path.write_text(DOMAIN, encoding="utf-8")
    assert cli.main(["fmt", "--write", str(path)]) == 0
    assert cli.main(["fmt", "--check", str(path)]) == 0
    assert parse_file(path).domains[0].grasp_spec("top-x") == GraspSpec("top-x", (0.0, 0.0, -1.0), (1.0, 0.0, 0.0))


@settings(max_examples=40, deadline=None)
@given(
    st.sampled_from([w for w in AXES if w[0] in "+-"]),
    st.sampled_from(list(AXES)),
    st.floats(0, 0.1),
    st.tuples(*[st.floats(-0.1, 0.1)] * 3),
)
def test_any_declared_grasp_prints_and_reads_back(
    approach: str, fingers: str, depth: float, offset: tuple[float, float, float]
) -> None:
    off = " ".join(repr(x) for x in offset)
    text = (
        f"(define (domain d) {KIND}\n  (:grasps (g :approach {approach} :fingers {fingers} :depth {depth!r} "
        f":offset ({off}))))\n"
    )
    perpendicular = sum(a * b for a, b in zip(AXES[approach], AXES[fingers])) == 0
    codes = check_codes(text)
    assert [c for c, _ in codes] == ([] if perpendicular else ["E241"])
    tree = parse_text(text, "g.mrg")
    assert parse_text(format_source(tree, text), "g.mrg") == tree
    if perpendicular:
        spec = parse_string(text, "g.mrg").domains[0].grasp_spec("g")
        assert spec is not None and spec.depth == depth and spec.offset == offset


# ---------------------------------------------------------------------------------------------- checks
@pytest.mark.parametrize(
    "grasps, code, words",
    [
        ("(g :approach -w :fingers x)", "E240", "unknown axis '-w' for ':approach' (did you mean '-x'?)"),
        ("(g :approach -z :fingers 1)", "E240", "':fingers' must be an axis"),
        ("(g :approach -z :fingers -z)", "E241", "must be perpendicular"),
        ("(g :approach -z :fingers y :depth -0.01)", "E242", "must not be negative"),
        (
            "(g :approach -z :fingers y :dept 0)",
            "E254",
            "unknown property ':dept' for grasp 'g' (did you mean 'depth'?)",
        ),
        ("(g :approach -z)", "E255", "grasp 'g' needs ':fingers'"),
        ("(g :approach -z :fingers y :offset (0 0))", "E252", "needs 3 numbers"),
        ("tpo", "E243", "grasp 'tpo' has no geometry"),
        ("top (top :approach -z :fingers x)", "E200", "grasp 'top' declared twice"),
    ],
)
def test_grasp_diagnostics(grasps: str, code: str, words: str) -> None:
    codes = check_codes(f"(define (domain d) {KIND} (:grasps {grasps}))")
    assert [c for c, _ in codes] == [code] and words in codes[0][1], codes


def test_unknown_grasp_on_a_geometric_problem_is_located_with_did_you_mean() -> None:
    problem = (
        DOMAIN
        + """
(define (problem p)
  (:domain cell)
  (:robots (r1 :kind panda :base (0 -0.6 0 90)))
  (:regions (start :shape (box 0.4 0.4 0.3) :pose (0 0 0.15 0)))
  (:movable (o :shape (box 0.04 0.04 0.1) :pose (0 0 0.05 0) :grasps (top-x side-y+ topx)))
  (:goal (in-region o start)))
"""
    )
    with pytest.raises(InputError) as info:
        parse_string(problem, "g.mrg")
    (d,) = info.value.diagnostics
    assert d.code == "E213" and "undeclared grasp 'topx'" in d.message and "did you mean" in d.message
    assert d.span is not None and problem.split("\n")[d.span.line - 1][d.span.column - 1 :].startswith("topx)")
    # side-y+ is built in though the domain leaves it out: a geometric problem's object may name it
    ok = parse_string(problem.replace(" topx", ""), "g.mrg").problem()
    assert ok.grasps_of("o") == ("top-x", "side-y+") and set(ok.grasp_specs) == {"top-x", "side-y+"}


def test_symbolic_domains_accept_any_grasp_name() -> None:
    text = """(define (domain abstract) (:grasps top side pinch))
(define (problem p) (:domain abstract) (:robots r1) (:movable o) (:regions a b)
  (:init (in-region o a) (reachable-pick o pinch r1)) (:goal (in-region o b)))"""
    problem = parse_string(text, "g.mrg").problem()
    assert problem.grasps_of("o") == ("top", "side", "pinch") and problem.grasp_specs == {"top": BUILTIN_GRASPS["top"]}


# ---------------------------------------------------------------------------------------------- frames
def test_built_in_grasps_keep_their_meaning() -> None:
    """The tool frames of the five original names are what they were (approach, fingers, 2 cm deep)."""
    shape = Box(0.06, 0.04, 0.12)
    old = {
        "top": ((0, 0, -1), (0, 1, 0)),
        "side-x+": ((-1, 0, 0), (0, 1, 0)),
        "side-x-": ((1, 0, 0), (0, 1, 0)),
        "side-y+": ((0, -1, 0), (1, 0, 0)),
        "side-y-": ((0, 1, 0), (1, 0, 0)),
    }
    for name, (approach, fingers) in old.items():
        t = grasp_transform(BUILTIN_GRASPS[name], shape)
        z, y = np.array(approach, dtype=float), np.array(fingers, dtype=float)
        assert np.allclose(t[:3, 2], z) and np.allclose(t[:3, 1], y) and np.allclose(t[:3, 0], np.cross(y, z))
        reach = float(np.abs(z) @ np.array([0.03, 0.02, 0.06]))
        assert np.allclose(t[:3, 3], -z * (reach - 0.02))  # 2 cm inside the approached face
    turned = grasp_transform(BUILTIN_GRASPS["top-x"], shape)
    assert np.allclose(turned[:3, :3], [[0, 1, 0], [1, 0, 0], [0, 0, -1]]) and np.allclose(turned[:3, 3], [0, 0, 0.04])


def test_depth_and_offset_move_the_tool_centre_point() -> None:
    spec = GraspSpec("g", (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), depth=0.005, offset=(0.0, 0.0, 0.03))
    t = grasp_transform(spec, Box(0.04, 0.04, 0.12))
    assert np.allclose(t[:3, 3], [0.015, 0.0, 0.03])
    deep = GraspSpec("g", (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), depth=1.0)
    assert np.allclose(grasp_transform(deep, Box(0.04, 0.04, 0.12))[:3, 3], 0)  # never past the centre


def test_finger_opening_is_the_width_along_the_finger_axis_plus_clearance() -> None:
    box = Box(0.12, 0.05, 0.1)
    assert width(BUILTIN_GRASPS["top"], box) == pytest.approx(0.05)
    assert width(BUILTIN_GRASPS["top-x"], box) == pytest.approx(0.12)
    assert finger_opening(BUILTIN_GRASPS["top"], box) == pytest.approx(0.05 + FINGER_CLEARANCE)
    assert width(BUILTIN_GRASPS["side-y+"], Cylinder(0.03, 0.2)) == pytest.approx(0.06)
    panda = RobotKind("panda")
    assert fits(BUILTIN_GRASPS["top"], box, panda) and not fits(BUILTIN_GRASPS["top-x"], box, panda)
    assert fits(BUILTIN_GRASPS["top-x"], box, RobotKind("wide", gripper_opening=0.15))


def test_a_grasp_wider_than_the_gripper_warns_and_yields_no_facts(tmp_path: Path) -> None:
    text = (ROOT / "tests" / "golden" / "errors" / "W270.mrg").read_text(encoding="utf-8")
    (tmp_path / "w.mrg").write_text(text, encoding="utf-8")
    problem = parse_file(tmp_path / "w.mrg").problem()
    (warning,) = grasp_warnings(problem)
    assert warning.code == "W270" and warning.severity == "warning" and "'top-x' of 'crate'" in warning.message
    facts = compute_facts(scene_from_problem(problem), workers=1).facts
    assert not [f for f in facts if "top-x" in f.args]
    assert Fact("reachable-pick", ("crate", "top", "r1")) in facts
    wide = text.replace('"panda_hand")', '"panda_hand" :gripper-opening 0.14)')
    (tmp_path / "w.mrg").write_text(wide, encoding="utf-8")
    problem = parse_file(tmp_path / "w.mrg").problem()
    assert grasp_warnings(problem) == []
    facts = compute_facts(scene_from_problem(problem), workers=1).facts
    assert Fact("reachable-pick", ("crate", "top-x", "r1")) in facts


# ---------------------------------------------------------------------------------------------- scenes
HANDOVER = """
(define (domain two-hands)
  (:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand"
    :tcp (0 0 0.105 0) :home (0 -0.785 0 -2.356 0 1.571 0.785))
  (:grasps side-y- side-y+
    (low-y- :approach +y :fingers x :offset (0 0 -0.03)) ; r1's hand on the lower end
    (high-y+ :approach -y :fingers x :offset (0 0 0.03)))) ; r2's on the upper end
(define (problem handover)
  (:domain two-hands)
  (:robots (r1 :kind panda :base (0 -0.55 0 90)) (r2 :kind panda :base (0 0.55 0 -90)))
  (:fixed (table :shape (box 1 1.6 0.05) :pose (0 0 -0.025 0)))
  (:regions (start :shape (box 0.3 0.3 0.3) :pose (0 -0.25 0.15 0))
            (bin :shape (box 0.2 0.2 0.3) :pose (-0.3 0.35 0.15 0)))
  (:movable (stick :shape (box 0.04 0.04 0.12) :pose (0 -0.25 0.06 0)))
  (:handover-points (h1 :position (0 0 0.45)))
  (:goal (in-region stick bin)))
"""


def test_offset_grasps_make_the_handover_of_a_small_box_feasible(tmp_path: Path) -> None:
    """Two Pandas facing each other; a 4 × 4 × 12 cm box.  Held from opposite sides at its centre (the
    built-in side-y- / side-y+, 2 cm deep in a 4 cm box), the fingers of the two hands overlap; held at its
    two ends (offsets ±3 cm), they do not."""
    (tmp_path / "h.mrg").write_text(HANDOVER, encoding="utf-8")
    facts = set(compute_facts(scene_from_problem(parse_file(tmp_path / "h.mrg").problem()), workers=1).facts)
    handovers = {f.args for f in facts if f.predicate == "enable-goal-handover"}
    assert ("stick", "low-y-", "high-y+", "r1", "r2") in handovers
    assert ("stick", "high-y+", "low-y-", "r2", "r1") in handovers
    assert not {h for h in handovers if {h[1], h[2]} == {"side-y-", "side-y+"}}  # centre to centre: overlap


PITCH = """
(define (problem pitch)
  (:domain packaging)
  (:robots (r1 :kind panda :base (0 -0.6 0 90)))
  (:fixed (table :shape (box 1 1.2 0.05) :pose (0 0 -0.025 0)))
  (:regions (start :shape (box 0.3 0.3 0.3) :pose (0 -0.1 0.15 0))
            (bin :shape (box 0.2 0.2 0.3) :pose (0.35 -0.3 0.15 0)))
  (:movable
    (o :shape (box 0.04 0.04 0.1) :pose (0 -0.1 0.05 0) :grasps (top top-x))
    (left :shape (box 0.04 0.06 0.1) :pose (0 -0.17 0.05 0))
    (right :shape (box 0.04 0.06 0.1) :pose (0 -0.03 0.05 0)))
  (:goal (in-region o bin)))
"""


def test_turning_the_wrist_picks_a_box_between_close_neighbours(tmp_path: Path) -> None:
    """A 4 cm box on a 7 cm pitch between two neighbours along y (2 cm gaps): ``top`` closes the fingers
    along y, into the neighbours; ``top-x`` closes them along x and is free."""
    shutil.copy(PACKAGING / "domain.mrg", tmp_path / "domain.mrg")
    (tmp_path / "pitch.mrg").write_text(PITCH, encoding="utf-8")
    facts = set(compute_facts(scene_from_problem(parse_file(tmp_path / "pitch.mrg").problem()), workers=1).facts)
    assert Fact("reachable-pick", ("o", "top", "r1")) in facts and Fact("reachable-pick", ("o", "top-x", "r1")) in facts
    blockers = {(f.args[0], f.args[2]) for f in facts if f.predicate == "occludes-pick" and f.args[1] == "o"}
    assert blockers == {("left", "top"), ("right", "top")}
