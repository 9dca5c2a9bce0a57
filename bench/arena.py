"""Export to OMPL's benchmark database format, which Planner Arena (plannerarena.org) reads.

``mrgc bench report --planner-arena OUT.db`` writes a new SQLite file with OMPL's tables (the schema
``ompl_benchmark_statistics.py`` creates):

- ``experiments``: one per study and instance set (Planner Arena's "problem"), named ``STUDY: SET``;
  ``timelimit`` / ``memorylimit`` are the runs' limits (the largest, if they differ), ``runcount`` the
  runs per method, ``version`` ``mrgc X.Y.Z``, ``setup`` the study file's text;
- ``plannerConfigs``: one per method, ``settings`` its spec as JSON;
- ``runs``: one per run, with the attributes ``time`` (planning seconds; for a run without them, its
  wall-clock seconds, as OMPL records the time a failed run took), ``solved`` (solved and valid),
  ``status`` (an enum, see ``enums``), ``valid``, ``makespan``, ``objects_moved``, ``arm_path``,
  ``base_path``, ``wall_time``, ``memory`` (peak MiB) and ``seed``;
- ``enums``: the status values; ``progress``: empty (runs report no progress over time).
"""

from __future__ import annotations

import json
import sqlite3
from typing import Any, Iterable

from mrgc import outputs
from mrgc.bench.db import ResultsDB
from mrgc.bench.outcome import RunStatus

_SCHEMA = """
CREATE TABLE experiments (id INTEGER PRIMARY KEY AUTOINCREMENT, name VARCHAR(512), totaltime REAL,
    timelimit REAL, memorylimit REAL, runcount INTEGER, version VARCHAR(128), hostname VARCHAR(1024),
    cpuinfo TEXT, date DATETIME, seed VARCHAR(24), setup TEXT);
CREATE TABLE plannerConfigs (id INTEGER PRIMARY KEY AUTOINCREMENT, name VARCHAR(512) NOT NULL, settings TEXT);
CREATE TABLE enums (name VARCHAR(512), value INTEGER, description TEXT, PRIMARY KEY (name, value));
CREATE TABLE runs (id INTEGER PRIMARY KEY AUTOINCREMENT, experimentid INTEGER, plannerid INTEGER,
    time REAL, solved BOOLEAN, status ENUM, valid BOOLEAN, makespan INTEGER, objects_moved INTEGER,
    arm_path REAL, base_path REAL, wall_time REAL, memory REAL, seed INTEGER,
    FOREIGN KEY (experimentid) REFERENCES experiments(id) ON DELETE CASCADE,
    FOREIGN KEY (plannerid) REFERENCES plannerConfigs(id) ON DELETE CASCADE);
CREATE TABLE progress (runid INTEGER, time REAL, PRIMARY KEY (runid, time),
    FOREIGN KEY (runid) REFERENCES runs(id) ON DELETE CASCADE);
"""

STATUS_VALUES = [s.value for s in RunStatus]


def export_planner_arena(db: ResultsDB, out: str, study: str | None = None, inputs: Iterable[str] = ()) -> int:
    """Write the runs of one study or of every study to a new OMPL benchmark database ``out`` (replaced if
    it exists, atomically: :func:`mrgc.outputs.atomic_path`; ``inputs``, the results database's files among
    them, are refused as ``out`` with E005); the number of runs written."""
    with outputs.atomic_path(out, inputs, option="--planner-arena") as tmp:
        conn = sqlite3.connect(tmp)
        try:
            conn.executescript(_SCHEMA)
            conn.executemany("INSERT INTO enums VALUES ('status', ?, ?)", list(enumerate(STATUS_VALUES)))
            written = 0
            for name in [study] if study is not None else db.studies():
                written += _study(conn, db, name)
            conn.commit()
        finally:
            conn.close()
    return written


def _study(conn: sqlite3.Connection, db: ResultsDB, name: str) -> int:
    runs = list(db.runs(name))
    text = db.conn.execute("SELECT text FROM studies WHERE name = ?", (name,)).fetchone()
    specs = dict(db.conn.execute("SELECT method, spec FROM methods WHERE study = ?", (name,)).fetchall())
    planners: dict[str, int] = {}
    for method in dict.fromkeys(r["method"] for r in runs):
        cur = conn.execute(
            "INSERT INTO plannerConfigs (name, settings) VALUES (?, ?)", (method, specs.get(method, json.dumps({})))
        )
        planners[method] = int(cur.lastrowid or 0)
    sets: dict[str, list[dict[str, Any]]] = {}
    for r in runs:
        sets.setdefault(str(r["instance_set"]), []).append(r)
    for set_name, rs in sets.items():
        per_method = max(sum(1 for r in rs if r["method"] == m) for m in planners)
        cur = conn.execute(
            "INSERT INTO experiments (name, totaltime, timelimit, memorylimit, runcount, version, hostname, "
            "cpuinfo, date, seed, setup) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                f"{name}: {set_name}",
                sum(float(r["wall_seconds"] or 0) for r in rs),
                max(float(r["time_limit"]) for r in rs),
                max(float(r["memory_limit_mb"]) for r in rs),
                per_method,
                "mrgc " + ", ".join(sorted({str(r["mrgc_version"]) for r in rs})),
                ", ".join(sorted({str(r["host"]) for r in rs})),
                None,
                min(str(r["started"]) for r in rs),
                ",".join(str(s) for s in sorted({int(r["seed"]) for r in rs})),
                text[0] if text else "",
            ),
        )
        experiment = cur.lastrowid
        conn.executemany(
            "INSERT INTO runs (experimentid, plannerid, time, solved, status, valid, makespan, objects_moved, "
            "arm_path, base_path, wall_time, memory, seed) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            [
                (
                    experiment,
                    planners[str(r["method"])],
                    r["planning_seconds"] if r["planning_seconds"] is not None else r["wall_seconds"],
                    int(bool(r["success"])),
                    STATUS_VALUES.index(str(r["status"])),
                    r["valid"],
                    r["makespan"],
                    r["objects_moved"],
                    r["arm_path"],
                    r["base_path"],
                    r["wall_seconds"],
                    r["peak_mb"],
                    r["seed"],
                )
                for r in rs
            ],
        )
    return len(runs)
