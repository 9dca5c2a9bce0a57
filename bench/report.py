"""Reports of a results database: tables shaped like the paper's Table I/II, as Markdown or CSV.

One row per instance set and method (``wide``: one row per instance set, a column per measure and method)
(sets in study order, methods in study order): runs, success rate (solved and valid, per cent of the
runs), and over the **solved** runs the mean ± standard error of the
mean (sample standard deviation / sqrt(n); no ± for a single run) of planning time, makespan, objects moved
(the paper's "motion cost") and path length (:mod:`mrgc.bench.outcome`).  A second table counts the
outcomes, so that no failure is hidden behind a success rate; methods a study skipped are listed with
their reason.  ``pairs`` sets the study's first method against each other one instance by instance (the
time ratio per instance, medians, who wins; :func:`pairs`).  ``runs`` CSV gives every recorded run, every
column.

Time is one of two clocks (``--time``, :data:`CLOCKS`): ``wall`` (default), the planning time the plan
reports (``planning_seconds``: wall-clock seconds of phase 1, search and the planner's own validation), or
``cpu``, the CPU seconds of the planner's process and its workers (``cpu_seconds``: start-up included),
which a study on a shared machine should compare, since others' load stretches wall time but not CPU time.
"""

from __future__ import annotations

import csv
import io
import math
import re
import statistics
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable

from mrgc.bench.db import COLUMNS, ResultsDB
from mrgc.bench.outcome import RunStatus

#: report formats of ``mrgc bench report --format``
FORMATS = ("markdown", "wide", "pairs", "csv", "runs")
#: the clocks a report's time can be read on (module docstring): clock -> (runs column, table heading)
CLOCKS = {"wall": ("planning_seconds", "planning time (s)"), "cpu": ("cpu_seconds", "CPU time (s)")}
_DASH = "–"


@dataclass(frozen=True)
class Stat:
    """Mean and standard error of the mean over ``n`` values (``se`` None for fewer than two)."""

    n: int
    mean: float | None
    se: float | None

    @staticmethod
    def of(values: Iterable[float | None]) -> "Stat":
        """Count, mean and standard error of the known values (None values are left out)."""
        xs = [float(v) for v in values if v is not None]
        if not xs:
            return Stat(0, None, None)
        mean = math.fsum(xs) / len(xs)
        if len(xs) < 2:
            return Stat(1, mean, None)
        var = math.fsum((x - mean) ** 2 for x in xs) / (len(xs) - 1)
        return Stat(len(xs), mean, math.sqrt(var / len(xs)))

    def text(self, digits: int, unit: str = "") -> str:
        """``mean ± se unit`` with ``digits`` decimals; a dash when no value is known."""
        if self.mean is None:
            return _DASH
        out = f"{self.mean:.{digits}f}" + (f" ± {self.se:.{digits}f}" if self.se is not None else "")
        return out + (f" {unit}" if unit else "")


@dataclass
class Row:
    """The aggregate of one instance set and method."""

    study: str
    instance_set: str
    method: str
    runs: int = 0
    solved: int = 0
    outcomes: Counter[str] = field(default_factory=Counter)
    time: Stat = Stat(0, None, None)
    makespan: Stat = Stat(0, None, None)
    moved: Stat = Stat(0, None, None)
    arm_path: Stat = Stat(0, None, None)
    base_path: Stat = Stat(0, None, None)

    @property
    def success(self) -> float:
        """Percentage of runs solved."""
        return 100.0 * self.solved / self.runs if self.runs else 0.0

    def path_text(self) -> str:
        """Path length: arm radians and base metres, each when known; a dash when neither is."""
        parts = [s.text(1, unit) for s, unit in ((self.arm_path, "rad"), (self.base_path, "m")) if s.mean is not None]
        return " + ".join(parts) if parts else _DASH


def aggregate(runs: Iterable[dict[str, Any]], clock: str = "wall") -> list[Row]:
    """Rows per (study, instance set, method) in the order of the runs (db.runs orders them); time on
    ``clock`` (:data:`CLOCKS`)."""
    column = CLOCKS[clock][0]
    groups: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
    order: dict[tuple[str, str, str], tuple[str, int, int]] = {}
    for r in runs:
        key = (r["study"], r["instance_set"], r["method"])
        groups.setdefault(key, []).append(r)
        order.setdefault(key, (r["study"], r["set_index"], r["method_index"]))
    out = []
    for key in sorted(groups, key=lambda k: (order[k][0], order[k][1], k[1], order[k][2], k[2])):
        rs = groups[key]
        ok = [r for r in rs if r["success"]]
        out.append(
            Row(
                *key,
                runs=len(rs),
                solved=len(ok),
                outcomes=Counter(r["status"] for r in rs),
                time=Stat.of(r[column] for r in ok),
                makespan=Stat.of(r["makespan"] for r in ok),
                moved=Stat.of(r["objects_moved"] for r in ok),
                arm_path=Stat.of(r["arm_path"] for r in ok),
                base_path=Stat.of(r["base_path"] for r in ok),
            )
        )
    return out


def _table(header: list[str], rows: list[list[str]], right: int) -> list[str]:
    lines = [
        "| " + " | ".join(header) + " |",
        "| " + " | ".join(["---"] * right + ["---:"] * (len(header) - right)) + " |",
    ]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


def markdown(db: ResultsDB, study: str | None = None, clock: str = "wall") -> str:
    """The Markdown report of one study or of every study in the database."""
    parts: list[str] = []
    for name in [study] if study is not None else db.studies():
        runs = list(db.runs(name))
        rows = aggregate(runs, clock)
        parts.append(f"## Study {name}\n")
        if not runs:
            parts.append("No recorded runs.\n")
            continue
        seeds = sorted({r["seed"] for r in runs})
        hosts = sorted({r["host"] for r in runs})
        versions = sorted({r["mrgc_version"] for r in runs})
        limits = sorted({(r["time_limit"], r["wall_limit"], r["memory_limit_mb"]) for r in runs})
        parts.append(
            f"{len(runs)} runs: {len({r['instance'] for r in runs})} instances in "
            f"{len({r['instance_set'] for r in runs})} sets, {len({r['method'] for r in runs})} methods, "
            f"seeds {_seeds(seeds)}; mrgc {', '.join(versions)} on {', '.join(hosts)}; limits per run: "
            + "; ".join(f"planner {t:g} s, wall {w:g} s, memory {m:g} MiB" for t, w, m in limits)
            + ".\n"
        )
        parts.append(
            "Success: solved and accepted by `mrgc validate`.  Other columns: mean ± standard error over "
            "the solved runs.  Objects moved is the paper's motion cost; path length sums the motions "
            "each plan lists (docs/bench.md).\n"
        )
        body = [
            [
                r.instance_set,
                r.method,
                str(r.runs),
                f"{r.success:.1f}",
                r.time.text(2),
                r.makespan.text(1),
                r.moved.text(1),
                r.path_text(),
            ]
            for r in rows
        ]
        parts.append(
            "\n".join(
                _table(
                    [
                        "instance",
                        "method",
                        "runs",
                        "success %",
                        CLOCKS[clock][1],
                        "makespan",
                        "objects moved",
                        "path length",
                    ],
                    body,
                    2,
                )
            )
            + "\n"
        )
        statuses = [s.value for s in RunStatus if any(r.outcomes[s.value] for r in rows)]
        counts = [[r.instance_set, r.method, *(str(r.outcomes[s]) for s in statuses)] for r in rows]
        parts.append("Outcomes (runs):\n")
        parts.append("\n".join(_table(["instance", "method", *statuses], counts, 2)) + "\n")
        for method, reason, n in db.skips(name):
            parts.append(f"Skipped: method {method} ({n} runs): {reason}.\n")
    return "\n".join(parts)


def wide(db: ResultsDB, study: str | None = None, clock: str = "wall") -> str:
    """The paper's layout (Table I): one row per instance set, each measure a group of columns with one
    column per method."""
    parts = []
    for name in [study] if study is not None else db.studies():
        rows = aggregate(db.runs(name), clock)
        methods = list(dict.fromkeys(r.method for r in rows))
        sets = list(dict.fromkeys(r.instance_set for r in rows))
        cell = {(r.instance_set, r.method): r for r in rows}
        measures: list[tuple[str, Callable[[Row], str]]] = [
            ("success %", lambda r: f"{r.success:.1f}"),
            ("time (s)" if clock == "wall" else "CPU (s)", lambda r: r.time.text(2)),
            ("makespan", lambda r: r.makespan.text(1)),
            ("moved", lambda r: r.moved.text(1)),
        ]
        header = ["instance"] + [f"{title} {m}" for title, _ in measures for m in methods]
        body = [[s] + [f(cell[s, m]) if (s, m) in cell else _DASH for _, f in measures for m in methods] for s in sets]
        parts.append(f"## Study {name}\n\n" + "\n".join(_table(header, body, 1)) + "\n")
    return "\n".join(parts)


def pairs(db: ResultsDB, study: str | None = None, clock: str = "wall") -> str:
    """The study's first method (the reference, A) against each other method (B), instance by instance: per
    instance set a row per instance and seed with A's and B's outcome, time, makespan and objects moved and
    the time ratio B / A (above 1: A faster), then the set's summary: solved by each, median time of each
    over its solved runs, median ratio and A's wins over the runs both solved, and the makespan and
    objects-moved means over those runs.  "Ours below Ap1 on every set" reads off the medians."""
    column = CLOCKS[clock][0]
    parts = []
    for name in [study] if study is not None else db.studies():
        runs = list(db.runs(name))
        methods = list(dict.fromkeys(r["method"] for r in sorted(runs, key=lambda r: r["method_index"])))
        for other in methods[1:]:
            parts.append(_pairs(name, methods[0], other, runs, column, clock))
    return "\n".join(parts)


def _pairs(study: str, a: str, b: str, runs: list[dict[str, Any]], column: str, clock: str) -> str:
    """:func:`pairs` of methods ``a`` and ``b`` of one study."""
    by: dict[tuple[str, str, int], dict[str, dict[str, Any]]] = {}
    sets: dict[str, None] = {}
    for r in sorted(runs, key=lambda r: (r["set_index"], _natural(r["instance"]), r["seed"])):
        by.setdefault((r["instance_set"], r["instance"], r["seed"]), {})[r["method"]] = r
        sets.setdefault(r["instance_set"], None)
    unit = "s" if clock == "wall" else "CPU s"

    def cell(r: dict[str, Any] | None) -> list[str]:
        if r is None:
            return [_DASH] * 3
        if not r["success"]:
            return [r["status"], _DASH, _DASH]
        return [f"{r[column]:.2f}", str(r["makespan"]), str(r["objects_moved"])]

    lines = [f"## Study {study}: {a} (A) against {b} (B), {unit}", ""]
    summary = []
    for s in sets:
        keys = [k for k in by if k[0] == s]
        body, both = [], []
        for k in keys:
            ra, rb = by[k].get(a), by[k].get(b)
            ratio = _DASH
            if ra is not None and rb is not None and ra["success"] and rb["success"]:
                both.append((ra, rb))
                ratio = f"{rb[column] / ra[column]:.2f}" if ra[column] else _DASH
            body.append([s, k[1], str(k[2]), *cell(ra), *cell(rb), ratio])
        header = ["set", "instance", "seed", f"{a} time", f"{a} makespan", f"{a} moved"]
        header += [f"{b} time", f"{b} makespan", f"{b} moved", "B / A"]
        lines += _table(header, body, 3) + [""]
        summary.append(_pair_summary(s, a, b, [by[k] for k in keys], both, column))
    header = ["set", f"solved {a}", f"solved {b}", f"median {a}", f"median {b}", "median B / A", f"{a} faster"]
    header += [f"makespan {a}", f"makespan {b}", f"moved {a}", f"moved {b}"]
    return "\n".join(lines + _table(header, summary, 1)) + "\n"


def _natural(name: str) -> tuple[Any, ...]:
    """A sort key that puts ``PA5-s2`` before ``PA5-s10``."""
    return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", name))


def _pair_summary(
    s: str,
    a: str,
    b: str,
    cells: list[dict[str, dict[str, Any]]],
    both: list[tuple[dict[str, Any], dict[str, Any]]],
    column: str,
) -> list[str]:
    """One set's summary row of :func:`_pairs`."""

    def solved(m: str) -> list[dict[str, Any]]:
        return [c[m] for c in cells if m in c and c[m]["success"]]

    def med(xs: list[float]) -> str:
        return f"{statistics.median(xs):.2f}" if xs else _DASH

    ratios = [rb[column] / ra[column] for ra, rb in both if ra[column]]
    return [
        s,
        f"{len(solved(a))}/{sum(a in c for c in cells)}",
        f"{len(solved(b))}/{sum(b in c for c in cells)}",
        med([r[column] for r in solved(a)]),
        med([r[column] for r in solved(b)]),
        med(ratios),
        f"{sum(x > 1 for x in ratios)}/{len(ratios)}",
        Stat.of(ra["makespan"] for ra, _ in both).text(2),
        Stat.of(rb["makespan"] for _, rb in both).text(2),
        Stat.of(ra["objects_moved"] for ra, _ in both).text(2),
        Stat.of(rb["objects_moved"] for _, rb in both).text(2),
    ]


def _seeds(seeds: list[int]) -> str:
    if len(seeds) > 2 and seeds == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}..{seeds[-1]}"
    return ", ".join(map(str, seeds))


def csv_text(db: ResultsDB, study: str | None = None, clock: str = "wall") -> str:
    """The aggregate table as CSV: one line per study, instance set and method; means and standard errors
    in their own columns (time on ``clock``), then the count of each outcome."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    statuses = [s.value for s in RunStatus]
    w.writerow(
        [
            "study",
            "instance",
            "method",
            "runs",
            "solved",
            "success_pct",
            "time_mean",
            "time_se",
            "makespan_mean",
            "makespan_se",
            "moved_mean",
            "moved_se",
            "arm_path_mean",
            "arm_path_se",
            "base_path_mean",
            "base_path_se",
            *("n_" + s.replace(" ", "_") for s in statuses),
        ]
    )

    def num(x: float | None) -> str:
        return "" if x is None else f"{x:.6g}"

    for name in [study] if study is not None else db.studies():
        for r in aggregate(db.runs(name), clock):
            stats = [num(v) for s in (r.time, r.makespan, r.moved, r.arm_path, r.base_path) for v in (s.mean, s.se)]
            w.writerow(
                [
                    r.study,
                    r.instance_set,
                    r.method,
                    r.runs,
                    r.solved,
                    f"{r.success:.1f}",
                    *stats,
                    *(r.outcomes[s] for s in statuses),
                ]
            )
    return out.getvalue()


def runs_csv(db: ResultsDB, study: str | None = None, clock: str = "wall") -> str:
    """Every recorded run, every column (docs/bench.md), as CSV (``clock`` changes nothing: both are
    columns)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(COLUMNS)
    for r in db.runs(study):
        w.writerow(["" if r[c] is None else r[c] for c in COLUMNS])
    return out.getvalue()


def render(db: ResultsDB, fmt: str = "markdown", study: str | None = None, clock: str = "wall") -> str:
    """The report in format ``fmt`` (:data:`FORMATS`), time on ``clock`` (:data:`CLOCKS`)."""
    return {"markdown": markdown, "wide": wide, "pairs": pairs, "csv": csv_text, "runs": runs_csv}[fmt](
        db, study, clock
    )
