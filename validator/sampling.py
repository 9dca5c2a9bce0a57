"""Where the validator looks along a motion: sample times and configurations at a time.

A motion is a list of configurations; the validator reads it as linear in joint space between consecutive
configurations (a planar yaw the shortest way round), consecutive configurations equally spaced in time
``s`` ∈ [0, 1].  Motions of different robots in one phase share that time: they are *paired by index*.

:func:`sample_times` picks the times to check so that between two consecutive samples no joint (or planar
base coordinate) moves more than the resolution: a motion of few configurations (an approach, a straight
transfer) gets every configuration and at least :data:`SUBSTEPS` samples per segment; a motion of many
(a path) gets equal steps of at most the resolution along its length, measured as the sum of the
segments' largest joint motions, so a dense path costs as much as its length, not as its configurations.
"""

from __future__ import annotations

import math

import numpy as np

from mrgc.geometry.conventions import wrap_angle

SUBSTEPS = 4  # samples per segment of a motion of few configurations, at least
FEW = 16  # a motion of at most this many segments is "few configurations"


def deltas(configs: np.ndarray, planar: bool) -> np.ndarray:
    """The motion of each segment (m-1, dof), a planar yaw wrapped into [-pi, pi)."""
    d = np.diff(configs, axis=0)
    if planar and d.size:
        d[:, 2] = wrap_angle(d[:, 2])
    return d


def sample_count(configs: np.ndarray, planar: bool, resolution: float) -> int:
    """How many samples :func:`sample_times` takes (computed without building them)."""
    m = len(configs)
    if m < 2:
        return 1
    seg = np.abs(deltas(configs, planar)).max(axis=1)
    if m - 1 <= FEW:
        return 1 + int(np.maximum(SUBSTEPS, np.ceil(seg / resolution)).sum())
    return 2 + int(math.ceil(float(seg.sum()) / resolution))


def sample_times(configs: np.ndarray, planar: bool, resolution: float) -> np.ndarray:
    """The times to check a motion at (sorted, from 0 to 1; see the module docstring)."""
    m = len(configs)
    if m < 2:
        return np.zeros(1)
    seg = np.abs(deltas(configs, planar)).max(axis=1)
    if m - 1 <= FEW:
        per = np.maximum(SUBSTEPS, np.ceil(seg / resolution)).astype(int)
        parts = [(j + np.arange(k) / k) / (m - 1) for j, k in enumerate(per)]
        return np.concatenate(parts + [np.ones(1)])
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    pieces = max(1, math.ceil(float(cum[-1]) / resolution))
    targets = np.linspace(0.0, float(cum[-1]), pieces + 1)
    j = np.clip(np.searchsorted(cum, targets, side="right") - 1, 0, m - 2)
    u = np.divide(targets - cum[j], seg[j], out=np.zeros_like(targets), where=seg[j] > 0)
    return np.unique(np.concatenate([(j + np.clip(u, 0.0, 1.0)) / (m - 1), [0.0, 1.0]]))


def config_at(configs: np.ndarray, s: float, planar: bool) -> np.ndarray:
    """The configuration at time ``s`` in [0, 1], consecutive configurations equally spaced."""
    m = len(configs)
    if m == 1:
        return configs[0]  # type: ignore[no-any-return]
    x = s * (m - 1)
    j = min(int(math.floor(x)), m - 2)
    u = x - j
    d = configs[j + 1] - configs[j]
    if planar:
        d = d.copy()
        d[2] = wrap_angle(float(d[2]))
    return configs[j] + u * d  # type: ignore[no-any-return]


def where(label: str, m: int, s: float) -> str:
    """Where a motion of ``m`` configurations called ``label`` is at time ``s``, in words."""
    if m == 1:
        return f"at its {label} configuration" if label != "home" else "at home"
    x = s * (m - 1)
    k = round(x)
    if abs(x - k) < 1e-9:
        return f"at {label} configuration {k + 1} of {m}"
    return f"between {label} configurations {math.floor(x) + 1} and {math.floor(x) + 2} of {m}"
