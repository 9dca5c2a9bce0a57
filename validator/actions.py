"""The validator's reading of one action's geometry: what the motion model requires of it, and every check
that needs no sweep (configurations, joint limits, grasps, approaches, handovers, path ends).

:class:`ActionReader` turns a typed :class:`~mrgc.planfile.format.PlannedAction` into an :class:`ActionGeometry`
(numpy arrays, the motion of each phase) and reports what is wrong with it; :mod:`mrgc.validator.replay`
sweeps the motions.  Forward kinematics are pybullet's (:class:`~mrgc.validator.world.ReplayScene`), grasp
frames come from their specification (:mod:`mrgc.geometry.grasps`), the planar model from
:mod:`mrgc.geometry.planar_grasps`; nothing comes from the planner's search or grounding.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mrgc.geometry.conventions import pose_error, wrap_angle, yaw_of
from mrgc.geometry.grasps import APPROACH, finger_opening, fits, grasp_transform, pregrasp_transform
from mrgc.geometry.planar_grasps import PLANAR_GRASPS, carry_transform, grasp_base
from mrgc.geometry.scene import SceneSpec
from mrgc.geometry.transforms import from_pose, inverse
from mrgc.planfile.format import MotionModel, PlannedAction
from mrgc.validator.violation import Violation, number
from mrgc.validator.world import ReplayScene

POS_TOL = 1e-3  # m: tool vs grasp, handover position, path continuity of planar bases
ROT_TOL = 0.01  # rad
LIMIT_TOL = 1e-6  # rad or m beyond a joint limit
JOINT_TOL = 1e-3  # rad: path ends vs the configurations they connect
WORLD = 1e4  # m: planar base coordinates beyond this are outside the world
MIN_APPROACH_CONFIGURATIONS = 5  # an approach of fewer would make its contact segment longer than a quarter
#: the tool in the contact segment: off the approach line at most this (m) and turned at most this (rad) (a
#: bound on the approach's shape; that the gripper cuts no deeper into the object than it stands at the
#: grasp is checked by the sweep); measured on the planner's plans: up to 5.9 mm and 0.011 rad
CONTACT_POS_TOL = 0.01
CONTACT_ROT_TOL = 0.05
CONTACT_SAMPLES = 17  # configurations of the contact segment where the tool's pose is checked
CONTACT_SLACK = 2.0  # the contact segment may start this much farther than its equal share of the back-off

#: path name -> (robot role, grasp role held on the way or None, where it starts, where it ends); a place is
#: ``home`` or (configs phase, index), ``transfer`` meaning where the object was taken (the last pick
#: configuration, or the taker's exchange configuration of a handover)
PATH_PHASES: dict[str, tuple[str, str | None, str | tuple[str, int], str | tuple[str, int]]] = {
    "to-pick": ("pick_robot", None, "home", ("pick", 0)),
    "to-handover": ("pick_robot", "pick_grasp", ("pick", -1), ("handover", 0)),
    "taker-to-handover": ("place_robot", None, "home", ("handover", 1)),
    "to-place": ("place_robot", "place_grasp", ("transfer", -1), ("place", 0)),
    "home": ("place_robot", None, ("place", -1), "home"),
    "giver-home": ("pick_robot", None, ("handover", 0), "home"),
}
HANDOVER_PATHS = ("to-handover", "taker-to-handover", "giver-home")
#: the paths a motion model requires: (robots planar?, arms model) -> names, for pick-and-place / handover
REQUIRED_PATHS: dict[tuple[bool, str], tuple[tuple[str, ...], tuple[str, ...]]] = {
    (True, "paths"): (("to-pick", "to-place", "home"), ()),
    (False, "configurations"): ((), ()),
    (False, "full"): (
        ("to-pick", "to-place", "home"),
        ("to-pick", "to-handover", "taker-to-handover", "to-place", "home", "giver-home"),
    ),
}
#: holding transfers an arm makes in a straight joint-space line when the plan gives no path (configurations
#: model): path name -> (from, to) as in PATH_PHASES
STRAIGHT_TRANSFERS = ("to-handover", "to-place")


@dataclass
class ActionGeometry:
    """One action with its geometry read: the place pose, the configurations of each phase, the motion of
    each path phase (given, or the straight transfer the model implies), and whether the collision sweep
    can run (everything it needs is present and well formed)."""

    step: int
    action: PlannedAction
    place_pose: np.ndarray | None = None
    configs: dict[str, np.ndarray] = field(default_factory=dict)
    paths: dict[str, np.ndarray] = field(default_factory=dict)
    straight: set[str] = field(default_factory=set)  # path phases that are the model's straight transfers
    geometry: bool = True

    @property
    def obj(self) -> str:
        """The object the action moves."""
        return self.action.object

    @property
    def handover(self) -> bool:
        """Whether the action is a handover."""
        return self.action.handover

    def robot(self, role: str) -> str:
        """The robot in ``role`` (``pick_robot`` or ``place_robot``)."""
        return str(getattr(self.action, role))

    def grasp(self, role: str | None) -> str | None:
        """The grasp in ``role`` (``pick_grasp`` or ``place_grasp``; None for none)."""
        return None if role is None else str(getattr(self.action, role))


class ActionReader:
    """The scene, the robots' homes and the specifications an action is read against."""

    def __init__(self, scene: SceneSpec, rs: ReplayScene, model: MotionModel) -> None:
        self.scene = scene
        self.rs = rs
        self.model = model
        self.out: list[Violation] = []
        self.poses = {b.name: np.array(b.pose, dtype=float) for b in scene.movable}
        self.shapes = {b.name: b.shape for b in (*scene.movable, *scene.fixed)}
        self.planar = {r.name: rs.robots[r.name].planar for r in scene.robots}
        self.tcp = {r.name: from_pose(r.kind.tcp) if r.kind.tcp is not None else np.eye(4) for r in scene.robots}
        self.home = {r.name: self._home(r.name) for r in scene.robots}
        self._held: dict[tuple[str, str, str], np.ndarray] = {}  # (robot, object, grasp) -> object in the tool frame

    # ------------------------------------------------------------------ specifications
    def _home(self, name: str) -> np.ndarray:
        rr = self.rs.robots[name]
        spec = self.scene.robot(name)
        if rr.planar:
            b = spec.base
            return np.array([b[0, 3], b[1, 3], yaw_of(b)])
        home = np.array(spec.kind.home, dtype=float)
        if len(home) < rr.dof:
            mid = np.where(np.isfinite(rr.lower) & np.isfinite(rr.upper), (rr.lower + rr.upper) / 2, 0.0)
            return mid
        return np.clip(home[: rr.dof], rr.lower, rr.upper)  # type: ignore[no-any-return]

    def _v(self, step: int | None, subject: str | None, code: str, message: str) -> None:
        self.out.append(Violation(step, subject, code, message))

    def tool(self, robot: str, q: np.ndarray) -> np.ndarray:
        """Arms: the tool centre point in the world (pybullet FK); planar robots: the base frame."""
        self.rs.set_config(robot, q)
        tool: np.ndarray = self.rs.ee_pose(robot) @ self.tcp[robot]
        return tool

    def grasp_frame(self, robot: str, obj: str, grasp: str) -> np.ndarray:
        """Arms: the tool pose in the object frame; planar robots: the object's carry pose in the base frame."""
        shape = self.shapes[obj]
        if not self.planar[robot]:
            return grasp_transform(self.scene.grasp(grasp), shape)
        return carry_transform(self.scene.robot(robot).kind, shape, grasp)

    def opening(self, obj: str, grasp: str) -> float:
        """An arm's finger opening holding ``obj`` with ``grasp`` (the grasp specification's)."""
        return finger_opening(self.scene.grasp(grasp), self.shapes[obj])

    def fingers(self, robot: str, obj: str, grasp: str | None) -> float | None:
        """An arm's finger opening while it approaches or holds ``obj`` with ``grasp`` (None: fully open)."""
        if grasp is None or self.planar[robot] or grasp not in self.scene.grasp_specs:
            return None
        return self.opening(obj, grasp)

    def held_pose(self, robot: str, q: np.ndarray, obj: str, grasp: str) -> np.ndarray:
        """Where ``robot`` at ``q`` holds ``obj`` grasped with ``grasp`` (world frame)."""
        self.rs.set_config(robot, q)
        return self.held_pose_now(robot, obj, grasp)

    def held_pose_now(self, robot: str, obj: str, grasp: str) -> np.ndarray:
        """Where ``robot``, at the configuration it was last set to, holds ``obj`` grasped with ``grasp``."""
        key = (robot, obj, grasp)
        if key not in self._held:
            g = self.grasp_frame(robot, obj, grasp)
            self._held[key] = g if self.planar[robot] else inverse(g)
        return self.rs.ee_pose(robot) @ self.tcp[robot] @ self._held[key]  # type: ignore[no-any-return]

    def _grasp_base(self, robot: str, obj: str, grasp: str, pose: np.ndarray) -> np.ndarray:
        """The planar model's base pose (x, y, yaw) for grasping ``obj`` at ``pose`` with ``grasp``: facing
        the grasped face, the front CLEARANCE from it."""
        return grasp_base(self.scene.robot(robot).kind, pose, self.shapes[obj], grasp)

    # ------------------------------------------------------------------ the model
    def check_model(self) -> None:
        """The plan's motion model is one this validator knows how to check ``[motion-model]``."""
        m = self.model
        if abs(m.approach_back_off - APPROACH) > 1e-9:
            self._v(
                None,
                None,
                "motion-model",
                f"the motion model's approach back-off is {m.approach_back_off:g} m; "
                f"the grasp specification's pre-grasp stands {APPROACH:g} m back",
            )
        if m.approach_configurations < MIN_APPROACH_CONFIGURATIONS:
            self._v(
                None,
                None,
                "motion-model",
                f"the motion model's approaches hold {m.approach_configurations} "
                f"configurations; at least {MIN_APPROACH_CONFIGURATIONS} are needed "
                f"(the object is exempt only in the last segment)",
            )

    # ------------------------------------------------------------------ reading one action
    def parse(self, t: int, a: PlannedAction) -> ActionGeometry:
        """``a`` (whose names resolve) with its geometry read and checked; ``geometry`` False when the sweep
        cannot run on it."""
        act = ActionGeometry(t, a)
        obj = a.object
        for robot, grasp in ((a.pick_robot, a.pick_grasp), (a.place_robot, a.place_grasp)):
            if self.planar[robot] and grasp not in PLANAR_GRASPS:
                self._v(
                    t,
                    obj,
                    "grasp",
                    f"planar robot {robot} cannot use grasp {grasp!r} (side grasps only: {', '.join(PLANAR_GRASPS)})",
                )
                act.geometry = False
            elif not self.planar[robot] and grasp not in self.scene.grasp_specs:
                self._v(
                    t,
                    obj,
                    "grasp",
                    f"grasp {grasp!r} has no geometric meaning (known: {', '.join(sorted(self.scene.grasp_specs))})",
                )
                act.geometry = False
            elif not self.planar[robot] and not fits(
                self.scene.grasp(grasp), self.shapes[obj], self.scene.robot(robot).kind
            ):
                self._v(
                    t,
                    obj,
                    "grasp",
                    f"grasp {grasp!r} needs the fingers {self.opening(obj, grasp):.3f} m apart; "
                    f"{robot} opens {self.scene.robot(robot).kind.gripper_opening:g} m",
                )
                act.geometry = False
        if a.handover and (self.planar[a.pick_robot] or self.planar[a.place_robot]):
            self._v(t, obj, "handover", "planar robots cannot hand objects over")
            act.geometry = False
        self._place_pose(act)
        self._configs(act)
        self._paths(act)
        if act.geometry:
            self._check_grasps(act)
            self._check_approaches(act)
            self._straight_transfers(act)
            for name, qs in act.paths.items():
                if name not in act.straight:
                    self._continuity(act, name, qs)
        return act

    def _place_pose(self, act: ActionGeometry) -> None:
        t, obj, pose = act.step, act.obj, act.action.place_pose
        if pose is None:
            self._v(t, obj, "missing", "the action has no place_pose")
            act.geometry = False
            return
        m = np.array(pose, dtype=float)
        r = m[:3, :3]
        if np.abs(r.T @ r - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0 or np.abs(m[3] - [0, 0, 0, 1]).max() > 1e-9:
            self._v(t, obj, "pose", "place_pose is not a rigid transform (orthonormal rotation, last row 0 0 0 1)")
            act.geometry = False
        elif np.abs(m[:3, 3]).max() > WORLD:
            self._v(t, obj, "pose", f"place_pose lies outside the world (|x|, |y|, |z| <= {WORLD:g} m)")
            act.geometry = False
        else:
            act.place_pose = m

    def _configs(self, act: ActionGeometry) -> None:
        a, t, obj = act.action, act.step, act.obj
        for phase in ["pick", "place"] + (["handover"] if a.handover else []):
            robot = a.pick_robot if phase == "pick" else a.place_robot
            qs = a.configs.get(phase)
            if not qs:
                self._v(t, obj, "missing", f"the action has no {phase} configurations")
                act.geometry = False
                continue
            if phase == "handover":
                if len(qs) != 2:
                    self._v(t, obj, "missing", f"configs.handover holds {len(qs)} configurations, not 2 (giver, taker)")
                    act.geometry = False
                    continue
                ok = self.check_configs(t, a.pick_robot, "handover", qs[:1], obj) & self.check_configs(
                    t, a.place_robot, "handover", qs[1:], obj
                )
            else:
                ok = self.check_configs(t, robot, phase, qs, obj)
            if ok:
                act.configs[phase] = np.array(qs, dtype=float)
            else:
                act.geometry = False
        if "handover" in a.configs and not a.handover:
            self._v(t, obj, "action", "a pick-and-place has no handover configurations")
        if a.handover:
            allowed = self.scene.handover_of.get(obj) or tuple(self.scene.handover_points)
            if a.handover_point is None:
                self._v(t, obj, "missing", "the handover names no handover_point")
                act.geometry = False
            elif a.handover_point not in allowed:
                self._v(
                    t,
                    obj,
                    "handover",
                    f"{obj} may not be handed over at {a.handover_point} (allowed: {', '.join(allowed)})",
                )
        elif a.handover_point is not None:
            self._v(t, obj, "action", f"a pick-and-place names a handover point ({a.handover_point})")

    def _paths(self, act: ActionGeometry) -> None:
        a, t, obj = act.action, act.step, act.obj
        for name, qs in a.paths.items():
            role = PATH_PHASES[name][0]
            if name in HANDOVER_PATHS and not a.handover:
                self._v(t, obj, "path", f"path {name!r} belongs to a handover, and this is a pick-and-place")
                continue
            if not qs:
                self._v(t, obj, "path", f"path {name!r} holds no configuration")
                act.geometry = False
            elif self.check_configs(t, act.robot(role), f"path {name!r}", qs, obj):
                act.paths[name] = np.array(qs, dtype=float)
            else:
                act.geometry = False
        planar = self.planar[a.pick_robot]
        required = REQUIRED_PATHS[(True, self.model.planar) if planar else (False, self.model.arms)]
        for name in required[1 if a.handover else 0]:
            if name not in a.paths:
                who = act.robot(PATH_PHASES[name][0])
                model = f"planar {self.model.planar!r}" if planar else f"arms {self.model.arms!r}"
                self._v(
                    t,
                    who,
                    "missing",
                    f"the action moving {obj} has no {name!r} path, which the motion model ({model}) requires",
                )

    def check_configs(self, t: int, robot: str, what: str, qs: Any, obj: str) -> bool:
        """Each configuration has one value per joint, lies in the world and within the joint limits."""
        rr = self.rs.robots[robot]
        if all(len(q) == rr.dof for q in qs):  # the usual case, checked at once; the loop below says what is wrong
            v = np.asarray(qs, dtype=float)
            out = (v < rr.lower - LIMIT_TOL) | (v > rr.upper + LIMIT_TOL) | (np.abs(v) > WORLD)
            if not out.any() and not (rr.planar and np.abs(v[:, :2]).max(initial=0.0) > WORLD):
                return True
        ok = True
        for i, q in enumerate(qs, 1):
            if len(q) != rr.dof:
                unit = "joints" if not rr.planar else "(x, y, yaw)"
                self._v(
                    t,
                    robot,
                    "config",
                    f"{what} configuration {i} of {len(qs)} (moving {obj}) has {len(q)} "
                    f"values; {robot} has {rr.dof} {unit}",
                )
                ok = False
                continue
            v = np.asarray(q, dtype=float)
            if rr.planar and max(abs(v[0]), abs(v[1])) > WORLD:
                self._v(
                    t,
                    robot,
                    "config",
                    f"{what} configuration {i} of {len(qs)} (moving {obj}) puts the base "
                    f"outside the world (|x|, |y| <= {WORLD:g} m)",
                )
                ok = False
                continue
            bad = np.nonzero((v < rr.lower - LIMIT_TOL) | (v > rr.upper + LIMIT_TOL) | (np.abs(v) > WORLD))[0]
            for j in bad:
                self._v(
                    t,
                    robot,
                    "joint-limits",
                    f"{what} configuration {i} of {len(qs)} (moving {obj}): "
                    f"{rr.joint_names[j]} = {number(v[j])} is outside "
                    f"[{number(rr.lower[j])}, {number(rr.upper[j])}]",
                )
                ok = False
        return ok

    # ------------------------------------------------------------------ static checks
    def _check_grasps(self, act: ActionGeometry) -> None:
        a, t, obj = act.action, act.step, act.obj
        assert act.place_pose is not None
        checks = [
            ("pick", a.pick_robot, a.pick_grasp, self.poses[obj], "the object"),
            ("place", a.place_robot, a.place_grasp, act.place_pose, "place_pose"),
        ]
        for phase, robot, grasp, pose, what in checks:
            q = act.configs[phase][-1]
            if self.planar[robot]:
                if len(act.configs[phase]) != 1:
                    self._v(
                        t,
                        robot,
                        "config",
                        f"configs.{phase} of planar robot {robot} holds "
                        f"{len(act.configs[phase])} base poses, not 1 (its motions are paths)",
                    )
                want = self._grasp_base(robot, obj, grasp, pose)
                dp = float(np.hypot(q[0] - want[0], q[1] - want[1]))
                dr = abs(wrap_angle(float(q[2] - want[2])))
                if dp > POS_TOL or dr > ROT_TOL:
                    self._v(
                        t,
                        robot,
                        "grasp",
                        f"the last {phase} base pose of {robot} is {dp * 1e3:.1f} mm, "
                        f"{dr:.3f} rad from where grasp {grasp!r} of {obj} puts it (at "
                        f"{what}; tolerance {POS_TOL * 1e3:g} mm, {ROT_TOL} rad)",
                    )
                from mrgc.validator.stability import cart_set_down

                # a cart lowers its box, upright, onto the floor it drives on (a pick takes the object as it is)
                placing = (
                    cart_set_down(obj, self.shapes[obj], pose, robot, ROT_TOL, POS_TOL) if phase == "place" else []
                )
                for message in placing:
                    self._v(t, robot, "placement", message)
                continue
            dp, dr = _pose_error(self.tool(robot, q), pose @ grasp_transform(self.scene.grasp(grasp), self.shapes[obj]))
            if dp > POS_TOL or dr > ROT_TOL:
                self._v(
                    t,
                    robot,
                    "grasp",
                    f"the last {phase} configuration of {robot} puts the tool "
                    f"{dp * 1e3:.1f} mm, {dr:.3f} rad from grasp {grasp!r} of {obj} at {what} "
                    f"(tolerance {POS_TOL * 1e3:g} mm, {ROT_TOL} rad)",
                )
        if a.handover:
            point = self.scene.handover_points.get(a.handover_point or "")
            h = act.configs["handover"]
            x1 = self.held_pose(a.pick_robot, h[0], obj, a.pick_grasp)
            x2 = self.held_pose(a.place_robot, h[1], obj, a.place_grasp)
            if point is not None:
                for robot, x, grasp in ((a.pick_robot, x1, a.pick_grasp), (a.place_robot, x2, a.place_grasp)):
                    d = float(np.linalg.norm(x[:3, 3] - point))
                    if d > POS_TOL:
                        self._v(
                            t,
                            robot,
                            "handover",
                            f"{robot} holds {obj} (grasp {grasp!r}) {d * 1e3:.1f} mm from "
                            f"handover point {a.handover_point} (tolerance "
                            f"{POS_TOL * 1e3:g} mm)",
                        )
            dp, dr = _pose_error(x1, x2)
            if dp > POS_TOL or dr > ROT_TOL:
                self._v(
                    t,
                    obj,
                    "handover",
                    f"giver {a.pick_robot} and taker {a.place_robot} hold {obj} at poses "
                    f"{dp * 1e3:.1f} mm, {dr:.3f} rad apart (tolerance {POS_TOL * 1e3:g} mm, "
                    f"{ROT_TOL} rad)",
                )

    def _check_approaches(self, act: ActionGeometry) -> None:
        """An arm's pick and place approaches hold the model's number of configurations, start at the
        pre-grasp (the grasp backed off by the specification's APPROACH along the tool's -z) and enter the
        contact segment (the last one) no farther than its share of the back-off ``[approach]``."""
        a, t, obj = act.action, act.step, act.obj
        assert act.place_pose is not None
        n = self.model.approach_configurations
        share = APPROACH / max(n - 1, 1) * CONTACT_SLACK
        for phase, robot, grasp, pose in (
            ("pick", a.pick_robot, a.pick_grasp, self.poses[obj]),
            ("place", a.place_robot, a.place_grasp, act.place_pose),
        ):
            if self.planar[robot]:
                continue
            qs = act.configs[phase]
            word = "pre-grasp" if phase == "pick" else "pre-place"
            if len(qs) != n:
                self._v(
                    t,
                    robot,
                    "approach",
                    f"the {phase} approach of {robot} (moving {obj}) holds {len(qs)} "
                    f"configuration{'s' * (len(qs) != 1)}; the motion model's approaches "
                    f"hold {n}, {word} first",
                )
            g = pose @ grasp_transform(self.scene.grasp(grasp), self.shapes[obj])
            dp, dr = _pose_error(
                self.tool(robot, qs[0]),
                pose @ pregrasp_transform(grasp_transform(self.scene.grasp(grasp), self.shapes[obj])),
            )
            if dp > POS_TOL or dr > ROT_TOL:
                self._v(
                    t,
                    robot,
                    "approach",
                    f"the first {phase} configuration of {robot} puts the tool "
                    f"{dp * 1e3:.1f} mm, {dr:.3f} rad from the {word} of {obj} ({APPROACH:g} m "
                    f"back from grasp {grasp!r}; tolerance {POS_TOL * 1e3:g} mm, {ROT_TOL} rad)",
                )
            if len(qs) > 1:
                self._contact_line(act, phase, robot, grasp, qs[-2], qs[-1], g)
            d = float(np.linalg.norm(self.tool(robot, qs[-2])[:3, 3] - g[:3, 3])) if len(qs) > 1 else 0.0
            if d > share + POS_TOL:
                self._v(
                    t,
                    robot,
                    "approach",
                    f"the contact segment of {robot}'s {phase} approach (moving {obj}) "
                    f"starts with the tool {d * 1e3:.1f} mm from the grasp; at most "
                    f"{share * 1e3:.1f} mm ({CONTACT_SLACK:g} x the back-off / {n - 1})",
                )

    def _contact_line(
        self, act: ActionGeometry, phase: str, robot: str, grasp: str, q0: np.ndarray, q1: np.ndarray, g: np.ndarray
    ) -> None:
        """In the contact segment (``q0`` to ``q1``, where the gripper may touch the object) the tool keeps
        the grasp's orientation and stays on its approach line (the grasp's z axis through its position), to
        :data:`CONTACT_ROT_TOL` and :data:`CONTACT_POS_TOL`, at :data:`CONTACT_SAMPLES` equally spaced
        configurations of the segment (both ends included) ``[approach]``."""
        z, worst = g[:3, 2], (0.0, 0.0, 0.0)
        for u in np.linspace(0.0, 1.0, CONTACT_SAMPLES):
            tool = self.tool(robot, q0 + u * (q1 - q0))
            d = tool[:3, 3] - g[:3, 3]
            off = float(np.linalg.norm(d - float(d @ z) * z))
            rot = _pose_error(tool, g)[1]
            if max(off / CONTACT_POS_TOL, rot / CONTACT_ROT_TOL) > max(
                worst[0] / CONTACT_POS_TOL, worst[1] / CONTACT_ROT_TOL
            ):
                worst = (off, rot, float(u))
        if worst[0] > CONTACT_POS_TOL or worst[1] > CONTACT_ROT_TOL:
            n = len(act.configs[phase])
            self._v(
                act.step,
                robot,
                "approach",
                f"in the contact segment of {robot}'s {phase} approach (moving {act.obj}; configurations {n - 1} "
                f"to {n} of {n}, at {worst[2]:.2f} of the way) the tool is {worst[0] * 1e3:.1f} mm off grasp "
                f"{grasp!r}'s approach line and turned {worst[1]:.3f} rad from it (tolerance "
                f"{CONTACT_POS_TOL * 1e3:g} mm, {CONTACT_ROT_TOL} rad)",
            )

    def _straight_transfers(self, act: ActionGeometry) -> None:
        """Arms under the configurations model: a holding transfer the plan gives no path for is the
        straight joint-space move between the configurations it connects."""
        if self.planar[act.action.pick_robot] or self.model.arms != "configurations":
            return
        for name in STRAIGHT_TRANSFERS:
            if name in act.paths or (name == "to-handover" and not act.handover):
                continue
            start, end = self.path_end(act, PATH_PHASES[name][2]), self.path_end(act, PATH_PHASES[name][3])
            if start is not None and end is not None:
                act.paths[name] = np.stack([start[0], end[0]])
                act.straight.add(name)

    def path_end(self, act: ActionGeometry, ref: str | tuple[str, int]) -> tuple[np.ndarray, str] | None:
        """The configuration a path end refers to, and its name in words (None: not in the plan)."""
        if isinstance(ref, str):  # home
            return None
        phase, k = ref
        if phase == "transfer":
            phase, k = ("handover", 1) if act.handover else ("pick", -1)
        if phase not in act.configs:
            return None
        if phase == "handover":
            return act.configs[phase][k], f"{('giver', 'taker')[k]}'s handover configuration"
        return act.configs[phase][k], f"{'first' if k == 0 else 'last'} {phase} configuration"

    def _continuity(self, act: ActionGeometry, name: str, qs: np.ndarray) -> None:
        role, _, start, end = PATH_PHASES[name]
        robot = act.robot(role)
        for which, ref, q in (("starts", start, qs[0]), ("ends", end, qs[-1])):
            if ref == "home":
                want, what = self.home[robot], "home"
            else:
                found = self.path_end(act, ref)
                if found is None:
                    continue
                want, what = found
            if self.planar[robot]:
                dp = float(np.hypot(*(q[:2] - want[:2])))
                dr = abs(wrap_angle(float(q[2] - want[2])))
                bad, gap = dp > POS_TOL or dr > ROT_TOL, f"{dp * 1e3:.1f} mm, {dr:.3f} rad"
            else:
                d = float(np.abs(q - want).max())
                bad, gap = d > JOINT_TOL, f"{number(d)} rad"
            if bad:
                self._v(
                    act.step,
                    robot,
                    "path",
                    f"path {name!r} (moving {act.obj}) {which} {gap} away from the "
                    f"{what} (tolerance {JOINT_TOL} rad; planar {POS_TOL * 1e3:g} mm, "
                    f"{ROT_TOL} rad)",
                )


def _pose_error(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Position distance (m) and rotation angle (rad) between two poses."""
    dp, dr = pose_error(a, b)
    return float(dp), float(dr)
