"""Issue 27 measured on scenes nobody tuned: the conformance scenes of tests/test_arms.py (xArm6, Panda, a
6-DOF arm from a URDF written here) with the objects, the arms' spacing and the handover height drawn at
random, planned with a few seeds; each plan is replayed by the validator.

    .venv/bin/python benchmarks/arms.py [--variants 6] [--time-limit 120] [--out results.jsonl]

``--arms issue`` draws issue 27's own scene instead (two xArm6 at ±0.45 m, three 4 cm boxes, two goals).
Prints one row per run (arm, variant, seed, facts, status, validated, makespan, handover, CPU s, wall s) and
a summary per arm; CPU seconds count the process and its phase-1 workers.
"""

from __future__ import annotations

import argparse
import json
import re
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_arms  # noqa: E402  (the conformance scenes and the 6-DOF arm's URDF)

import mrgc  # noqa: E402

#: the arms, their spacing (± x of the bases) and how far in front of a1 its objects stand, as the test has them
ARMS = {"xarm6": (0.55, 0.28), "panda": (0.7, 0.4), "arm6": (0.6, 0.3)}


def cpu() -> float:
    """CPU seconds of this process and its finished children."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def variant(arm: str, k: int) -> str:
    """Conformance scene ``k`` of ``arm``: the spacing ± 3 cm, the two objects anywhere in the start region's
    inner 16 × 24 cm (apart by 7 cm), o1 turned by up to 45°, the handover point 0.25-0.35 m high."""
    rng = np.random.default_rng(2700 + k)
    base, front = ARMS[arm]
    base += float(rng.uniform(-0.03, 0.03))
    if arm == "xarm6":
        test_arms.KINDS.setdefault("xarm6", _xarm_kind())
    text = test_arms.scene(arm, round(base, 3), front)
    near = -round(base, 3) + front
    while True:
        a = rng.uniform([-0.06, -0.1], [0.06, 0.1], size=(2, 2))
        if np.linalg.norm(a[0] - a[1]) > 0.07:
            break
    yaw = float(rng.uniform(-45, 45))
    height = float(rng.uniform(0.25, 0.35))
    text = re.sub(
        r"\(o1 :shape \(box 0.04 0.04 0.12\) :pose \([^)]*\)",
        f"(o1 :shape (box 0.04 0.04 0.12) :pose ({near + a[0, 0]:.3f} {a[0, 1]:.3f} 0.06 {yaw:.0f})",
        text,
    )
    text = re.sub(
        r"\(o2 :shape \(box 0.04 0.04 0.04\) :pose \([^)]*\)",
        f"(o2 :shape (box 0.04 0.04 0.04) :pose ({near + a[1, 0]:.3f} {a[1, 1]:.3f} 0.02 0)",
        text,
    )
    return text.replace("(h1 :position (0 0 0.3))", f"(h1 :position (0 0 {height:.2f}))")


def issue_scene(k: int) -> str:
    """Issue 27's own scene, drawn: two xArm6 at x = ±0.45 standing on the table (z = 0), three 4 cm boxes
    0.25-0.4 m in front of a1 (|y| <= 0.12, 6 cm apart), a bin in front of a2, a handover point; two goals."""
    rng = np.random.default_rng(2750 + k)
    while True:
        xy = np.column_stack([rng.uniform(-0.2, -0.05, 3), rng.uniform(-0.12, 0.12, 3)])
        if min(np.linalg.norm(xy[i] - xy[j]) for i in range(3) for j in range(i)) > 0.06:
            break
    boxes = "\n".join(
        f"    (o{i + 1} :shape (box 0.04 0.04 0.04) :pose ({x:.3f} {y:.3f} 0.02 {rng.uniform(-45, 45):.0f}))"
        for i, (x, y) in enumerate(xy)
    )
    kind = _xarm_kind()
    return f"""(define (domain xarm)
  (:requirements :handover)
  {kind}
  (:grasps top top-x side-x+ side-x- side-y+ side-y-))

(define (problem issue27)
  (:domain xarm)
  (:robots
    (a1 :kind xarm6 :base (-0.45 0 0 0))
    (a2 :kind xarm6 :base (0.45 0 0 180)))
  (:fixed
    (table :shape (box 1.4 1 0.05) :pose (0 0 -0.025 0)))
  (:regions
    (start :shape (box 0.2 0.34 0.2) :pose (-0.125 0 0.1 0))
    (bin :shape (box 0.16 0.16 0.2) :pose (0.2 {rng.uniform(-0.15, 0.15):.2f} 0.1 0)))
  (:movable
{boxes})
  (:handover-points
    (h1 :position (0 0 0.3)))
  (:goal (and (in-region o1 bin) (in-region o2 bin))))
"""


def _xarm_kind() -> str:
    example = test_arms.docs_example()
    found = re.search(r"\(:robot-kind xarm6.*?:gripper-opening 0.085\)", example, re.S)
    assert found is not None
    return re.sub(r" ;[^\n]*", "", found.group(0))


def run(arm: str, k: int, seed: int, time_limit: float, folder: Path) -> dict[str, object]:
    """One plan of variant ``k`` of ``arm``, validated."""
    path = folder / f"{arm}-{k}.mrg"
    (folder / "arm6.urdf").write_text(test_arms.arm6_urdf(), encoding="utf-8")
    path.write_text(issue_scene(k) if arm == "issue" else variant(arm, k), encoding="utf-8")
    c0, t0 = cpu(), time.perf_counter()
    problem = mrgc.parse_file(path).problem()
    facts = mrgc.compute_facts(problem, seed=seed)
    plan = mrgc.plan(problem, facts=facts.facts, seed=seed, time_limit=time_limit)
    valid = None
    if plan.steps:
        plan_file = folder / f"{arm}-{k}-{seed}.plan.json"
        plan_file.write_text(plan.dumps(), encoding="utf-8")
        valid = mrgc.validate(problem, plan_file).ok
    summary = plan.summary()
    return {
        "arm": arm,
        "variant": k,
        "seed": seed,
        "facts": len(facts.facts),
        "status": str(plan.status),
        "valid": valid,
        "makespan": len(plan.steps),
        "handover": any("->" in line for line in summary),
        "cpu": round(cpu() - c0, 2),
        "wall": round(time.perf_counter() - t0, 2),
        "why": [line for line in summary if line.startswith(("why", "  "))][:3] if str(plan.status) != "solved" else [],
    }


def main() -> int:
    """Run the study and print its rows and summary."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", type=int, default=6)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--arms", nargs="+", default=list(ARMS), help="xarm6, panda, arm6, or issue (issue 27's scene)")
    ap.add_argument("--out")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for arm in args.arms:
            for k in range(args.variants):
                for seed in args.seeds:
                    row = run(arm, k, seed, args.time_limit, Path(tmp))
                    rows.append(row)
                    print(json.dumps(row), flush=True)
    if args.out:
        Path(args.out).write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    for arm in args.arms:
        mine = [r for r in rows if r["arm"] == arm]
        ok = [r for r in mine if r["status"] == "solved" and r["valid"]]
        cpus = sorted(float(r["cpu"]) for r in mine)  # type: ignore[arg-type]
        print(
            f"{arm}: {len(ok)}/{len(mine)} solved and valid, {sum(bool(r['handover']) for r in ok)} by a handover; "
            f"CPU s median {cpus[len(cpus) // 2]:.1f}, max {cpus[-1]:.1f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
