"""Figures of a results database (``mrgc bench report --figures DIR``; matplotlib, imported here only).

Per study, as PNG files in DIR:

- ``STUDY-success.png``: success rate per instance set, one bar per method;
- ``STUDY-time-ecdf.png``: for each method, the fraction of its runs solved (and valid) within t seconds
  of planning time, t on a log scale: the empirical distribution function of solved times, scaled by the
  success rate, so a curve's end height is the method's success rate;
- ``STUDY-cactus.png``: for each method, its solved runs' planning times in increasing order against
  how many runs are solved within that time (the SAT-competition "cactus" plot).

Times are on the report's clock (``--time wall|cpu``, :data:`mrgc.bench.report.CLOCKS`).
"""

from __future__ import annotations

import os
from typing import Any

from mrgc import outputs
from mrgc.bench.db import ResultsDB
from mrgc.bench.report import CLOCKS, aggregate


def write_figures(db: ResultsDB, folder: str, study: str | None = None, clock: str = "wall") -> list[str]:
    """Write the figures of one study or of every study, times on ``clock``; the paths written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(folder, exist_ok=True)
    written = []
    for name in [study] if study is not None else db.studies():
        runs = list(db.runs(name))
        if not runs:
            continue
        rows = aggregate(runs, clock)
        column, label = CLOCKS[clock]
        methods = list(dict.fromkeys(r.method for r in rows))
        sets = list(dict.fromkeys(r.instance_set for r in rows))
        written.append(_success(plt, name, rows, methods, sets, folder))
        times = {
            m: sorted(r[column] for r in runs if r["method"] == m and r["success"] and r[column] is not None)
            for m in methods
        }
        totals = {m: sum(1 for r in runs if r["method"] == m) for m in methods}
        written.append(_ecdf(plt, name, times, totals, folder, label))
        written.append(_cactus(plt, name, times, folder, label))
    return written


def _success(plt: Any, name: str, rows: list[Any], methods: list[str], sets: list[str], folder: str) -> str:
    fig, ax = plt.subplots(figsize=(max(5.0, 1.2 * len(sets) * max(1, len(methods)) / 2 + 2), 3.5))
    width = 0.8 / max(1, len(methods))
    cell = {(r.instance_set, r.method): r.success for r in rows}
    for i, m in enumerate(methods):
        xs = [j + (i - (len(methods) - 1) / 2) * width for j in range(len(sets))]
        ax.bar(xs, [cell.get((s, m), 0.0) for s in sets], width, label=m)
    ax.set_xticks(range(len(sets)), sets, rotation=20 if len(sets) > 6 else 0)
    ax.set_ylabel("success %")
    ax.set_ylim(0, 105)
    ax.set_title(f"{name}: success rate")
    ax.legend(fontsize="small")
    return _save(plt, fig, folder, f"{name}-success.png")


def _ecdf(plt: Any, name: str, times: dict[str, list[float]], totals: dict[str, int], folder: str, label: str) -> str:
    fig, ax = plt.subplots(figsize=(5.5, 3.5))
    for m, ts in times.items():
        if ts:
            ys = [(i + 1) / totals[m] for i in range(len(ts))]
            ax.step([ts[0]] + ts, [0.0] + ys, where="post", label=m)
    ax.set_xscale("log")
    ax.set_xlabel(label)
    ax.set_ylabel("fraction of runs solved")
    ax.set_ylim(0, 1.02)
    ax.set_title(f"{name}: solved within t")
    ax.legend(fontsize="small")
    return _save(plt, fig, folder, f"{name}-time-ecdf.png")


def _cactus(plt: Any, name: str, times: dict[str, list[float]], folder: str, label: str) -> str:
    fig, ax = plt.subplots(figsize=(5.5, 3.5))
    for m, ts in times.items():
        if ts:
            ax.plot(range(1, len(ts) + 1), ts, marker="o", markersize=3, label=m)
    ax.set_yscale("log")
    ax.set_xlabel("runs solved")
    ax.set_ylabel(label)
    ax.set_title(f"{name}: cactus plot")
    ax.legend(fontsize="small")
    return _save(plt, fig, folder, f"{name}-cactus.png")


def _save(plt: Any, fig: Any, folder: str, file: str) -> str:
    path = os.path.join(folder, file)
    fig.tight_layout()
    try:
        with outputs.atomic_path(path, option="--figures") as tmp:  # a figure is whole or not there
            fig.savefig(tmp, dpi=120, format="png")
    finally:
        plt.close(fig)
    return path
