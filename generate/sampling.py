"""Drawing a layout: argument checks, the seeded random stream, rejection sampling of whole layouts.

Every generator draws from ``numpy.random.default_rng(seed)`` only, in a fixed order, so the same
arguments give the same file.  A layout attempt returns None when some item found no place; the next
attempt continues the same random stream (nothing is re-seeded, nothing depends on time).
"""

from __future__ import annotations

from typing import Callable, TypeVar

import numpy as np

from mrgc.errors import Diagnostic, InputError

T = TypeVar("T")

ATTEMPTS = 200  # rejection-sampling attempts per item, and layouts per instance


def usage_error(message: str) -> InputError:
    """A bad generator argument: a one-line E000 diagnostic (exit code 2 on the command line)."""
    return InputError([Diagnostic("E000", message)])


def check_count(name: str, value: int, low: int, high: int) -> None:
    """A usage error unless ``value`` is an integer from ``low`` to ``high``."""
    if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= high:
        raise usage_error(f"{name} must be an integer from {low} to {high} (got {value!r})")


def check_seed(seed: int) -> None:
    """E000 unless ``seed`` is a seed the command line takes (:func:`mrgc.limits.checked`, the API's one
    check of ``--seed``'s bound: a generated file's header names the command that makes it again)."""
    from mrgc.limits import checked

    checked("seed", seed, "count")


def uniform(rng: np.random.Generator, lo: float, hi: float, digits: int = 3) -> float:
    """A uniform draw from [lo, hi], rounded to ``digits`` decimals (millimetres by default)."""
    return round(float(rng.uniform(lo, hi)), digits) + 0.0


def draw_layout(
    kind: str,
    ranges: dict[str, tuple[int, int]],
    counts: dict[str, int],
    seed: int,
    attempt: Callable[[np.random.Generator], T | None],
) -> tuple[np.random.Generator, T]:
    """Check ``counts`` (``--robots`` etc.) against ``ranges`` and the seed, then draw layouts until one fits.

    Returns the random stream (to draw the rest from) and the layout.
    """
    for name, value in counts.items():
        check_count(name, value, *ranges[name])
    check_seed(seed)
    rng = np.random.default_rng(seed)
    for _ in range(ATTEMPTS):
        layout = attempt(rng)
        if layout is not None:
            return rng, layout
    raise AssertionError(f"no {kind} layout for {counts}, seed {seed}")  # never seen within the ranges
