"""One process under limits: its own process group, a wall-clock limit and a memory limit, killed as a group.

:func:`run_limited` starts a command in a new session (so its process group holds it and everything it
starts, and a Ctrl-C on the terminal reaches only ``mrgc bench``), samples the group's memory every
:data:`SAMPLE_SECONDS`, and kills the whole group with SIGKILL

- at the wall-clock limit (``killed="timeout"``),
- when the group's memory passes the limit (``killed="memout"``),
- when the caller cancels (``killed="cancelled"``: ``bench run`` interrupted; such a run is not recorded).

Memory is the proportional set size (PSS, ``/proc/PID/smaps_rollup``) summed over the group's processes:
resident memory with pages shared between forked workers counted once.  PSS is dear: the kernel walks the
process's page tables for it (70 ms for a 2.8 GB planner on the loaded 2-core machine, a third of a core
at 5 samples a second, taken from the runs being measured).  So each sample reads the resident set size
(``/proc/PID/statm``, microseconds), which is never below PSS, and reads PSS only when the RSS passes the
limit (to decide) and for the peak, at most every :func:`pss_interval` seconds.  It is not ``RLIMIT_AS``: that
bounds *reserved* address space, which OpenBLAS, OR-Tools and Python threads reserve by gigabytes without
touching, and a process that hits it fails somewhere arbitrary (we measured ``mrgc plan`` under small
limits exit 1, 4, 70, 130 or abort: outcomes that mean other things) instead of being classified.

When the leader ends by itself the group is killed too (a worker it left behind does not outlive the run);
the leader is reaped only after that, so its process group id cannot have been reused.
"""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time
from dataclasses import dataclass

#: seconds between two memory samples (and the finest resolution of the limits)
SAMPLE_SECONDS = 0.2
#: longest interval between two PSS readings for the peak (seconds)
PSS_MAX_SECONDS = 5.0
#: characters of standard error kept for the record
TAIL_CHARS = 2000


@dataclass(frozen=True)
class ProcessResult:
    """How a limited process ended.  ``exit_code`` is its exit status, or None when a signal ended it
    (``signal``); ``killed`` says why the runner killed it (None: it ended by itself); ``seconds`` is the
    wall-clock time from start to end; ``peak_mb`` the largest group memory sampled (MiB); ``cpu_seconds`` the
    CPU time (user + system) of the process and of every process it started and waited for (its worker
    processes), from the kernel's accounting when the process is reaped — on a shared machine the measure
    that does not grow with others' load.  A process killed at a limit counts what it had used; workers it
    had not reaped by then are not counted."""

    argv: tuple[str, ...]
    exit_code: int | None
    signal: int | None
    seconds: float
    peak_mb: float
    killed: str | None
    stdout_path: str
    stderr_path: str
    cpu_seconds: float = 0.0

    def stderr_tail(self, chars: int = TAIL_CHARS) -> str:
        """The last ``chars`` characters of the process's standard error."""
        return tail(self.stderr_path, chars)


def read_text(path: str) -> str | None:
    """A UTF-8 text file's contents, or None when it cannot be read."""
    try:
        with open(path, encoding="utf-8") as fh:
            return fh.read()
    except (OSError, UnicodeDecodeError):
        return None


def tail(path: str, chars: int = TAIL_CHARS) -> str:
    """The last ``chars`` characters of a text file ('' if it cannot be read)."""
    try:
        with open(path, "rb") as fh:
            fh.seek(0, os.SEEK_END)
            size = fh.tell()
            fh.seek(max(0, size - 4 * chars))
            return fh.read().decode("utf-8", errors="replace")[-chars:]
    except OSError:
        return ""


def group_members(pgid: int) -> list[int]:
    """The live processes of process group ``pgid`` (from /proc)."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as fh:
                stat = fh.read()
        except OSError:
            continue
        fields = stat[stat.rfind(b")") + 2 :].split()
        if len(fields) > 2 and int(fields[2]) == pgid and fields[0] != b"Z":
            out.append(int(entry))
    return out


def pss_interval(elapsed: float) -> float:
    """Seconds until the next PSS reading for the peak, ``elapsed`` seconds into a run: every sample at
    first (small processes, cheap readings), then a tenth of the time elapsed, at most PSS_MAX_SECONDS."""
    return min(PSS_MAX_SECONDS, max(SAMPLE_SECONDS, elapsed / 10))


def group_rss_mb(pids: list[int]) -> float:
    """Resident set size of ``pids`` in MiB, summed (an upper bound of their PSS; cheap to read)."""
    total = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/statm", "rb") as fh:
                total += int(fh.read().split()[1])
        except (OSError, IndexError, ValueError):
            continue
    return total * os.sysconf("SC_PAGE_SIZE") / 2**20


def group_memory_mb(pgid: int, pids: list[int] | None = None) -> float:
    """PSS of the group's processes (or of ``pids``, its members) in MiB (RSS where smaps_rollup is not
    readable)."""
    total_kb = 0
    for pid in group_members(pgid) if pids is None else pids:
        try:
            with open(f"/proc/{pid}/smaps_rollup", "rb") as fh:
                for line in fh:
                    if line.startswith(b"Pss:"):
                        total_kb += int(line.split()[1])
                        break
        except OSError:
            try:
                with open(f"/proc/{pid}/statm", "rb") as fh:
                    total_kb += int(fh.read().split()[1]) * (os.sysconf("SC_PAGE_SIZE") // 1024)
            except OSError:
                continue
    return total_kb / 1024


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def run_limited(
    argv: list[str],
    *,
    wall: float,
    memory_mb: float,
    stdout: str,
    stderr: str,
    cwd: str | None = None,
    cancel: threading.Event | None = None,
    env: dict[str, str] | None = None,
) -> ProcessResult:
    """Run ``argv`` to its end or to a limit (module docstring); standard output and error go to files."""
    killed: str | None = None
    peak = 0.0
    with open(stdout, "wb") as out, open(stderr, "wb") as err:
        start = time.monotonic()
        proc = subprocess.Popen(
            argv, stdin=subprocess.DEVNULL, stdout=out, stderr=err, cwd=cwd, env=env, start_new_session=True
        )
    pgid = proc.pid
    try:
        next_sample = next_pss = start
        while True:
            ended = os.waitid(os.P_PID, proc.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT)
            if ended is not None:
                break
            now = time.monotonic()
            if now >= next_sample:
                pids = group_members(pgid)
                if now >= next_pss or group_rss_mb(pids) > memory_mb:
                    pss = group_memory_mb(pgid, pids)
                    peak = max(peak, pss)
                    next_pss = now + pss_interval(now - start)
                    if pss > memory_mb:
                        killed = "memout"
                next_sample = now + SAMPLE_SECONDS
            if killed is None and now - start >= wall:
                killed = "timeout"
            if killed is None and cancel is not None and cancel.is_set():
                killed = "cancelled"
            if killed is not None:
                _kill_group(pgid)
                break
            if cancel is not None:
                cancel.wait(min(SAMPLE_SECONDS, max(0.0, wall - (now - start))) / 2)
            else:
                time.sleep(SAMPLE_SECONDS / 2)
    finally:  # also on KeyboardInterrupt (a cancelled Ray task): nothing of the run may outlive it
        _kill_group(pgid)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        cpu = usage.ru_utime + usage.ru_stime
    seconds = time.monotonic() - start
    code = proc.returncode
    return ProcessResult(
        tuple(argv),
        code if code >= 0 else None,
        -code if code < 0 else None,
        seconds,
        peak,
        killed,
        stdout,
        stderr,
        round(cpu, 3),
    )
