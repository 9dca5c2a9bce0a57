"""``mrgc bench run`` and ``mrgc bench report``: the command line over :mod:`mrgc.bench` (docs/bench.md).

Registered by ``mrgc.cli`` with :func:`add_bench_parser`; this module imports nothing heavy at import
time (``mrgc --help`` builds its parser).  Exit codes: 0 the study ran (whatever its runs' outcomes; the
report says) or the report was written; 2 a bad study, instance, database or command line (E000, E600-E603,
or an instance file's own diagnostics); 4 ``--executor ray`` without Ray installed; 130 / 143 interrupted
by SIGINT / SIGTERM (the running runs are killed, every finished one is kept).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any


def add_bench_parser(sub: Any) -> None:
    """Add ``bench run`` and ``bench report`` to the subcommands ``sub`` of the mrgc parser."""
    p = sub.add_parser("bench", help="run studies (instances x methods x seeds) into a results database; report them")
    inner = p.add_subparsers(dest="bench_command", metavar="SUBCOMMAND", parser_class=type(p))
    p.set_defaults(func=lambda args: _missing(p))

    r = inner.add_parser("run", help="run a study's unfinished runs (resumes: finished runs are skipped)")
    r.add_argument("study", metavar="STUDY.yaml")
    r.add_argument("--db", default=None, metavar="PATH", help="results database (default mrgc-bench.db)")
    r.add_argument("--jobs", "-j", type=int, default=1, metavar="N", help="runs at a time (default 1)")
    r.add_argument(
        "--executor",
        choices=["local", "ray"],
        default="local",
        help="local processes (default) or Ray tasks (pip install 'mrgc[ray]')",
    )
    r.add_argument("--address", default=None, metavar="A", help="Ray cluster address (default: start Ray here)")
    r.add_argument(
        "--work",
        default=None,
        metavar="DIR",
        help="folder for generated instances and run files (default: DB name + '-files')",
    )
    r.add_argument(
        "--retry",
        nargs="+",
        default=[],
        metavar="STATUS",
        help="also re-run recorded runs with these statuses (e.g. crash error)",
    )
    r.set_defaults(func=cmd_run)

    q = inner.add_parser("report", help="tables (Markdown, CSV) and figures of a results database")
    q.add_argument("--db", default=None, metavar="PATH", help="results database (default mrgc-bench.db)")
    q.add_argument("--study", default=None, help="only this study (default: every study in the database)")
    q.add_argument(
        "--format",
        choices=["markdown", "wide", "pairs", "csv", "runs"],  # mrgc.bench.report.FORMATS (not imported here)
        default="markdown",
        help="markdown (default): a row per instance set and method; wide: the paper's layout; "
        "pairs: the first method against each other one, per instance (time ratio, medians); "
        "csv: the same numbers; runs: every run as CSV",
    )
    q.add_argument(
        "--time",
        choices=["wall", "cpu"],
        default="wall",
        help="wall (default): the planning time each plan reports; cpu: CPU seconds of the planner's process "
        "and its workers (compare these on a shared machine)",
    )
    q.add_argument("--figures", default=None, metavar="DIR", help="also write PNG figures here (matplotlib)")
    q.add_argument(
        "--planner-arena",
        default=None,
        metavar="OUT.db",
        help="also write the runs as an OMPL benchmark database (Planner Arena reads it)",
    )
    q.set_defaults(func=cmd_report)


def _missing(p: argparse.ArgumentParser) -> int:
    p.print_help()
    return 2


def cmd_run(args: argparse.Namespace) -> int:
    """``mrgc bench run``: run the study's unfinished runs with a progress line per run, then a summary."""
    from mrgc.bench.progress import Progress
    from mrgc.bench.run import DEFAULT_DB, run_study

    if args.jobs < 1:
        from mrgc.errors import Diagnostic, InputError

        raise InputError([Diagnostic("E000", "--jobs must be at least 1")])
    progress: list[Progress] = []

    def started(total: int, todo: int) -> None:
        again = f" (--retry {' '.join(args.retry)}: those run again)" if args.retry else ""
        print(f"{args.study}: {total} runs, {total - todo} recorded and kept{again}, {todo} to run", flush=True)
        progress.append(Progress(args.study, todo, args.jobs))

    from mrgc import signals

    try:
        with signals.activity(
            f"running the study {args.study}", left="every run recorded so far is kept (bench run again goes on)"
        ):
            summary = run_study(
                args.study,
                args.db or DEFAULT_DB,
                jobs=args.jobs,
                executor=args.executor,
                address=args.address,
                work=args.work,
                retry=args.retry,
                on_start=started,
                on_result=lambda r: progress[0].update(r),
            )
    finally:
        for p in progress:
            p.close()
    for line in summary.lines():
        print(line)
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """``mrgc bench report``: tables on standard output; figures and a Planner Arena database on request."""
    from mrgc import outputs
    from mrgc.bench.db import ResultsDB
    from mrgc.bench.report import render
    from mrgc.bench.run import DEFAULT_DB

    path = args.db or DEFAULT_DB
    # the outputs are checked before the report is made: the database read is no output, a folder is made
    figures = args.figures if args.figures and outputs.check_folder(args.figures, option="--figures") else None
    if args.planner_arena:
        outputs.check_output(args.planner_arena, _database_files(path), option="--planner-arena")
    with ResultsDB(path, readonly=True) as db:
        if args.study is not None and args.study not in db.studies():
            from mrgc.errors import Diagnostic, InputError
            from mrgc.language.suggest import did_you_mean

            raise InputError(
                [
                    Diagnostic(
                        "E000",
                        f"no study '{args.study}' in {db.path}"
                        f"{did_you_mean(args.study, db.studies())} "
                        f"(studies: {', '.join(db.studies()) or 'none'})",
                    )
                ]
            )
        sys.stdout.write(render(db, args.format, args.study, args.time))
        if figures is not None:
            from mrgc.bench.figures import write_figures

            for written in write_figures(db, figures, args.study, args.time):
                print(f"figure written: {written}", file=sys.stderr)
        if args.planner_arena:
            from mrgc.bench.arena import export_planner_arena

            n = export_planner_arena(db, args.planner_arena, args.study, inputs=_database_files(path))
            print(f"{args.planner_arena}: {n} runs as an OMPL benchmark database (Planner Arena)", file=sys.stderr)
    return 0


def _database_files(path: str) -> list[str]:
    """The files of the SQLite results database ``path`` (its write-ahead log and shared memory too): inputs
    of ``bench report``, which no output may replace."""
    return [path, path + "-wal", path + "-shm"]
