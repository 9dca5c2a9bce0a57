"""Worker processes that never outlive the call that started them.

:func:`map_in_workers` runs a function over jobs in forked processes (phase 1: one robot per process) with
these guarantees, whatever ends the call (a result, an exception in a worker, Ctrl-C, SIGTERM):

- on any exception in the parent (a worker's error re-raised, ``KeyboardInterrupt``,
  :class:`~mrgc.signals.Terminated`) every worker is killed (SIGKILL) and reaped before the exception
  propagates: no worker keeps running, none is left a zombie;
- workers ignore SIGINT (Ctrl-C reaches the terminal's whole process group; the parent decides) and take
  SIGTERM's default action (they do not inherit the parent's Python handlers);
- a worker dies with its parent (Linux ``PR_SET_PDEATHSIG``), so even a parent killed outright with
  SIGKILL leaves no worker behind;
- a worker that crashes (a segfault in a native library) ends the call with
  :class:`~mrgc.errors.InternalError` instead of a hang.

The number of processes is capped by :func:`worker_count`: at most one per job and one per usable core.

:func:`map_until` is the same with a time limit: when the limit passes before every job has finished, the
workers are killed the same way and the call answers None (the planners' ``--time-limit`` covers phase 1
this way, without a clock read inside the jobs).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from concurrent.futures import FIRST_EXCEPTION, ProcessPoolExecutor
from concurrent.futures import wait as wait_for
from concurrent.futures.process import BrokenProcessPool
from typing import Callable, Sequence, TypeVar

from mrgc import signals
from mrgc.errors import InternalError

T = TypeVar("T")
R = TypeVar("R")

_HANDLED = (signal.SIGINT, signal.SIGTERM)


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity, else the machine's count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def worker_count(requested: int | None, jobs: int) -> int:
    """Processes to use for ``jobs`` jobs: ``requested`` (default: one per job), capped at one per job
    and one per usable core, at least 1."""
    n = jobs if requested is None else requested
    return max(1, min(n, jobs, usable_cores()))


def _init_worker(parent: int) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        signal.set_wakeup_fd(-1)
    except ValueError:  # pragma: no cover - not the main thread
        pass
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover
            pass
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _HANDLED)
    if os.getppid() != parent:  # the parent died before PR_SET_PDEATHSIG took effect
        os._exit(1)


def map_in_workers(fn: Callable[[T], R], jobs: Sequence[T], workers: int) -> list[R]:
    """``[fn(j) for j in jobs]`` computed in ``workers`` forked processes (in order; ``workers <= 1`` or a
    single job runs here).  ``fn`` and the results must be picklable; see the module docstring for what
    happens to the workers when the call ends."""
    if workers <= 1 or len(jobs) <= 1:
        return [fn(j) for j in jobs]
    results = _pool(fn, jobs, workers, None)
    assert results is not None  # no time limit: every job ends
    return results


def map_until(fn: Callable[[T], R], jobs: Sequence[T], workers: int, seconds: float) -> list[R] | None:
    """:func:`map_in_workers` within ``seconds`` of wall-clock time, or None when they pass first (every
    worker killed and reaped).  Always in worker processes, even one job, so that it can be cut."""
    if not jobs:
        return []
    return _pool(fn, jobs, max(1, workers), max(0.0, seconds))


def _pool(fn: Callable[[T], R], jobs: Sequence[T], workers: int, seconds: float | None) -> list[R] | None:
    before = {p.pid for p in multiprocessing.active_children()}
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("fork"),
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )
    mine: list[multiprocessing.process.BaseProcess] = []
    try:
        # forks happen while submitting: block the signals so a child never runs the parent's handlers
        # (it unblocks them in _init_worker; here they are delivered right after)
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _HANDLED)
        try:
            futures = [pool.submit(fn, j) for j in jobs]
            mine = [p for p in multiprocessing.active_children() if p.pid not in before]
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        try:
            _, pending = wait_for(futures, timeout=seconds, return_when=FIRST_EXCEPTION)
            if pending and not any(f.done() and f.exception() is not None for f in futures):
                with signals.shielded():  # out of time: nothing of the jobs may run on
                    _kill(mine or [p for p in multiprocessing.active_children() if p.pid not in before])
                    pool.shutdown(wait=True, cancel_futures=True)
                return None
            results = [f.result() for f in futures]
        except BrokenProcessPool as exc:
            codes = sorted({p.exitcode for p in mine if p.exitcode not in (None, 0)})
            raise InternalError(f"a worker process died (exit codes {codes}): {exc}") from None
    except BaseException:
        with signals.shielded():
            _kill(mine or [p for p in multiprocessing.active_children() if p.pid not in before])
            pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return results


def _kill(processes: Sequence[multiprocessing.process.BaseProcess]) -> None:
    for p in processes:
        if p.exitcode is None:
            try:
                p.kill()
            except OSError:  # pragma: no cover - already gone
                pass
    for p in processes:
        p.join(timeout=10)
