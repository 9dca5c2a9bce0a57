"""The check and fmt commands end to end (through cli.main, and once through the installed script)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from mrgc import __version__, cli

GOOD = """(define (domain abstract) (:grasps top side))
(define (problem tiny)  (:domain abstract)
  (:robots r1) (:movable o1) (:regions start goal)   ; one object
  (:init (in-region o1 start) (reachable-pick o1 top r1) (reachable-place o1 goal top r1))
  (:goal (in-region o1 goal)))
"""


@pytest.fixture()
def good(tmp_path: Path) -> Path:
    path = tmp_path / "tiny.mrg"
    path.write_text(GOOD, encoding="utf-8")
    return path


def test_check_ok(good: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["check", str(good)]) == 0
    out = capsys.readouterr().out
    assert "ok" in out and "problem tiny (symbolic: 1 robot, 1 movable, 2 regions, 1 goal, 3 facts)" in out


def test_check_names_a_domain_two_problems_share_once(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two problems of one file using the domain.mrg beside it: the domain is named once (each problem loads
    its own copy of it, and the line named it once per copy)."""
    (tmp_path / "domain.mrg").write_text(GOOD.split("\n", 1)[0] + "\n", encoding="utf-8")
    problems = GOOD.split("\n", 1)[1]
    (tmp_path / "two.mrg").write_text(problems + problems.replace("tiny", "tiny-b"), encoding="utf-8")
    assert cli.main(["check", str(tmp_path / "two.mrg")]) == 0
    out = capsys.readouterr().out
    assert out.count("domain abstract from") == 1 and "problem tiny (" in out and "problem tiny-b (" in out


def test_check_reports_every_file(good: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.mrg"
    bad.write_text(GOOD.replace("(reachable-pick o1 top r1)", "(reachable-pick o1 top r9)"), encoding="utf-8")
    assert cli.main(["check", str(bad), str(good)]) == 2
    cap = capsys.readouterr()
    assert "error[E210]: undeclared robot 'r9' (did you mean 'r1'?)" in cap.err
    assert str(good) in cap.out


def test_fmt_prints_canonical_text(good: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["fmt", str(good)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("(define (domain abstract)\n  (:grasps top side))\n\n(define (problem tiny)\n")
    assert "(:regions start goal) ; one object" in out


def test_fmt_check_and_write(good: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["fmt", "--check", str(good)]) == 1
    assert "would reformat" in capsys.readouterr().err
    assert cli.main(["fmt", "--write", str(good)]) == 0
    assert cli.main(["fmt", "--check", str(good)]) == 0
    text = good.read_text(encoding="utf-8")
    assert "; one object" in text
    assert cli.main(["check", str(good)]) == 0


def test_fmt_of_a_broken_file_is_an_input_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.mrg"
    bad.write_text("(define (domain d) (:grasps top)", encoding="utf-8")
    assert cli.main(["fmt", "--check", str(bad)]) == 2
    assert "error[E102]" in capsys.readouterr().err


def test_fmt_needs_a_mode_for_several_files(good: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["fmt", str(good), str(good)]) == 2
    assert "error[E000]" in capsys.readouterr().err


def test_no_command_prints_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main([]) == 2
    assert "usage: mrgc" in capsys.readouterr().out


def test_installed_script(good: Path) -> None:
    exe = str(Path(sys.executable).with_name("mrgc"))  # the console script installed beside this interpreter
    version = subprocess.run([exe, "--version"], capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.strip() == f"mrgc {__version__}"
    res = subprocess.run([exe, "check", str(good)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr


def test_the_command_leaves_its_start_up_objects_to_the_collector_again_when_it_ends(
    good: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``mrgc plan`` freezes the objects that exist when it starts for the run (the collector's full passes
    skip them) and unfreezes them when it ends: an in-process caller keeps nothing frozen."""
    import gc

    from mrgc import api

    seen: list[int] = []
    real = api.plan

    def plan(*args: object, **kwargs: object) -> object:
        seen.append(gc.get_freeze_count())
        return real(*args, **kwargs)

    monkeypatch.setattr(api, "plan", plan)
    before = gc.get_freeze_count()
    assert cli.main(["plan", str(good), "-o", str(tmp_path / "plan.json")]) == 0
    assert len(seen) == 1 and seen[0] > before + 1000  # the modules, the problem, the command line
    assert gc.get_freeze_count() == before


@pytest.mark.parametrize("ompl", [False, True])
def test_the_command_spares_the_interpreter_s_exit_its_full_collection_unless_ompl_was_loaded(ompl: bool) -> None:
    # an exit handler registered before mrgc.cli loads runs after the command's own (last in, first out); with
    # OMPL loaded (a path planned) the exit keeps its collection, and nanobind finds nothing leaked
    path = (
        "from mrgc.geometry.motion import plan_joint_path; "
        "print(plan_joint_path([0, 0], [1, 1], [0.1, 0.1], [0.9, 0.9], lambda q: True).solved, flush=True); "
    )
    probe = (
        "import atexit, gc; atexit.register(lambda: print(gc.get_freeze_count() > 1000, flush=True)); "
        "import mrgc.cli; print(gc.get_freeze_count(), flush=True); " + (path if ompl else "")
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == (["0", "True", "False"] if ompl else ["0", "True"]), out.stderr
    assert "leaked" not in out.stderr


@pytest.mark.parametrize("given, threads", [(None, "1"), ("2", "2")])
def test_the_command_runs_numpy_s_blas_on_one_thread_unless_told_otherwise(given: str | None, threads: str) -> None:
    # what numpy's OpenBLAS reads when it loads, and the threads its pool started (this interpreter's tasks)
    probe = (
        "import os, mrgc.cli, numpy; "
        "print(os.environ['OPENBLAS_NUM_THREADS'], len(os.listdir('/proc/self/task')), len(os.sched_getaffinity(0)))"
    )
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=60)
    seen, tasks, cores = out.stdout.split()
    assert seen == threads, out.stderr
    # OpenBLAS starts one thread fewer than it uses (the caller's is one), at most one per core
    assert int(tasks) == min(int(threads), int(cores)), f"{tasks} threads on {cores} cores, asked {threads}"
