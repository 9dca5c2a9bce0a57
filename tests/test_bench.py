"""Studies (mrgc bench): schema errors, method command lines, resume after SIGTERM, limits (timeout, memout),
crashes, invalid plans, skipped planners, the Ray executor, golden reports on a fixed database, figures.

Runs are real ``mrgc plan`` / ``mrgc validate`` processes on symbolic problems (fast) or a shipped
packaging problem where a run must outlast a limit.  Golden reports: ``tests/golden/bench/runs.sql`` is a
fixed database (recorded from a real run of ``tests/golden/bench/study.yaml``, see docs/bench.md); the
expected reports are regenerated with MRGC_UPDATE_GOLDEN=1.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import sqlite3
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from mrgc.bench import ResultsDB, RunStatus, parse_study, render, run_study
from mrgc.bench.execute import RunTask, execute_run, mrgc_argv
from mrgc.bench.instances import expand_instances
from mrgc.bench.methods import check_methods, method_args
from mrgc.bench.outcome import classify, why_detail
from mrgc.bench.runner import run_limited
from mrgc.bench.schema import parse_megabytes, parse_seeds
from mrgc.bench.study import Limits
from mrgc.errors import InputError

ROOT = Path(__file__).resolve().parent.parent
SYMBOLIC = ROOT / "domains" / "symbolic"
GOLDEN = ROOT / "tests" / "golden" / "bench"
MRGC = [sys.executable, "-m", "mrgc.cli"]


def symbolic_copy(folder: Path, *names: str) -> Path:
    """Copies of shipped symbolic problems (and their domain) in ``folder``: paths no other test uses."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("domain", *names):
        shutil.copy(SYMBOLIC / f"{name}.mrg", folder / f"{name}.mrg")
    return folder


def packaging_copy(folder: Path, name: str) -> Path:
    """A copy of a shipped packaging problem (and its domain) in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    for file in ("domain", name):
        shutil.copy(ROOT / "domains" / "packaging" / f"{file}.mrg", folder / f"{file}.mrg")
    return folder


def write_study(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def leftover(marker: str) -> list[str]:
    """Command lines of live processes that mention ``marker`` (a test's temporary folder)."""
    out = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if marker in cmd and state != "Z" and int(pid) != os.getpid():
            out.append(cmd)
    return out


def rows(db: Path) -> list[dict[str, object]]:
    with ResultsDB(str(db), readonly=True) as results:
        return list(results.runs())


# ---------------------------------------------------------------- study files
def test_a_study_file_is_checked_with_every_error_located() -> None:
    text = (
        "study: demo\n"
        "seeds: 0..x\n"
        "limits: {time: -1, memory: lots}\n"
        "instances:\n"
        "  - file: a.mrg\n"
        "    glob: '*.mrg'\n"
        "methods:\n"
        "  - {name: Ours, planer: mcts}\n"
        "  - {name: Skel, compile: true, planner: mcts}\n"
    )
    with pytest.raises(InputError) as err:
        parse_study(text, "s.yaml")
    lines = {(d.span.line, d.span.column, d.code) for d in err.value.diagnostics if d.span}
    assert (2, 8, "E601") in lines  # seeds
    assert (3, 16, "E601") in lines and (3, 28, "E601") in lines  # time, memory
    assert (5, 5, "E601") in lines  # file and glob
    assert (8, 18, "E601") in lines  # planer
    assert (9, 33, "E601") in lines  # a compile-only method has no planner
    messages = " ".join(d.message for d in err.value.diagnostics)
    assert "did you mean 'planner'" in messages
    with pytest.raises(InputError) as err:
        parse_study("study: x\ninstances: [\n", "s.yaml")
    assert err.value.diagnostics[0].code == "E600" and err.value.diagnostics[0].span is not None


@pytest.mark.parametrize("path", sorted((ROOT / "benchmarks").glob("*.yaml")), ids=lambda p: p.name)
def test_every_shipped_study_file_is_a_valid_study(path: Path) -> None:
    study = parse_study(path.read_text(encoding="utf-8"), str(path))
    assert study.name and study.methods and study.instances


def test_a_valid_study_and_its_methods_as_mrgc_command_lines() -> None:
    study = parse_study(
        "study: demo\nseeds: [0, 3..4]\nlimits: {time: 20, memory: 2GB}\n"
        "instances: [{file: ../domains/symbolic/chain-3.mrg}]\n"
        "methods:\n"
        "  - {name: Ours, backend: mip, encoding: paper, options: {skeletons: 3, c: 0.5, anytime: true,"
        " max_makespan: 4}, limits: {wall: 9}}\n"
        "  - {name: Ap1, planner: ap1}\n"
        "  - {name: Skel, compile: true, backend: smt, options: {skeletons: 2}, only: [chain-3]}\n",
        str(ROOT / "benchmarks" / "x.yaml"),
    )
    assert study.seeds == (0, 3, 4)
    ours, ap1, skel = study.methods
    assert ours.limits == Limits(time=20.0, wall=9.0, memory_mb=2048.0) and ap1.limits.wall_seconds == 70
    assert method_args(ours) == [
        "plan",
        "--backend",
        "mip",
        "--encoding",
        "paper",
        "--skeletons",
        "3",
        "-c",
        "0.5",
        "--anytime",
        "--max-makespan",
        "4",
    ]
    assert method_args(ap1) == ["plan", "--planner", "ap1"]
    assert method_args(skel) == ["compile", "--format", "json", "--backend", "smt", "--skeletons", "2"]
    assert check_methods(study) == ([], {})
    from mrgc.cli import build_parser

    for m in study.methods:  # every command line is one the real parser accepts
        args = build_parser().parse_args([*method_args(m)[:1], "x.mrg", *method_args(m)[1:]])
        # mrgc plan passes a planner only the options given (its own defaults apply); compile's default is cpsat
        assert getattr(args, "backend", "cpsat") == (m.backend or "cpsat")
    with pytest.raises(InputError) as err:  # the methods' errors come with the study's (once, all of them)
        parse_study(
            "study: d\ninstances: [{file: a.mrg}]\nmethods:\n  - {name: A, options: {skeleton: 3}}\n"
            "  - {name: B, backend: cplex, options: {anytime: 3}}\n  - {name: C, options: {seed: 1}}\n"
            "  - {name: D, options: {skeletons: 0}}\n",
            "s.yaml",
        )
    diags = err.value.diagnostics
    text = "\n".join(d.message for d in diags)
    assert "option 'skeletons': must be a whole number from 1 to 10,000 (got 0)" in text  # was "'0' is not an integer"
    assert "no option --skeleton (did you mean 'skeletons'?)" in text and "unknown backend 'cplex'" in text
    assert "is a flag" in text and "set by the study itself" in text


def test_each_run_computes_its_own_phase_1_unless_the_study_shares_the_facts_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the runs' processes inherit this environment: the cache on, in a folder of this test's own
    monkeypatch.delenv("MRGC_NO_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    packaging_copy(tmp_path / "p", "pa3-place-obstacle")
    entries = tmp_path / "cache" / "mrgc" / "facts"
    for sharing, stored in (("", 0), ("facts_cache: own\n", 0), ("facts_cache: shared\n", 1)):
        study = write_study(
            tmp_path / "s.yaml",
            f"study: cache{len(sharing)}\nlimits: {{time: 60}}\n{sharing}"
            "instances: [{file: p/pa3-place-obstacle.mrg}]\nmethods: [{name: O, backend: mip}]\n",
        )
        db = tmp_path / f"r{len(sharing)}.db"
        run_study(str(study), str(db))
        (row,) = rows(db)
        assert row["success"], row["stderr_tail"]
        assert str(row["command"]).endswith(" --no-cache") == (stored == 0), row["command"]
        assert len(list(entries.glob("*.json")) if entries.is_dir() else []) == stored, sharing
    with pytest.raises(InputError) as err:
        parse_study("study: x\nfacts_cache: yes\ninstances: [{file: a.mrg}]\nmethods: [{name: O}]\n", "s.yaml")
    (diag,) = err.value.diagnostics
    assert diag.code == "E601" and diag.span is not None and (diag.span.line, diag.span.column) == (2, 14)
    assert "facts_cache must be one of own, shared" in diag.message


@given(st.integers(0, 10**6), st.integers(0, 50))
def test_seed_ranges_are_inclusive(a: int, n: int) -> None:
    assert parse_seeds(f"{a}..{a + n}") == tuple(range(a, a + n + 1))
    assert parse_seeds([a, f"{a + 1}..{a + 1 + n}"]) == (a, *range(a + 1, a + n + 2))
    assert parse_seeds(f"{a + n + 1}..{a}") is None and parse_seeds(-1 - a) is None


def test_memory_sizes() -> None:
    assert [parse_megabytes(v) for v in (512, "512MB", "4GB", "4 GiB", "1.5G", "2048k")] == [
        512,
        512,
        4096,
        4096,
        1536,
        2,
    ]
    assert [parse_megabytes(v) for v in ("lots", 0, -3, True, "4 parsecs")] == [None] * 5


def test_generated_instances_are_the_generator_s_text_and_bad_calls_are_located(tmp_path: Path) -> None:
    study = parse_study(
        "study: gen\ninstances:\n  - {generate: packaging, name: tiny, robots: 2, goals: 1, "
        "others: 0, seeds: 0..1}\nmethods: [{name: Ours}]\n",
        str(tmp_path / "s.yaml"),
    )
    instances = expand_instances(study, str(tmp_path / "work"))
    assert [i.name for i in instances] == ["tiny-s0", "tiny-s1"] and instances[0].sha256 != instances[1].sha256
    cli = subprocess.run(
        [*MRGC, "generate", "packaging", "--robots", "2", "--goals", "1", "--others", "0", "--seed", "1"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert Path(instances[1].path).read_text(encoding="utf-8") == cli.stdout
    assert dict(instances[0].bases) == {"r1": "fixed", "r2": "fixed"}
    bad = parse_study(
        "study: gen\ninstances:\n  - {generate: packaging, robots: 99}\nmethods: [{name: O}]\n",
        str(tmp_path / "s.yaml"),
    )
    with pytest.raises(InputError) as err:
        expand_instances(bad, str(tmp_path / "work"))
    d = err.value.diagnostics[0]
    assert d.code == "E602" and d.span is not None and d.span.line == 3 and "--robots" in d.message


# ---------------------------------------------------------------- running
def test_a_study_killed_mid_way_and_resumed_loses_no_finished_run_and_repeats_none(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3", "parallel", "place-obstacle")
    study = write_study(
        tmp_path / "s.yaml",
        "study: resume\nseeds: 0..1\nlimits: {time: 30}\n"
        "instances: [{glob: p/*.mrg, name: sym}]\nmethods: [{name: Ours}]\n",
    )
    db = tmp_path / "r.db"
    proc = subprocess.Popen(
        [*MRGC, "bench", "run", str(study), "--db", str(db), "--jobs", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    seen = []
    deadline = time.monotonic() + 120
    while len(seen) < 2 and time.monotonic() < deadline:
        line = proc.stdout.readline()
        if line.startswith("["):
            seen.append(line)
    time.sleep(0.3)  # let the third run start: it is in flight when the signal comes
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "terminated (SIGTERM)" in err
    first = rows(db)
    assert len(first) >= 2 and all(r["success"] for r in first)
    assert not leftover(str(tmp_path / "p")), "a run outlived bench run"
    again = subprocess.run(
        [*MRGC, "bench", "run", str(study), "--db", str(db)], capture_output=True, text=True, timeout=300
    )
    assert again.returncode == 0, again.stderr
    assert f"6 runs, {len(first)} recorded and kept, {6 - len(first)} to run" in again.stdout
    final = rows(db)
    keys = [(r["instance"], r["seed"]) for r in final]
    assert len(final) == 6 and len(set(keys)) == 6
    assert [r for r in final if (r["instance"], r["seed"]) in {(f["instance"], f["seed"]) for f in first}] == first
    assert sum(line.startswith("[") for line in again.stdout.splitlines()) == 6 - len(first)


def one_run_study(tmp_path: Path, name: str, limits: str, problem: str) -> tuple[Path, Path, dict[str, object]]:
    """A study of one instance (``p/PROBLEM.mrg``, already copied there), one seed and method Ours, run once:
    the study file, its database and the run's row."""
    study = write_study(
        tmp_path / "s.yaml",
        f"study: {name}\nseeds: 0..0\nlimits: {limits}\ninstances: [{{glob: p/{problem}.mrg, name: one}}]\n"
        "methods: [{name: Ours}]\n",
    )
    db = tmp_path / "r.db"
    run_study(str(study), str(db))
    (row,) = rows(db)
    return study, db, row


def file_texts(folder: Path) -> dict[str, bytes]:
    """The bytes of every file in ``folder``, by name."""
    return {f.name: f.read_bytes() for f in sorted(folder.iterdir())}


def test_an_edited_instance_keeps_the_old_runs_files_and_reports_only_its_new_content(tmp_path: Path) -> None:
    """A study run, its instance edited, run again: two rows (an edited instance is a new instance), each with
    its own plan file (the file names carry the content hash: the second run overwrote the first's, whose
    row then pointed at the new problem's plan), and the reports read the new content's runs alone (they
    averaged the two problems)."""
    folder = symbolic_copy(tmp_path / "p", "chain-3")
    study, db, _ = one_run_study(tmp_path, "edit", "{time: 30}", "chain-3")
    shutil.copy(SYMBOLIC / "parallel.mrg", folder / "chain-3.mrg")  # another problem under the same name
    run_study(str(study), str(db))
    with ResultsDB(str(db), readonly=True) as results:
        every = list(results.conn.execute("SELECT instance_sha256, plan_file, objects_moved FROM runs ORDER BY id"))
        shown = list(results.runs())
    assert len(every) == 2 and every[0][0] != every[1][0] and every[0][1] != every[1][1]
    for _, plan_file, moved in every:
        assert json.loads(Path(plan_file).read_text(encoding="utf-8"))["motion_cost"] == moved
    assert [r["instance_sha256"] for r in shown] == [every[1][0]]
    # the edit taken back: nothing runs (that content's run is recorded), and the reports read it again
    shutil.copy(SYMBOLIC / "chain-3.mrg", folder / "chain-3.mrg")
    assert run_study(str(study), str(db)).ran == 0
    assert [r["instance_sha256"] for r in rows(db)] == [every[0][0]]


def test_an_interrupted_retry_keeps_the_recorded_run_and_its_files(tmp_path: Path) -> None:
    """``bench run --retry`` of a recorded run, interrupted: the run's row and files stay as they were (the
    retry deleted the plan file up front, and its cancelled attempt was never recorded: a row pointing at
    nothing)."""
    packaging_copy(tmp_path / "p", "pa18-4arms")
    study, db, before = one_run_study(tmp_path, "retry", "{time: 0.5, wall: 120}", "pa18-4arms")
    assert before["plan_file"] and Path(str(before["plan_file"])).is_file()
    folder = Path(str(before["plan_file"])).parent
    texts = file_texts(folder)
    proc = subprocess.Popen(
        [*MRGC, "bench", "run", str(study), "--db", str(db), "--retry", str(before["status"])],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not list(folder.glob("*.attempt.*")) and time.monotonic() < deadline:
        time.sleep(0.01)  # until the retry's attempt has started (its files made)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip() == (  # not "nothing written": the recorded runs are
        "mrgc: interrupted (SIGINT) while running the study s.yaml; every run recorded so far is kept "
        "(bench run again goes on)"
    ).replace("s.yaml", str(study))
    assert rows(db) == [before]
    assert file_texts(folder) == texts


def test_a_retry_that_fails_to_be_recorded_leaves_the_recorded_run_s_files(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The attempt's files are put in place only once its row is committed: a retry whose recording fails
    (here the database write raises) leaves the recorded run's row and files as they were, and the next
    ``bench run`` sweeps the attempt's leftovers."""
    symbolic_copy(tmp_path / "p", "chain-3")
    study, db, before = one_run_study(tmp_path, "settle", "{time: 30}", "chain-3")
    folder = Path(str(before["plan_file"])).parent
    texts = file_texts(folder)

    def refuse(self: ResultsDB, result: object) -> None:
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(ResultsDB, "add", refuse)
        with pytest.raises(KeyboardInterrupt):
            run_study(str(study), str(db), retry=[str(before["status"])])
    assert rows(db) == [before]
    assert {n: t for n, t in file_texts(folder).items() if ".attempt." not in n} == texts
    assert [f.name for f in folder.iterdir() if ".attempt." in f.name]  # the attempt, not put in place
    run_study(str(study), str(db))  # nothing to run; the leftovers swept
    assert file_texts(folder) == texts


def test_a_run_past_its_wall_clock_limit_is_killed_as_a_group(tmp_path: Path) -> None:
    """The runner's wall-clock limit (shorter than the planner's own) kills a run as a group: timeout; the
    planner's own time limit ends a run by itself: time limit.  The instance is one no run solves in seconds
    (6 arms, 40 objects, generated seed 2: time limit at 300 s in docs/benchmarks.md), so that neither
    outcome depends on how fast the planner is (pa10 used to be: it now plans within the 2 s)."""
    study = write_study(
        tmp_path / "s.yaml",
        "study: hang\ninstances: [{generate: packaging, robots: 6, goals: 10, others: 30, seeds: 2}]\n"
        "methods:\n  - {name: Hang, limits: {time: 600, wall: 2}}\n  - {name: Short, limits: {time: 1}}\n",
    )
    summary = run_study(str(study), str(tmp_path / "r.db"), jobs=2)
    hang, short = rows(tmp_path / "r.db")
    assert summary.outcomes == {"timeout": 1, "time limit": 1}
    # killed by the 2 s wall limit, long before its own 600 s (the bound is loose: a loaded 2-core machine with
    # two test workers and two runs once took 6 s to start, run and kill it)
    assert hang["status"] == "timeout" and not hang["success"] and 2 <= hang["wall_seconds"] < 60  # type: ignore[operator]
    assert hang["signal"] == signal.SIGKILL and hang["planning_seconds"] is None
    assert short["status"] == "time limit" and short["exit_code"] == 3 and short["plan_status"] == "time limit"
    assert short["planning_seconds"] >= 1 and not short["success"]  # type: ignore[operator]
    assert not leftover(str(tmp_path))


def test_cpu_seconds_count_the_process_and_the_workers_it_waited_for(tmp_path: Path) -> None:
    """The runner's CPU time is the kernel's: a process that forks a worker, which spins for 0.6 s of CPU,
    and waits for it, is charged at least that, and sleeping costs no CPU time."""
    spin = (
        "import os, time\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    t = time.process_time()\n"
        "    while time.process_time() - t < 0.6: pass\n"
        "    os._exit(0)\n"
        "os.waitpid(pid, 0)\n"
        "time.sleep(0.5)\n"
    )
    out = run_limited(
        [sys.executable, "-c", spin],
        wall=60,
        memory_mb=4096,
        stdout=str(tmp_path / "o"),
        stderr=str(tmp_path / "e"),
    )
    assert out.exit_code == 0 and out.killed is None
    assert 0.6 <= out.cpu_seconds < out.seconds, (out.cpu_seconds, out.seconds)


def test_a_study_records_cpu_seconds_reports_either_clock_and_leaves_no_lock(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(
        tmp_path / "s.yaml",
        "study: clocks\nlimits: {time: 30}\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: O}]\n",
    )
    db = tmp_path / "r.db"
    run_study(str(study), str(db))
    assert not (tmp_path / "r.db.lock").exists(), "bench run left its lock file behind"
    (row,) = rows(db)
    assert row["success"] and 0 < row["cpu_seconds"] < 60  # type: ignore[operator]
    for clock, heading in (("wall", "planning time (s)"), ("cpu", "CPU time (s)")):
        out = subprocess.run(
            [*MRGC, "bench", "report", "--db", str(db), "--time", clock], capture_output=True, text=True, timeout=60
        )
        assert out.returncode == 0 and heading in out.stdout, out.stderr
    cpu = subprocess.run(
        [*MRGC, "bench", "report", "--db", str(db), "--time", "cpu", "--format", "csv"],
        capture_output=True,
        text=True,
        timeout=60,
    ).stdout.splitlines()
    assert float(cpu[1].split(",")[6]) == pytest.approx(row["cpu_seconds"])


def test_a_database_of_the_first_schema_is_read_and_upgraded_in_place(tmp_path: Path) -> None:
    db = golden_db(tmp_path)
    with ResultsDB(str(db), readonly=True) as old:
        before = list(old.runs())
        assert before and all(r["cpu_seconds"] is None for r in before)
        assert "CPU time (s)" in render(old, "markdown", clock="cpu")
    with ResultsDB(str(db)) as new:  # as bench run opens it
        assert new.conn.execute("PRAGMA user_version").fetchone()[0] == 2
        assert list(new.runs()) == before


def test_a_run_over_its_memory_limit_is_recorded_as_memout(tmp_path: Path) -> None:
    """A packaging run passes 100 MiB for a second or more (coal, phase 1, the referee's pybullet world; its
    peak was 165 MiB on 2026-12-04, since grounded steps keep compact volumes: 120 MiB, the limit before, was
    passed for a few tenths of a second at the end of a PA10 run on a busy machine, and a full suite saw
    it solve); a symbolic one, ending at about 30 MiB within a second, made the outcome depend on where the
    samples fell."""
    packaging_copy(tmp_path / "g", "pa10")
    study = write_study(
        tmp_path / "s.yaml",
        "study: mem\nlimits: {memory: 100MB}\ninstances: [{file: g/pa10.mrg}]\nmethods: [{name: Ours}]\n",
    )
    run_study(str(study), str(tmp_path / "r.db"))
    (r,) = rows(tmp_path / "r.db")
    assert r["status"] == "memout" and not r["success"] and r["peak_mb"] > 100  # type: ignore[operator]
    assert "memory limit of 100 MiB" in str(r["detail"])


def test_a_crashing_run_is_recorded_as_a_crash_with_its_stderr(tmp_path: Path) -> None:
    folder = packaging_copy(tmp_path / "g", "pa10")
    study = write_study(
        tmp_path / "s.yaml",
        "study: crash\nlimits: {time: 600, wall: 120}\ninstances: [{file: g/pa10.mrg}]\nmethods: [{name: Ours}]\n",
    )

    def segfault() -> None:  # what a crash in a C extension looks like from outside: SIGSEGV mid-run
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            for pid in filter(str.isdigit, os.listdir("/proc")):
                try:
                    cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
                except OSError:
                    continue
                if str(folder).encode() in cmd and b"\0plan\0" in cmd:
                    time.sleep(1.0)
                    os.kill(int(pid), signal.SIGSEGV)
                    return
            time.sleep(0.05)

    killer = threading.Thread(target=segfault)
    killer.start()
    run_study(str(study), str(tmp_path / "r.db"))
    killer.join()
    (r,) = rows(tmp_path / "r.db")
    assert r["status"] == "crash" and not r["success"] and r["signal"] == signal.SIGSEGV
    assert "SIGSEGV" in str(r["detail"]) and r["exit_code"] is None


def test_a_failed_run_records_its_reasons(tmp_path: Path) -> None:
    """A failure's ``detail`` holds the plan's reasons, not only its summary: the fact that proves a real
    run infeasible; and, from the recorded ``why`` of a real BO8 run cut by its time limit, the plans the
    validator rejected and the most frequent grounding failures."""
    symbolic_copy(tmp_path / "p", "infeasible")
    study = parse_study(
        "study: why\ninstances: [{file: p/infeasible.mrg}]\nmethods: [{name: Ours}]\n", str(tmp_path / "s.yaml")
    )
    (inst,) = expand_instances(study, str(tmp_path / "w"))
    task = RunTask("why", inst, "Ours", tuple(method_args(study.methods[0])), 0, Limits(time=30), str(tmp_path / "out"))
    result = classify(execute_run(task))
    assert result.status == "infeasible" and not result.success
    assert result.detail.startswith("infeasible by the facts; every action moving o1 is obstructed by")
    why = json.loads((GOLDEN / "why-time-limit.json").read_text(encoding="utf-8"))["why"]
    detail = why_detail(why)
    assert detail.startswith(
        "no plan within the time limit of 300 s; 42 complete plan(s) rejected by the validator; "
        "most frequent grounding failures: 28 x step 1, r2 moves door-s to start (side-x-): "
        "carry to the placement: no path; 22 x step 5, validator (1 violation): "
        "collision-robot-fixed (home: footprint of r1"
    )
    assert detail.count(" x step ") == 3
    assert len(why_detail(why, limit=80)) == 80


def test_an_invalid_plan_is_a_failure(tmp_path: Path) -> None:
    """A real plan, doctored (its goal object put back in the start region), judged by the real validator."""
    symbolic_copy(tmp_path / "p", "chain-3")
    study = parse_study(
        "study: inv\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: Ours}]\n", str(tmp_path / "s.yaml")
    )
    (inst,) = expand_instances(study, str(tmp_path / "w"))
    task = RunTask("inv", inst, "Ours", tuple(method_args(study.methods[0])), 0, Limits(time=30), str(tmp_path / "out"))
    raw = execute_run(task)
    good = classify(raw)
    assert good.status == "solved" and good.success and good.valid
    plan = json.loads(raw.plan_text or "")
    plan["steps"][0]["actions"][0]["region"] = "start"
    doctored = tmp_path / "doctored.plan.json"
    doctored.write_text(json.dumps(plan), encoding="utf-8")
    check = run_limited(
        mrgc_argv(["validate", inst.path, str(doctored), "--format", "json"]),
        wall=60,
        memory_mb=4096,
        stdout=str(tmp_path / "v.json"),
        stderr=str(tmp_path / "v.err"),
    )
    bad = classify(
        replace(raw, plan_text=doctored.read_text(), validate=check, validate_text=(tmp_path / "v.json").read_text())
    )
    assert bad.status == RunStatus.INVALID.value and not bad.success and bad.valid is False
    assert "goal" in bad.detail
    with ResultsDB(str(tmp_path / "r.db")) as db:
        db.add(bad)
        assert "| chain-3 | Ours | 1 | 0.0 |" in render(db, "markdown")


def test_an_unknown_planner_is_skipped_with_its_reason_and_nothing_recorded(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(
        tmp_path / "s.yaml",
        "study: skip\nseeds: 0..1\ninstances: [{file: p/chain-3.mrg}]\n"
        "methods: [{name: Ours}, {name: Ap9, planner: ap9}]\n",
    )
    db = tmp_path / "r.db"
    out = subprocess.run(
        [*MRGC, "bench", "run", str(study), "--db", str(db)], capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert "skipped method Ap9 (2 runs): planner 'ap9' is not offered by this mrgc" in out.stdout
    assert {r["method"] for r in rows(db)} == {"Ours"}
    report = subprocess.run([*MRGC, "bench", "report", "--db", str(db)], capture_output=True, text=True, timeout=60)
    assert "Skipped: method Ap9 (2 runs): planner 'ap9'" in report.stdout
    changed = write_study(tmp_path / "s.yaml", study.read_text().replace("{name: Ours}", "{name: Ours, backend: mip}"))
    refused = subprocess.run(
        [*MRGC, "bench", "run", str(changed), "--db", str(db)], capture_output=True, text=True, timeout=120
    )
    assert refused.returncode == 2 and "error[E603]: method 'Ours' of study 'skip' changed" in refused.stderr


def test_the_ray_executor_runs_a_two_run_study_on_a_local_ray(tmp_path: Path) -> None:
    import ray  # the test extra installs it (pip install -e '.[test]')

    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(
        tmp_path / "s.yaml", "study: ray\nseeds: 0..1\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: Ours}]\n"
    )
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        summary = run_study(str(study), str(tmp_path / "r.db"), executor="ray")
    finally:
        ray.shutdown()
    assert summary.outcomes == {"solved": 2}
    got = rows(tmp_path / "r.db")
    assert sorted(r["seed"] for r in got) == [0, 1] and all(r["valid"] for r in got)
    for r in got:  # the plans came back from the workers and are kept here
        assert json.loads(Path(str(r["plan_file"])).read_text())["status"] == "solved"


def test_without_ray_the_ray_executor_says_how_to_get_it(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(tmp_path / "s.yaml", "study: noray\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: O}]\n")
    code = (
        "import sys; sys.modules['ray'] = None\nfrom mrgc.cli import main\n"
        f"sys.exit(main(['bench', 'run', {str(study)!r}, '--db', {str(tmp_path / 'r.db')!r}, "
        "'--executor', 'ray']))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 4 and "pip install 'mrgc[ray]'" in out.stderr and "Traceback" not in out.stderr


# ---------------------------------------------------------------- reports
def golden_db(tmp_path: Path) -> Path:
    db = tmp_path / "golden.db"
    conn = sqlite3.connect(db)
    conn.executescript((GOLDEN / "runs.sql").read_text(encoding="utf-8"))
    conn.close()
    return db


@pytest.mark.parametrize(
    "fmt, name",
    [("markdown", "report.md"), ("wide", "report-wide.md"), ("pairs", "report-pairs.md"), ("csv", "report.csv")],
)
def test_reports_of_a_fixed_database_are_golden(tmp_path: Path, fmt: str, name: str) -> None:
    db = golden_db(tmp_path)
    out = subprocess.run(
        [*MRGC, "bench", "report", "--db", str(db), "--format", fmt], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, out.stderr
    golden = GOLDEN / name
    if os.environ.get("MRGC_UPDATE_GOLDEN") == "1":
        golden.write_text(out.stdout, encoding="utf-8")
    assert out.stdout == golden.read_text(encoding="utf-8"), f"{name} changed; regenerate with MRGC_UPDATE_GOLDEN=1"


def test_report_numbers_are_means_and_standard_errors_of_the_solved_runs(tmp_path: Path) -> None:
    import math

    from mrgc.bench import aggregate

    with ResultsDB(str(golden_db(tmp_path)), readonly=True) as db:
        runs = list(db.runs())
        for row in aggregate(runs):
            mine = [r for r in runs if (r["instance_set"], r["method"]) == (row.instance_set, row.method)]
            solved = [float(r["planning_seconds"]) for r in mine if r["success"]]
            assert row.runs == len(mine) and row.solved == len(solved)
            assert all(r["valid"] for r in mine if r["success"] and r["plan_status"] == "solved")
            if len(solved) >= 2:
                mean = sum(solved) / len(solved)
                se = math.sqrt(sum((x - mean) ** 2 for x in solved) / (len(solved) - 1) / len(solved))
                assert row.time.mean == pytest.approx(mean) and row.time.se == pytest.approx(se)


def test_pairs_give_each_instance_its_time_ratio_and_each_set_its_medians(tmp_path: Path) -> None:
    import statistics

    from mrgc.bench.report import pairs

    with ResultsDB(str(golden_db(tmp_path)), readonly=True) as db:
        runs = list(db.runs())
        text = pairs(db)
    methods = list(dict.fromkeys(r["method"] for r in sorted(runs, key=lambda r: r["method_index"])))
    a, b = methods[0], methods[1]
    cell = {(r["instance_set"], r["instance"], r["seed"], r["method"]): r for r in runs}
    for (s, inst, seed, m), ra in cell.items():
        rb = cell.get((s, inst, seed, b))
        if m != a or rb is None or not (ra["success"] and rb["success"]):
            continue
        ratio = rb["planning_seconds"] / ra["planning_seconds"]
        assert any(
            line.startswith(f"| {s} | {inst} | {seed} |") and line.endswith(f"| {ratio:.2f} |")
            for line in text.splitlines()
        )
    for s in dict.fromkeys(r["instance_set"] for r in runs):
        solved = [r["planning_seconds"] for r in runs if (r["instance_set"], r["method"]) == (s, a) and r["success"]]
        row = [line for line in text.splitlines() if line.startswith(f"| {s} | ") and "/" in line.split("|")[2]]
        assert row and f"| {statistics.median(solved):.2f} |" in row[-1]


def test_figures_of_a_fixed_database(tmp_path: Path) -> None:
    db = golden_db(tmp_path)
    out = subprocess.run(
        [*MRGC, "bench", "report", "--db", str(db), "--figures", str(tmp_path / "fig")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    written = sorted(p.name for p in (tmp_path / "fig").iterdir())
    assert written == ["golden-cactus.png", "golden-success.png", "golden-time-ecdf.png"]
    for p in (tmp_path / "fig").iterdir():
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 5000


def test_report_errors_are_one_line_with_exit_code_2(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("hello")
    for db in (tmp_path / "none.db", tmp_path / "notes.txt"):
        out = subprocess.run([*MRGC, "bench", "report", "--db", str(db)], capture_output=True, text=True, timeout=60)
        assert out.returncode == 2 and out.stderr.startswith("error[E603]") and "Traceback" not in out.stderr


def test_a_ray_address_nobody_answers_is_one_line(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(tmp_path / "s.yaml", "study: far\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: O}]\n")
    out = subprocess.run(
        [
            *MRGC,
            "bench",
            "run",
            str(study),
            "--db",
            str(tmp_path / "r.db"),
            "--executor",
            "ray",
            "--address",
            "127.0.0.1:1",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 2 and "error[E000]: --address 127.0.0.1:1: no Ray cluster answers there" in out.stderr
    assert rows(tmp_path / "r.db") == []


def test_planner_arena_export_has_ompl_s_tables(tmp_path: Path) -> None:
    db, out = golden_db(tmp_path), tmp_path / "arena.db"
    done = subprocess.run(
        [*MRGC, "bench", "report", "--db", str(db), "--planner-arena", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    conn = sqlite3.connect(out)
    tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    assert {"experiments", "plannerConfigs", "enums", "runs", "progress"} <= tables
    with ResultsDB(str(db), readonly=True) as results:
        mine = list(results.runs())
    assert conn.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == len(mine)
    experiments = [r[0] for r in conn.execute("SELECT name FROM experiments ORDER BY id")]
    assert experiments == ["golden: chain-3", "golden: symbolic", "golden: pa3-handover"]
    solved = conn.execute(
        "SELECT p.name, SUM(r.solved) FROM runs r JOIN plannerConfigs p ON p.id = r.plannerid GROUP BY p.name"
    ).fetchall()
    assert dict(solved) == {m: sum(r["success"] for r in mine if r["method"] == m) for m in {r["method"] for r in mine}}
    status = dict(conn.execute("SELECT value, description FROM enums WHERE name = 'status'").fetchall())
    for (code,) in conn.execute("SELECT status FROM runs"):
        assert status[code] in {s.value for s in RunStatus}
    assert all(v.startswith("mrgc ") for (v,) in conn.execute("SELECT version FROM experiments"))


def test_report_outputs_are_checked_first_and_never_replace_the_database(tmp_path: Path) -> None:
    """The database read is no output (E005: --planner-arena onto it used to overwrite it, every run lost); a
    folder, a file given as --figures' folder, a missing folder are E006 before the report is printed (they
    were internal errors, exit 70, after it; --planner-arena /tmp left /tmp.mrgc-tmp behind)."""
    db = golden_db(tmp_path)
    before = db.read_bytes()
    (tmp_path / "notes.txt").write_text("hello", encoding="utf-8")
    cases = [
        (["--planner-arena", str(db)], "error[E005]: --planner-arena"),
        (["--planner-arena", str(tmp_path)], "error[E006]: --planner-arena"),
        (["--planner-arena", str(tmp_path / "no" / "a.db")], "error[E006]: --planner-arena"),
        (["--figures", str(tmp_path / "notes.txt")], "error[E006]: --figures"),
        (["--figures", "/dev/null"], "error[E006]: --figures"),
    ]
    for extra, first in cases:
        out = subprocess.run(
            [*MRGC, "bench", "report", "--db", str(db), *extra], capture_output=True, text=True, timeout=60
        )
        assert out.returncode == 2 and out.stderr.startswith(first) and out.stdout == "", (extra, out.stderr)
    assert db.read_bytes() == before and len(rows(db)) > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["golden.db", "notes.txt"]  # no temp file left
    out = subprocess.run(
        [*MRGC, "bench", "report", "--db", str(db), "--figures", str(tmp_path / "f" / "g")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0 and sorted(p.suffix for p in (tmp_path / "f" / "g").iterdir()) == [".png"] * 3


def test_a_study_that_is_a_fifo_or_a_work_folder_that_is_a_file_is_refused_at_once(tmp_path: Path) -> None:
    symbolic_copy(tmp_path / "p", "chain-3")
    study = write_study(tmp_path / "s.yaml", "study: s\ninstances: [{file: p/chain-3.mrg}]\nmethods: [{name: O}]\n")
    fifo = tmp_path / "s.fifo"
    os.mkfifo(fifo)
    out = subprocess.run(
        [*MRGC, "bench", "run", str(fifo), "--db", str(tmp_path / "r.db")], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 2 and out.stderr.startswith("error[E600]") and "FIFO" in out.stderr
    out = subprocess.run(
        [*MRGC, "bench", "run", str(study), "--db", str(tmp_path / "r.db"), "--work", str(study)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 2 and out.stderr.startswith("error[E006]: --work") and not (tmp_path / "r.db").exists()


def test_the_python_api_names_resolve_and_importing_it_loads_no_heavy_library() -> None:
    code = (
        "import sys, mrgc.bench as b\n"
        "names = [getattr(b, n) for n in b.__all__]\n"
        "print(sorted(m for m in ('ray', 'matplotlib', 'pybullet', 'ortools') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "[]"


def test_a_study_s_errors_come_at_once(tmp_path: Path) -> None:
    """Schema, instance files and methods checked together (they came in three rounds: fix five errors, get
    seven more, then a glob that matches nothing); a seed past 32 bits is an error at once (every run was
    recorded as 'error' and never retried)."""
    study = write_study(
        tmp_path / "s.yaml",
        "study: s\nseeds: 2147483648\ninstances: [{glob: none-*.mrg}]\n"
        "methods: [{name: A, backend: gurobi, options: {c: -1}}]\n",
    )
    out = subprocess.run(
        [*MRGC, "bench", "run", str(study), "--db", str(tmp_path / "r.db")], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 2 and not (tmp_path / "r.db").exists()
    codes = re.findall(r"error\[(E60\d)\]", out.stderr)
    assert sorted(codes) == ["E601", "E601", "E601", "E602"], out.stderr
    assert "seeds must be a seed (0 to 2,147,483,647)" in out.stderr and "unknown backend 'gurobi'" in out.stderr
    assert (
        "option 'c': must be a finite number from 0 to 1e+06" in out.stderr and "matches no problem file" in out.stderr
    )
