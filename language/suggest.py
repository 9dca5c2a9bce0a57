"""The "Did you mean" suggestions for misspelt names, near-linear in the number of names.

A file with thousands of misspelt names asks for thousands of suggestions from thousands of candidates;
comparing every pair was quadratic (1,000 misspelt names took 92 s).  Now each distinct candidate pool is
indexed once (cached): every candidate and each of its one-character deletions point back to it, so the
candidates within one edit of a word (a substitution, insertion, deletion, or a swap of neighbours) are
found by looking up the word and its own deletions, exactly.  Only when none is that close are candidates
compared in full: those whose length is within the allowed number of edits, nearest lengths first, at
most :data:`MAX_SCAN` of them, with a distance computation that stops once the bound is exceeded, then
difflib over the same capped list.  docs/benchmarks.md has the measurements.
"""

from __future__ import annotations

import difflib
import functools
from typing import Iterable

#: candidates compared in full per word when no candidate is within one edit
MAX_SCAN = 300
#: words longer than this get no suggestion (a paragraph is not a misspelt name)
MAX_WORD = 64


def edit_distance(a: str, b: str, bound: int | None = None) -> int:
    """Levenshtein distance (insertions, deletions, substitutions each cost 1); with ``bound``, any
    distance above it is reported as ``bound + 1`` (and computed no further)."""
    if len(a) < len(b):
        a, b = b, a
    if bound is not None and len(a) - len(b) > bound:
        return bound + 1
    prev = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        cur = [i]
        for j, cb in enumerate(b, 1):
            cur.append(min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (ca != cb)))
        if bound is not None and min(cur) > bound:
            return bound + 1
        prev = cur
    return prev[-1]


def _deletions(word: str) -> set[str]:
    return {word[:i] + word[i + 1 :] for i in range(len(word))}


class _Pool:
    """A candidate pool indexed for suggestions."""

    def __init__(self, names: frozenset[str]) -> None:
        self.near: dict[str, list[str]] = {}
        self.by_length: dict[int, list[str]] = {}
        for name in sorted(names):
            for key in {name, *_deletions(name)}:
                self.near.setdefault(key, []).append(name)
            self.by_length.setdefault(len(name), []).append(name)

    def within_one(self, word: str) -> set[str]:
        """Every candidate at most one edit (or one swap of neighbours) from ``word`` (and a few at two)."""
        out: set[str] = set()
        for key in (word, *_deletions(word)):
            out.update(self.near.get(key, ()))
        out.discard(word)
        return out

    def scan(self, word: str, spread: int) -> list[str]:
        """Up to MAX_SCAN candidates whose length is within ``spread`` of the word's, nearest lengths first."""
        out: list[str] = []
        for d in range(spread + 1):
            for length in sorted({len(word) - d, len(word) + d}):
                out.extend(c for c in self.by_length.get(length, ()) if c != word)
                if len(out) >= MAX_SCAN:
                    return out[:MAX_SCAN]
        return out


@functools.lru_cache(maxsize=32)
def _pool(names: frozenset[str]) -> _Pool:
    return _Pool(names)


def did_you_mean(word: str, candidates: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest candidate, or the empty string when none is close.

    Close means at most one edit per three characters (at least one edit), or a difflib similarity of 0.6
    or more; ties go to the alphabetically first candidate, so the hint is deterministic.
    """
    if len(word) > MAX_WORD:
        return ""
    names = candidates if isinstance(candidates, frozenset) else frozenset(candidates)
    if not names or names == {word}:
        return ""
    pool = _pool(names)
    allowed = max(1, len(word) // 3)
    near = pool.within_one(word)
    if near:
        best = min(near, key=lambda c: (edit_distance(word, c, 2), c))
        if edit_distance(word, best, 1) <= 1:  # the closest possible: every candidate one edit away is in near
            return f" (did you mean '{best}'?)"
    if allowed > 1:
        scan = pool.scan(word, allowed)
        if scan:
            best = min(scan, key=lambda c: (edit_distance(word, c, allowed), c))
            if edit_distance(word, best, allowed) <= allowed:
                return f" (did you mean '{best}'?)"
    # difflib's ratio of 0.6 needs the shorter of the two at least 0.43 times the longer
    match = difflib.get_close_matches(word, sorted(pool.scan(word, 2 * len(word))), n=1, cutoff=0.6)
    return f" (did you mean '{match[0]}'?)" if match else ""


def by_meaning(word: str, candidates: Iterable[str], synonyms: dict[str, tuple[str, ...]] | None = None) -> str:
    """`` (did you mean 'x'?)`` (or ``'x' or 'y'``) by what ``word`` means, else by spelling (:func:`did_you_mean`).

    Meaning: ``synonyms`` maps words users write to the candidates they stand for (``handover`` →
    ``enable-goal-handover``); otherwise the candidates whose hyphen-separated parts include every part of
    ``word`` (``reachable`` → ``reachable-pick`` or ``reachable-place``, ``goal-place`` →
    ``occludes-goal-place``).  Case and ``_`` versus ``-`` do not matter.
    """
    names = sorted(set(candidates))
    key = word.lower().replace("_", "-")
    found: list[str] = []
    if synonyms and key in synonyms:
        found = [c for c in synonyms[key] if c in names]
    if not found and key not in names:
        parts = [p for p in key.split("-") if p]
        found = [c for c in names if parts and all(p in c.split("-") for p in parts)]
    found = [c for c in found if c != word]
    if found:
        if len(found) == 1:
            return f" (did you mean '{found[0]}'?)"
        return " (did you mean " + " or ".join(f"'{c}'" for c in found[:3]) + "?)"
    return did_you_mean(word, names)
