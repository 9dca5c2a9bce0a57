"""Phase 1 wired up: a checked geometric problem → its geometric facts (geometry/predicates.py)."""

from __future__ import annotations

from mrgc.geometry.predicates import FactsResult, compute_facts
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.model import Problem


def compute_problem_facts(problem: Problem, seed: int = 0, workers: int | None = None) -> FactsResult:
    """All facts of a geometric problem (InputError E402 for a symbolic one)."""
    return compute_facts(scene_from_problem(problem), seed=seed, workers=workers)
