"""Draws keyed by what is grounded (planner/ground.py ``draw_key``): the same skeleton under the same moves draws the
same random placements and relay spots however many groundings came before it, and grounds the same way."""

from __future__ import annotations

from typing import Any

import numpy as np
from support import ROOT

from mrgc import parse_file
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.scene import scene_from_problem
from mrgc.planner.ground import Grounding, Outcome, ReverseGrounder, draw_key

HANDOVER = Action("o1", "bin-b", "r1", "r2", "top", "side-x+")
PARK = Action("o2", "start", "r1", "r1", "top", "top")
SKELETON = Skeleton(((PARK,), (HANDOVER,)))


def _reverse() -> ReverseGrounder:
    problem = parse_file(ROOT / "domains" / "packaging" / "pa3-handover.mrg").problem()
    return ReverseGrounder(Grounder(scene_from_problem(problem), seed=0), dict(problem.goal_regions))


def _geometry(result: Grounding) -> list[Any]:
    """Every grounded action's placement and configurations, rounded (what a re-draw would change)."""
    out = []
    for step in result.steps:
        for a in step.actions:
            configs = {k: np.round(np.asarray(v, dtype=float), 9).tolist() for k, v in sorted(a.configs.items())}
            out.append((a.object, a.region, np.round(np.asarray(a.place_pose, dtype=float), 9).tolist(), configs))
    return out


def test_the_key_is_made_of_the_skeleton_and_the_suffixs_moves_only() -> None:
    same = Skeleton(
        ((Action("o2", "start", "r1", "r1", "top", "top"),), (Action("o1", "bin-b", "r1", "r2", "top", "side-x+"),))
    )
    key = draw_key(SKELETON, [])
    assert key == draw_key(same, []) and len(key) == 16 and int(key, 16) >= 0
    assert key == "ed27ca8f96071565"  # the same on every machine and in every process (a SHA-1, not hash())
    other_grasp = Skeleton(((PARK,), (Action("o1", "bin-b", "r1", "r2", "top", "side-x-"),)))
    other_order = Skeleton(((HANDOVER,), (PARK,)))
    assert len({key, draw_key(other_grasp, []), draw_key(other_order, [])}) == 3
    grounded = _reverse().ground(Skeleton(((HANDOVER,),)), [], key="x")
    assert grounded.outcome is Outcome.SUCCESS, grounded.reason
    under = draw_key(Skeleton(((PARK,),)), grounded.steps)
    assert under != draw_key(Skeleton(((PARK,),)), [])  # the suffix's moves are part of it


def test_a_skeleton_grounds_the_same_way_whatever_was_grounded_before_it() -> None:
    alone = _reverse().ground(SKELETON, [], key=draw_key(SKELETON, []))
    assert alone.outcome is Outcome.SUCCESS, alone.reason
    after = _reverse()
    for before in (
        Skeleton(((HANDOVER,),)),
        Skeleton(((Action("o3", "start", "r1", "r1", "top", "top"),), (HANDOVER,))),
    ):
        after.ground(before, [], key=draw_key(before, []))
    again = after.ground(SKELETON, [], key=draw_key(SKELETON, []))
    assert again.outcome is Outcome.SUCCESS and _geometry(again) == _geometry(alone)
