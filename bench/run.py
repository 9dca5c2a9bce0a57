"""Running a study: expand it into runs, skip the finished ones, execute the rest, record each as it ends.

The runs of a study are every (instance, seed, method) in study order (methods innermost, so a partial
study compares its methods on the same instances).  A run's key is ``(study, instance content hash,
method, seed)``: a run whose key is in the database is finished and skipped (``retry`` lists statuses to
run again, e.g. ``crash``).  Files of a run (plan, standard output and error, the validator's report) are
kept under ``WORK/STUDY/runs/METHOD/``; generated instances under ``WORK/STUDY/instances/``.
"""

from __future__ import annotations

import os
import re
from collections import Counter
from dataclasses import dataclass, field
from typing import Callable, Iterable

from mrgc import outputs, signals
from mrgc.bench.db import ResultsDB, WriterLock
from mrgc.bench.execute import ATTEMPT, RawRun, RunTask, now, settle
from mrgc.bench.instances import expand_instances
from mrgc.bench.methods import check_methods, method_args
from mrgc.bench.outcome import RunResult, RunStatus, classify
from mrgc.bench.schema import load_study
from mrgc.bench.study import Study
from mrgc.errors import Diagnostic, InputError

#: the database ``bench run`` and ``bench report`` use without ``--db``
DEFAULT_DB = "mrgc-bench.db"


def default_work(db_path: str) -> str:
    """Where a database's run files go by default: ``NAME-files/`` beside ``NAME.db``."""
    return os.path.splitext(db_path)[0] + "-files"


@dataclass
class StudySummary:
    """What a ``bench run`` did: ``total`` runs in the study (skipped methods excluded), ``already`` of them
    finished before, ``ran`` now, their outcomes, and the skipped methods (method → (reason, runs))."""

    study: str
    total: int
    already: int
    ran: int = 0
    outcomes: Counter[str] = field(default_factory=Counter)
    skipped: dict[str, tuple[str, int]] = field(default_factory=dict)

    def lines(self) -> list[str]:
        """The summary printed at the end of ``bench run``."""

        def runs(n: int) -> str:
            return f"{n} run{'s' * (n != 1)}"

        out = [
            f"study {self.study}: {runs(self.total)}, {self.already} recorded and kept, {self.ran} run now"
            + (": " + ", ".join(f"{n} {s}" for s, n in self.outcomes.most_common()) if self.ran else "")
        ]
        out += [f"skipped method {m} ({runs(n)}): {why}" for m, (why, n) in self.skipped.items()]
        return out


def study_tasks(study: Study, work: str) -> tuple[list[RunTask], dict[str, tuple[str, int]]]:
    """Every run of the study in study order (each with ``--no-cache`` unless the study's ``facts_cache`` is
    ``shared``), and the methods skipped with their reason and run count."""
    diags, skip = check_methods(study)
    if diags:
        raise InputError(diags, {study.path: study.text})
    instances = expand_instances(study, os.path.join(work, study.name))
    tasks: list[RunTask] = []
    skipped: dict[str, tuple[str, int]] = {}
    for inst in instances:
        for seed in study.seeds:
            for m in study.methods:
                if not m.runs_on(inst.set):
                    continue
                if m.name in skip:
                    why, n = skipped.get(m.name, (skip[m.name], 0))
                    skipped[m.name] = (why, n + 1)
                    continue
                out_dir = os.path.join(work, study.name, "runs", re.sub(r"[^A-Za-z0-9_.+-]", "-", m.name))
                args = (*method_args(m), *(("--no-cache",) if study.facts_cache == "own" else ()))
                tasks.append(RunTask(study.name, inst, m.name, args, seed, m.limits, out_dir))
    return tasks, skipped


def run_study(
    study: Study | str,
    db: str = DEFAULT_DB,
    *,
    jobs: int = 1,
    executor: str = "local",
    address: str | None = None,
    work: str | None = None,
    retry: Iterable[str] = (),
    on_result: Callable[[RunResult], None] | None = None,
    on_start: Callable[[int, int], None] | None = None,
) -> StudySummary:
    """Run the study's unfinished runs and record them in ``db`` (module docstring).

    ``on_start(total, to_run)`` is called once the runs are known, ``on_result`` after each run is
    recorded.  InputError for a bad study, instance or database; MissingBackendError when ``executor`` is
    ``ray`` and Ray is not installed.  Interrupting it (KeyboardInterrupt) kills the running runs and
    keeps every recorded one."""
    from mrgc.bench.executors import EXECUTORS, make_executor

    if isinstance(study, str):
        study = load_study(study)
    if executor not in EXECUTORS:
        raise InputError([Diagnostic("E000", f"unknown executor '{executor}' (choose from {', '.join(EXECUTORS)})")])
    bad = sorted(set(retry) - {s.value for s in RunStatus})
    if bad:
        raise InputError(
            [
                Diagnostic(
                    "E000", f"--retry: unknown status '{bad[0]}' (choose from {', '.join(s.value for s in RunStatus)})"
                )
            ]
        )
    work = work or default_work(db)
    outputs.check_folder(work, option="--work")  # made before any run (E006 when it cannot be)
    method_index = {m.name: i for i, m in enumerate(study.methods)}
    with WriterLock(db), ResultsDB(db) as results:
        tasks, skipped = study_tasks(study, work)
        results.begin_study(
            study.name,
            os.path.abspath(study.path),
            study.text,
            {m.name: m.spec() for m in study.methods if m.name not in skipped},
            skipped,
            now(),
            {t.instance.name: t.instance.sha256 for t in tasks},
        )
        _sweep_attempts(tasks)
        finished = results.finished(study.name)
        todo = [t for t in tasks if finished.get((t.study, t.instance.sha256, t.method, t.seed)) in (None, *retry)]
        summary = StudySummary(study.name, len(tasks), len(tasks) - len(todo), skipped=skipped)
        if on_start is not None:
            on_start(len(tasks), len(todo))
        if not todo:
            return summary
        with make_executor(executor, jobs, address) as exe:
            for raw in exe.results(todo):
                plan_file = _keep_files(raw) if exe.remote else _plan_file(raw)
                result = classify(raw, method_index[raw.task.method], plan_file)
                with signals.shielded():  # recorded, then its files put in place: an interrupt waits for both
                    results.add(result)
                    settle(raw.task)
                summary.ran += 1
                summary.outcomes[result.status] += 1
                if on_result is not None:
                    on_result(result)
    return summary


def _sweep_attempts(tasks: list[RunTask]) -> None:
    """Attempt files a run left when its ``bench run`` was killed (SIGKILL: no cleanup ran), removed while
    this ``bench run`` holds the database's writer lock (no other one writes the study's folders)."""
    for folder in sorted({t.out_dir for t in tasks}):
        if os.path.isdir(folder):
            for name in sorted(os.listdir(folder)):
                if ATTEMPT + "." in name:
                    os.unlink(os.path.join(folder, name))


def _plan_file(raw: RawRun) -> str | None:
    """Where the run's plan file will be once the run is recorded (:func:`settle`), None when it wrote none."""
    t = raw.task
    path = os.path.join(t.out_dir, t.stem + (".compile.json" if t.compile_only else ".plan.json"))
    attempt = os.path.join(t.out_dir, t.stem + ATTEMPT + (".compile.json" if t.compile_only else ".plan.json"))
    return path if os.path.isfile(attempt) else None


def _keep_files(raw: RawRun) -> str | None:
    """Write what a remote run sent back into its local folder, as attempt files (:func:`settle` puts them
    in place once the run is recorded); the plan file's path."""
    t = raw.task
    os.makedirs(t.out_dir, exist_ok=True)
    stem = os.path.join(t.out_dir, t.stem + ATTEMPT)
    texts = {
        (".compile.json" if t.compile_only else ".plan.json"): raw.plan_text,
        ".err": raw.plan_stderr,
        ".validate.json": raw.validate_text,
        ".validate.err": raw.validate_stderr if raw.validate else None,
    }
    for suffix, text in texts.items():
        if text is not None:
            with open(stem + suffix, "w", encoding="utf-8") as fh:
                fh.write(text)
    return _plan_file(raw)
