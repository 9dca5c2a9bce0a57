"""The bounds of every number the command line takes, as argparse types.

Each option's value is parsed and checked when the command line is read, so a bad number is a usage error
(``error[E000]``, exit code 2) before any work starts: not finite (``nan``, ``inf``), not positive where a
count or a duration is meant, or beyond a bound that keeps the solvers' own integer types and memory
safe.  The bounds are data (:data:`BOUNDS`); docs/cli.md lists them.  Commands added later take their
numbers through the same types (``type=limits.count("--runs", 1, 10_000)``).
"""

from __future__ import annotations

import argparse
import math
import numbers
from typing import Any, Callable

#: option -> (lowest, highest) accepted value; the reason for each bound is in docs/cli.md
BOUNDS: dict[str, tuple[float, float]] = {
    "--time-limit": (0.0, 1e6),  # seconds, > 0: about 11.6 days; z3 takes milliseconds in 32 bits
    "--seed": (0, 2**31 - 1),  # CP-SAT's random_seed is a 32-bit signed integer
    "--skeletons": (1, 10_000),
    "--max-makespan": (1, 10_000),  # a skeleton moves each object at most once: makespan <= objects
    "--horizon": (1, 10_000),  # the exported model's horizon: as --max-makespan
    "--workers": (1, 1_000_000),  # then capped at one per robot and one per usable core
    "-c": (0.0, 1e6),
    "--alpha": (0.0, 1e6),
}


def _int_text(text: str) -> int:
    if len(text) > 40:  # int() of thousands of digits is slow and meaningless here
        raise ValueError
    return int(text)


def count(option: str, lo: int | None = None, hi: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer in [lo, hi] (default: ``BOUNDS[option]``)."""
    blo, bhi = BOUNDS.get(option, (lo, hi))
    low, high = int(lo if lo is not None else blo), int(hi if hi is not None else bhi)  # type: ignore[arg-type]

    def parse(text: str) -> int:
        try:
            value = _int_text(text.strip())
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be a whole number from {low} to {high:,} (got {_shown(text)})"
            ) from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be a whole number from {low} to {high:,} (got {value})")
        return value

    parse.__name__ = "integer"
    return parse


def number(
    option: str, lo: float | None = None, hi: float | None = None, *, positive: bool = False
) -> Callable[[str], float]:
    """An argparse type: a finite float in [lo, hi] (default: ``BOUNDS[option]``); ``positive`` excludes
    ``lo`` itself (a duration of 0 s is no duration)."""
    blo, bhi = BOUNDS.get(option, (lo, hi))
    low, high = float(lo if lo is not None else blo), float(hi if hi is not None else bhi)  # type: ignore[arg-type]
    what = f"{'more than' if positive else 'from'} {low:g} {'and at most' if positive else 'to'} {high:g}"

    def parse(text: str) -> float:
        try:
            value = float(text.strip()) if len(text) <= 64 else float("nan")
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a finite number {what} (got {_shown(text)})") from None
        if not math.isfinite(value) or value > high or value < low or (positive and value <= low):
            raise argparse.ArgumentTypeError(f"must be a finite number {what} (got {_shown(text)})")
        return value

    parse.__name__ = "number"
    return parse


def _shown(text: str) -> str:
    return repr(text if len(text) <= 40 else text[:37] + "...")


def checked(
    name: str,
    value: object,
    kind: str,
    *,
    option: str | None = None,
    bounds: tuple[float, float] | None = None,
    none: bool = False,
    positive: bool = False,
) -> Any:
    """A Python API argument checked as the command line checks its option (``option``, default ``--`` +
    ``name`` with dashes; ``bounds``, default its row of :data:`BOUNDS`): ``kind`` ``"count"`` (a whole
    number, ``bool`` excluded) or ``"number"`` (finite; ``positive`` excludes the lowest bound); ``none`` lets
    None through.  The value,
    else InputError E000 ``name=...: must be ...`` (the API's misuse is an exception of the one root, never a
    solver's own error or a wrong verdict: a seed past CP-SAT's 32 bits was a false "time limit")."""
    from mrgc.errors import Diagnostic, InputError

    if value is None and none:
        return None
    flag = option or "--" + name.replace("_", "-")
    lo, hi = bounds if bounds is not None else BOUNDS[flag]
    whole = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if kind == "count":
        ok = whole and lo <= value <= hi  # type: ignore[operator]
        what = f"must be a whole number from {int(lo)} to {int(hi):,}"
    else:
        real = whole or isinstance(value, numbers.Real) and not isinstance(value, bool)
        # bounds first: math.isfinite of an int past a float's range raises OverflowError
        ok = real and lo <= value <= hi and math.isfinite(value) and not (positive and value <= lo)  # type: ignore[arg-type,operator]
        span = f"more than {lo:g} and at most {hi:g}" if positive else f"from {lo:g} to {hi:g}"
        what = f"must be a finite number {span}"
    if not ok:
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise InputError([Diagnostic("E000", f"{name}={shown}: {what}{' or None' if none else ''}")])
    return value
