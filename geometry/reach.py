"""Where each arm reaches, seen from above: the data of the reach map (``mrgc render FILE --reach``).

For every fixed-base arm of a scene, a grid over the floor (the scene's extent, :data:`STEP` apart) says
whether the arm's tool centre point gets to that (x, y) at the **pick height** of the problem's objects,
by inverse kinematics alone (joint limits included; obstacles, the table and the other arms are not
checked: the facts say what is blocked, ``mrgc facts --summary``).  Two tool orientations are tried per
point, as the built-in grasps hold an object: pointing straight down at the height of a top grasp (the
median top face of the movable objects, :data:`~mrgc.language.model.DEFAULT_GRASP_DEPTH` below it), and
level, pointing away from the arm's shoulder, at the height of a side grasp (the objects' median centre).
A point counts as reached when either orientation has an IK solution (:data:`YAWS`: the turns of the tool
about its axis tried; a quarter turn more changed no point of the shipped problems, so one is tried).
Planar robots drive and have no reach map.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mrgc.geometry.scene import SceneSpec, half_extents

#: grid spacing (m)
STEP = 0.03
#: turns of the tool about its own axis tried at each point (degrees)
YAWS = (0.0,)
#: how far beyond everything in the scene the grid reaches (m)
MARGIN = 0.3
#: the grid never holds more points than this per axis (the spacing grows for a large scene)
MAX_SIDE = 90


@dataclass
class ReachMap:
    """The grid (``xs``, ``ys``: cell centres) and, per arm, a (len(ys), len(xs)) bool array of the points
    it reaches; ``top_z`` and ``side_z`` the heights tried."""

    xs: np.ndarray
    ys: np.ndarray
    top_z: float
    side_z: float
    reached: dict[str, np.ndarray] = field(default_factory=dict)


def pick_heights(scene: SceneSpec) -> tuple[float, float]:
    """(top-grasp tool height, side-grasp tool height) of the scene's movable objects (medians)."""
    from mrgc.language.model import DEFAULT_GRASP_DEPTH

    if not scene.movable:
        return 0.1, 0.05
    tops = [float(b.pose[2, 3] + half_extents(b.shape)[2]) for b in scene.movable]
    centres = [float(b.pose[2, 3]) for b in scene.movable]
    return float(np.median(tops)) - DEFAULT_GRASP_DEPTH, float(np.median(centres))


def grid(scene: SceneSpec) -> tuple[np.ndarray, np.ndarray]:
    """The cell centres along x and y over everything in the scene, grown by :data:`MARGIN`."""
    from mrgc.geometry.scene import outline

    pts = [r.base[:3, 3] for r in scene.robots]
    for b in (*scene.fixed, *scene.movable, *scene.regions):
        pts.extend(outline(b.shape) @ b.pose[:3, :3].T + b.pose[:3, 3])
    xy = np.array(pts)[:, :2]
    lo, hi = xy.min(axis=0) - MARGIN, xy.max(axis=0) + MARGIN
    step = max(STEP, float(np.max(hi - lo)) / MAX_SIDE)
    return np.arange(lo[0], hi[0] + step / 2, step), np.arange(lo[1], hi[1] + step / 2, step)


def reach_map(scene: SceneSpec) -> ReachMap:
    """Where each arm of ``scene`` reaches (module docstring)."""
    from mrgc.geometry.arm import Arm

    xs, ys = grid(scene)
    top_z, side_z = pick_heights(scene)
    out = ReachMap(xs, ys, top_z, side_z)
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    for spec in scene.robots:
        if spec.kind.driven:
            continue
        arm = Arm(spec)
        out.reached[spec.name] = _reached(arm, points, top_z, side_z).reshape(gx.shape)
    return out


def _reached(arm: object, points: np.ndarray, top_z: float, side_z: float) -> np.ndarray:
    """Which of ``points`` (N, 2) the arm reaches from above at ``top_z`` or level at ``side_z`` (the level
    tool is tried only where the one from above failed)."""
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.ik import solve_ik_many
    from mrgc.geometry.transforms import rot_z

    assert isinstance(arm, Arm)
    shoulder = (arm.base @ np.append(arm.model.shoulder, 1.0))[:3]
    done = np.zeros(len(points), dtype=bool)
    heading = np.arctan2(points[:, 1] - shoulder[1], points[:, 0] - shoulder[0])
    for yaw in YAWS:
        spin = rot_z(np.radians(yaw))[:3, :3]
        for level in (False, True):
            todo = np.flatnonzero(~done)
            if not len(todo):
                return done
            tools = np.tile(np.eye(4), (len(todo), 1, 1))
            tools[:, :3, 3] = np.column_stack([points[todo], np.full(len(todo), side_z if level else top_z)])
            if level:  # the tool's z level, pointing away from the shoulder; its x pointing down
                c, s = np.cos(heading[todo]), np.sin(heading[todo])
                zero = np.zeros(len(todo))
                rot = np.stack(
                    [np.stack([zero, -s, c], -1), np.stack([zero, c, s], -1), np.stack([-1 + zero, zero, zero], -1)], 1
                )
                tools[:, :3, :3] = rot @ spin
            else:  # the tool's z pointing down
                tools[:, :3, :3] = np.diag([1.0, -1.0, -1.0]) @ spin
            targets = arm.base_inv @ tools @ arm.tcp_inv  # Arm.ee_target, batched
            results = solve_ik_many(arm.model, targets, seed=0, restarts=2, max_iters=60)
            done[todo[[r.solved for r in results]]] = True
    return done
