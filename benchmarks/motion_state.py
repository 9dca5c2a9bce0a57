"""What one state of a motion check costs, stage by stage, in microseconds (issues 22 and 23).

    python benchmarks/motion_state.py                       # the 6-arm, 40-object instance of seed 2
    python benchmarks/motion_state.py FILE.mrg --robot r2 --states 3000

An arm path's RRTConnect (``geometry/arm_paths.py``) asks for one configuration at a time, and each goes
through ``Volumes.free_posed``: the arm's pieces posed at the configuration (forward kinematics, the held
object's pose, the kernel's ``Posed``), the world the path must keep clear of, then the arm's own links and
the object it holds.  On the 6-arm instance these motion checks were about half of a run's CPU (a py-spy
profile of seed 2, docs/benchmarks.md, "Session 29").  The robot holds the problem's first movable object
with its first grasp; the configurations are drawn uniformly between home and the joint limits at 40 % of
the way (some reach into the objects, some fold into the arm).  Each row is the best of five passes over
the same states (per state), so the figures are the costs, not the machine's noise; ``cpu_plan.py`` runs
measure whole plans.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from typing import Callable

import numpy as np

from mrgc.generate import generate
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.scene import scene_from_problem
from mrgc.language.loader import parse_file


def per_state(fn: Callable[[int], object], states: int) -> float:
    """Microseconds per state: the best of five passes of ``fn`` over the states."""
    best = float("inf")
    for _ in range(5):
        t = time.perf_counter()
        for k in range(states):
            fn(k)
        best = min(best, (time.perf_counter() - t) / states)
    return best * 1e6


def _default_instance(folder: str) -> str:
    """``mrgc generate packaging --robots 6 --goals 10 --others 30 --seed 2``, written into ``folder``."""
    path = os.path.join(folder, "r6-g10-o30-s2.mrg")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(generate("packaging", seed=2, robots=6, goals=10, others=30))
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", nargs="?", help="an .mrg problem (default: generated, 6 arms, 40 objects, seed 2)")
    ap.add_argument("--robot", default="r1")
    ap.add_argument("--states", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = args.file or _default_instance(folder)
        problem = parse_file(path).problem()
    g = Grounder(scene_from_problem(problem), seed=0)
    arms = sorted(r.name for r in g.scene.robots if r.kind.base == "fixed")
    if args.robot not in arms:
        ap.error(f"--robot {args.robot}: not an arm of {os.path.basename(path)} (its arms: {', '.join(arms)})")
    robot, arm = args.robot, g.arm(args.robot)
    obj = problem.movable[0].name
    grasp = sorted(g.scene.grasp_specs)[0]
    rng = np.random.default_rng(args.seed)
    span = rng.uniform(size=(args.states, arm.model.dof)) * (arm.model.upper - arm.model.lower)
    qs = arm.home + (arm.model.lower + span - arm.home) * 0.4
    holding = (obj, grasp)
    held, opening = g._held(robot, holding), g._grip(robot, obj, grasp)[0]
    against = ("fixed", *g._others(robot, "to-place"), *[o for o in sorted(g.poses) if o != obj])
    posed = [arm.posed(q[None], held, opening) for q in qs]

    def world(k: int) -> bool:
        return g.world.probe_collides(posed[k][0], against=against, ignore=(obj,))

    def itself(k: int) -> bool:
        _, links, poses = posed[k]
        if hasattr(arm, "collides_with_itself_at"):
            return bool(arm.collides_with_itself_at(links, held[0] if held else None, poses))
        # (a tree before 99a6847, for comparisons: the two checks it made one after the other)
        return bool(arm.self_collides_at(links) or arm.held_collides_at(links, held[0], poses))  # type: ignore[index]

    def free(k: int) -> object:
        return g.free_posed(
            robot,
            qs[k : k + 1],
            holding,
            None,
            clear=lambda p: not g.world.probe_collides(p, against=against, ignore=(obj,)),
        )

    rows = [
        ("forward kinematics (the probed links)", lambda k: arm.link_transforms(qs[k : k + 1], opening)),
        ("the arm's pieces posed (Arm.posed)", lambda k: arm.posed(qs[k : k + 1], held, opening)),
        (f"against the world ({len(g.world._select(against, (obj,), ()))} objects)", world),
        ("the arm and what it holds, against themselves", itself),
        ("a state of a motion check (Volumes.free_posed)", free),
    ]
    blocked = sum(world(k) for k in range(args.states))
    print(
        f"{os.path.basename(path)}, {robot} holding {obj} ({grasp}), {args.states} states, {blocked} against the world"
    )
    print("| stage | µs per state |\n|---|---:|")
    for name, fn in rows:
        print(f"| {name} | {per_state(fn, args.states):.1f} |")


if __name__ == "__main__":
    main()
