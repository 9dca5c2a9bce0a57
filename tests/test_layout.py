"""The package's shape: what is packaged, who may import whom, and which heavy libraries load when."""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SKIP_DIRS = {".venv", ".git", "tests", "docs", "benchmarks", "build", "dist", "domains", ".hypothesis"}

#: DESIGN.md section 3: layer -> layers it may import (besides itself)
MAY_IMPORT: dict[str, set[str]] = {
    "errors": set(),
    "language": {"errors"},
    "compiler": {"errors", "language"},
    "backends": {"errors", "language", "compiler", "signals"},
    "geometry": {"errors", "language", "workers"},
    "planner": {"errors", "language", "compiler", "backends", "geometry"},
    "generate": {"errors", "language"},
    "render": {"errors", "language", "compiler", "backends", "geometry", "planner", "outputs", "workers"},
    "signals": set(),
    "workers": {"errors", "signals"},
    "outputs": {"errors", "signals"},
    "limits": {"errors"},
    "cli": {"*"},
    "api": {"*"},
    # test helpers for users and plug-ins: the conformance kit compiles through planner/skeletons.py
    "testing": {"errors", "language", "compiler", "backends", "planner", "signals"},  # the public API the CLI wraps: it calls into every layer, nothing imports it but cli and __init__
    "bench": {"*"},  # studies drive the command line: bench imports everything, nothing imports bench but cli
    "__init__": {"*"},
}

#: heavy library -> the one module allowed to import it (filled in as backends/geometry modules land)
HEAVY = {
    "highspy": "backends/highs.py",
    "z3": "backends/z3opt.py",
    "pysmt": "backends/pysmt_opt.py",
    "ortools": "backends/cpsat.py",
    "coal": "geometry/collision.py",
    "pybullet": "geometry/bullet.py",
    "pybullet_data": "geometry/bullet.py",
    "ompl": "geometry/motion.py",
    "imageio": "render/video.py",
    "imageio_ffmpeg": "render/video.py",
    "PIL": "render/picture.py",
    "matplotlib": "render/gantt.py",
    "viser": "render/html.py",
    "ray": "bench/ray_executor.py",
    "jsonschema": "planner/plan_reader.py",
}
#: heavy libraries a second module may import too: pybullet's renderer draws the pictures
ALSO_HEAVY = {"render/raster.py": {"pybullet"}, "bench/figures.py": {"matplotlib"}}


def code_files() -> list[Path]:
    out = []
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in SKIP_DIRS or rel.parts[0].startswith("."):
            continue
        out.append(path)
    return sorted(out)


def layer(rel: Path) -> str:
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def imports(path: Path) -> list[tuple[str, bool]]:
    """(module, at top level?) for every import in the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = set(map(id, tree.body))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, id(node) in top) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.append((node.module, id(node) in top))
    return out


def test_every_code_folder_is_packaged() -> None:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    packages = set(config["tool"]["setuptools"]["packages"])
    found = {"mrgc"} | {
        "mrgc." + ".".join(p.parent.relative_to(ROOT).parts)
        for p in ROOT.rglob("__init__.py")
        if p.parent != ROOT and p.relative_to(ROOT).parts[0] not in SKIP_DIRS
    }
    assert found == packages


def test_the_user_layout_exists() -> None:
    for name in ["pyproject.toml", "language", "compiler", "backends", "geometry", "planner", "domains",
                 "benchmarks", "tests", "docs", "README.md", "py.typed"]:
        assert (ROOT / name).exists(), name
    assert not (ROOT / "tests" / "__init__.py").exists()


@pytest.mark.parametrize("path", code_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_import_rules(path: Path) -> None:
    rel = path.relative_to(ROOT)
    me = layer(rel)
    allowed = MAY_IMPORT[me]
    for module, _ in imports(path):
        parts = module.split(".")
        if parts[0] == "mrgc":
            if len(parts) == 1:
                assert me in {"cli", "__init__"} or module == "mrgc", f"{rel} imports the mrgc root"
                continue
            target = parts[1]
            assert target != "cli" or me in {"__init__", "bench"}, f"{rel} imports the CLI"
            assert target != "bench" or me in {"cli", "bench"}, f"{rel} imports mrgc.bench (only the CLI may)"
            assert "*" in allowed or target == me or target in allowed, f"{rel} ({me}) may not import {module}"
        if parts[0] in HEAVY:
            assert str(rel) == HEAVY[parts[0]] or parts[0] in ALSO_HEAVY.get(str(rel), set()), \
                f"{rel} imports {parts[0]}; only {HEAVY[parts[0]]} may"


@pytest.mark.parametrize("path", code_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_heavy_libraries_are_imported_lazily(path: Path) -> None:
    rel = path.relative_to(ROOT)
    for module, top_level in imports(path):
        if module.split(".")[0] in HEAVY:
            assert not top_level, f"{rel} imports {module} at module level"


def test_importing_mrgc_loads_no_heavy_library() -> None:
    code = ("import sys, mrgc, mrgc.cli, mrgc.language; "
            "print(sorted(m for m in %r if m in sys.modules))" % sorted(HEAVY))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_skeleton_oracle_shares_no_code_with_the_compiler() -> None:
    """mrgc.testing.oracle reads the task graph's data types and nothing else of mrgc.compiler."""
    mrgc_imports = {m for m, _ in imports(ROOT / "testing" / "oracle.py") if m.startswith("mrgc.")}
    assert mrgc_imports == {"mrgc.compiler.task_graph", "mrgc.language.model"}
    source = (ROOT / "testing" / "oracle.py").read_text(encoding="utf-8")
    assert "from mrgc.compiler.task_graph import Action, TaskGraph\n" in source


def test_importing_mrgc_testing_loads_neither_hypothesis_nor_a_solver() -> None:
    code = ("import sys, mrgc.testing, mrgc.testing.oracle, mrgc.testing.conformance; "
            "print(sorted(m for m in %r if m in sys.modules))" % sorted([*HEAVY, "hypothesis"]))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
