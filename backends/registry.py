"""The explicit registry of backends: lazy ``"module:Class"`` strings plus the ``mrgc.backends`` entry points.

Looking a backend up imports only its mrgc module (cheap: solver libraries are imported inside it, lazily).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
from dataclasses import dataclass
from typing import Any

from mrgc.backends.base import Backend, BackendInfo
from mrgc.compiler.ir import Feature
from mrgc.errors import Diagnostic, InputError

BACKENDS: dict[str, str] = {
    "mip": "mrgc.backends.highs:HighsBackend",
    "smt": "mrgc.backends.z3opt:Z3Backend",
    "pysmt": "mrgc.backends.pysmt_opt:PysmtBackend",
    "cpsat": "mrgc.backends.cpsat:CpSatBackend",
}

ENTRY_POINT_GROUP = "mrgc.backends"


def _all() -> dict[str, str]:
    import importlib.metadata

    out = dict(BACKENDS)
    for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        out.setdefault(ep.name, ep.value)
    return out


def names() -> list[str]:
    """The names of every registered backend: the built-in ones, then the entry-point plug-ins."""
    return list(_all())


def backend_class(name: str) -> type[Backend]:
    """The backend class registered as ``name`` (InputError E301 naming the choices otherwise).  A built-in
    name is found without reading the installed packages' entry points (importlib.metadata costs a CLI
    start-up tens of milliseconds)."""
    table = BACKENDS if name in BACKENDS else _all()
    if name not in table:
        from mrgc.language.suggest import did_you_mean

        raise InputError(
            [Diagnostic("E301", f"unknown backend '{name}'{did_you_mean(name, table)} (installed: {', '.join(table)})")]
        )
    module, _, cls = table[name].partition(":")
    found: Any = getattr(importlib.import_module(module), cls)
    return found  # type: ignore[no-any-return]


def installed(info: BackendInfo) -> bool:
    """Whether the solver library of ``info`` can be imported (found without importing it)."""
    return importlib.util.find_spec(info.module) is not None


def version(info: BackendInfo) -> str:
    """The installed version of the solver library of ``info`` (``-`` when it is not installed)."""
    import importlib.metadata

    try:
        return importlib.metadata.version(info.distribution)
    except importlib.metadata.PackageNotFoundError:
        return "-"


def describe() -> list[dict[str, Any]]:
    """One record per backend: name, installed?, library version, native features, encodings, exports."""
    rows = []
    for name in names():
        info = backend_class(name).info
        rows.append(
            {
                "name": name,
                "title": info.title,
                "installed": installed(info),
                "library": info.distribution,
                "version": version(info),
                "features": sorted(f.value for f in info.features),
                "encodings": list(info.encodings),
                "exports": list(info.exports),
            }
        )
    return rows


@dataclass(frozen=True)
class BackendRecord:
    """A registered solver backend: its name (for ``backend=``), what it is, whether its library is
    installed (and which version), the model features it translates natively (the others are rewritten to
    rows), the encodings it runs and the model files it writes (extensions)."""

    name: str
    title: str
    installed: bool
    library: str
    version: str
    features: tuple[str, ...] = ()
    encodings: tuple[str, ...] = ()
    exports: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        """The record as ``mrgc backends --format json`` prints it."""
        return {
            "name": self.name,
            "title": self.title,
            "installed": self.installed,
            "library": self.library,
            "version": self.version,
            "features": list(self.features),
            "encodings": list(self.encodings),
            "exports": list(self.exports),
        }


def records() -> list[BackendRecord]:
    """Every registered backend (the built-in ones, then plug-ins of the ``mrgc.backends`` entry-point
    group), in registry order; looking them up imports no solver library."""
    return [
        BackendRecord(
            r["name"],
            r["title"],
            r["installed"],
            r["library"],
            r["version"],
            tuple(r["features"]),
            tuple(r["encodings"]),
            tuple(r["exports"]),
        )
        for r in describe()
    ]


def feature_table() -> str:
    """A backend × feature table (native = translated by the solver, lowered = rewritten to rows)."""
    feats = list(Feature)
    header = ["backend", *[f.value for f in feats], "exports"]
    lines = [header]
    for name in names():
        info = backend_class(name).info
        lines.append(
            [
                name,
                *["native" if f in info.features else "lowered" for f in feats],
                " ".join("." + e for e in info.exports) or "-",
            ]
        )
    widths = [max(len(r[i]) for r in lines) for i in range(len(header))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in lines)


def check_export(backend: str | type[Backend], path: str) -> None:
    """InputError E300 (with the backend × feature table as notes) when ``backend`` (a registered name or a
    class) cannot write files of ``path``'s extension."""
    info = (backend if isinstance(backend, type) else backend_class(backend)).info
    ext = os.path.splitext(path)[1].lstrip(".").lower()
    if ext not in info.exports:
        raise InputError(
            [
                Diagnostic(
                    "E300",
                    f"backend '{info.name}' cannot write .{ext} files "
                    f"(it writes: {', '.join('.' + e for e in info.exports) or 'none'})",
                    notes=tuple(feature_table().splitlines()),
                )
            ]
        )
