"""The benchmark scripts take what a study needs: ``benchmarks/planning.py --problems`` names shipped
problems or paths of .mrg files (a file of one's own, a generated one)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from support import ROOT

SCRIPT = ROOT / "benchmarks" / "planning.py"


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def test_planning_takes_paths_of_mrg_files(tmp_path: Path) -> None:
    own = tmp_path / "mine.mrg"
    own.write_text(
        (ROOT / "domains" / "symbolic" / "domain.mrg").read_text(encoding="utf-8")
        + "\n"
        + (ROOT / "domains" / "symbolic" / "chain-3.mrg").read_text(encoding="utf-8"),
        encoding="utf-8",
    )
    out = run(
        "--problems",
        "mine.mrg",
        str(ROOT / "domains" / "symbolic" / "handover.mrg"),
        "--seeds",
        "1",
        "--time-limit",
        "30",
        cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    rows = [line.split(" | ") for line in out.stdout.splitlines()[2:]]
    assert [(r[0], r[1]) for r in rows] == [("| mine", "1/1"), ("| handover", "1/1")], out.stdout
    assert rows[0][4] == "1" and rows[1][4] == "3"  # makespans of chain-3 and handover


def test_planning_refuses_what_is_neither_a_name_nor_a_file(tmp_path: Path) -> None:
    for item, why in (("missing.mrg", "no such file"), ("pa55", "not a shipped problem or a .mrg file")):
        out = run("--problems", "pa5", item, cwd=tmp_path)
        assert out.returncode == 2 and out.stdout == ""
        assert out.stderr.startswith(f"planning.py: error: --problems {item}: {why} (shipped: pa-basic")


def test_phase1_cpu_times_the_generated_instances_of_a_preset(tmp_path: Path) -> None:
    """``benchmarks/phase1.py --cpu PRESET --seeds ...``: one row per generated instance with its fact count (that
    of ``compute_facts`` on the same instance) and CPU seconds; an unknown preset is refused by argparse."""
    from mrgc import parse_string
    from mrgc.generate import preset
    from mrgc.geometry.predicates import compute_facts
    from mrgc.geometry.scene import scene_from_problem

    script = ROOT / "benchmarks" / "phase1.py"
    cmd = [sys.executable, str(script), "--cpu", "pa5", "--seeds", "3", "--repeat", "1"]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stderr
    row = out.stdout.splitlines()[-1].split("|")
    problem = parse_string(preset("pa5", 3), "pa5-s3.mrg", str(ROOT / "domains" / "packaging")).problem()
    assert row[1].strip() == "pa5-s3" and int(row[2]) == len(compute_facts(scene_from_problem(problem)).facts)
    assert 0 < float(row[4]) <= float(row[3])
    bad = subprocess.run([sys.executable, str(script), "--cpu", "pa55"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "invalid choice: 'pa55'" in bad.stderr


def test_abba_plans_each_instance_with_both_trees_in_turn(tmp_path: Path) -> None:
    """``benchmarks/abba.py``: four runs per instance (A, B, B, A), each tree's CPU times, and per instance set
    the medians and ratios, and whether the four plans are the same (one tree twice here: they are)."""
    tree = tmp_path / "tree"
    tree.mkdir()
    (tree / "mrgc").symlink_to(ROOT, target_is_directory=True)
    problem = ROOT / "domains" / "symbolic" / "chain-3.mrg"
    cmd = [sys.executable, str(ROOT / "benchmarks" / "abba.py"), "--a", str(tree), "--b", str(tree)]
    out = subprocess.run(
        [*cmd, "--out", str(tmp_path / "out"), str(problem)], capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert [line.split()[:2] for line in lines[:4]] == [["chain-3", s] for s in "abba"]
    assert all(float(line.split()[2]) > 0 for line in lines[:4])
    assert lines[4].startswith("chain: 1 instances, median CPU A ") and lines[4].endswith("same plans on 1")
    assert sorted(p.name for p in (tmp_path / "out").glob("*.json")) == [
        f"chain-3-{k}{s}.json" for k, s in enumerate("abba")
    ]


def test_motion_state_costs_each_stage_of_a_motion_check(tmp_path: Path) -> None:
    """``benchmarks/motion_state.py FILE --states N``: the instance, robot and number of states (and how many of
    them hit the world), then a row per stage with its microseconds per state."""
    script = ROOT / "benchmarks" / "motion_state.py"
    pa10 = ROOT / "domains" / "packaging" / "pa10.mrg"
    cmd = [sys.executable, str(script), str(pa10), "--robot", "r2", "--states", "60"]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    head = lines[0].split(", ")
    assert head[0] == "pa10.mrg" and head[1].startswith("r2 holding ") and head[2] == "60 states"
    assert 0 <= int(head[3].split()[0]) <= 60
    rows = [line.strip("|").split("|") for line in lines[3:]]
    assert len(rows) == 5 and rows[-1][0].strip() == "a state of a motion check (Volumes.free_posed)"
    assert all(float(r[1]) > 0 for r in rows)
    bad = subprocess.run([*cmd[:3], "--robot", "r9"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert bad.returncode == 2 and bad.stderr.splitlines()[-1] == (
        "motion_state.py: error: --robot r9: not an arm of pa10.mrg (its arms: r1, r2)"
    )


def _table(cmd: list[str]) -> tuple[str, dict[str, tuple[str, str]]]:
    """A table script's first line and its rows (first column -> the next two), the script exiting 0."""
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    return lines[0], {r[0].strip("| "): (r[1], r[2]) for r in (line.split(" | ") for line in lines[4:])}


def test_search_log_classes_each_grounding_line_and_its_seconds(tmp_path: Path) -> None:
    """``benchmarks/search_log.py LOG``: the grounding lines of a ``-v`` log, written here by the search's own
    formatter (``planner/search.py``'s ``_log_line``), counted by where they were grounded and how the root's
    ended (the action of the first failure), with the seconds since the line before; a file without one is
    refused with exit code 2."""
    from mrgc.compiler.skeleton import Skeleton
    from mrgc.compiler.task_graph import Action
    from mrgc.geometry.collision import Packed, Posed
    from mrgc.planfile.format import PlannedAction
    from mrgc.planner.ground import GroundedStep, Grounding, Outcome, label
    from mrgc.planner.outcome import Failure
    from mrgc.planner.search import _log_line

    park = Action("o2", "start", "r1", "r1", "top", "top")
    relay = Action("o1", "bin-b", "r1", "r2", "top", "top", via="start")
    hand = Action("o1", "bin-b", "r1", "r2", "top", "side")
    cart = Action("b1", "goal", "cart1", "cart1", "push", "push")  # a robot of any name
    skel = Skeleton(((park,), (hand,)))
    step = GroundedStep([PlannedAction("o1", "bin-b", "r1", "r2", "top", "side")], Packed.of(Posed.of([])), ("o1",))
    lines = [
        _log_line(
            2.0, 1, skel, [], Grounding(Outcome.FAIL, failures=[Failure(1, label(park), "place by r1: collision")])
        ),
        _log_line(
            5.5,
            2,
            Skeleton(((relay,),)),
            [],
            Grounding(Outcome.PARTIAL, [step], {"o3"}, failures=[Failure(1, label(relay), "relay: no spot")]),
        ),
        "  deferred after 3 failures: r1 places o2 in start (skeletons without it first)",
        _log_line(6.0, 3, Skeleton(((park,),)), [step], Grounding(Outcome.FAIL, reason="no", failures=[])),
        _log_line(
            7.0, 4, Skeleton(((cart,),)), [], Grounding(Outcome.FAIL, failures=[Failure(1, label(cart), "drive")])
        ),
        _log_line(9.0, 5, skel, [], Grounding(Outcome.SUCCESS, [step])),
    ]
    log = tmp_path / "run.log"
    log.write_text("\n".join(lines) + "\n", encoding="utf-8")
    script = ROOT / "benchmarks" / "search_log.py"
    head, rows = _table([sys.executable, str(script), str(log)])
    assert head == "5 groundings, the last at t=9.0 s"
    assert rows == {
        "root, fail, move start": ("1", "2.0"),
        "root, fail, move goal": ("1", "1.0"),
        "root, partial, relay via start": ("1", "3.5"),
        "under a partial suffix": ("1", "0.5"),
        "plan": ("1", "2.0"),
    }, rows
    # by the check that failed, over two logs: robots and the object of the failing action written R and O
    more = tmp_path / "more.log"
    clash = Failure(2, label(hand), "pick: robots of the step collide", ("r1", "r2"))
    unnamed = Failure(0, "", "placement: no free pose")  # a failure no action was named for yet
    more.write_text(
        _log_line(4.0, 1, skel, [], Grounding(Outcome.FAIL, failures=[clash]))
        + "\n"
        + _log_line(4.5, 2, skel, [], Grounding(Outcome.FAIL, failures=[unnamed]))
        + "\n",
        encoding="utf-8",
    )
    head, rows = _table([sys.executable, str(script), "--by", "check", str(log), str(more)])
    assert head == "7 groundings, 13.5 s in 2 logs"
    assert rows == {
        "fail: place by R: collision": ("1", "2.0"),
        "fail: drive": ("1", "1.0"),
        "fail: pick: robots of the step collide": ("1", "4.0"),
        "fail: placement: no free pose": ("1", "0.5"),
        "partial": ("1", "3.5"),
        "fail: no": ("1", "0.5"),
        "plan": ("1", "2.0"),
    }, rows
    # partial groundings by the strict failure their relaxed attempt got past (the one partial line: a relay)
    head, rows = _table([sys.executable, str(script), "--by", "partial", str(log)])
    assert head == "5 groundings, the last at t=9.0 s"
    assert rows == {"not partial": ("4", "5.5"), "partial after: relay: no spot": ("1", "3.5")}, rows
    empty = tmp_path / "quiet.log"
    empty.write_text("plan for x: solved\n", encoding="utf-8")
    out = subprocess.run([sys.executable, str(script), str(empty)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "no grounding line" in out.stderr
