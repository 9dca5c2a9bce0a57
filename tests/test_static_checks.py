"""Style and types, checked by the tools with the configuration in pyproject.toml (docs/architecture.md,
"Style and type checks"): ruff's rules (with a complexity limit) and ruff's formatting on every Python file of
the repository, and mypy, strict, on the package.  They run here so that the one test command of the README
(and .ci/run) checks them too."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from support import ROOT


def run(*args: str, cwd: Path = ROOT, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


def test_ruff_finds_nothing() -> None:
    out = run("ruff", "check", "--no-cache", "--output-format", "concise", ".")
    assert out.returncode == 0, out.stdout + out.stderr


def test_ruff_format_changes_nothing() -> None:
    """Every Python file (and Python block of the Markdown docs) is as ``ruff format`` writes it, with the
    settings of pyproject.toml's [tool.ruff.format]."""
    out = run("ruff", "format", "--check", "--no-cache", ".")
    assert out.returncode == 0, out.stdout + out.stderr


def test_mypy_finds_nothing() -> None:
    """The package is the repository root (``package-dir = {"mrgc" = "."}``), which mypy cannot find through
    the editable install's import hook: a link named ``mrgc`` in the ignored .mypy_cache folder puts it on
    MYPYPATH under its name."""
    import os

    path = ROOT / ".mypy_cache" / "path"
    path.mkdir(parents=True, exist_ok=True)
    link = path / "mrgc"
    if not link.is_symlink():
        link.symlink_to(ROOT, target_is_directory=True)
    env = {**os.environ, "MYPYPATH": str(path)}
    out = run(
        "mypy",
        "--config-file",
        str(ROOT / "pyproject.toml"),
        "--cache-dir",
        str(ROOT / ".mypy_cache"),
        "-p",
        "mrgc",
        env=env,
    )
    assert out.returncode == 0, out.stdout + out.stderr
