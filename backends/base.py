"""The backend base class: capabilities as data, checks in the public methods, work in private hooks; and
:func:`solver_library`, the one way a backend imports its solver library (lazily, on first use)."""

from __future__ import annotations

import contextlib
import os
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar, Iterator, Sequence

from mrgc.compiler.encodings import ENCODINGS
from mrgc.compiler.ir import Feature, Row, SkeletonModel, Solution, Solver, SolveStatus
from mrgc.compiler.lowering import lower
from mrgc.errors import Diagnostic, InputError, MissingBackendError, MrgcError


@dataclass(frozen=True)
class BackendInfo:
    """What a backend is and can do, readable without importing its solver library.

    ``features`` are the optional model features it translates natively (the others are lowered to rows);
    ``exports`` the file extensions ``export`` writes; ``module`` / ``distribution`` the import name and the
    pip name of its library.  ``grow_horizon``: an encoding whose one model covers every makespan up to the
    horizon limit (time-of-move) is still solved one horizon at a time, T = T0, T0 + 1, ..., as the loop
    encodings are (the same skeleton keys in the same order; a model bounded near the makespan is proved
    optimal far sooner by CP-SAT, HiGHS and pysmt's bound tightening, docs/compiler.md); False where
    loading a model costs more than the larger search (z3's Python API).
    """

    name: str
    title: str
    module: str
    distribution: str
    features: frozenset[Feature]
    exports: tuple[str, ...] = ()
    encodings: tuple[str, ...] = tuple(ENCODINGS)
    install: str = ""
    grow_horizon: bool = True

    @property
    def pip(self) -> str:
        """What to ``pip install`` for the library (``install``, else the distribution's name)."""
        return self.install or self.distribution


@contextlib.contextmanager
def solver_library(info: BackendInfo) -> Iterator[None]:
    """Around a backend's import of its solver library (inside a function, so that only a solve loads it):
    an ImportError becomes a :class:`~mrgc.errors.MissingBackendError`, one line naming what to ``pip
    install`` (exit code 4)::

        def _highspy() -> Any:
            with solver_library(HighsBackend.info):
                import highspy
            return highspy
    """
    try:
        yield
    except ImportError as exc:
        raise MissingBackendError(
            f"backend '{info.name}' needs {info.distribution}: pip install '{info.pip}' ({exc})"
        ) from None


class Backend(ABC):
    """A solver behind the :class:`~mrgc.compiler.ir.Solver` protocol.

    ``load`` lowers the model to the features in ``info.features``; ``solve`` never raises for
    infeasibility, time-outs or solver failures (they are statuses) and self-checks every solution it
    returns against the lowered model.
    """

    info: ClassVar[BackendInfo]

    def __init__(self, seed: int = 0, threads: int = 1) -> None:
        self.seed = seed
        self.threads = threads
        self.model: SkeletonModel | None = None

    @property
    def name(self) -> str:
        """The registered name (``info.name``)."""
        return self.info.name

    def load(self, model: SkeletonModel) -> None:
        """Take a skeleton model, lowered to the features this backend translates natively (replaces any previous
        one)."""
        self.model = lower(model, self.info.features)
        self._load(self.model)

    def add_rows(self, rows: Sequence[Row]) -> None:
        """Add rows (cuts) to the loaded model; the next solve respects them."""
        if self.model is None:
            raise RuntimeError("add_rows before load")
        self.model.rows.extend(rows)
        self._add_rows(rows)

    def solve(self, time_limit: float | None = None) -> Solution:
        """Minimise the loaded model's objectives in order: a :class:`~mrgc.compiler.ir.Solution` whose status says
        how the solve ended (never an exception for infeasibility, time-outs or solver failures); every solution
        returned satisfies the lowered model."""
        if self.model is None:
            raise RuntimeError("solve before load")
        t0 = time.perf_counter()
        try:
            sol = self._solve(time_limit)
        except Exception as exc:  # noqa: BLE001 - a failing solver is an outcome, not a crash
            return Solution(
                SolveStatus.ERROR, message=f"{self.name}: {type(exc).__name__}: {exc}", seconds=time.perf_counter() - t0
            )
        seconds = time.perf_counter() - t0
        if sol.status in (SolveStatus.OPTIMAL, SolveStatus.FEASIBLE):
            bad = self.model.violated(sol.values)
            if bad:
                return Solution(
                    SolveStatus.ERROR, message=f"{self.name} returned a solution violating {bad[:3]}", seconds=seconds
                )
            objective = tuple(self.model.evaluate(o, sol.values) for o in self.model.objectives)
            return Solution(sol.status, sol.values, objective, seconds, sol.message)
        return Solution(sol.status, (), (), seconds, sol.message)

    def export(self, path: str) -> None:
        """Write the loaded model to ``path`` in the format its extension names (one of ``info.exports``;
        :func:`mrgc.backends.registry.check_export` refuses any other as bad input, E300, and a call with
        one is a ValueError).

        The path is checked before the solver library sees it (some crash on a missing folder), and the
        file must exist and be non-empty afterwards (some report failure only by a return value).
        """
        if self.model is None:
            raise RuntimeError("export before load")
        ext = os.path.splitext(path)[1].lstrip(".").lower()
        if ext not in self.info.exports:
            raise ValueError(f"backend '{self.name}' does not write .{ext} files (check_export first)")
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            raise InputError([Diagnostic("E006", f"cannot write {path}: folder {folder} does not exist")])
        self._export(path)
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            raise MrgcError(f"backend '{self.name}' wrote nothing to {path}")

    @abstractmethod
    def _load(self, model: SkeletonModel) -> None: ...

    @abstractmethod
    def _add_rows(self, rows: Sequence[Row]) -> None: ...

    @abstractmethod
    def _solve(self, time_limit: float | None) -> Solution: ...

    def _export(self, path: str) -> None:  # pragma: no cover - backends with exports override
        raise NotImplementedError


def _is_a_solver(backend: Backend) -> Solver:
    """Never called: mypy checks here that a :class:`Backend` satisfies the compiler's
    :class:`~mrgc.compiler.ir.Solver` protocol."""
    return backend
