"""Phase 1 wired up: a checked geometric problem → its geometric facts (geometry/predicates.py), and the
facts file ``mrgc facts`` writes.

The facts file is byte-reproducible (same input, seed and mrgc version → same bytes: its header holds no
time; ``mrgc facts --stats`` prints the timing instead) and stands on its own wherever it is written.
Written to another folder than the problem file, it carries a copy of the domain definition (no
includes), and the local geometry files it names (mesh files of shapes, a robot kind's URDF found beside
its domain, with the mesh files that URDF names) are copied into ``NAME.files/`` beside it, keeping their
layout relative to the problem's folder, so every relative path inside a copied URDF still resolves.  Its
paths are rewritten to point there.  URDFs from pybullet_data are referred to as before; a file outside
the problem's folder tree (allowed with ``--allow-outside``) is referred to by its absolute path.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

from mrgc.errors import Diagnostic, InputError
from mrgc.geometry.facts import FactsResult
from mrgc.geometry.predicates import compute_facts
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.loader import MrgFile, inside, urdf_candidates
from mrgc.language.model import Fact, Problem


def compute_problem_facts(
    problem: Problem, seed: int = 0, workers: int | None = None, deadline: float | None = None
) -> FactsResult:
    """All facts of a geometric problem (InputError E402 for a symbolic one); ``deadline`` (a
    ``time.perf_counter`` value) cuts phase 1 short (``complete`` False, no facts).  The facts cache
    (:mod:`mrgc.planner.facts_cache`) is asked first, and a complete phase 1 is stored there; a hit's
    ``stats`` say ``cached`` 1, ``seconds`` the lookup's, ``computed_seconds`` the phase 1 that made it."""
    import time

    from mrgc.planner import facts_cache

    t0 = time.perf_counter()
    digest = None
    if facts_cache.enabled() and not problem.symbolic:
        from mrgc.language.digest import problem_digest

        digest = problem_digest(problem)
        hit = facts_cache.load(digest, seed)
        if hit is not None:
            facts, stats = hit
            stats = {**stats, "computed_seconds": stats.get("seconds", 0.0), "cached": 1.0}
            stats["seconds"] = round(time.perf_counter() - t0, 6)
            return FactsResult(facts, stats)
    result = compute_facts(scene_from_problem(problem), seed=seed, workers=workers, deadline=deadline)
    if digest is not None and result.complete:  # a phase 1 cut short is never stored
        facts_cache.store(digest, seed, list(result.facts), dict(result.stats))
    return result


@dataclass(frozen=True)
class FactsFile:
    """What ``mrgc facts`` writes: the text, and the geometry files to copy beside it (path → bytes)."""

    text: str
    assets: dict[str, bytes] = field(default_factory=dict)


def facts_file(
    mf: MrgFile, problem: Problem, facts: list[Fact], seed: int, version: str, out_path: str | None
) -> FactsFile:
    """The facts file of ``problem`` (from ``mf``) with ``facts``, to be written at ``out_path`` (None:
    standard output, read as if beside the problem file)."""
    from mrgc.language.edit import facts_document

    header = (
        f"facts of problem {problem.name} computed by mrgc {version} (seed {seed}) from "
        f"{os.path.basename(mf.path)}: {len(facts)} facts"
    )
    relocation = _Relocation(mf.path, out_path) if out_path is not None else None
    text = facts_document(
        mf.syntax,
        problem.name,
        problem.domain.name,
        problem.domain.source,
        facts,
        mf.path,
        out_path,
        header,
        relocation.path if relocation is not None else None,
    )
    return FactsFile(text, relocation.assets if relocation is not None else {})


class _Relocation:
    """Rewrites the paths of a facts file written to another folder, collecting the files to copy."""

    def __init__(self, source: str, out_path: str) -> None:
        self.root = os.path.realpath(os.path.dirname(os.path.abspath(source)))
        self.out_dir = os.path.dirname(os.path.abspath(out_path))
        stem = os.path.splitext(os.path.basename(out_path))[0]
        self.store = os.path.join(self.out_dir, f"{stem}.files")
        self.assets: dict[str, bytes] = {}

    def path(self, written: str, what: str, declaring_file: str) -> str:
        base = os.path.dirname(os.path.abspath(declaring_file))
        if what == "urdf":
            found = next(((c, in_data) for c, in_data in urdf_candidates(written, base) if os.path.isfile(c)), None)
            if found is None or found[1]:
                return written  # from pybullet_data (or missing: the check of the output says so)
            target = os.path.realpath(found[0])
        else:
            target = os.path.realpath(written if os.path.isabs(written) else os.path.join(base, written))
        if not os.path.isfile(target):
            return written
        if not inside(target, (self.root,)):
            return target  # allowed with --allow-outside: the output needs the same permission
        self._copy(target)
        if what == "urdf":
            from mrgc.geometry.urdf import parse_urdf, referenced_files

            for mesh in referenced_files(parse_urdf(target)):
                if not inside(mesh, (self.root,)):
                    raise InputError(
                        [
                            Diagnostic(
                                "E236",
                                f"robot URDF '{written}' names mesh file '{mesh}' outside "
                                f"the folder tree of {self.root}: it cannot be copied beside the "
                                f"output; write the facts beside the problem file instead",
                            )
                        ]
                    )
                self._copy(mesh)
        return os.path.relpath(self._copy_path(target), self.out_dir).replace(os.sep, "/")

    def _copy_path(self, target: str) -> str:
        return os.path.join(self.store, os.path.relpath(target, self.root))

    def _copy(self, target: str) -> None:
        from mrgc.language.files import read_regular

        self.assets[self._copy_path(target)] = read_regular(target, 256 << 20)
