"""CLI start-up: wall time of ``mrgc --help``, ``check``, ``compile`` and ``plan`` on a symbolic file.

    python benchmarks/startup.py                      # this checkout, 15 runs per command
    python benchmarks/startup.py --root /tmp/old-checkout --root . --runs 15   # before / after
    python benchmarks/startup.py --only cpsat          # the commands whose name holds "cpsat"

Each run is a fresh interpreter running the CLI (``from mrgc.cli import main``) with the checkout at
``--root`` first on the import path; with several roots their runs alternate, so a busy machine slows
them alike.  Bytecode is cached (``PYTHONPYCACHEPREFIX`` in a temporary folder, warmed by one run of each
command first), as in an installed package: without a cache every start compiles mrgc's sources again.
The table gives, per checkout, the median and the least wall time of each command, its median CPU time
(user + system, of the child process: less sensitive than wall time to other jobs on the machine, though
not immune), and the number of modules it imports (counted in an extra run).
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CHAIN3 = "domains/symbolic/chain-3.mrg"
COMMANDS = {
    "mrgc --help": ["--help"],
    "mrgc check chain-3.mrg": ["check", CHAIN3],
    "mrgc check pa5.mrg (geometric)": ["check", "domains/packaging/pa5.mrg"],
    "mrgc compile chain-3.mrg (cpsat)": ["compile", CHAIN3],
    "mrgc compile chain-3.mrg --backend mip": ["compile", CHAIN3, "--backend", "mip"],
    "mrgc compile chain-3.mrg --backend smt": ["compile", CHAIN3, "--backend", "smt"],
    "mrgc plan chain-3.mrg (cpsat)": ["plan", CHAIN3],
}
RUNNER = (
    "import sys; sys.path.insert(0, sys.argv[1]); del sys.argv[1]; "
    "from mrgc.cli import main; code = main(sys.argv[1:]); "
    "print(len(sys.modules), file=sys.stderr) if __import__('os').environ.get('COUNT') else None; "
    "sys.exit(code)"
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, action="append", help="a checkout to measure (repeatable; default: this one)")
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--only", default="", help="measure only the commands whose name holds this text")
    args = ap.parse_args()
    commands = {name: argv for name, argv in COMMANDS.items() if args.only in name}
    if not commands:
        ap.error(f"no command's name holds {args.only!r}: {', '.join(COMMANDS)}")
    roots = [r.resolve() for r in (args.root or [ROOT])]
    with tempfile.TemporaryDirectory() as tmp:
        links = []
        for k, root in enumerate(roots):  # each checkout importable as `mrgc`, with its own bytecode cache
            link = Path(tmp) / f"path{k}" / "mrgc"
            link.parent.mkdir()
            link.symlink_to(root)
            links.append(link)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}

        def run(k: int, argv: list[str], count: bool = False) -> tuple[float, float, str]:
            t0, c0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
            out = subprocess.run(
                [sys.executable, "-c", RUNNER, str(links[k].parent), *argv],
                cwd=roots[k],
                text=True,
                capture_output=True,
                env={**env, "PYTHONPYCACHEPREFIX": str(Path(tmp) / f"pyc{k}"), **({"COUNT": "1"} if count else {})},
            )
            seconds, c1 = time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
            if out.returncode != 0:
                raise SystemExit(f"mrgc {' '.join(argv)} failed ({out.returncode}): {out.stderr.strip()[-300:]}")
            return seconds, c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime, out.stderr

        for k in range(len(roots)):  # warm the bytecode caches
            for argv in commands.values():
                run(k, argv)
        print(
            f"{args.runs} runs per command and checkout, Python {sys.version.split()[0]}, load average "
            f"{os.getloadavg()[0]:.1f} at the start; median / least wall time in seconds, median CPU time "
            f"(user + system) in seconds, modules imported"
        )
        print()
        print("| command | " + " | ".join(str(r) for r in roots) + " |")
        print("| --- |" + " --- |" * len(roots))
        for name, argv in commands.items():
            times: list[list[float]] = [[] for _ in roots]
            cpu: list[list[float]] = [[] for _ in roots]
            for _ in range(args.runs):
                for k in range(len(roots)):
                    wall, used, _err = run(k, argv)
                    times[k].append(wall)
                    cpu[k].append(used)
            cells = []
            for k in range(len(roots)):
                modules = run(k, argv, count=True)[2].strip().splitlines()[-1]
                cells.append(
                    f"{statistics.median(times[k]):.3f} / {min(times[k]):.3f}, CPU "
                    f"{statistics.median(cpu[k]):.3f} ({modules})"
                )
            print(f"| `{name}` | " + " | ".join(cells) + " |", flush=True)
        print(f"\nload average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
