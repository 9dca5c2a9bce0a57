"""Geometric evidence for a "no plan" answer: which bodies overlap, and by how much.

When the facts say an object's every pick is obstructed by another (a blocking cycle, compiler/diagnose.py),
the user should be able to see that the facts are right.  :func:`pick_obstruction` re-solves the pick
approach ignoring the blocker and measures, with coal's signed distance, how deep the robot's links (fingers
at the grasp's opening) reach into it: ``top by r1: panda_leftfinger of r1 overlaps o2 by 6.3 mm``.
"""

from __future__ import annotations

import math

from mrgc.geometry.collision import CollisionWorld
from mrgc.geometry.conventions import refine
from mrgc.geometry.grounding import Grounder


def pick_obstruction(g: Grounder, robot: str, obj: str, grasp: str, blocker: str) -> str:
    """One line: the deepest overlap of ``robot``'s approach to pick ``obj`` with ``grasp`` and ``blocker``
    (at its current pose), or why no approach exists at all."""
    answer = g.pick(robot, obj, grasp, avoid=())
    if not answer.ok or answer.configs is None:
        return f"{grasp} by {robot}: {answer.status.value} even with {blocker} ignored"
    arm = g.arm(robot)
    shapes, index = arm.probes
    names = [arm.model.links[i].name for i in index]
    volume = g.arm_volume(robot, refine(answer.configs), grasp=(obj, grasp))
    world = CollisionWorld()
    world.add(blocker, g.shape(blocker), g.poses[blocker], "blocker")
    depth, link = math.inf, ""
    for k, (shape, t) in enumerate(volume):
        world.add("probe", shape, t, "probe")
        d = world.distance("probe", blocker)
        world.remove("probe")
        if d < depth:
            depth, link = d, names[k % len(names)]
    if depth > 0:
        return f"{grasp} by {robot}: this approach clears {blocker} by {depth * 1e3:.1f} mm (other IK branches do not)"
    return f"{grasp} by {robot}: {link} of {robot} overlaps {blocker} by {-depth * 1e3:.1f} mm"
