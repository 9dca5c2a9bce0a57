"""The ``mrgc`` command: a thin layer over the Python API.

Exit codes: the table of :mod:`mrgc.exits` (docs/errors.md is written from it).  No input produces a Python
traceback: unexpected exceptions are reported in one line with exit code 70.

The commands are :mod:`mrgc.commands`; this module adds the command groups of ``render/`` and ``bench/`` to
their parser and runs it.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Callable, Sequence


def _one_blas_thread() -> None:
    """Run numpy's OpenBLAS on one thread unless the environment says otherwise (``OPENBLAS_NUM_THREADS``).

    mrgc's linear algebra is 4x4 transforms and 7x7 solves, far below what OpenBLAS splits over threads, yet
    its pool starts one thread per core when numpy is imported and they wake and spin on its calls: about
    70 ms of CPU at import and 0.05-0.21 s over a PA5-BO8 run on 2 cores, for nothing (the plans are the
    same bit for bit; docs/benchmarks.md, "Session 27").  Read by OpenBLAS once, when numpy loads, so this
    runs before any module that imports numpy; worker processes inherit it."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


_one_blas_thread()


def _no_collection_at_exit() -> None:
    """Spare the interpreter's exit its full garbage collection: ``gc.freeze()`` as the last exit handler,
    unless OMPL was loaded.

    When a command returns, Python's shutdown walks every object the run made (tens of thousands: modules,
    models, the search's records) looking for reference cycles to free, memory the process is about to give
    back whole: 45-70 ms of a PA5 run's 1.0 s of CPU (measured at the end of ``main`` and by ``time``; the PA5
    presets, each run before, after, after, before: median CPU 4.8 % lower, docs/benchmarks.md, "Session 28").
    Frozen, they are left out of that pass (objects are still freed by their reference counts as modules
    are torn down; only cycles among them are not looked for, which Python does not promise to collect at
    exit anyway).  OMPL's bindings (nanobind) count their objects still alive when they unload and print a
    page of "leaked" warnings when cycles holding them were not collected, so a run that planned a path with
    OMPL (:mod:`mrgc.geometry.motion`, loaded on its first path; 5 of the 20 PA5 presets) keeps the
    collection, as before.  Registered once, when the command's module loads, so it runs after the exit handlers
    registered later (multiprocessing's, which reaps workers); an in-process caller of :func:`main` (the
    tests) is unaffected until its own interpreter exits."""
    import atexit
    import gc

    def freeze_unless_ompl() -> None:
        if "ompl" not in sys.modules:
            gc.freeze()

    atexit.register(freeze_unless_ompl)


_no_collection_at_exit()

from mrgc import commands  # noqa: E402  (after the BLAS setting: commands may import numpy)
from mrgc.errors import InputError, MrgcError  # noqa: E402
from mrgc.exits import ExitCode  # noqa: E402


def build_parser() -> argparse.ArgumentParser:
    """The ``mrgc`` argument parser with every command (usage errors are one ``E000`` line, exit 2): those
    of :mod:`mrgc.commands`, then render's and bench's."""
    parser = commands.build_parser()
    sub = commands.subcommands(parser)

    from mrgc.render.command import add_commands as add_render_commands

    add_render_commands(sub)  # render, graph

    from mrgc.bench.command import add_bench_parser

    add_bench_parser(sub)  # bench run, bench report
    return parser


def run() -> None:
    """The ``mrgc`` console script: :func:`main`, then exit with its code.  The signal policy stays installed
    until the process exits, signals only recorded from the end of the command on (a second Ctrl-C after
    the first one's report would otherwise meet Python's default handler: a traceback, or death by the
    second signal instead of the first one's exit code).  Ignored while the interpreter shuts down: its
    finalisation gives the signals their default actions back, and a SIGTERM then would end the process as
    killed by it, after the command's own exit code was settled."""
    import signal

    from mrgc import signals

    try:
        code = main(keep_handlers=True)
    except KeyboardInterrupt:  # a signal in the few bytecodes before main() stopped raising them
        code = signals.exit_code()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    sys.exit(code)


def main(argv: Sequence[str] | None = None, *, keep_handlers: bool = False) -> int:
    """Run the CLI; returns the exit code (the console script exits with it).

    SIGINT and SIGTERM follow the one policy of :mod:`mrgc.signals` while a command runs (exit 130 / 143,
    workers killed, nothing written); Python's defaults are restored when ``main`` returns, unless
    ``keep_handlers`` (:func:`run`: the process exits next), which leaves signals recorded and ignored.
    A signal that comes while the command ends on an earlier one (its report, the exit) is only recorded:
    one line and the first signal's exit code, never a traceback.
    """
    from mrgc import signals

    try:
        return _main(argv)
    except KeyboardInterrupt as exc:  # a signal while an error was reported, or a second one while the first
        signals.ending()  # one's exception was caught (before the line): the line, then the first one's code
        print(f"mrgc: {signals.describe(exc)}; {signals.left()}", file=sys.stderr)
        return signals.exit_code(signal_of(exc))
    finally:
        signals.ending()
        if not keep_handlers:
            signals.uninstall()


def _main(argv: Sequence[str] | None) -> int:
    """:func:`main`'s command, its errors reported in one line each."""
    from mrgc import signals

    parser = build_parser()
    signals.reset()
    signals.install()
    try:
        args = parser.parse_args(argv)
        if not getattr(args, "func", None):
            parser.print_help()
            return ExitCode.INPUT
        func: Callable[[argparse.Namespace], int] = args.func
        if getattr(args, "no_cache", False):
            from mrgc.planner.facts_cache import disabled

            with disabled():
                code = func(args)
        else:
            code = func(args)
        if signals.received() is not None and code not in signals.EXIT_CODES.values():
            # something swallowed the signal's exception: the signal still ends the run
            signals.ending()
            print(f"mrgc: {signals.describe()}; {signals.left()}", file=sys.stderr)
            return signals.exit_code()
        return code
    except SystemExit as exc:  # argparse --help / --version / usage errors
        return exc.code if isinstance(exc.code, int) else ExitCode.INPUT
    except KeyboardInterrupt as exc:  # SIGINT, or SIGTERM (signals.Terminated)
        signals.ending()
        print(f"mrgc: {signals.describe(exc)}; {signals.left()}", file=sys.stderr)
        return signals.exit_code(signal_of(exc))
    except InputError as exc:
        commands.report_input_error(exc)
        return exc.exit_code
    except MrgcError as exc:
        print(f"mrgc: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except BrokenPipeError:
        return ExitCode.OK
    except Exception as exc:  # noqa: BLE001 - the promise is: never a traceback
        if signals.received() is not None:  # the signal's exception came back as another one (ctypes wraps a
            # KeyboardInterrupt raised while it converts a call's arguments, as in z3's model building, in an
            # ArgumentError): the signal still ends the run
            signals.ending()
            print(f"mrgc: {signals.describe()}; {signals.left()}", file=sys.stderr)
            return signals.exit_code()
        print(
            f"mrgc: internal error[E070]: {type(exc).__name__}: {exc} "
            "(please report this with the input that caused it)",
            file=sys.stderr,
        )
        return ExitCode.INTERNAL


def signal_of(exc: BaseException) -> int:
    """The signal an interrupt exception stands for (the first received, else by its type)."""
    import signal

    from mrgc import signals

    got = signals.received()
    if got is not None:
        return got
    return signal.SIGTERM if isinstance(exc, signals.Terminated) else signal.SIGINT


if __name__ == "__main__":  # pragma: no cover
    run()
