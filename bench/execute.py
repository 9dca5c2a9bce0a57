"""One run, where it executes (this machine or a Ray worker): the planning process, then the validator.

:func:`execute_run` runs ``mrgc plan`` (or ``mrgc compile`` for a compile-only method) under the run's
limits (:mod:`mrgc.bench.runner`) and, when the plan file says ``solved``, ``mrgc validate`` on it as a
separate process under the same limits.  It judges nothing: it returns a :class:`RawRun` (the processes'
outcomes, the plan and validator texts, the tails of their standard error) that
:func:`mrgc.bench.outcome.classify` turns into a recorded result.  Everything here is picklable, so a Ray
worker runs the same function and sends the same value back.

Each mrgc process is ``python -c SHIM ARGS``: the shim asks the kernel to SIGKILL it if the thread that
started it dies (``PR_SET_PDEATHSIG``), so a ``bench run`` killed with SIGKILL leaves no planner running,
then calls ``mrgc.cli.main(ARGS)``.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import sys
import tempfile
import threading
from dataclasses import dataclass, field
from datetime import datetime, timezone

from mrgc.bench.instances import Instance
from mrgc.bench.runner import ProcessResult, run_limited
from mrgc.bench.runner import read_text as _read
from mrgc.bench.study import Limits

SHIM = """\
import os, sys
try:
    import ctypes
    ctypes.CDLL(None).prctl(1, 9)  # PR_SET_PDEATHSIG, SIGKILL
except Exception:
    pass
if os.environ.get("MRGC_BENCH_PARENT") and os.getppid() != int(os.environ["MRGC_BENCH_PARENT"]):
    sys.exit(137)  # the parent died before the request took effect
from mrgc.cli import main
sys.exit(main(sys.argv[1:]))
"""


@dataclass(frozen=True)
class RunTask:
    """What to run: the key (study, instance content hash, method, seed) and how.  ``args`` are the method's
    mrgc arguments (:func:`mrgc.bench.methods.method_args`); ``out_dir`` is where this machine keeps the
    run's files (a Ray worker uses a temporary folder and sends the texts back)."""

    study: str
    instance: Instance
    method: str
    args: tuple[str, ...]
    seed: int
    limits: Limits
    out_dir: str

    @property
    def compile_only(self) -> bool:
        """Whether the run only generates skeletons (``mrgc compile``)."""
        return self.args[0] == "compile"

    @property
    def stem(self) -> str:
        """The base name of the run's files: instance, seed and the first 8 hex digits of the instance's
        content hash (an edited instance is a new instance: its runs' files do not replace the old ones')."""
        return f"{self.instance.name}-s{self.seed}-{self.instance.sha256[:8]}"


@dataclass
class RawRun:
    """What happened, unjudged (see the module docstring)."""

    task: RunTask
    plan: ProcessResult
    plan_text: str | None  # the plan file (plan) or standard output (compile)
    plan_stderr: str
    validate: ProcessResult | None = None
    validate_text: str | None = None
    validate_stderr: str = ""
    host: str = field(default_factory=socket.gethostname)
    mrgc_version: str = ""
    started: str = ""
    finished: str = ""

    @property
    def cancelled(self) -> bool:
        """Whether a process of the run was killed because the study was interrupted."""
        return self.plan.killed == "cancelled" or (self.validate is not None and self.validate.killed == "cancelled")


def now() -> str:
    """The current UTC time, ISO 8601 to the second (a run's start and end)."""
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _problem_path(inst: Instance, scratch: str) -> str:
    """The instance's file here: its own path when this machine has it unchanged, else the shipped texts
    written into ``scratch`` (a Ray worker without the study's files)."""
    if os.path.isfile(inst.path) and _read(inst.path) == dict(inst.files).get(os.path.basename(inst.path)):
        return inst.path
    folder = os.path.join(scratch, "instance")
    os.makedirs(folder, exist_ok=True)
    for name, text in inst.files:
        with open(os.path.join(folder, name), "w", encoding="utf-8") as fh:
            fh.write(text)
    return os.path.join(folder, os.path.basename(inst.path))


def mrgc_argv(args: list[str]) -> list[str]:
    """The command line of an mrgc process started by the runner."""
    return [sys.executable, "-c", SHIM, *args]


def execute_run(task: RunTask, cancel: threading.Event | None = None, remote: bool = False) -> RawRun:
    """Run ``task`` (module docstring).  ``remote``: keep files in a temporary folder (a Ray worker)."""
    from mrgc import __version__

    scratch = tempfile.mkdtemp(prefix="mrgc-bench-") if remote else None
    out_dir = scratch or task.out_dir
    os.makedirs(out_dir, exist_ok=True)
    env = dict(os.environ, MRGC_BENCH_PARENT=str(os.getpid()))
    stem = os.path.join(out_dir, task.stem) + ATTEMPT  # put in place of the run's once it is recorded (settle)
    done = False
    try:
        problem = _problem_path(task.instance, scratch) if scratch else task.instance.path
        plan_path = stem + (".compile.json" if task.compile_only else ".plan.json")
        extra = ["--problem", task.instance.problem] if task.instance.problem else []
        args = [task.args[0], problem, *extra, "--seed", str(task.seed), "--time-limit", f"{task.limits.time:g}"]
        if not task.compile_only:
            args += ["-o", plan_path]
        args += list(task.args[1:])
        started = now()  # (attempts a SIGKILLed bench run left were swept when this one started)

        def limited(argv: list[str], out: str, err: str) -> ProcessResult:
            return run_limited(
                mrgc_argv(argv),
                wall=task.limits.wall_seconds,
                memory_mb=task.limits.memory_mb,
                stdout=out,
                stderr=err,
                cancel=cancel,
                env=env,
            )

        proc = limited(args, stem + (".compile.json" if task.compile_only else ".out"), stem + ".err")
        text = _read(plan_path) if proc.killed is None else None
        raw = RawRun(task, proc, text, proc.stderr_tail(), mrgc_version=__version__, started=started)
        if proc.killed is None and not task.compile_only and text is not None and _status(text) == "solved":
            vargs = ["validate", problem, plan_path, "--format", "json", *extra]
            raw.validate = limited(vargs, stem + ".validate.json", stem + ".validate.err")
            raw.validate_text = _read(stem + ".validate.json")
            raw.validate_stderr = raw.validate.stderr_tail()
        raw.finished = now()
        done = not raw.cancelled and not (cancel is not None and cancel.is_set())
        return raw
    finally:
        if not done:  # interrupted: never recorded, so a recorded earlier run of the same key keeps its files
            remove_attempt(stem)
        if scratch:
            shutil.rmtree(scratch, ignore_errors=True)


#: the suffix of a run's files until the run is recorded (``INSTANCE-sSEED-HASH.attempt.plan.json``, ...)
ATTEMPT = ".attempt"
#: the files of a run, by suffix
SUFFIXES = (".plan.json", ".compile.json", ".out", ".err", ".validate.json", ".validate.err")


def settle(task: RunTask) -> None:
    """A recorded run's attempt files put in place of the run's files (those of an earlier run of its key that
    the attempt did not write removed: a validation that did not happen this time).  Called once the run's
    row is committed, so that an interrupt before leaves the recorded run and its files as they were."""
    final = os.path.join(task.out_dir, task.stem)
    for suffix in SUFFIXES:
        if os.path.exists(final + ATTEMPT + suffix):
            os.replace(final + ATTEMPT + suffix, final + suffix)
        elif os.path.exists(final + suffix):
            os.unlink(final + suffix)


def remove_attempt(stem: str) -> None:
    """The files of the attempt ``stem`` (ending in :data:`ATTEMPT`), gone."""
    for suffix in SUFFIXES:
        if os.path.exists(stem + suffix):
            os.unlink(stem + suffix)


def _status(plan_text: str) -> str | None:
    try:
        data = json.loads(plan_text)
    except ValueError:
        return None
    return data.get("status") if isinstance(data, dict) else None
