"""An independent check of "no robot can pick M": analytic Franka IK, not mrgc's solver.

    pip install geofikpy          # GeoFIK (MIT): analytic IK of the Franka Panda
    python benchmarks/reach_audit.py PROBLEM.mrg o15 [o1 ...]

For every arm of the problem (Panda kind) and every grasp of each named object that the gripper opens wide
enough for, the grasp's tool pose at the object's initial pose, and its pre-grasp (a pick needs both), is
solved with GeoFIK's closed-form IK
(``franka_ik_q7``) for joint 7 swept over its whole range in 0.25 degree steps (every solution branch of
each q7), each solution kept only inside the model's joint limits and when GeoFIK's own forward kinematics
reproduces the pose to 0.1 mm / 1 mrad.  Collisions are ignored, so "unreachable" here is stronger than
phase 1's "no reachable-pick": no configuration of the arm puts its fingers at that grasp and at its
pre-grasp at all.

The tool frame is mrgc's (geometry/grasps.py): the TCP 0.105 m along the flange axis of the model's end
frame; GeoFIK's frame E is 0.1034 m along it, so E = tool · T(0, 0, -0.0016) (measured against the model's
forward kinematics, rotation identical).  Prints one line per object and arm, then a verdict.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from typing import Iterator

import numpy as np

E_FROM_TOOL = -0.0016  # m along the tool's z: GeoFIK's frame E is 0.1034 m past the flange, mrgc's TCP 0.105
STEP = np.radians(0.25)  # q7 sweep step
POS_TOL, ROT_TOL = 1e-4, 1e-3


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """GeoFIK prints "ERROR: unable to assembly kinematic chain" on standard output (from C++) for every
    pose it cannot solve: that descriptor goes to /dev/null meanwhile."""
    sys.stdout.flush()
    saved, null = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)


def reachable(geofik: object, e_pose: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray | None:
    """A configuration (within ``lower``..``upper``) putting frame E at ``e_pose`` (arm base frame), or None."""
    r, rot = list(e_pose[:3, 3]), list(e_pose[:3, :3].reshape(-1))
    for q7 in np.arange(lower[6], upper[6] + 1e-12, STEP):
        sols, n = geofik.franka_ik_q7(r, rot, float(q7))  # type: ignore[attr-defined]
        for q in np.asarray(sols[:n], dtype=float):
            if not np.all(np.isfinite(q)) or np.any(q < lower - 1e-9) or np.any(q > upper + 1e-9):
                continue
            back = np.asarray(geofik.franka_fk(list(q), "E"))  # type: ignore[attr-defined]
            d_rot = np.linalg.norm(back[:3, :3] - e_pose[:3, :3])
            if np.linalg.norm(back[:3, 3] - e_pose[:3, 3]) <= POS_TOL and d_rot <= ROT_TOL:
                return q
    return None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("problem")
    parser.add_argument("objects", nargs="+")
    args = parser.parse_args(argv)
    try:
        import geofikpy
    except ImportError:
        print("reach_audit: needs geofikpy (pip install geofikpy)", file=sys.stderr)
        return 2
    from mrgc import parse_file
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.grasps import APPROACH, fits, grasp_transform, pregrasp_transform
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.scene import scene_from_problem
    from mrgc.geometry.transforms import translation

    scene = scene_from_problem(parse_file(args.problem).problem())
    arms = [Arm(spec) for spec in scene.robots if approaches(spec.kind)]
    unreachable = []
    for obj in args.objects:
        body = scene.body(obj)
        grasps = [g for g in scene.grasps[obj] if g in scene.grasp_specs]
        found = []
        for arm in arms:
            lower, upper = arm.model.lower, arm.model.upper
            usable = [g for g in grasps if fits(scene.grasp_specs[g], body.shape, arm.spec.kind)]
            hits, grasp_only = [], []
            for g in usable:
                tool = body.pose @ grasp_transform(scene.grasp_specs[g], body.shape)
                poses = [tool, tool @ pregrasp_transform(np.eye(4))]  # a pick needs both
                with quiet_stdout():
                    ok = [
                        reachable(geofikpy, arm.base_inv @ t @ translation(0.0, 0.0, E_FROM_TOOL), lower, upper)
                        is not None
                        for t in poses
                    ]
                if all(ok):
                    hits.append(g)
                elif ok[0]:
                    grasp_only.append(g)
            found += hits
            shoulder = np.linalg.norm(
                (arm.base_inv[:3, :3] @ body.pose[:3, 3] + arm.base_inv[:3, 3]) - arm.model.shoulder
            )
            said = "reaches " + ", ".join(hits) if hits else "no grasp with its pre-grasp reachable"
            if grasp_only:
                said += f" ({', '.join(grasp_only)}: the grasp, not its pre-grasp {APPROACH * 100:g} cm back)"
            print(
                f"{obj} by {arm.name}: {said}; {len(usable)} grasps tried, "
                f"object centre {shoulder:.3f} m from the shoulder"
            )
        if not found:
            unreachable.append(obj)
    print(
        f"verdict: {', '.join(unreachable)} out of every arm's reach (analytic IK, collisions ignored)"
        if unreachable
        else "verdict: every object has a kinematically reachable grasp"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
