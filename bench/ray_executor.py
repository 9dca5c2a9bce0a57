"""The Ray executor (``mrgc bench run --executor ray [--address A]``; optional extra ``mrgc[ray]``).

Each run is one Ray task (one CPU, no retries) calling the same :func:`~mrgc.bench.execute.execute_run` as
the local executor, on whichever node Ray places it; the task returns the raw outcome with the plan and
validator texts, and the driver records it in its database as each task finishes.

- ``--address A`` connects to a running cluster (``ray start --head`` ...); without it Ray is started
  on this machine with ``--jobs`` CPUs (or Ray's own ``RAY_ADDRESS`` is used), and stopped at the end.
  When the caller already called ``ray.init`` (tests, notebooks), that session is used and left running.
- Workers need the same mrgc installed.  A worker without the study's files gets the instance's text (and
  a ``domain.mrg`` beside it) with the task and writes them into a temporary folder; an instance whose
  domain lives elsewhere needs the same path on the worker (a shared file system).
- Interrupting ``bench run`` cancels the tasks: a running one gets KeyboardInterrupt, on which the runner
  kills its process group; nothing of a cancelled task is recorded.
"""

from __future__ import annotations

from typing import Any, Iterable, Iterator

from mrgc.bench.execute import RawRun, RunTask, execute_run
from mrgc.errors import Diagnostic, InputError, MissingBackendError


def _check_reachable(address: str) -> None:
    """A ``HOST:PORT`` address that refuses a TCP connection is a one-line error at once (Ray itself
    retries for minutes in native code, deaf to Ctrl-C); other forms (``auto``, ``ray://``) go to Ray."""
    import re
    import socket

    m = re.fullmatch(r"\[?([^\]/]+?)\]?:(\d+)", address)
    if m is None:
        return
    try:
        socket.create_connection((m.group(1), int(m.group(2))), timeout=5).close()
    except OSError as exc:
        raise InputError(
            [Diagnostic("E000", f"--address {address}: no Ray cluster answers there ({exc.strerror or exc})")]
        ) from None


def _run_remote(task: RunTask) -> RawRun:
    return execute_run(task, remote=True)


class RayExecutor:
    """Runs as Ray tasks (module docstring)."""

    remote = True

    def __init__(self, jobs: int = 1, address: str | None = None) -> None:
        try:
            import ray
        except ImportError as exc:
            raise MissingBackendError(f"--executor ray needs Ray: pip install 'mrgc[ray]' ({exc})") from None
        self.ray: Any = ray
        self.owns = not ray.is_initialized()
        if self.owns:
            kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
            if address is not None:
                _check_reachable(address)
                kwargs["address"] = address
            else:
                kwargs["num_cpus"] = max(1, jobs)
            try:
                ray.init(**kwargs)
            except Exception as exc:  # noqa: BLE001 - Ray raises several kinds for an unusable cluster
                where = f"at {address}" if address is not None else "on this machine"
                raise InputError([Diagnostic("E000", f"cannot start or reach Ray {where}: {exc}")]) from None
        self.pending: list[Any] = []

    def results(self, tasks: Iterable[RunTask]) -> Iterator[RawRun]:
        """Submit ``tasks`` as Ray tasks (one CPU each); yield runs as they end, except cancelled ones."""
        ray = self.ray
        remote = ray.remote(num_cpus=1, max_retries=0)(_run_remote)
        self.pending = [remote.remote(t) for t in tasks]
        while self.pending:
            ready, self.pending = ray.wait(self.pending, num_returns=1, timeout=0.5)
            for ref in ready:
                raw: RawRun = ray.get(ref)
                if not raw.cancelled:
                    yield raw

    def close(self) -> None:
        """Cancel the pending tasks and wait (at most 10 s) for them to end."""
        for ref in self.pending:
            try:
                self.ray.cancel(ref)
            except Exception:  # noqa: BLE001 - a task that already ended cannot be cancelled
                pass
        if self.pending:
            self.ray.wait(self.pending, num_returns=len(self.pending), timeout=10)
        self.pending = []
        if self.owns:
            self.ray.shutdown()

    def __enter__(self) -> "RayExecutor":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
