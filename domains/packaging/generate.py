"""Write the generated packaging benchmark problems (PA-n): n boxes packed in a grid in front of r1.

    python domains/packaging/generate.py            # rewrites pa5.mrg, pa10.mrg, pa18-4arms.mrg here

The layout (mrgc.generate.packaging.grid_benchmark) follows the paper's packaging domain: arms around a
table, objects packed tightly in a start region (neighbours block each other's side grasps), three bins
reachable by different arms, so some goals need a handover at h1.  Deterministic: the same n and seed give
the same file.  Random packaging problems nobody tuned: ``mrgc generate packaging`` (docs/generators.md).
"""

from __future__ import annotations

import os

from mrgc.generate.packaging import SHIPPED, grid_benchmark

HERE = os.path.dirname(os.path.abspath(__file__))


def main() -> None:
    """Write the shipped grid benchmarks into this folder."""
    for name, n, arms, seed in SHIPPED:
        with open(os.path.join(HERE, f"{name}.mrg"), "w", encoding="utf-8") as fh:
            fh.write(grid_benchmark(name, n, arms, seed))


if __name__ == "__main__":
    main()
