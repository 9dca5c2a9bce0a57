"""Phase 1 computed once: a cache of the geometric facts of problems, on disk (docs/geometry.md, "The facts
cache").

Phase 1 takes seconds to minutes (pa10: 10 s), and ``plan``, ``compile``, ``graph``, ``render`` and the
studies of ``mrgc bench`` all need the same facts.  :func:`mrgc.planner.phase1.compute_problem_facts`, which
every one of them goes through, looks here first and stores what a complete phase 1 found.

- **Where**: ``$XDG_CACHE_HOME/mrgc/facts/`` (default ``~/.cache/mrgc/facts/``), one JSON file per entry.
- **Key**: the SHA-256 of the problem's content digest (:func:`mrgc.language.digest.problem_digest`: its
  geometry, robot kinds and their URDF files' bytes, grasps, goal; not its spans, comments or file name),
  the seed, the mrgc version, and a fingerprint of phase 1's code (the bytes of ``geometry/*.py``,
  ``language/*.py`` and ``planner/phase1.py``), so a changed problem, seed or program never meets an old
  entry.
- **Verified on read**: an entry is used only when it parses, names the same key fields, and the SHA-256
  of its facts matches the one stored with them; anything else (a truncated or edited file, another
  format) is ignored, removed, and phase 1 runs.  Entries are written atomically (a temporary file renamed
  into place), so readers never see half a file.
- **Never a partial phase 1**: a phase 1 cut short by a deadline (``complete`` False) is not stored.
- **Bypass**: ``--no-cache`` on ``plan``, ``compile``, ``facts``, ``graph`` and ``render`` (neither read
  nor written; ``mrgc bench`` gives it to every run unless the study says ``facts_cache: shared``), or
  ``MRGC_NO_CACHE=1`` in the environment.  Delete the folder to empty the cache.

Cached facts are the same list phase 1 returns (sorted); the statistics say ``cached: 1`` and the seconds
of the lookup, and keep ``computed_seconds``, the phase 1 that made them.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any, Iterator

from mrgc.language.model import Fact

#: the layout of an entry; another value is not read
FORMAT = "mrgc-facts-cache/1"
#: environment variable that turns the cache off (any non-empty value but "0")
NO_CACHE_ENV = "MRGC_NO_CACHE"

_disabled = 0


@contextlib.contextmanager
def disabled() -> Iterator[None]:
    """Within this block the cache is neither read nor written (``--no-cache``)."""
    global _disabled
    _disabled += 1
    try:
        yield
    finally:
        _disabled -= 1


def enabled() -> bool:
    """Whether the cache is in use (not inside :func:`disabled`, ``MRGC_NO_CACHE`` unset or ``0``)."""
    return not _disabled and os.environ.get(NO_CACHE_ENV, "") in ("", "0")


def folder() -> Path:
    """The cache folder: ``$XDG_CACHE_HOME/mrgc/facts`` (an absolute XDG_CACHE_HOME only, as the XDG
    specification says), else ``~/.cache/mrgc/facts``."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    root = Path(base) if base and os.path.isabs(base) else Path.home() / ".cache"
    return root / "mrgc" / "facts"


@functools.cache
def code_fingerprint() -> str:
    """SHA-256 over phase 1's code: every ``geometry/*.py`` and ``language/*.py`` file and
    ``planner/phase1.py`` (names and bytes, in name order)."""
    root = Path(__file__).resolve().parent.parent
    files = sorted([*root.glob("geometry/*.py"), *root.glob("language/*.py"), root / "planner" / "phase1.py"])
    h = hashlib.sha256()
    for path in files:
        h.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def key_fields(digest: str, seed: int) -> dict[str, Any]:
    """What an entry is for: the problem's digest, the seed, the mrgc version and the code fingerprint."""
    from mrgc import __version__

    return {"digest": digest, "seed": seed, "version": __version__, "code": code_fingerprint()}


def _path(fields: dict[str, Any]) -> Path:
    text = json.dumps(fields, sort_keys=True, separators=(",", ":"))
    return folder() / f"{hashlib.sha256(text.encode()).hexdigest()}.json"


def _facts_sha(facts: list[list[str]]) -> str:
    return hashlib.sha256(json.dumps(facts, separators=(",", ":")).encode()).hexdigest()


def load(digest: str, seed: int) -> tuple[list[Fact], dict[str, float]] | None:
    """The cached facts and statistics of (problem digest, seed), or None (no entry, cache off, or an
    entry that fails verification: removed)."""
    if not enabled():
        return None
    fields = key_fields(digest, seed)
    path = _path(fields)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        _discard(path)
        return None
    good = (
        isinstance(doc, dict)
        and doc.get("format") == FORMAT
        and doc.get("key") == fields
        and isinstance(doc.get("facts"), list)
        and all(isinstance(f, list) and f and all(isinstance(a, str) for a in f) for f in doc["facts"])
        and doc.get("sha256") == _facts_sha(doc["facts"])
        and isinstance(doc.get("stats"), dict)
    )
    if not good:
        _discard(path)
        return None
    facts = [Fact(f[0], tuple(f[1:])) for f in doc["facts"]]
    stats = {k: float(v) for k, v in doc["stats"].items() if isinstance(v, (int, float))}
    return facts, stats


def store(digest: str, seed: int, facts: list[Fact], stats: dict[str, float]) -> None:
    """Store a complete phase 1's facts (best effort: a cache that cannot be written is skipped)."""
    if not enabled():
        return
    fields = key_fields(digest, seed)
    rows = [[f.predicate, *f.args] for f in facts]
    doc = {"format": FORMAT, "key": fields, "facts": rows, "sha256": _facts_sha(rows), "stats": stats}
    path = _path(fields)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".json", dir=path.parent)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(doc, fh, separators=(",", ":"))
        os.replace(tmp, path)
    except OSError:
        with contextlib.suppress(OSError, UnboundLocalError):
            os.unlink(tmp)


def _discard(path: Path) -> None:
    with contextlib.suppress(OSError):
        path.unlink()
