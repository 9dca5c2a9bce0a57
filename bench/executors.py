"""Executors: where a study's runs execute.  ``local`` runs ``--jobs N`` at a time on this machine; ``ray``
(:mod:`mrgc.bench.ray_executor`, the optional extra ``mrgc[ray]``) places each run as a Ray task.

An executor yields each run's :class:`~mrgc.bench.execute.RawRun` as it finishes, in the order they
finish; the caller records it at once.  Closing an executor (the ``with`` block ends, normally or by an
exception such as Ctrl-C or SIGTERM) cancels what is still running: the runner kills each run's process
group, and a cancelled run yields nothing, so it is not recorded and the next ``bench run`` repeats it.
"""

from __future__ import annotations

import queue
import threading
from typing import Iterable, Iterator, Protocol

from mrgc.bench.execute import RawRun, RunTask, execute_run

#: executor name -> "module:class" (lazy: the Ray module imports ray only when used)
EXECUTORS: dict[str, str] = {
    "local": "mrgc.bench.executors:LocalExecutor",
    "ray": "mrgc.bench.ray_executor:RayExecutor",
}


class Executor(Protocol):
    """What ``bench run`` needs of an executor."""

    #: whether runs execute elsewhere (their files come back as texts)
    remote: bool

    def results(self, tasks: Iterable[RunTask]) -> Iterator[RawRun]:
        """Execute ``tasks``, yielding each finished run (in the order they end)."""

    def close(self) -> None:
        """Stop: kill the running runs and wait for them."""

    def __enter__(self) -> "Executor": ...

    def __exit__(self, *exc: object) -> None: ...


def make_executor(name: str, jobs: int = 1, address: str | None = None) -> Executor:
    """The executor called ``name`` (``local`` or ``ray``)."""
    import importlib

    module, _, cls = EXECUTORS[name].partition(":")
    factory = getattr(importlib.import_module(module), cls)
    executor: Executor = factory(jobs=jobs, address=address)
    return executor


class LocalExecutor:
    """``jobs`` threads, each running one run's processes at a time on this machine."""

    remote = False

    def __init__(self, jobs: int = 1, address: str | None = None) -> None:
        if address is not None:
            raise ValueError("the local executor takes no address")
        self.jobs = max(1, jobs)
        self.cancel = threading.Event()
        self.threads: list[threading.Thread] = []

    def results(self, tasks: Iterable[RunTask]) -> Iterator[RawRun]:
        """Run ``tasks`` on ``jobs`` threads (a run each at a time); yield runs as they end, but cancelled ones."""
        todo: queue.Queue[RunTask] = queue.Queue()
        for t in tasks:
            todo.put(t)
        done: queue.Queue[RawRun | BaseException | None] = queue.Queue()

        def work() -> None:
            try:
                while not self.cancel.is_set():
                    try:
                        task = todo.get_nowait()
                    except queue.Empty:
                        return
                    done.put(execute_run(task, self.cancel))
            except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread
                done.put(exc)
            finally:
                done.put(None)

        self.threads = [
            threading.Thread(target=work, name=f"mrgc-bench-{i}", daemon=True)
            for i in range(min(self.jobs, todo.qsize()))
        ]
        for th in self.threads:
            th.start()
        running = len(self.threads)
        while running:
            try:
                item = done.get(timeout=0.5)  # a timeout keeps the main thread responsive to signals
            except queue.Empty:
                continue
            if item is None:
                running -= 1
            elif isinstance(item, BaseException):
                raise item
            elif not item.cancelled:
                yield item

    def close(self) -> None:
        """Cancel the running runs (their processes are killed) and wait for the threads."""
        self.cancel.set()
        for th in self.threads:
            th.join()

    def __enter__(self) -> "LocalExecutor":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
