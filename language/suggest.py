""""Did you mean" suggestions for misspelt names."""

from __future__ import annotations

import difflib
from typing import Iterable


def edit_distance(a: str, b: str) -> int:
    """Levenshtein distance (insertions, deletions, substitutions each cost 1)."""
    if len(a) < len(b):
        a, b = b, a
    prev = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        cur = [i]
        for j, cb in enumerate(b, 1):
            cur.append(min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (ca != cb)))
        prev = cur
    return prev[-1]


def did_you_mean(word: str, candidates: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest candidate, or the empty string when none is close.

    Close means at most one edit per three characters (at least one edit), or a difflib similarity of 0.6
    or more; ties go to the alphabetically first candidate, so the hint is deterministic.
    """
    pool = sorted(set(candidates) - {word})
    if not pool:
        return ""
    if len(pool) > 2000:  # keep the hint cheap on generated problems with thousands of names
        pool = [c for c in pool if abs(len(c) - len(word)) <= 2]
    best = min(pool, key=lambda c: (edit_distance(word, c), c), default=None)
    if best is not None and edit_distance(word, best) <= max(1, len(word) // 3):
        return f" (did you mean '{best}'?)"
    match = difflib.get_close_matches(word, pool, n=1, cutoff=0.6)
    return f" (did you mean '{match[0]}'?)" if match else ""
