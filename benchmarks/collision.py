"""Collision query costs through the public CollisionWorld API and the kernel (coal underneath), in microseconds.

    python benchmarks/collision.py                 # default: 20 scene boxes, links 1/7/14, 2000 calls per row
    python benchmarks/collision.py --boxes 50 --calls 5000 --seed 1

Scene: ``--boxes`` boxes (4–12 cm sides, random yaw) on a 1.2 × 0.8 m table, plus the table.  Robot links:
convex hulls of 60 random points in a 10 × 10 × 20 cm ellipsoid, laid out as a chain of ``L`` links from
a base beside the table at random joint angles, so some configurations reach into the objects and some
do not.  Each row reports the median and 90th percentile of the per-call time over batches of calls (each
batch runs the same query ``--repeat`` times; the per-call time is the batch time / repeat).

The kernel rows (issue 22): a batch of 50 configurations of a 7-link chain against the scene in one query
(``batch_collides``, per configuration), and two swept volumes (300 configurations × 7 links each, the size
of a transfer) against each other, as a whole (``posed_collide``) and sample by sample (``grouped_collide``).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from typing import Callable

import numpy as np

from mrgc.geometry.collision import (
    CollisionShape,
    CollisionWorld,
    ConvexHull,
    Posed,
    collision_shape,
    grouped_collide,
    posed_collide,
)
from mrgc.geometry.transforms import rot_z, rpy_matrix, translation
from mrgc.language.model import Box


def make_scene(n_boxes: int, rng: np.random.Generator) -> CollisionWorld:
    world = CollisionWorld()
    world.add("table", Box(1.2, 0.8, 0.05), translation(0.6, 0.0, -0.025), "fixed")
    for i in range(n_boxes):
        sx, sy, sz = rng.uniform(0.04, 0.12, 3)
        t = rot_z(rng.uniform(-math.pi, math.pi))
        t[:3, 3] = (rng.uniform(0.05, 1.15), rng.uniform(-0.35, 0.35), sz / 2 + 0.001)
        world.add(f"o{i}", Box(sx, sy, sz), t, "movable")
    return world


def make_links(n: int, rng: np.random.Generator) -> list[CollisionShape]:
    links = []
    for _ in range(n):
        pts = rng.normal(size=(60, 3))
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        links.append(collision_shape(ConvexHull(pts * np.array([0.05, 0.05, 0.1]))))
    return links


def chain(n: int, rng: np.random.Generator) -> np.ndarray:
    """Link transforms (n, 4, 4) of a random-angle chain of 0.2 m links from a base at (0.6, -0.5, 0.2)."""
    t = translation(0.6, -0.5, 0.2)
    out = []
    for _ in range(n):
        r = np.eye(4)
        r[:3, :3] = rpy_matrix(*rng.uniform(-1.2, 1.2, 3))
        t = t @ r
        out.append(t @ translation(0, 0, 0.1))
        t = t @ translation(0, 0, 0.2)
    return np.array(out)


def measure(fn: Callable[[int], object], batches: int, repeat: int) -> tuple[float, float]:
    """(median, p90) per-call microseconds; ``fn(i)`` runs query number ``i``."""
    per_call = []
    for b in range(batches):
        t0 = time.perf_counter()
        for _ in range(repeat):
            fn(b)
        per_call.append((time.perf_counter() - t0) / repeat * 1e6)
    per_call.sort()
    return statistics.median(per_call), per_call[int(0.9 * (len(per_call) - 1))]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--boxes", type=int, default=20)
    ap.add_argument("--calls", type=int, default=2000, help="calls per row (batches × repeat)")
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    batches = max(1, args.calls // args.repeat)
    rng = np.random.default_rng(args.seed)
    world = make_scene(args.boxes, rng)
    rows: list[tuple[str, float, float, str]] = []

    def row(name: str, fn: Callable[[int], object], note: str = "") -> None:
        med, p90 = measure(fn, batches, args.repeat)
        rows.append((name, med, p90, note))

    # pairs: a world of two objects, one overlapping pair
    pair = CollisionWorld()
    pair.add("a", Box(0.3, 0.3, 0.3), translation(0, 0, 0))
    pair.add("b", Box(0.3, 0.3, 0.3), translation(0.2, 0.01, 0.02))
    row("box–box `collides` (overlapping)", lambda i: pair.collides("a"))
    pair.set_transform("b", translation(0.31, 0.01, 0.02))
    row("box–box `collides` (AABBs overlap, shapes do not)", lambda i: pair.collides("a"))
    pair.set_transform("b", translation(1.0, 0, 0))
    row("box–box `collides` (far apart)", lambda i: pair.collides("a"))
    hull = make_links(1, rng)[0]
    row("hull–box `probe_collides` (overlapping)", lambda i: pair.probe_collides([(hull, translation(0.1, 0, 0))]))
    rotations = [rot_z(a) @ translation(0.1, 0, 0) for a in np.linspace(0, math.pi, batches)]
    row("hull–box `probe_collides` (new pose each call)", lambda i: pair.probe_collides([(hull, rotations[i])]))
    row("`set_transform` (one object)", lambda i: pair.set_transform("b", rotations[i]))

    # link hulls against the scene
    for n_links in (1, 7, 14):
        links = make_links(n_links, rng)
        configs = [chain(n_links, rng) for _ in range(batches)]
        probes = [list(zip(links, c)) for c in configs]
        hits = sum(bool(world.probe_collides(p)) for p in probes)
        note = f"{hits}/{batches} configurations collide"
        row(
            f"{n_links} link hulls vs {args.boxes} boxes + table: `probe_collides`",
            lambda i, probes=probes: world.probe_collides(probes[i]),
            note,
        )
        row(
            f"{n_links} link hulls vs {args.boxes} boxes + table: `probe_hits`",
            lambda i, probes=probes: world.probe_hits(probes[i]),
            note,
        )
        row(
            f"{n_links} link hulls vs {args.boxes} boxes + table: `batch_collides`",
            lambda i, links=links, configs=configs: world.batch_collides(links, configs[i]),
            note,
        )

    # swept volume: 30 configurations of a 7-link chain
    links = make_links(7, rng)
    sweeps = [np.array([chain(7, np.random.default_rng(1000 * i + k)) for k in range(30)]) for i in range(batches)]
    row("sweep of 30 configurations × 7 links: `batch_hits`", lambda i: world.batch_hits(links, sweeps[i]), "")

    # the kernel: configurations in batches, and volumes against volumes
    batch = [np.array([chain(7, np.random.default_rng(77 * i + k)) for k in range(50)]) for i in range(batches)]
    med, p90 = measure(lambda i: world.batch_collides(links, batch[i], against="movable"), batches, args.repeat)
    rows.append(
        (f"kernel: 50 configurations × 7 links vs {args.boxes} boxes, per configuration", med / 50, p90 / 50, "")
    )
    far = translation(0.0, 0.05, 0.0)
    volumes = [
        (
            Posed.batch(links, np.array([chain(7, np.random.default_rng(5 * i + k)) for k in range(300)])),
            Posed.batch(links, far @ np.array([chain(7, np.random.default_rng(5 * i + k + 1)) for k in range(300)])),
        )
        for i in range(min(batches, 20))
    ]
    starts, diagonal = np.arange(0, 2101, 7), np.repeat(np.arange(300), 2).reshape(-1, 2)
    row(
        "kernel: volume vs volume, 2 × 2,100 pieces, `posed_collide`",
        lambda i: posed_collide(*volumes[i % len(volumes)]),
    )
    row(
        "kernel: the same, sample by sample, `grouped_collide`",
        lambda i: grouped_collide(volumes[i % len(volumes)][0], starts, volumes[i % len(volumes)][1], starts, diagonal),
    )

    # colliding_with: which of the 20 objects does one object hit
    names = world.names("movable")
    row(
        f"`colliding_with` one object vs {args.boxes} objects + table",
        lambda i: world.colliding_with(names[i % len(names)]),
    )
    row(
        "`colliding_with` one object vs movables, ignoring 3",
        lambda i: world.colliding_with(names[i % len(names)], against="movable", ignore=names[:3]),
    )

    print(
        f"# Collision query costs\n\n`{' '.join([sys.executable.rsplit('/', 1)[-1], *sys.argv])}`  "
        f"(boxes={args.boxes}, {batches} batches × {args.repeat} calls, seed {args.seed})\n"
    )
    print("| query | median µs | p90 µs | note |\n|---|---:|---:|---|")
    for name, med, p90, note in rows:
        print(f"| {name} | {med:.1f} | {p90:.1f} | {note} |")


if __name__ == "__main__":
    main()
