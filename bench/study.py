"""Study files: which instances, which methods, which seeds, under which per-run limits (docs/bench.md).

A study is a YAML file read with pyyaml's safe loader (plain data only: no tags that build objects) by
:func:`mrgc.bench.schema.load_study`.  Its schema, checked there with every error located at
``file:line:col`` (code E601, E600 for a file that is not YAML at all)::

    study: smoke                  # the study's name: part of every run's key in the results database
    description: free text        # optional
    seeds: 0..1                   # planner seeds of every run: an integer, "a..b" (inclusive) or a list
    limits: {time: 60, memory: 4GB}   # per run (see Limits); a method may override them
    facts_cache: own              # optional: own (default) or shared, see FACTS_CACHE
    instances:                    # one entry per instance set (a row group of the report)
      - file: ../domains/packaging/pa5.mrg     # relative to the study file
      - glob: ../domains/symbolic/c*.mrg      # every match is an instance of the set
        name: symbolic
      - generate: packaging                    # `mrgc generate packaging --robots 2 ... --seed S`
        name: PA5
        robots: 2
        goals: 3
        others: 2
        seeds: 0..19                           # generator seeds: one instance per seed
    methods:
      - {name: Ours, planner: mcts, backend: cpsat, encoding: time-of-move, options: {skeletons: 5}}
      - {name: Ap1, planner: ap1}
      - {name: cpsat-tom, compile: true, backend: cpsat, encoding: time-of-move, only: [PA5]}

This module holds what a checked study is (the data types below, which the rest of :mod:`mrgc.bench`
reads); reading and checking a study file is :mod:`mrgc.bench.schema`, expanding instance entries into
files :mod:`mrgc.bench.instances`, turning methods into command lines :mod:`mrgc.bench.methods`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from mrgc.errors import Span

#: diagnostic codes of study files
E_STUDY_READ, E_STUDY_SCHEMA = "E600", "E601"

#: the values of a study's ``facts_cache`` and what each means for its runs.  ``own`` (the default): every run
#: computes its own phase 1 (the runner adds ``--no-cache``), so a run costs the same whichever method ran on
#: the instance before it; ``shared``: runs read and fill mrgc's facts cache (docs/geometry.md, "The facts
#: cache"), so only the first run on each instance pays for phase 1 (studies of skeleton generation alone).
FACTS_CACHE = {
    "own": "every run computes its own phase 1",
    "shared": "runs on the same instance share phase 1 through the facts cache",
}


@dataclass(frozen=True)
class Limits:
    """Per-run limits.  ``time`` is the planner's own limit (``--time-limit``, seconds): the paper's timeout.
    ``wall`` is the runner's hard wall-clock limit on each process (default ``2 * time + 30``): a process
    still alive then is killed with its whole process group and the run recorded as ``timeout``.
    ``memory_mb`` bounds the proportional set size (PSS) of the run's process group: at the limit the group
    is killed and the run recorded as ``memout``."""

    time: float = 60.0
    wall: float | None = None
    memory_mb: float = 8192.0

    @property
    def wall_seconds(self) -> float:
        """The runner's wall-clock limit: ``wall``, else ``2 * time + 30`` seconds."""
        return self.wall if self.wall is not None else 2 * self.time + 30

    def to_json(self) -> dict[str, float]:
        """The limits as stored in the results database."""
        return {"time": self.time, "wall": self.wall_seconds, "memory_mb": self.memory_mb}


@dataclass(frozen=True)
class InstanceSpec:
    """One entry of ``instances``: a file, a glob or a generator call; ``name`` is the instance set's name
    (the report's row label).  ``options`` are the generator's options (``robots: 2`` → ``--robots 2``)."""

    kind: str  # "file" | "glob" | "generate"
    name: str
    source: str  # the path, the glob pattern (relative to the study's folder) or the generator kind
    problem: str | None = None
    options: tuple[tuple[str, Any], ...] = ()
    seeds: tuple[int, ...] = ()
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Method:
    """One entry of ``methods``: how a run plans (``planner``, default ``mcts``: the paper's method) or,
    with ``compile``, only generates skeletons (``mrgc compile``).  ``options`` are further command-line
    options of ``mrgc plan`` / ``mrgc compile`` (``skeletons: 5`` → ``--skeletons 5``, ``anytime: true``
    → ``--anytime``)."""

    name: str
    planner: str = "mcts"
    compile: bool = False
    backend: str | None = None
    encoding: str | None = None
    options: tuple[tuple[str, Any], ...] = ()
    limits: Limits = Limits()
    #: the instance sets the method runs on (empty: all of them)
    only: tuple[str, ...] = ()
    span: Span | None = field(default=None, compare=False)

    def runs_on(self, instance_set: str) -> bool:
        """Whether the method runs on the instance set named ``instance_set``."""
        return not self.only or instance_set in self.only

    def spec(self) -> dict[str, Any]:
        """What the method is, as stored in the results database: a changed spec under the same name is
        refused there (docs/bench.md)."""
        out: dict[str, Any] = {"compile": True} if self.compile else {"planner": self.planner}
        if self.backend is not None:
            out["backend"] = self.backend
        if self.encoding is not None:
            out["encoding"] = self.encoding
        if self.options:
            out["options"] = dict(self.options)
        out["limits"] = self.limits.to_json()
        return out


@dataclass(frozen=True)
class Study:
    """A checked study file."""

    name: str
    path: str
    text: str
    instances: tuple[InstanceSpec, ...]
    methods: tuple[Method, ...]
    seeds: tuple[int, ...] = (0,)
    limits: Limits = Limits()
    description: str = ""
    facts_cache: str = "own"  # a key of FACTS_CACHE

    @property
    def folder(self) -> str:
        """The folder of the study file: relative paths in it start there."""
        return os.path.dirname(os.path.abspath(self.path))
