"""The command line's one policy for SIGINT and SIGTERM.

Both signals stop whatever the main thread is doing by raising an exception there, so every command
stops the same way: SIGINT (Ctrl-C) raises :class:`KeyboardInterrupt` (exit code 130), SIGTERM raises
:class:`Terminated`, a ``KeyboardInterrupt`` too (exit code 143).  Code that stops cleanly on Ctrl-C
(the tree search returns what it had) therefore stops cleanly on SIGTERM.  What happens then:

- worker processes are killed and reaped by whoever started them (:mod:`mrgc.workers` does it for
  phase 1's pool; its workers ignore SIGINT and die with their parent);
- nothing is written as a result: :mod:`mrgc.outputs` refuses to put an output in place once a signal was
  received, and temp files are removed;
- the CLI prints one line saying what was interrupted (:func:`activity` names it) and exits with
  :func:`exit_code`.

Native solvers hold the main thread inside C code, where Python cannot run a signal handler until the
solve returns (CP-SAT with a 60 s limit would ignore Ctrl-C for up to 60 s).  :func:`install` therefore
also starts a watcher thread woken by :func:`signal.set_wakeup_fd`; inside :func:`stop_on_signal` it calls
the solver's own stop function (CP-SAT ``StopSearch``, HiGHS ``cancelSolve``, z3 ``interrupt``), the solve
returns at once, and the handler's exception follows.  Solvers' own SIGINT handlers stay disabled
(CP-SAT's ``catch_sigint_signal = False``) so this policy is the only one.

Without :func:`install` (library use, tests calling ``cli.main`` in-process) nothing is changed:
Python's default Ctrl-C behaviour stays, and :func:`stop_on_signal` does nothing.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from typing import Callable, Iterator

from mrgc.exits import ExitCode

#: exit code of each handled signal (128 + the signal number, the shell's convention)
EXIT_CODES: dict[int, ExitCode] = {signal.SIGINT: ExitCode.INTERRUPTED, signal.SIGTERM: ExitCode.TERMINATED}
#: signals whose exception is raised in a run: the first, and a second in case Python swallowed the first
#: (raised in a ``__del__``); later ones are only recorded (the run is stopping; see :func:`ending`)
RAISED = 2
NAMES: dict[int, str] = {signal.SIGINT: "interrupted (SIGINT)", signal.SIGTERM: "terminated (SIGTERM)"}


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the main thread is, like Ctrl-C's KeyboardInterrupt."""


class _State:
    def __init__(self) -> None:
        self.installed = False
        self.received: list[int] = []  # signals received, in order
        self.doing: list[str] = []  # activity stack of the main thread
        self.what: str = ""  # the activity when the first signal came
        self.left: list[str] = []  # what the activities running leave done when interrupted (activity(left=))
        self.kept: str = ""  # what was left done when the first signal came
        self.stops: dict[int, Callable[[], None]] = {}  # stop functions of running native solves
        self.lock = threading.Lock()
        self.next_id = 0
        self.wakeup: tuple[int, int] | None = None
        self.previous: tuple[object, object, int] | None = None  # handlers and wakeup fd before install()
        self.unraisable: Callable[..., object] | None = None  # sys.unraisablehook before install()
        self.shield = 0  # > 0: inside cleanup that a second signal must not cut short
        self.ending = False  # the command is ending: signals are recorded, never raised (ending())


_S = _State()


def install() -> None:
    """Install the policy (main thread only; a second call does nothing)."""
    if _S.installed or threading.current_thread() is not threading.main_thread():
        return
    old_int = signal.signal(signal.SIGINT, _handler)
    old_term = signal.signal(signal.SIGTERM, _handler)
    old_fd = -1
    try:
        r, w = os.pipe()
        os.set_blocking(w, False)
        old_fd = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
    except (OSError, ValueError):  # pragma: no cover - no pipes: solves just stop later
        pass
    else:
        _S.wakeup = (r, w)
        threading.Thread(target=_watch, args=(r,), name="mrgc-signal-watcher", daemon=True).start()
    _S.previous = (old_int, old_term, old_fd)
    _S.unraisable = sys.unraisablehook
    sys.unraisablehook = _unraisable
    _S.installed = True


def uninstall() -> None:
    """Restore the handlers :func:`install` replaced (for callers of ``cli.main`` that keep running)."""
    if not _S.installed or threading.current_thread() is not threading.main_thread():
        return
    assert _S.previous is not None
    old_int, old_term, old_fd = _S.previous
    signal.signal(signal.SIGINT, old_int if old_int is not None else signal.SIG_DFL)  # type: ignore[arg-type]
    signal.signal(signal.SIGTERM, old_term if old_term is not None else signal.SIG_DFL)  # type: ignore[arg-type]
    if _S.wakeup is not None:
        signal.set_wakeup_fd(old_fd)
        os.close(_S.wakeup[1])  # the watcher reads EOF and closes its end
        _S.wakeup = None
    if _S.unraisable is not None:
        sys.unraisablehook = _S.unraisable
    _S.installed = False
    _S.ending = False


def _unraisable(info: "sys.UnraisableHookArgs") -> None:
    """A signal's exception raised where Python cannot raise it (a ``__del__``): dropped silently, no
    traceback; the next checkpoint raises it again (:func:`stop_on_signal`, :func:`raise_if_received`)."""
    if isinstance(info.exc_value, KeyboardInterrupt) and _S.received:
        return
    if _S.unraisable is not None:
        _S.unraisable(info)


def reset() -> None:
    """Forget received signals and activities (a new command in the same process; main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        return
    _S.received.clear()
    _S.doing.clear()
    _S.left.clear()
    _S.what = ""
    _S.kept = ""
    _S.ending = False


def _handler(signum: int, frame: object) -> None:
    first = not _S.received
    _S.received.append(signum)
    if first:
        _S.what = _S.doing[-1] if _S.doing else ""
        _S.kept = _S.left[-1] if _S.left else ""
    if _S.shield or _S.ending or len(_S.received) > RAISED:
        # let the cleanup (killing workers, removing temp files) finish, shielded() raising after it; or the
        # command is ending on a signal already; or two were raised (the second only for a first that Python
        # swallowed): the run is stopping, and a further exception would only cut its report short
        return
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def ending() -> None:
    """The command is ending (``cli.main`` reports the signal's exception, or has returned and the process is
    about to exit): further signals are recorded, never raised, so that no second Ctrl-C or SIGTERM turns
    the one line and exit code of the first into a traceback.  :func:`uninstall` ends this.  Only the main
    thread's command, while the policy is installed, says so (a ``cli.main`` run in another thread does not
    silence the main thread's signals)."""
    if _S.installed and threading.current_thread() is threading.main_thread():
        _S.ending = True


def _watch(fd: int) -> None:
    while True:
        try:
            data = os.read(fd, 64)
        except OSError:  # pragma: no cover
            return
        if not data:
            os.close(fd)
            return
        if any(b in EXIT_CODES for b in data):
            with _S.lock:
                stops = list(_S.stops.values())
            for stop in stops:
                try:
                    stop()
                except Exception:  # noqa: BLE001 - a failing stop must not kill the watcher
                    pass


def received() -> int | None:
    """The first signal received since :func:`reset` (None: none)."""
    return _S.received[0] if _S.received else None


def exit_code(signum: int | None = None) -> int:
    """The exit code for ``signum`` (default: the first received; SIGINT's 130 when none was)."""
    sig = signum if signum is not None else received()
    return EXIT_CODES.get(sig if sig is not None else signal.SIGINT, ExitCode.INTERRUPTED)


def describe(exc: BaseException | None = None) -> str:
    """One line: which signal, and what it interrupted (``terminated (SIGTERM) while computing ...``)."""
    sig = received()
    if sig is None:
        sig = signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT
    what = _S.what or (_S.doing[-1] if _S.doing else "")
    return NAMES[sig] + (f" while {what}" if what else "")


def raise_if_received() -> None:
    """Raise the signal's exception again if one was received while the policy is installed (for code
    about to commit a result, or to start more work, after something swallowed the first exception)."""
    sig = received()
    if sig is not None and _S.installed and not _S.ending:
        raise Terminated() if sig == signal.SIGTERM else KeyboardInterrupt()


@contextlib.contextmanager
def activity(what: str, left: str = "") -> Iterator[None]:
    """Name what the main thread is doing (``computing the facts of pa10``), for the interrupt message;
    ``left``: what an interrupt leaves done when it is not "nothing written" (a study's recorded runs)."""
    _S.doing.append(what)
    if left:
        _S.left.append(left)
    try:
        yield
    finally:
        if _S.doing and _S.doing[-1] == what:
            _S.doing.pop()
        if left and _S.left and _S.left[-1] == left:
            _S.left.pop()


def left() -> str:
    """What the interrupted command leaves done, for its one line: "nothing written", or what the activity
    running when the first signal came said (:func:`activity`)."""
    return _S.kept or "nothing written"


@contextlib.contextmanager
def shielded() -> Iterator[None]:
    """Cleanup after a signal (killing and reaping workers, removing temp files): a further signal is
    recorded but does not cut it short; one that is the first signal is raised when the block ends."""
    _S.shield += 1
    before = len(_S.received)
    try:
        yield
    finally:
        _S.shield -= 1
    if before == 0 and _S.received and _S.installed:
        raise_if_received()


@contextlib.contextmanager
def stop_on_signal(stop: Callable[[], None]) -> Iterator[None]:
    """While inside, a SIGINT or SIGTERM calls ``stop`` at once from the watcher thread (a native solver's
    thread-safe stop function), so the solve returns and the signal's exception is raised promptly.

    The block is also a checkpoint: entering or leaving it after a signal raises the signal's exception
    again, so a signal whose exception was swallowed (Python drops exceptions raised in ``__del__``,
    where a handler may happen to run) still stops the run at the next solve, never turning into a
    solver verdict."""
    if not _S.installed:
        yield
        return
    raise_if_received()
    with _S.lock:
        key = _S.next_id
        _S.next_id += 1
        _S.stops[key] = stop
    try:
        yield
    finally:
        with _S.lock:
            _S.stops.pop(key, None)
    raise_if_received()
