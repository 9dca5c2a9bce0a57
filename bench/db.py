"""The results database: SQLite, one row per finished run, committed per run (WAL journal).

Tables (schema version :data:`SCHEMA_VERSION` in ``PRAGMA user_version``; a database of an older schema is
upgraded in place when ``bench run`` opens it — columns added since read as NULL — and read as it is by
reports):

- ``runs``: one row per finished run, the columns of :class:`~mrgc.bench.outcome.RunResult`; unique on
  the run key ``(study, instance_sha256, method, seed)``.  A run is written when it finishes, in its own
  transaction, so killing ``bench run`` loses at most the runs in flight.
- ``studies``: the study file's path and text at its last ``bench run``.
- ``methods``: each method's spec per study; ``bench run`` refuses (E603) a method whose spec changed
  under the same name, since its recorded runs would mix two methods.
- ``skips``: methods this mrgc could not run (an unknown planner) and why, per study, from the last
  ``bench run``; the report prints them.

Only the process running ``bench run`` writes (one writer per database, held by a lock file
``DB.lock``); reports read concurrently.
"""

from __future__ import annotations

import json
import os
import sqlite3
from typing import Any, Iterator

from mrgc.bench.outcome import RunResult
from mrgc.errors import Diagnostic, InputError

#: 2 added ``cpu_seconds``
SCHEMA_VERSION = 2
#: diagnostic code: the results database cannot be used
E_DB = "E603"

_COLUMNS: list[tuple[str, str]] = [
    ("study", "TEXT NOT NULL"),
    ("instance", "TEXT NOT NULL"),
    ("instance_set", "TEXT NOT NULL"),
    ("set_index", "INTEGER NOT NULL"),
    ("instance_file", "TEXT NOT NULL"),
    ("instance_sha256", "TEXT NOT NULL"),
    ("method", "TEXT NOT NULL"),
    ("method_index", "INTEGER NOT NULL"),
    ("seed", "INTEGER NOT NULL"),
    ("status", "TEXT NOT NULL"),
    ("success", "INTEGER NOT NULL"),
    ("detail", "TEXT"),
    ("exit_code", "INTEGER"),
    ("signal", "INTEGER"),
    ("planning_seconds", "REAL"),
    ("facts_seconds", "REAL"),
    ("wall_seconds", "REAL"),
    ("cpu_seconds", "REAL"),
    ("validate_seconds", "REAL"),
    ("peak_mb", "REAL"),
    ("makespan", "INTEGER"),
    ("objects_moved", "INTEGER"),
    ("arm_path", "REAL"),
    ("base_path", "REAL"),
    ("valid", "INTEGER"),
    ("plan_status", "TEXT"),
    ("stderr_tail", "TEXT"),
    ("command", "TEXT"),
    ("time_limit", "REAL"),
    ("wall_limit", "REAL"),
    ("memory_limit_mb", "REAL"),
    ("mrgc_version", "TEXT"),
    ("host", "TEXT"),
    ("started", "TEXT"),
    ("finished", "TEXT"),
    ("plan_file", "TEXT"),
]
COLUMNS = [name for name, _ in _COLUMNS]

_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS runs (
    id INTEGER PRIMARY KEY,
    {", ".join(f"{n} {t}" for n, t in _COLUMNS)},
    UNIQUE (study, instance_sha256, method, seed)
);
CREATE TABLE IF NOT EXISTS studies (name TEXT PRIMARY KEY, path TEXT, text TEXT, updated TEXT);
CREATE TABLE IF NOT EXISTS methods (study TEXT, method TEXT, spec TEXT, PRIMARY KEY (study, method));
CREATE TABLE IF NOT EXISTS skips (study TEXT, method TEXT, reason TEXT, runs INTEGER, PRIMARY KEY (study, method));
CREATE TABLE IF NOT EXISTS contents (study TEXT, instance TEXT, sha256 TEXT, PRIMARY KEY (study, instance));
"""

RunKey = tuple[str, str, str, int]


class ResultsDB:
    """An open results database (module docstring).  ``readonly`` opens an existing one for reports."""

    def __init__(self, path: str, readonly: bool = False) -> None:
        self.path = path
        if readonly and not os.path.isfile(path):
            raise InputError([Diagnostic(E_DB, f"no results database at '{path}' (mrgc bench run writes one)")])
        try:
            uri = f"file:{os.path.abspath(path)}{'?mode=ro' if readonly else ''}"
            self.conn = sqlite3.connect(uri, uri=True, timeout=30)
            self.conn.row_factory = sqlite3.Row
            version = self.conn.execute("PRAGMA user_version").fetchone()[0]
            tables = {r[0] for r in self.conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        except sqlite3.DatabaseError as exc:
            raise InputError([Diagnostic(E_DB, f"'{path}' is not a results database: {exc}")]) from None
        if version > SCHEMA_VERSION or (tables and "runs" not in tables) or (version == 0 and tables):
            self.conn.close()
            raise InputError(
                [
                    Diagnostic(
                        E_DB,
                        f"'{path}' is not a results database of this mrgc "
                        f"(schema {version}; this mrgc reads {SCHEMA_VERSION})",
                    )
                ]
            )
        if not readonly:
            self.conn.execute("PRAGMA journal_mode = WAL")
            self.conn.execute("PRAGMA synchronous = NORMAL")
            self.conn.executescript(_SCHEMA)
            for name, kind in _COLUMNS:  # an older schema: add the columns it lacks
                if name not in self._present():
                    self.conn.execute(f"ALTER TABLE runs ADD COLUMN {name} {kind.replace(' NOT NULL', '')}")
            self.conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
            self.conn.commit()
        elif not tables:
            self.conn.close()
            raise InputError([Diagnostic(E_DB, f"'{path}' holds no results")])
        self.present = self._present()

    def _present(self) -> set[str]:
        """The columns the ``runs`` table has."""
        return {r[1] for r in self.conn.execute("PRAGMA table_info(runs)")}

    def close(self) -> None:
        """Close the connection."""
        self.conn.close()

    def __enter__(self) -> "ResultsDB":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------ writing
    def begin_study(
        self,
        name: str,
        path: str,
        text: str,
        specs: dict[str, dict[str, Any]],
        skips: dict[str, tuple[str, int]],
        updated: str,
        contents: dict[str, str] | None = None,
    ) -> None:
        """Record the study and its method specs; E603 if a method changed under the same name.  ``contents``:
        each instance's content hash now (by name), which the reports read (:meth:`runs`)."""
        known = {
            r["method"]: r["spec"]
            for r in self.conn.execute("SELECT method, spec FROM methods WHERE study = ?", (name,))
        }
        for method, spec in specs.items():
            text_spec = json.dumps(spec, sort_keys=True)
            if method in known and known[method] != text_spec:
                n = self.conn.execute(
                    "SELECT COUNT(*) FROM runs WHERE study = ? AND method = ?", (name, method)
                ).fetchone()[0]
                if n:
                    raise InputError(
                        [
                            Diagnostic(
                                E_DB,
                                f"method '{method}' of study '{name}' changed since its {n} "
                                f"recorded run(s) in {self.path} (was {known[method]}, now "
                                f"{text_spec}): give the changed method a new name, or use another "
                                "--db",
                            )
                        ]
                    )
        with self.conn:
            self.conn.execute("INSERT OR REPLACE INTO studies VALUES (?, ?, ?, ?)", (name, path, text, updated))
            for method, spec in specs.items():
                self.conn.execute(
                    "INSERT OR REPLACE INTO methods VALUES (?, ?, ?)", (name, method, json.dumps(spec, sort_keys=True))
                )
            self.conn.execute("DELETE FROM skips WHERE study = ?", (name,))
            for method, (reason, runs) in skips.items():
                self.conn.execute("INSERT INTO skips VALUES (?, ?, ?, ?)", (name, method, reason, runs))
            if contents is not None:
                self.conn.execute("DELETE FROM contents WHERE study = ?", (name,))
                self.conn.executemany(
                    "INSERT INTO contents VALUES (?, ?, ?)", [(name, i, sha) for i, sha in sorted(contents.items())]
                )

    def add(self, result: RunResult) -> None:
        """Write one finished run (replacing an earlier row of the same key: a retried run) and commit."""
        row = result.to_row()
        with self.conn:
            self.conn.execute(
                f"INSERT OR REPLACE INTO runs ({', '.join(COLUMNS)}) VALUES ({', '.join('?' for _ in COLUMNS)})",
                [row[c] for c in COLUMNS],
            )

    # ------------------------------------------------------------ reading
    def finished(self, study: str) -> dict[RunKey, str]:
        """The keys of the study's recorded runs → their status."""
        return {
            (r["study"], r["instance_sha256"], r["method"], r["seed"]): r["status"]
            for r in self.conn.execute(
                "SELECT study, instance_sha256, method, seed, status FROM runs WHERE study = ?", (study,)
            )
        }

    def studies(self) -> list[str]:
        """Study names in the order they were first run."""
        return [r[0] for r in self.conn.execute("SELECT study FROM runs GROUP BY study ORDER BY MIN(id)")]

    def runs(self, study: str | None = None) -> Iterator[dict[str, Any]]:
        """The recorded runs (all studies, or one) in a stable order, of each instance's current content only:
        the content the study had when it was last run (its ``contents``; for a database without them, the
        content of the instance's latest recorded run).  The runs of an instance's other contents (edited
        since) stay in the database but are not the study's, and a report mixing them would average two
        problems under one name."""
        where, args = ("WHERE study = ?", (study,)) if study is not None else ("", ())
        current = {
            (r[0], r[1]): r[2]
            for r in self.conn.execute(
                "SELECT study, instance, instance_sha256 FROM runs WHERE id IN "
                f"(SELECT MAX(id) FROM runs {where} GROUP BY study, instance)",
                args,
            )
        }
        if self._has("contents"):
            current.update(
                ((r[0], r[1]), r[2])
                for r in self.conn.execute(f"SELECT study, instance, sha256 FROM contents {where}", args)
            )
        columns = ", ".join(c if c in self.present else f"NULL AS {c}" for c in COLUMNS)
        for row in self.conn.execute(
            f"SELECT {columns} FROM runs {where} ORDER BY study, set_index, instance, method_index, method, seed",
            args,
        ):
            if current.get((row["study"], row["instance"])) == row["instance_sha256"]:
                yield dict(row)

    def _has(self, table: str) -> bool:
        """Whether the database has ``table`` (a database written by an older mrgc may not)."""
        return bool(
            self.conn.execute("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?", (table,)).fetchone()
        )

    def skips(self, study: str) -> list[tuple[str, str, int]]:
        """The methods skipped in ``study``: (method, reason, runs), by method."""
        return [
            (r["method"], r["reason"], r["runs"])
            for r in self.conn.execute(
                "SELECT method, reason, runs FROM skips WHERE study = ? ORDER BY method", (study,)
            )
        ]


class WriterLock:
    """The one-writer lock of a database (``DB.lock``, an flock): E603 if another ``bench run`` holds it.

    The lock file exists only while a writer holds it: the holder removes it before letting go.  A process
    that opened the file just before it was removed would lock a file nobody else sees, so after locking it
    checks that the path still names the file it locked, and starts again when it does not."""

    def __init__(self, db_path: str) -> None:
        self.path = db_path + ".lock"
        self.fd: int | None = None

    def __enter__(self) -> "WriterLock":
        import fcntl

        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise InputError(
                    [Diagnostic(E_DB, f"cannot write a results database at {self.path[:-5]}: {exc.strerror or exc}")]
                ) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise InputError([Diagnostic(E_DB, f"another mrgc bench run is writing to {self.path[:-5]}")]) from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self.fd = fd
                return self
            os.close(fd)  # the holder before us removed the file we locked: lock the one the path names now

    def __exit__(self, *exc: object) -> None:
        if self.fd is not None:
            try:
                os.unlink(self.path)
            except OSError:
                pass
            os.close(self.fd)
            self.fd = None
