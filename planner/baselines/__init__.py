"""The paper's baselines, one module each (:mod:`~mrgc.planner.baselines.ap1`); the registry of every
planning method is :mod:`mrgc.planner.registry`, re-exported here for older imports."""

from __future__ import annotations

from mrgc.planner.registry import DEFAULT_PLANNER, PLANNERS, plan_with

__all__ = ["DEFAULT_PLANNER", "PLANNERS", "plan_with"]
