"""Issue 21, adversarial review (second round): the doctored plans the validator accepted, rebuilt.

The review (docs/validator.md, "Adversarial review, second round (issue 21)") tried 80 doctored plans; its
full generator needs plans that are not stored (pa3-handover, pa18-4arms, pa5 --motions full planned afresh)
and about 20 minutes of ``mrgc validate``, so it is not part of the repository.  This script rebuilds, from
the stored ``tests/data/round2/pa5.json`` alone and in well under two minutes, the two physically wrong plans
it accepted and a harmless twin of each, runs ``mrgc validate`` on them and, with ``--physics``, shows with
pybullet's dynamics (gravity, friction, o1 driven along the gripper's path) what happens to the boxes:

- **A21** (tower): two steps are appended; r1 sets o2 on o1, 3 mm inside o1's top edge (o2 alone stands),
  then o3 on o2, 3 mm inside o2's edge (o3 alone stands).  Together o2 and o3 have their centre of mass
  4.6 mm beyond o1's edge, and the pair topples off o1.  H13 is the same with both boxes centred.
- **A31** (support out and back in one step): o2 is set centred on o1; the next step's r1 pulls o1 out from
  under o2 (side-x- grasp, 8 cm to the left), lifts it 6 cm, tips it 60 degrees and back, and slides it back
  in to its own pose.  o2 has nothing under it while o1 is out (it falls; riding along on o1 it slides off at
  the tip), but rests on o1 again at the end of the step, the only time support is checked.  A31-twin is
  the same excursion of o1 with nothing on it.

Usage (from the repository root; writes the plans to OUT, default /tmp/adversarial_round2)::

    .venv/bin/python tests/adversarial_round2.py [--out OUT] [--physics]

Exit 0 when every verdict is the expected one (wrong plans exit 1, twins exit 0), 1 otherwise.  The motions
are built here (IK in a pybullet world of this script's own, the grasp frames of mrgc.geometry.grasps) and
checked for collisions here too; nothing of the validator's code is used.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pybullet as pb
import pybullet_data

import mrgc
from mrgc.geometry.grasps import finger_opening, grasp_transform

ROOT = Path(__file__).resolve().parents[1]
PROBLEM = ROOT / "domains" / "packaging" / "pa5.mrg"
BASE = ROOT / "tests" / "data" / "round2" / "pa5.json"
LIFT = 0.004  # a stacked box is released this far above its support's top (inside the 10 mm band)


def trans(x: float, y: float, z: float) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def rot(axis: int, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    t = np.eye(4)
    t[i, i], t[i, j], t[j, i], t[j, j] = c, -s, s, c
    return t


def to_pq(t: np.ndarray) -> tuple[list[float], list[float]]:
    r = t[:3, :3]
    w = math.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    return list(t[:3, 3]), [x, y, z, w]


def from_pq(p: Any, q: Any) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = np.array(pb.getMatrixFromQuaternion(q)).reshape(3, 3)
    t[:3, 3] = p
    return t


def pose_of(p: Any) -> np.ndarray:
    return trans(p.x, p.y, p.z) @ rot(2, math.radians(p.yaw))


class World:
    """pa5 in a pybullet client of its own: the arms from pybullet_data, boxes as convex hulls."""

    LO = np.array([-2.9671, -1.8326, -2.9671, -3.1416, -2.9671, -0.0873, -2.9671])
    HI = np.array([2.9671, 1.8326, 2.9671, 0.0, 2.9671, 3.8223, 2.9671])

    def __init__(self, plan: dict[str, Any]) -> None:
        self.problem = mrgc.load_problem(str(PROBLEM))
        self.cid = pb.connect(pb.DIRECT)
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=self.cid)
        self.kind = self.problem.domain.robot_kinds[0]
        self.arms = {}
        for r in self.problem.robots:
            p, q = to_pq(pose_of(r.base))
            self.arms[r.name] = pb.loadURDF(self.kind.urdf, p, q, useFixedBase=True, physicsClientId=self.cid)
            self.set_q(r.name, self.kind.home)
        self.bodies: dict[str, int] = {}
        self.pose: dict[str, np.ndarray] = {}
        self.shape: dict[str, Any] = {}
        for b in (*self.problem.movable, *self.problem.fixed):
            h = (b.shape.sx / 2, b.shape.sy / 2, b.shape.sz / 2)
            v = [[i * h[0], j * h[1], k * h[2]] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)]
            s = pb.createCollisionShape(pb.GEOM_MESH, vertices=v, physicsClientId=self.cid)
            self.bodies[b.name] = pb.createMultiBody(0, s, physicsClientId=self.cid)
            self.shape[b.name] = b.shape
            self.set_pose(b.name, pose_of(b.pose))
        for st in plan["steps"]:
            for a in st["actions"]:
                self.set_pose(a["object"], np.array(a["place_pose"]))

    def set_pose(self, name: str, t: np.ndarray) -> None:
        self.pose[name] = np.array(t)
        p, q = to_pq(t)
        pb.resetBasePositionAndOrientation(self.bodies[name], p, q, physicsClientId=self.cid)

    def set_q(self, robot: str, q: Any, opening: float = 0.08) -> None:
        for j in range(7):
            pb.resetJointState(self.arms[robot], j, float(q[j]), physicsClientId=self.cid)
        for j in (9, 10):
            pb.resetJointState(self.arms[robot], j, opening / 2, physicsClientId=self.cid)

    def tool(self, robot: str, q: Any) -> np.ndarray:
        self.set_q(robot, q)
        st = pb.getLinkState(self.arms[robot], 8, computeForwardKinematics=True, physicsClientId=self.cid)
        return from_pq(st[4], st[5]) @ trans(0, 0, self.kind.tcp.z)

    def grasp(self, obj: str, name: str) -> np.ndarray:
        return grasp_transform(self.problem.grasp_specs[name], self.shape[obj])

    def ik(self, robot: str, target: np.ndarray, seed: Any, restarts: int = 12) -> list[float]:
        """Damped least squares on a numerical Jacobian, clamped to the joint limits; restarts near the seed,
        the solution nearest to it kept."""
        rng = np.random.default_rng(0)
        found = []
        for r in range(restarts):
            q = np.array(seed, float) if r == 0 else np.clip(seed + rng.normal(0, 0.3 + 0.1 * r, 7), self.LO, self.HI)
            q = self._solve(robot, target, q)
            if q is not None:
                if r == 0:
                    return list(q)
                found.append(q)
            if found and r >= 8:
                break
        if not found:
            raise RuntimeError(f"no IK solution for {robot}")
        return list(min(found, key=lambda v: float(np.abs(v - np.asarray(seed)).max())))

    def _error(self, t: np.ndarray, target: np.ndarray) -> np.ndarray:
        r = target[:3, :3] @ t[:3, :3].T
        ang = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2
        return np.concatenate([target[:3, 3] - t[:3, 3], ang])

    def _solve(self, robot: str, target: np.ndarray, q: np.ndarray) -> np.ndarray | None:
        for _ in range(300):
            t = self.tool(robot, q)
            e = self._error(t, target)
            if np.linalg.norm(e[:3]) < 1e-4 and np.linalg.norm(e[3:]) < 1e-4:
                return q
            jac = np.zeros((6, 7))
            for j in range(7):
                d = np.zeros(7)
                d[j] = 1e-6
                jac[:, j] = -(self._error(self.tool(robot, q + d), t)) / 1e-6
            dq = jac.T @ np.linalg.solve(jac @ jac.T + 4e-4 * np.eye(6), e)
            dq *= min(1.0, 0.2 / max(1e-12, float(np.abs(dq).max())))
            q = np.clip(q + dq, self.LO, self.HI)
        return None

    def walk(
        self, robot: str, q0: Any, poses: list[np.ndarray], step: float = 0.01, keep: int = 4
    ) -> list[list[float]]:
        """A joint path from q0 through the tool poses (straight lines, rotations slerped), IK in small steps."""
        out, q, t0, n_done = [list(q0)], list(q0), self.tool(robot, q0), 0
        for t1 in poses:
            n = max(1, math.ceil(np.linalg.norm(t1[:3, 3] - t0[:3, 3]) / step), math.ceil(self._angle(t0, t1) / 0.05))
            for i in range(1, n + 1):
                q = self.ik(robot, _between(t0, t1, i / n), q)
                n_done += 1
                if n_done % keep == 0:
                    out.append(q)
            if out[-1] is not q:
                out.append(q)
            t0 = t1
        return out

    @staticmethod
    def _angle(a: np.ndarray, b: np.ndarray) -> float:
        c = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2
        return math.acos(max(-1.0, min(1.0, c)))

    def approach(self, robot: str, q_pre: Any, tool: np.ndarray) -> list[list[float]]:
        """Five configurations from the pre-grasp (0.08 m back along the tool's z) in to ``tool``."""
        out = [list(q_pre)]
        for i in range(1, 5):
            out.append(self.walk(robot, out[-1], [tool @ trans(0, 0, -0.08 * (1 - i / 4))], step=0.005)[-1])
        return out

    def clearance(
        self, robot: str, configs: list[list[float]], held: str | None, in_tool: np.ndarray, opening: float
    ) -> float:
        """The smallest distance (1 mm mesh margins added back) between the arm with what it holds and every
        box or the table along the straight joint-space segments (2 mm steps); the object it holds is only
        checked against the others, and the arm against the object it picks (``held`` None) not at all."""
        worst = 1.0
        for a, b in zip(configs, configs[1:]):
            a, b = np.asarray(a), np.asarray(b)
            n = max(1, math.ceil(float(np.abs(b - a).max()) / 0.002))
            for k in range(n + 1):
                q = a + (b - a) * k / n
                if held:
                    self.set_pose(held, self.tool(robot, q) @ in_tool)
                self.set_q(robot, q, opening)
                worst = min(worst, self._distance(robot, held))
        return worst

    def _distance(self, robot: str, held: str | None) -> float:
        d = 1.0
        for name, body in self.bodies.items():
            if name == held:
                continue
            for link in range(-1, 11):
                if link == -1 and name == "table":
                    continue  # the base is bolted to the table
                for p in pb.getClosestPoints(self.arms[robot], body, 0.05, link, -1, physicsClientId=self.cid):
                    d = min(d, p[8] + 0.002)
            if held:
                for p in pb.getClosestPoints(self.bodies[held], body, 0.05, physicsClientId=self.cid):
                    d = min(d, p[8] + 0.002)
        return d


def _between(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    _, qa = to_pq(a)
    _, qb = to_pq(b)
    qa_, qb_ = np.array(qa), np.array(qb)
    if qa_ @ qb_ < 0:
        qb_ = -qb_
    om = math.acos(min(1.0, float(qa_ @ qb_)))
    q = qa_ if om < 1e-9 else (math.sin((1 - s) * om) * qa_ + math.sin(s * om) * qb_) / math.sin(om)
    t = from_pq((1 - s) * a[:3, 3] + s * b[:3, 3], list(q / np.linalg.norm(q)))
    return t


def add_move(
    plan: dict[str, Any], obj: str, grasp: str, place: np.ndarray, via: Callable[..., Any] | None = None
) -> str:
    """Append a step: r1 takes ``obj`` with ``grasp`` to pose ``place`` (lift 15 cm, across, down; or through
    the tool poses ``via(world, grasp frame)`` returns); return what my own collision check finds."""
    w = World(plan)
    g = w.grasp(obj, grasp)
    tool0, tool1 = w.pose[obj] @ g, place @ g
    pre = w.ik("r1", tool0 @ trans(0, 0, -0.08), [0.0, 0.2, 0.0, -2.2, 0.0, 2.4, 0.785], restarts=30)
    pick = w.approach("r1", pre, tool0)
    ways = via(w, g) if via else [trans(0, 0, 0.15) @ tool0, trans(0, 0, 0.15) @ tool1 @ trans(0, 0, -0.08)]
    transfer = w.walk("r1", pick[-1], [*ways, tool1 @ trans(0, 0, -0.08)])
    put = w.approach("r1", transfer[-1], tool1)
    opening = finger_opening(w.problem.grasp_specs[grasp], w.shape[obj])
    in_tool = np.linalg.inv(g)
    clear = min(
        w.clearance("r1", pick[:-1], None, in_tool, opening), w.clearance("r1", transfer + put, obj, in_tool, opening)
    )
    act = {
        "kind": "pick-place",
        "object": obj,
        "region": "start",
        "pick_robot": "r1",
        "place_robot": "r1",
        "pick_grasp": grasp,
        "place_grasp": grasp,
        "place_pose": place.tolist(),
        "configs": {"pick": pick, "place": put},
        "paths": {"to-place": transfer},
    }
    plan["steps"].append({"index": len(plan["steps"]) + 1, "actions": [act], "waiting": ["r2"]})
    plan["makespan"] = len(plan["steps"])
    plan["motion_cost"] = sum(len(s["actions"]) for s in plan["steps"])
    pb.disconnect(w.cid)
    return f"{obj}: closest {clear * 1e3:.1f} mm"


def on_top(plan: dict[str, Any], obj: str, on: str, dx: float) -> np.ndarray:
    w = World(plan)
    t = trans(dx, 0, w.shape[on].sz / 2 + w.shape[obj].sz / 2 + LIFT) @ w.pose[on]
    pb.disconnect(w.cid)
    return t


def tower(plan: dict[str, Any], dx: float) -> str:
    a = add_move(plan, "o2", "top", on_top(plan, "o2", "o1", dx))
    b = add_move(plan, "o3", "top", on_top(plan, "o3", "o2", dx))
    return f"{a}; {b}"


def excursion(plan: dict[str, Any], load: bool) -> str:
    """o1 out 8 cm, up 6 cm, tipped 60 degrees and back, in again (with o2 centred on it when ``load``)."""
    a = add_move(plan, "o2", "top", on_top(plan, "o2", "o1", 0.0)) if load else ""

    def via(w: World, g: np.ndarray) -> list[np.ndarray]:
        out = trans(-0.08, 0, 0) @ w.pose["o1"]
        up = trans(0, 0, 0.06) @ out
        return [out @ g, up @ g, up @ rot(0, 1.05) @ g, up @ g, out @ g]

    w = World(plan)
    home = w.pose["o1"].copy()
    pb.disconnect(w.cid)
    b = add_move(plan, "o1", "side-x-", home, via)
    return f"{a}; {b}" if a else b


def validate(path: Path) -> tuple[int, str]:
    mrgc_cli = Path(sys.executable).with_name("mrgc")
    r = subprocess.run([str(mrgc_cli), "validate", str(PROBLEM), str(path)], capture_output=True, text=True, cwd=ROOT)
    lines = (r.stdout + r.stderr).strip().splitlines()
    return r.returncode, (lines[0] if lines else "")


def drop_test(plan: dict[str, Any], driven: str | None = None) -> str:
    """Every box where the plan leaves it, simulated 2 s with gravity (friction 0.6); with ``driven``, that box
    first follows the last step's gripper motion (o1 on a constraint, 5 cm/s) before it is left alone."""
    w = World({"steps": plan["steps"][:-1]} if driven else plan)
    path: list[np.ndarray] = []
    if driven:
        a = plan["steps"][-1]["actions"][0]
        in_tool = np.linalg.inv(w.grasp(driven, a["pick_grasp"]))
        qs = a["paths"]["to-place"] + a["configs"]["place"]
        for q0, q1 in zip(qs, qs[1:]):
            q0, q1 = np.asarray(q0), np.asarray(q1)
            n = max(1, math.ceil(float(np.abs(q1 - q0).max()) / 0.002))
            path += [w.tool("r1", q0 + (q1 - q0) * k / n) @ in_tool for k in range(n)]
        path.append(w.tool("r1", qs[-1]) @ in_tool)
    cid = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    pb.setTimeStep(1e-3, physicsClientId=cid)
    ids = {}
    for name, shape in w.shape.items():
        h = [shape.sx / 2, shape.sy / 2, shape.sz / 2]
        s = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=h, physicsClientId=cid)
        mass = 0.0 if name == "table" else 1000 * shape.sx * shape.sy * shape.sz
        p, q = to_pq(path[0] if name == driven else w.pose[name])
        ids[name] = pb.createMultiBody(mass, s, basePosition=p, baseOrientation=q, physicsClientId=cid)
        pb.changeDynamics(ids[name], -1, lateralFriction=0.6, physicsClientId=cid)
    start = {n: np.array(pb.getBasePositionAndOrientation(b, physicsClientId=cid)[0]) for n, b in ids.items()}
    if driven:
        p, q = to_pq(path[0])
        con = pb.createConstraint(
            ids[driven], -1, -1, -1, pb.JOINT_FIXED, [0, 0, 0], [0, 0, 0], p, [0, 0, 0, 1], q, physicsClientId=cid
        )
        for t0, t1 in zip(path, path[1:]):
            n = max(1, int(np.linalg.norm(t1[:3, 3] - t0[:3, 3]) / 5e-5))
            for k in range(1, n + 1):
                p, q = to_pq(t1 if k == n else t0 + (t1 - t0) * k / n)
                pb.changeConstraint(con, p, q, maxForce=500, physicsClientId=cid)
                pb.stepSimulation(physicsClientId=cid)
        pb.removeConstraint(con, physicsClientId=cid)
    for _ in range(2000):
        pb.stepSimulation(physicsClientId=cid)
    out = []
    for n in ("o1", "o2", "o3"):
        p, q = pb.getBasePositionAndOrientation(ids[n], physicsClientId=cid)
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, from_pq(p, q)[2, 2]))))
        out.append(f"{n} drops {(start[n][2] - p[2]) * 1e3:.0f} mm, tilts {tilt:.0f} deg")
    pb.disconnect(cid)
    pb.disconnect(w.cid)
    return "; ".join(out)


A21 = "o2 on o1 and o3 on o2, each 3 mm inside the edge below: o2+o3 4.6 mm beyond o1's edge"
A31 = "o2 centred on o1; in one step o1 pulled out from under it, tipped and pushed back"
CASES: list[tuple[str, bool, str, Callable[[dict[str, Any]], str], str | None]] = [
    ("A21", True, A21, lambda p: tower(p, 0.017), None),
    ("H13", False, "the same tower, centred", lambda p: tower(p, 0.0), None),
    ("A31", True, A31, lambda p: excursion(p, True), "o1"),
    ("A31-twin", False, "the same excursion of o1 with nothing on it", lambda p: excursion(p, False), "o1"),
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="/tmp/adversarial_round2")
    ap.add_argument("--physics", action="store_true", help="also simulate the boxes with gravity")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    base = json.loads(BASE.read_text())
    bad = 0
    for name, wrong, what, build, driven in CASES:
        plan = copy.deepcopy(base)
        mine = build(plan)
        path = Path(args.out) / f"{name}.json"
        path.write_text(json.dumps(plan))
        rc, first = validate(path)
        ok = (rc == 1) if wrong else (rc == 0)
        bad += not ok
        expect = "reject" if wrong else "accept"
        print(f"{name}: {what}\n  expected {expect}, mrgc validate exit {rc}: {first}\n  my check: {mine}")
        if args.physics:
            print(f"  dynamics: {drop_test(plan, driven)}")
        print(f"  {'ok' if ok else 'WRONG VERDICT'}  ({path})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
