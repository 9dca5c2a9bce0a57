"""mrgc render and mrgc graph: pictures of real plans, checked by what they hold (sizes, frames, colours, text).

The plan comes from ``mrgc plan`` on the shipped handover problem (once per session); generated problems are
drawn too.  The HTML replay is loaded in a real headless Chromium (tests/headless_chromium.py).  Pictures
are kept small (160×120) and frame rates low so the file runs in well under a minute, the browser included.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest
from headless_chromium import colour_share, screenshot_when
from hypothesis import example, given, settings
from hypothesis import strategies as st
from PIL import Image
from support import ROOT, run_cli

from mrgc import cli
from mrgc.language.loader import parse_file
from mrgc.render.camera import PRESETS
from mrgc.render.command import CAMERA_HELP
from mrgc.render.frames import PHASES, build_timeline, interpolate
from mrgc.render.palette import GOAL_REGION, ROBOT_COLOURS, byte_colour
from mrgc.render.world import World

HANDOVER = ROOT / "domains" / "packaging" / "pa3-handover.mrg"
SMALL = ["--size", "160x120", "--fps", "4"]


def run(args: list[str | Path], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_cli(capsys, *args)


@pytest.fixture(scope="session")
def plan_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A validated plan of the shipped handover problem, from mrgc plan."""
    path = tmp_path_factory.mktemp("plan") / "pa3-handover.plan.json"
    assert cli.main(["plan", str(HANDOVER), "-o", str(path), "--time-limit", "120"]) == 0
    plan = json.loads(path.read_text())
    assert any(a["kind"] == "handover" for s in plan["steps"] for a in s["actions"])
    return path


def non_blank(img: np.ndarray) -> bool:
    """Many distinct colours and real contrast: something was drawn."""
    flat = img.reshape(-1, img.shape[-1])[:, :3]
    return len(np.unique(flat, axis=0)) > 20 and float(flat.std()) > 20


def test_gif_has_a_frame_for_every_phase_of_every_step(
    plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "plan.gif"
    code, stdout, _ = run(["render", HANDOVER, plan_file, "-o", out, *SMALL], capsys)
    assert code == 0 and str(out.resolve()) in stdout
    plan = json.loads(plan_file.read_text())
    world = World(parse_file(str(HANDOVER)).problem(None), plan)
    timeline = build_timeline(world, plan)
    phases = {(p.step, p.name) for p in timeline.phases}
    for t, step in enumerate(plan["steps"], 1):  # every motion of the step has its phase
        assert {(t, "to-pick"), (t, "pick"), (t, "to-place"), (t, "place"), (t, "home")} <= phases
        if any(a["kind"] == "handover" for a in step["actions"]):
            assert {(t, "to-handover"), (t, "handover")} <= phases
    with Image.open(out) as gif:
        assert gif.size == (160, 120)
        frames = []
        for i in range(gif.n_frames):
            gif.seek(i)
            frames.append(np.asarray(gif.convert("RGB")))
    assert len(frames) >= 1 + len(timeline.phases)
    assert all(non_blank(f) for f in frames[:: max(1, len(frames) // 5)])
    assert any(not np.array_equal(frames[0], f) for f in frames[1:]), "nothing moves"


def test_drawing_in_worker_processes_gives_the_same_images(plan_file: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from mrgc.render import outputs

    plan = json.loads(plan_file.read_text())
    opts = outputs.Options(96, 72, 4.0)
    world, _, frames, camera = outputs.replay_frames(parse_file(str(HANDOVER)).problem(None), plan, opts, "plan")
    monkeypatch.setattr(outputs, "PARALLEL_FRAMES", len(frames) + 1)
    alone, _ = outputs.draw(world, frames, camera, opts)
    monkeypatch.setattr(outputs, "PARALLEL_FRAMES", 2)
    monkeypatch.setattr("mrgc.workers.usable_cores", lambda: 2)
    shared, _ = outputs.draw(world, frames, camera, opts)
    assert len(alone) == len(shared) == len(frames)
    assert all(np.array_equal(a, b) for a, b in zip(alone, shared))


def test_held_objects_follow_the_grasp_and_land_on_the_place_pose(plan_file: Path) -> None:
    """Taking an object and putting it down do not make it jump (the plan was validated: the tool is at
    the grasp), and after the place the object is at its place_pose."""
    plan = json.loads(plan_file.read_text())
    world = World(parse_file(str(HANDOVER)).problem(None), plan)
    frames = build_timeline(world, plan).frames(6)
    for before, after in zip(frames, frames[1:]):
        for obj in world.objects:
            jump = float(np.linalg.norm(after.poses[obj][:3, 3] - before.poses[obj][:3, 3]))
            if after.phase in ("to-handover", "to-place") or (
                after.phase in ("pick", "handover", "place") and before.phase == after.phase
            ):
                continue  # moving with a robot (a transfer is a long path whose frames lie far apart)
            assert jump < 0.25, (after.step, after.phase, obj, jump)
    last = frames[-1]
    for step in plan["steps"]:
        for a in step["actions"]:
            assert np.allclose(last.poses[a["object"]], np.array(a["place_pose"]), atol=1e-9)
    ends = [f for f in frames if f.key and f.phase == "pick"]
    assert ends, "no pick key frame"
    # at the end of a pick the object is still where it was grasped, now held by the robot
    for t, step in enumerate(plan["steps"], 1):
        end = next(f for f in ends if f.step == t)
        start = next(f for f in frames if f.step == t)
        for a in step["actions"]:
            d = np.linalg.norm(end.poses[a["object"]][:3, 3] - start.poses[a["object"]][:3, 3])
            assert d < 2e-3, (t, a["object"], d)


def test_sheet_scene_and_camera_presets(plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sheet = tmp_path / "sheet.png"
    assert run(["render", HANDOVER, plan_file, "-o", sheet, *SMALL], capsys)[0] == 0
    img = np.asarray(Image.open(sheet).convert("RGB"))
    assert img.shape[0] > 120 and img.shape[1] > 160 and non_blank(img)  # several tiles
    scenes = {}
    for preset in sorted(PRESETS):
        path = tmp_path / f"scene-{preset}.png"
        assert run(["render", HANDOVER, "-o", path, "--size", "160x120", "--camera", preset], capsys)[0] == 0
        scenes[preset] = np.asarray(Image.open(path).convert("RGB"))
        assert scenes[preset].shape == (120, 160, 3) and non_blank(scenes[preset])
        # both robots are in the picture (their colours survive the shading)
        for colour in ROBOT_COLOURS[:2]:
            assert colour_share(scenes[preset], byte_colour(colour)) > 0.0005, preset
    assert not np.array_equal(scenes["iso"], scenes["top"])
    assert all(name in CAMERA_HELP for name in PRESETS) and CAMERA_HELP.count(",") + 2 == len(PRESETS)


def test_generated_problems_are_drawn(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for kind, seed in (("packaging", 7), ("box-moving", 3)):
        problem = tmp_path / f"{kind}.mrg"
        assert (
            run(["generate", kind, "--seed", seed, "--robots", 2, "--goals", 2, "--others", 1, "-o", problem], capsys)[
                0
            ]
            == 0
        )
        out = tmp_path / f"{kind}.png"
        code, _, err = run(["render", problem, "-o", out, "--size", "320x240"], capsys)
        assert code == 0, err
        img = np.asarray(Image.open(out).convert("RGB"))
        assert img.shape == (240, 320, 3) and non_blank(img)
        region = byte_colour(GOAL_REGION)  # translucent over the floor: its hue, faintly saturated
        assert colour_share(img, region, hue_tolerance=0.05, min_saturation=0.08) > 0.005, f"{kind}: no goal region"
        for colour in ROBOT_COLOURS[:2]:  # (maybe seen through a region's tint)
            assert colour_share(img, byte_colour(colour), hue_tolerance=0.06) > 0.0005, f"{kind}: a robot is missing"


def test_gantt_svg_and_png(plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plan = json.loads(plan_file.read_text())
    svg = tmp_path / "plan-gantt.svg"
    assert run(["render", HANDOVER, plan_file, "-o", svg], capsys)[0] == 0
    text = svg.read_text()
    assert text.lstrip().startswith("<?xml") and "<svg" in text
    for robot in ("r1", "r2"):
        assert f">{robot}<" in text
    for step in plan["steps"]:
        for a in step["actions"]:
            assert f"{a['object']} \u2192 {a['region']}" in text
            if a["kind"] == "handover":
                assert a["handover_point"] in text and f"{a['object']} \u2192 {a['place_robot']}" in text
    # the legend keys the colours the chart has: "moved obstacle" only when the plan moves one
    goals = parse_file(str(HANDOVER)).problem().goal_regions
    obstacles = {a["object"] for s in plan["steps"] for a in s["actions"]} - set(goals)
    assert ("moved obstacle" in text) == bool(obstacles) and "goal object" in text
    again = tmp_path / "again-gantt.svg"
    assert run(["render", HANDOVER, plan_file, "-o", again], capsys)[0] == 0
    assert again.read_text() == text  # deterministic
    png = tmp_path / "plan.png"
    assert run(["render", HANDOVER, plan_file, "-o", png, "--gantt"], capsys)[0] == 0
    img = np.asarray(Image.open(png).convert("RGB"))
    assert img.shape[1] > 300 and non_blank(img)


def test_mp4(
    plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from mrgc.render import video

    out = tmp_path / "plan.mp4"
    code, _, err = run(["render", HANDOVER, plan_file, "-o", out, *SMALL], capsys)
    if video.mp4_available():
        import imageio.v3 as iio

        assert code == 0, err
        frames = iio.imread(out, plugin="FFMPEG")
        assert frames.shape[1:] == (120, 160, 3) and frames.shape[0] > 10
    else:
        assert code == 4 and "imageio-ffmpeg" in err
    monkeypatch.setattr(video, "mp4_available", lambda: False)
    code, _, err = run(["render", HANDOVER, plan_file, "-o", tmp_path / "no.mp4", *SMALL], capsys)
    assert code == 4 and "pip install imageio-ffmpeg" in err and not (tmp_path / "no.mp4").exists()


def test_html_replay_is_self_contained_and_shows_the_robots_in_chromium(
    plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "plan.html"
    code, stdout, _ = run(["render", HANDOVER, plan_file, "-o", out, "--fps", "5"], capsys)
    assert code == 0 and str(out.resolve()) in stdout and "web browser" in stdout
    page = out.read_text(encoding="utf-8")
    assert "__VISER_EMBED_DATA__" in page
    # nothing is fetched from elsewhere: no script, stylesheet or image from a URL
    assert not re.search(r"""<(script|link|img)[^>]+(src|href)=["']?(https?:)?//""", page, re.I)
    blue, purple = (byte_colour(c) for c in ROBOT_COLOURS[:2])
    from mrgc.render import outputs
    from mrgc.render.labels import anchors

    plan = json.loads(plan_file.read_text())
    world = World(parse_file(str(HANDOVER)).problem(None), plan)
    frames = build_timeline(world, plan).frames(5)
    camera = outputs.html_camera(world, frames, outputs.Options())
    points = {lb.text: p.reshape(-1, 3).mean(axis=0, keepdims=True) for lb, p in anchors(world, frames[0])}

    def unnamed(picture: np.ndarray) -> list[str]:
        """The names of robots and regions without dark text (which nothing else in the scene is) near
        where their anchors project."""
        h, w = picture.shape[:2]
        # a short name drawn by software WebGL is a few anti-aliased grey glyphs (r1: none below 94)
        dark = picture.max(axis=2) < 150
        out = []
        for name, point in points.items():
            c, r, _ = camera.project(point, w, h)
            x, y = int(c[0]), int(r[0])
            if dark[max(0, y - 80) : y + 40, max(0, x - 70) : x + 70].sum() < 12:
                out.append(name)
        return out

    picture, ok = screenshot_when(
        out.as_uri(),
        lambda p: colour_share(p, blue) > 0.004 and colour_share(p, purple) > 0.004 and not unnamed(p),
        timeout=150,
        size=(640, 480),
    )
    Image.fromarray(picture).save(tmp_path / "chromium.png")
    assert non_blank(picture), "the page stayed blank"
    assert ok, (
        f"the robots or their names did not appear (blue {colour_share(picture, blue):.4f}, purple "
        f"{colour_share(picture, purple):.4f}, unnamed {unnamed(picture)}); screenshot at {tmp_path / 'chromium.png'}"
    )
    assert {"r1", "r2", "bin-b", "start"} <= set(points)
    # the legend (plain HTML) shows each robot's colour, and names the robots and regions
    for colour in (blue, purple):
        assert (np.abs(picture.astype(int) - colour).sum(axis=2) <= 24).sum() >= 30, colour
    legend = page[page.index('<div id="mrgc-legend"') :]
    assert ">r1</div>" in legend and ">r2</div>" in legend and "bin-b" in legend


def test_bad_requests_are_one_line_errors(plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cases = [
        (["render", HANDOVER, plan_file, "-o", tmp_path / "x.bmp"], 2, "E000"),
        (["render", HANDOVER, "-o", tmp_path / "x.gif"], 2, "needs a plan"),
        (["render", HANDOVER, plan_file, "-o", tmp_path / "x.gif", "--size", "10x10"], 2, "--size"),
        (["render", HANDOVER, plan_file, "-o", tmp_path / "x.gif", "--camera", "fisheye"], 2, "--camera"),
        (["render", HANDOVER, plan_file, "-o", tmp_path / "x.gif", "--fps", "0"], 2, "--fps"),
        (["render", HANDOVER, plan_file, "-o", tmp_path / "x.png", "--object-labels", "--no-labels"], 2, "opposite"),
        (["render", ROOT / "domains/symbolic/handover.mrg", "-o", tmp_path / "x.png"], 2, "E402"),
        (["render", HANDOVER, tmp_path / "none.json", "-o", tmp_path / "x.gif"], 2, "E500"),
        (["render", HANDOVER, plan_file, "-o", tmp_path / "missing" / "x.gif"], 2, "error[E"),
    ]
    bad = json.loads(plan_file.read_text())
    bad["steps"][0]["actions"][0]["object"] = "o99"
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps(bad))
    cases.append((["render", HANDOVER, wrong, "-o", tmp_path / "x.gif"], 2, "E510"))
    for args, want, text in cases:
        code, _, err = run(args, capsys)
        assert code == want and text in err, (args, code, err)
        assert "Traceback" not in err and len(err.strip().splitlines()) <= 3
    assert not list(tmp_path.glob("x.*"))


@pytest.mark.parametrize("value", [1e308, 1e5, -2e4])
def test_a_number_beyond_the_bound_in_a_plan_is_e510(
    plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], value: float
) -> None:
    """A hand-edited joint or placement number beyond 10,000 (the bound on any number of a problem) does not
    fit (E510), in every output: 1e308 was an internal error (an overflow), 1e5 and 1e6 rad drew for minutes
    and took gigabytes."""
    for field in ("configs", "place_pose"):
        bad = json.loads(plan_file.read_text())
        action = bad["steps"][0]["actions"][0]
        if field == "configs":
            action["configs"]["pick"][0][0] = value
        else:
            action["place_pose"][0][3] = value
        path = tmp_path / f"{field}.json"
        path.write_text(json.dumps(bad))
        for out in ("x.png", "x.html"):
            code, _, err = run(["render", HANDOVER, path, "-o", tmp_path / out, *SMALL], capsys)
            assert code == 2 and "error[E510]" in err and "within 10000" in err, err
            assert "Traceback" not in err and "Warning" not in err
    assert not list(tmp_path.glob("x.*"))


def test_a_joint_turned_far_in_a_plan_is_drawn_in_phases_of_at_most_max_phase(plan_file: Path) -> None:
    """Within the bound, a joint turned 10,000 rad away (outside its limits: drawn where it is) makes a phase
    of at most MAX_PHASE seconds, not 2,500 s of frames."""
    from mrgc.render.frames import MAX_PHASE, build_timeline
    from mrgc.render.world import World

    plan = json.loads(plan_file.read_text())
    plan["steps"][0]["actions"][0]["configs"]["pick"][0][0] = 1e4
    timeline = build_timeline(World(parse_file(str(HANDOVER)).problem(None), plan), plan)
    assert max(ph.duration for ph in timeline.phases) == pytest.approx(MAX_PHASE)
    assert len(timeline.frames(10)) < 10 * MAX_PHASE * len(timeline.phases)


# ------------------------------------------------------------------------------------------- graph
GOLDEN_GRAPH = ROOT / "tests" / "golden" / "graph"


@pytest.mark.parametrize("name,skeleton", [("place-obstacle", None), ("chain-3", 1), ("handover", None)])
def test_graph_dot_is_golden(
    name: str, skeleton: int | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / f"{name}.dot"
    args = ["graph", ROOT / "domains" / "symbolic" / f"{name}.mrg", "-o", out]
    if skeleton:
        args += ["--skeleton", skeleton]
    assert run(args, capsys)[0] == 0
    golden = GOLDEN_GRAPH / f"{name}{'-skeleton' if skeleton else ''}.dot"
    if os.environ.get("MRGC_UPDATE_GOLDEN"):
        golden.write_text(out.read_text(encoding="utf-8"), encoding="utf-8")
    assert out.read_text(encoding="utf-8") == golden.read_text(encoding="utf-8")


def test_graph_styles_edges_as_the_paper(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from mrgc.render.graph import ACTION_EDGE, BLOCK_PICK, BLOCK_PLACE

    out = tmp_path / "chain.dot"
    assert run(["graph", ROOT / "domains/symbolic/chain-3.mrg", "-o", out], capsys)[0] == 0
    text = out.read_text()
    edges = [ln for ln in text.splitlines() if "->" in ln and "legend" not in ln]
    assert all(ACTION_EDGE in ln for ln in edges if re.match(r'\s*"o', ln))  # object -> action
    assert all(BLOCK_PICK in ln or BLOCK_PLACE in ln for ln in edges if re.match(r'\s*"a\d', ln))
    assert any(BLOCK_PICK in ln for ln in edges) or any(BLOCK_PLACE in ln for ln in edges)


def test_a_large_graph_draws_a_skeleton_clustered_at_a_readable_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from mrgc.render import graph

    problem, facts = tmp_path / "cell.mrg", tmp_path / "cell.facts.mrg"
    args = ["--robots", 3, "--goals", 5, "--others", 3, "--seed", 1, "-o", problem]
    assert run(["generate", "packaging", *args], capsys)[0] == 0
    assert run(["facts", problem, "-o", facts], capsys)[0] == 0
    out = tmp_path / "cell.png"
    code, stdout, err = run(["graph", facts, "-o", out], capsys)
    assert code == 0, err
    actions = int(re.search(r"(\d+) actions", stdout).group(1))  # type: ignore[union-attr]
    assert actions > graph.LARGE_ACTIONS and "skeleton 1's" in stdout and "--full" in stdout
    with Image.open(out) as img:
        assert max(img.size) <= graph.MAX_PIXELS and min(img.size) >= 200, img.size
    dot = tmp_path / "cell.dot"
    assert run(["graph", facts, "-o", dot], capsys)[0] == 0
    text = dot.read_text()
    shown = re.findall(r'^\s*"a\d+" \[shape=box.*$', text, re.M)
    assert 0 < len(shown) < actions and all("\\nstep " in ln for ln in shown)  # the skeleton's actions only
    assert 'subgraph "cluster_' in text and "moves of " in text
    full = tmp_path / "full.dot"
    assert run(["graph", facts, "-o", full, "--full"], capsys)[0] == 0
    assert len(re.findall(r'^\s*"a\d+" \[shape=box', full.read_text(), re.M)) == actions
    monkeypatch.setattr(graph, "MAX_PIXELS", 600)  # the size guard scales a drawing down to fit
    code, stdout, _ = run(["graph", facts, "-o", tmp_path / "small.png", "--full"], capsys)
    assert code == 0 and "scaled down" in stdout
    with Image.open(tmp_path / "small.png") as img:
        assert max(img.size) <= 600 + 2, img.size


def test_graph_svg_through_dot_and_a_clear_message_without_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    from mrgc.render import graph

    assert shutil.which("dot"), (
        "Graphviz's dot is needed: apt-get install -y graphviz (tests/system-packages.sh installs it)"
    )
    svg = tmp_path / "g.svg"
    code, _, err = run(["graph", ROOT / "domains/symbolic/handover.mrg", "-o", svg, "--skeleton", 1], capsys)
    assert code == 0, err
    text = svg.read_text()
    assert "<svg" in text and "step 1" in text and "o3" in text
    monkeypatch.setattr(graph.shutil, "which", lambda name: None)
    code, _, err = run(["graph", ROOT / "domains/symbolic/handover.mrg", "-o", tmp_path / "h.png"], capsys)
    assert code == 4 and "apt-get install graphviz" in err and not (tmp_path / "h.png").exists()
    code, _, err = run(
        ["graph", ROOT / "domains/symbolic/handover.mrg", "-o", tmp_path / "h.dot", "--skeleton", 99], capsys
    )
    assert code == 2 and "--skeleton 99" in err


# ------------------------------------------------------------------------------------------- frames
configs = st.integers(2, 6).flatmap(
    lambda m: st.lists(st.lists(st.floats(-3, 3), min_size=3, max_size=3), min_size=m, max_size=m)
)


@settings(max_examples=60, deadline=None)
@given(configs, st.floats(0, 1))
def test_interpolation_passes_every_configuration_in_order(cs: list[list[float]], s: float) -> None:
    c = np.array(cs)
    assert np.allclose(interpolate(c, 0.0), c[0]) and np.allclose(interpolate(c, 1.0), c[-1])
    m = len(c)
    for k in range(m):
        assert np.allclose(interpolate(c, k / (m - 1)), c[k])
    q = interpolate(c, s)
    j = min(int(s * (m - 1)), m - 2)  # between configurations j and j+1, on the segment
    lo, hi = np.minimum(c[j], c[j + 1]), np.maximum(c[j], c[j + 1])
    assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9)


@settings(max_examples=60, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-np.pi, np.pi))
@example(-np.pi, 0.0)
def test_planar_yaw_turns_the_short_way(a: float, b: float) -> None:
    mid = interpolate(np.array([[0.0, 0.0, a], [0.0, 0.0, b]]), 0.5, planar=True)[2]
    turn = (b - a + np.pi) % (2 * np.pi) - np.pi
    half = ((mid - a) + np.pi) % (2 * np.pi) - np.pi
    if abs(abs(turn) - np.pi) < 1e-9:  # half a turn has no short way: either way is right
        assert abs(abs(half) - np.pi / 2) < 1e-9
    else:
        assert abs(half - turn / 2) < 1e-9


def test_phases_are_the_validators() -> None:
    from mrgc.validator.replay import PATH_PHASES

    assert set(PATH_PHASES) <= {"to-pick", "to-handover", "taker-to-handover", "to-place", "home", "giver-home"}
    assert PHASES == ("to-pick", "pick", "to-handover", "handover", "to-place", "place", "home")


# ------------------------------------------------------------------------------------------- names, legend
def _label_pixels(img: np.ndarray, box: tuple[int, int, int, int], fill: tuple[int, int, int]) -> tuple[float, int]:
    """The share of a label box's pixels in its fill colour, and how many are far from it (the name)."""
    x0, y0, x1, y1 = box
    part = img[y0 + 1 : y1, x0 + 1 : x1].astype(int)
    diff = np.abs(part - np.array(fill)).sum(axis=2)
    return float((diff <= 12).mean()), int((diff > 200).sum())


def test_sheet_names_robots_and_regions_and_has_a_legend(
    plan_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mrgc.render import outputs
    from mrgc.render.labels import frame_labels, world_legend
    from mrgc.render.picture import label_style, legend_band, place_labels, text_size

    plan = json.loads(plan_file.read_text())
    opts = outputs.Options(240, 180, 4.0)
    sheets = {}
    for name, flags in (("names", []), ("plain", ["--no-labels"])):
        sheets[name] = tmp_path / f"{name}.png"
        args = ["render", HANDOVER, plan_file, "-o", sheets[name], "--size", "240x180", "--fps", "4", *flags]
        assert run(args, capsys)[0] == 0
    # where the first tile's names are: the same layout, camera and placement as the command's
    world, _, frames, _ = outputs.replay_frames(parse_file(str(HANDOVER)).problem(None), plan, opts, "plan")
    keys = [f for f in frames if f.key]
    lay = outputs.frame_layout(world, keys, opts, legend=False)
    camera = outputs.frame_camera(world, frames, opts, lay)
    labels = frame_labels(world, keys[0], camera, 240, lay.scene_height, lay.labels)
    assert {lb.text for lb in labels} == {"r1", "r2", *(b.name for b, _ in world.regions)}
    named = np.asarray(Image.open(sheets["names"]).convert("RGB"))
    plain = np.asarray(Image.open(sheets["plain"]).convert("RGB"))
    top = legend_band(named.shape[1], world_legend(world), text_size(300)).shape[0]
    assert named.shape[0] == plain.shape[0] + top  # the legend band over the sheet
    for label, (x0, y0, x1, y1) in place_labels(labels, lay.size, 240, lay.scene_height):
        fill = label_style(label)[0]
        share, ink = _label_pixels(named, (x0, y0 + top, x1, y1 + top), fill)
        assert share > 0.35 and ink >= 3, (label.text, share, ink)  # the box in its colour, the name in it
        share, ink = _label_pixels(plain, (x0, y0, x1, y1), fill)
        assert share < 0.35 or ink < 3, label.text  # (the check fails without names)
    legend = named[:top]
    for colour in ROBOT_COLOURS[:2]:
        assert (np.abs(legend.astype(int) - byte_colour(colour)).sum(axis=2) <= 6).sum() >= 20


def test_planar_robots_are_named_where_they_stand_and_show_their_heading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mrgc.render import outputs
    from mrgc.render.labels import frame_labels

    bo8 = ROOT / "domains" / "box-moving" / "bo8-two-doors.mrg"
    out = tmp_path / "bo8.png"
    assert run(["render", bo8, "-o", out, "--camera", "top", "--object-labels"], capsys)[0] == 0
    img = np.asarray(Image.open(out).convert("RGB"))
    world = World(parse_file(str(bo8)).problem(None))
    frame = outputs.scene_frame(world)
    opts = outputs.Options(400, 300, labels=("robot", "region", "object"))
    lay = outputs.frame_layout(world, [frame], opts)
    camera = outputs.frame_camera(world, [frame], opts, lay)
    names = {lb.text: lb for lb in frame_labels(world, frame, camera, 400, lay.scene_height, lay.labels)}
    assert {"r1", "r2", "start", "goal", "g1", "b3"} <= set(names)
    for robot in ("r1", "r2"):
        view = world.robots[robot]
        parts = {p.name: pose for p, pose in view.part_poses(view.home)}
        heading = parts[f"{robot}/heading"]
        tip = heading[:3, :3] @ np.array([0.95 * view.mobile.half[0], 0, 0])
        yaw = view.home[2]
        assert np.allclose(tip[:2] / np.linalg.norm(tip[:2]), [np.cos(yaw), np.sin(yaw)])  # it points ahead
        # the name sits over the robot: its anchor projects inside the robot's footprint's picture
        c, r, _ = camera.project(parts[f"{robot}/footprint"][:3, 3].reshape(1, 3), 400, lay.scene_height)
        assert abs(names[robot].x - c[0]) < 25 and 0 <= r[0] - names[robot].y < 40
    # white arrowheads on the robots' tops (from above)
    assert (img[lay.top : lay.top + lay.scene_height].min(axis=2) > 225).sum() > 20


def test_what_stands_in_a_region_keeps_its_colour() -> None:
    from mrgc.render.camera import Camera
    from mrgc.render.raster import region_patches, tint_regions

    camera = Camera(np.array([0.0, 0.0, 3.0]), np.zeros(3), np.array([0.0, 1.0, 0.0]))
    pose = np.eye(4)
    pose[2, 3] = 0.25  # a 1 × 1 × 0.5 region standing on the floor (z = 0)
    patches = region_patches(camera, [(pose, np.array([0.5, 0.5, 0.25]), GOAL_REGION)], 100, 100)
    depth = np.full((100, 100), 3.0)  # the floor
    depth[45:55, 45:55] = 2.8  # a robot standing in the region
    robot = byte_colour(ROBOT_COLOURS[0])
    rgb = np.empty((100, 100, 3), dtype=np.uint8)
    rgb[:] = (200, 200, 200)
    rgb[45:55, 45:55] = robot
    out = tint_regions(rgb, depth, patches)
    assert (out[47:53, 47:53] == robot).all()  # the robot is not veiled
    floor = out[30, 40].astype(int)
    assert floor[1] > floor[0] and floor[1] > floor[2]  # the floor in the region is tinted green
    assert (out[2, 2] == (200, 200, 200)).all()  # outside the region nothing changes


SHIPPED_REPLAYS = [ROOT / "domains" / "packaging" / "pa10.mrg", ROOT / "domains" / "box-moving" / "bo8-two-doors.mrg"]


@pytest.mark.parametrize("problem", SHIPPED_REPLAYS, ids=lambda p: p.stem)
def test_sheets_and_html_replays_of_pa10_and_bo8_name_their_robots_and_regions(
    problem: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 24's "done when": a PNG sheet and the HTML replay of pa10 and bo8 show robot and region names
    (the sheet by the pixels of each name's box, which fail without names; the replay in headless Chromium:
    the legend names every robot and region, and dark glyphs stand where each region's name is anchored)."""
    from mrgc.render import outputs
    from mrgc.render.labels import anchors, frame_labels, world_legend
    from mrgc.render.picture import label_style, legend_band, place_labels, text_size

    plan_path = tmp_path / "plan.json"
    assert cli.main(["plan", str(problem), "-o", str(plan_path), "--time-limit", "300"]) == 0
    plan = json.loads(plan_path.read_text())
    opts = outputs.Options(320, 240, 4.0)
    sheet = tmp_path / "sheet.png"
    assert run(["render", problem, plan_path, "-o", sheet, "--size", "320x240", "--fps", "4"], capsys)[0] == 0
    world, _, frames, _ = outputs.replay_frames(parse_file(str(problem)).problem(None), plan, opts, "plan")
    keys = [f for f in frames if f.key]
    lay = outputs.frame_layout(world, keys, opts, legend=False)
    camera = outputs.frame_camera(world, frames, opts, lay)
    labels = frame_labels(world, keys[0], camera, 320, lay.scene_height, lay.labels)
    robots = {r.name for r in parse_file(str(problem)).problem(None).robots}
    regions = {b.name for b, _ in world.regions}
    assert {lb.text for lb in labels} == robots | regions

    named = np.asarray(Image.open(sheet).convert("RGB"))
    top = legend_band(named.shape[1], world_legend(world), text_size(300)).shape[0]
    for label, (x0, y0, x1, y1) in place_labels(labels, lay.size, 320, lay.scene_height):
        share, ink = _label_pixels(named, (x0, y0 + top, x1, y1 + top), label_style(label)[0])
        assert share > 0.35 and ink >= 3, (problem.stem, label.text, share, ink)
    page_path = tmp_path / "replay.html"
    assert run(["render", problem, plan_path, "-o", page_path, "--fps", "5"], capsys)[0] == 0
    page = page_path.read_text(encoding="utf-8")
    legend = page[page.index('<div id="mrgc-legend"') :]
    assert all(f">{name}</div>" in legend for name in robots), robots
    assert all(name in legend for name in regions), regions
    html_frames = build_timeline(world, plan).frames(5)
    html_camera = outputs.html_camera(world, html_frames, outputs.Options())
    points = {lb.text: p.reshape(-1, 3).mean(axis=0) for lb, p in anchors(world, html_frames[0]) if lb.text in regions}

    def unnamed(picture: np.ndarray) -> list[str]:
        h, w = picture.shape[:2]
        dark = picture.max(axis=2) < 150
        out = []
        for name, point in points.items():
            c, r, _ = html_camera.project(point[None], w, h)
            x, y = int(c[0]), int(r[0])
            if dark[max(0, y - 80) : y + 40, max(0, x - 70) : x + 70].sum() < 12:
                out.append(name)
        return out

    picture, ok = screenshot_when(page_path.as_uri(), lambda p: non_blank(p) and not unnamed(p), timeout=150)
    Image.fromarray(picture).save(tmp_path / "chromium.png")
    assert ok, f"region names missing in the replay: {unnamed(picture)} ({tmp_path / 'chromium.png'})"


@settings(max_examples=200, deadline=None)
@given(
    w=st.integers(16, 4096),
    h=st.integers(16, 4096),
    caption=st.text(alphabet="abc ,.", min_size=0, max_size=300),
)
@example(w=400, h=16, caption="pa3-handover: step 1 of 1, to-place: r1 hands o1 over to r2")
def test_every_allowed_size_leaves_half_the_picture_to_the_scene(w: int, h: int, caption: str) -> None:
    """At the documented 16 px the caption band used to take the whole height: pybullet was asked for a
    picture of no rows (std::bad_alloc, exit 134) or 1 row (ZeroDivisionError, exit 70)."""
    from mrgc.render.picture import layout

    lay = layout(w, h, [caption] if caption else [])
    assert lay.scene_height >= h / 2 and lay.scene_height > 0


def test_the_smallest_pictures_are_drawn(tmp_path: Path) -> None:
    src = ROOT / "domains" / "packaging" / "pa3-handover.mrg"
    for size in ("16x16", "400x17"):
        out = tmp_path / f"{size}.png"
        assert cli.main(["render", str(src), "--size", size, "-o", str(out)]) == 0
        assert Image.open(out).size == tuple(int(v) for v in size.split("x"))
