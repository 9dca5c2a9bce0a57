"""Render speed: ``mrgc render`` of a plan as a GIF, time per frame and per step.

    python benchmarks/render.py domains/packaging/pa10.mrg pa10.plan.json
    python benchmarks/render.py domains/packaging/pa10.mrg pa10.plan.json --size 640x480 --repeat 3

For each size: the frames (10 fps), the drawing time per frame (pybullet's TinyRenderer, regions and caption;
wall clock, and CPU time of all processes: long replays are drawn by one process per core), the GIF encoding
time, and the whole command's wall and CPU time per step (a fresh ``mrgc render`` process, imports
included).  The best of ``--repeat`` runs (by wall time).  Prints a Markdown table; note the machine's load.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mrgc.language.loader import parse_file
from mrgc.render import outputs
from mrgc.render.picture import write_gif


def _cpu() -> float:
    """CPU seconds of this process and its finished children (drawing workers, the mrgc process)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("problem")
    ap.add_argument("plan")
    ap.add_argument("--size", action="append", help="WxH (default: 400x300 and 640x480)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    problem = parse_file(args.problem).problem(None)
    plan = json.loads(Path(args.plan).read_text())
    print(
        "| size | frames | steps | draw / frame (wall) | draw / frame (CPU) | GIF write "
        "| `mrgc render` / step (wall) | `mrgc render` / step (CPU) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for size in args.size or ["400x300", "640x480"]:
        w, h = (int(v) for v in size.split("x"))
        opts = outputs.Options(w, h)
        best = None
        for _ in range(args.repeat):
            world, timeline, frames, camera = outputs.replay_frames(problem, plan, opts, args.plan)
            c0 = _cpu()
            images, seconds = outputs.draw(world, frames, camera, opts)
            cpu = _cpu() - c0
            with tempfile.TemporaryDirectory() as tmp:
                t0 = time.perf_counter()
                write_gif(str(Path(tmp) / "x.gif"), images, opts.fps)
                gif = time.perf_counter() - t0
                t0, c0 = time.perf_counter(), _cpu()
                subprocess.run(
                    [
                        sys.executable,
                        "-m",
                        "mrgc.cli",
                        "render",
                        args.problem,
                        args.plan,
                        "-o",
                        str(Path(tmp) / "y.gif"),
                        "--size",
                        size,
                    ],
                    check=True,
                    capture_output=True,
                )
                command, command_cpu = time.perf_counter() - t0, _cpu() - c0
            steps = max(1, timeline.steps)
            row = (seconds / len(frames), cpu / len(frames), gif, command / steps, command_cpu / steps)
            best = row if best is None or row[3] < best[3] else best
            n, steps = len(frames), timeline.steps
        assert best is not None
        print(
            f"| {size} | {n} | {steps} | {best[0] * 1e3:.1f} ms | {best[1] * 1e3:.1f} ms | {best[2]:.2f} s | "
            f"{best[3]:.2f} s | {best[4]:.2f} s |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
