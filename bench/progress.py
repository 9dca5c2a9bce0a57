"""Progress of ``bench run``: a rich progress bar on a terminal (done/total, solved so far, elapsed, ETA)
with each finished run printed above it; one plain line per finished run otherwise (logs, pipes, CI)."""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

from mrgc.bench.outcome import RunResult


def describe(r: RunResult) -> str:
    """One line about a finished run."""
    head = f"{r.instance} {r.method} seed {r.seed}: {r.status}"
    if r.success:
        parts = [f"{r.planning_seconds:.2f} s" if r.planning_seconds is not None else f"{r.wall_seconds:.1f} s wall"]
        if r.makespan is not None:
            parts.append(f"makespan {r.makespan}, {r.objects_moved} moved")
        if r.valid:
            parts.append("valid")
        return f"{head} ({', '.join(parts)})"
    detail = f": {r.detail}" if r.detail else ""
    return f"{head} after {r.wall_seconds:.1f} s{detail}"[:300]


class Progress:
    """Reports finished runs (module docstring).  ``rich`` None: decide by whether ``stream`` is a terminal."""

    def __init__(
        self, study: str, total: int, jobs: int = 1, stream: TextIO | None = None, rich: bool | None = None
    ) -> None:
        self.study, self.total, self.jobs = study, total, max(1, jobs)
        self.stream = stream or sys.stdout
        self.done = self.solved = 0
        self.start = time.monotonic()
        use_rich = rich if rich is not None else sys.stderr.isatty()
        self.bar: Any = None
        if use_rich and total:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn
            from rich.progress import Progress as Bar

            self.bar = Bar(
                TextColumn("[bold]{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("solved {task.fields[solved]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            self.task = self.bar.add_task(study, total=total, solved=0)
            self.bar.start()

    def update(self, r: RunResult) -> None:
        """Count a finished run and print its line."""
        self.done += 1
        self.solved += r.success
        line = describe(r)
        if self.bar is not None:
            self.bar.console.print(line, markup=False, highlight=False)
            self.bar.update(self.task, advance=1, solved=self.solved)
            return
        elapsed = time.monotonic() - self.start
        eta = elapsed / self.done * (self.total - self.done)
        print(
            f"[{self.done}/{self.total}, {self.solved} solved, ETA {_clock(eta)}] {line}", file=self.stream, flush=True
        )

    def close(self) -> None:
        """Stop the progress bar (if any)."""
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
