"""The package's shape: what is packaged, who may import whom, and which heavy libraries load when."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from support import ROOT

SKIP_DIRS = {".venv", ".git", "tests", "docs", "benchmarks", "build", "dist", "domains", ".hypothesis"}

ARCHITECTURE = ROOT / "docs" / "architecture.md"


def layer_rules() -> dict[str, set[str]]:
    """docs/architecture.md's table "Layers and who may import whom": layer -> the layers it may import
    (besides itself and exits.py); ``{"*"}`` for "everything"."""
    text = ARCHITECTURE.read_text(encoding="utf-8").split("## Layers and who may import whom", 1)[1]
    rules: dict[str, set[str]] = {}
    for line in text.split("\n\n", 2)[1].splitlines()[2:]:
        names, may = (cell.strip() for cell in line.strip("|").split("|")[:2])
        if may.startswith("everything"):
            allowed = {"*"}
        elif may.startswith("nothing of mrgc"):
            allowed = set()
        else:
            allowed = {word.strip() for word in may.split(",")}
        for name in re.findall(r"`([\w_]+)(?:\.py|/)`", names):
            rules[name] = allowed
    return rules


#: the table of docs/architecture.md: layer -> layers it may import (besides itself and exits.py)
MAY_IMPORT = layer_rules()

#: docs/architecture.md, "Rules inside the layers": module -> the only mrgc modules it may import
ONLY_IMPORTS: dict[str, set[str]] = {
    # the pybullet client knows nothing of mrgc's kinematics (the references are mrgc.testing's)
    "geometry/bullet.py": {"mrgc.geometry.transforms"},
    # the conventions sit under everything else of the geometry layer
    "geometry/conventions.py": {"mrgc.geometry.transforms"},
}
#: the validator (docs/validator.md): every module of validator/.  Nothing of the planner, phase 1, grounding,
#: the compiler, coal, the numpy kinematics, OMPL or the lattice is reachable from it; it replays in pybullet
#: (validator/world.py) and reads plans through planfile/
VALIDATOR = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "validator").glob("*.py"))
#: packages no module of the validator may reach, and single modules of the layers it may import
NOT_FOR_THE_VALIDATOR_PACKAGES = ("mrgc.planner", "mrgc.compiler")
NOT_FOR_THE_VALIDATOR_MODULES = {
    "mrgc.geometry.grounding",
    # grounding's job modules (geometry/grounding.py's Grounder is made of them)
    "mrgc.geometry.placements",
    "mrgc.geometry.approaches",
    "mrgc.geometry.arm_paths",
    "mrgc.geometry.base_paths",
    "mrgc.geometry.volumes",
    "mrgc.geometry.step_world",
    "mrgc.geometry.predicates",
    "mrgc.geometry.relays",
    "mrgc.geometry.path_predicates",
    "mrgc.geometry.collision",
    "mrgc.geometry.fk",
    "mrgc.geometry.ik",
    "mrgc.geometry.ik_analytic",
    "mrgc.geometry.arm",
    "mrgc.geometry.motion",
    "mrgc.geometry.lattice",
    "mrgc.geometry.planar",
}


def not_for_the_validator(module: str) -> bool:
    """Whether the validator may not reach ``module`` (a planner or compiler module, or one listed)."""
    return module in NOT_FOR_THE_VALIDATOR_MODULES or any(
        module == p or module.startswith(p + ".") for p in NOT_FOR_THE_VALIDATOR_PACKAGES
    )


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
    "jsonschema": "planfile/reader.py",
    "geofikpy": "geometry/ik_analytic.py",
}
#: heavy libraries a second module may import too: pybullet's renderer draws the pictures
ALSO_HEAVY = {
    "render/raster.py": {"pybullet"},
    "render/reach.py": {"matplotlib"},
    "bench/figures.py": {"matplotlib"},
}


def code_files() -> list[Path]:
    out = []
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in SKIP_DIRS or rel.parts[0].startswith(".") or rel.parts[0].endswith(".egg-info"):
            continue
        out.append(path)
    return sorted(out)


def layer(rel: Path) -> str:
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def module_name(rel: Path) -> str:
    parts = list(rel.with_suffix("").parts)
    return ".".join(["mrgc", *(parts[:-1] if parts[-1] == "__init__" else parts)])


MODULES = {module_name(p.relative_to(ROOT)): p for p in code_files()}


def imports(path: Path, rel: Path | None = None) -> list[tuple[str, bool]]:
    """(module, at top level?) for every import in the file (at ``rel`` in the package, default: where it
    is): absolute and relative (resolved), at module level, inside functions and under ``if
    TYPE_CHECKING``; ``from package import module`` names the module."""
    rel = rel or path.relative_to(ROOT)
    package = module_name(rel) if path.name == "__init__.py" else module_name(rel).rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = set(map(id, tree.body))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, id(node) in top) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else []))
            for a in node.names:
                name = f"{base}.{a.name}"
                out.append((name if name in MODULES else base, id(node) in top))
    return out


def mrgc_imports(path: Path, rel: Path | None = None) -> set[str]:
    """The mrgc modules ``path`` imports (a name inside a module counts as its module)."""
    out = set()
    for module, _ in imports(path, rel):
        while module not in MODULES and "." in module:
            module = module.rpartition(".")[0]
        if module in MODULES and module != "mrgc":
            out.add(module)
    return out


def import_cycles() -> list[list[str]]:
    """The strongly connected components of more than one module of the import graph (Tarjan)."""
    graph = {m: mrgc_imports(p) - {m} for m, p in MODULES.items()}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop()
                scc.append(w)
                if w == v:
                    break
            if len(scc) > 1:
                out.append(sorted(scc))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


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
    for name in [
        "pyproject.toml",
        "language",
        "compiler",
        "backends",
        "geometry",
        "planner",
        "domains",
        "benchmarks",
        "tests",
        "docs",
        "README.md",
        "py.typed",
    ]:
        assert (ROOT / name).exists(), name
    assert not (ROOT / "tests" / "__init__.py").exists()


@pytest.mark.parametrize("path", code_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_import_rules(path: Path) -> None:
    rel = path.relative_to(ROOT)
    me = layer(rel)
    assert me in MAY_IMPORT, f"{rel}: layer {me!r} is not in the table of docs/architecture.md"
    allowed = MAY_IMPORT[me]
    for module, _ in imports(path):
        parts = module.split(".")
        if parts[0] == "mrgc":
            if len(parts) == 1:
                continue  # the package root: its __version__ and the lazy API names
            target = parts[1]
            assert target != "cli", f"{rel} imports the CLI (bench/ reads the commands' parser from commands.py)"
            assert target != "bench" or me in {"cli", "bench"}, f"{rel} imports mrgc.bench (only the CLI may)"
            assert target != "render" or me in {"cli", "render"}, f"{rel} imports mrgc.render (only the CLI may)"
            assert "*" in allowed or target in {me, "exits"} or target in allowed, (
                f"{rel} ({me}) may not import {module}"
            )
        if parts[0] in HEAVY:
            assert str(rel) == HEAVY[parts[0]] or parts[0] in ALSO_HEAVY.get(str(rel), set()), (
                f"{rel} imports {parts[0]}; only {HEAVY[parts[0]]} may"
            )
    if str(rel) in ONLY_IMPORTS:
        assert mrgc_imports(path) <= ONLY_IMPORTS[str(rel)], f"{rel} imports {mrgc_imports(path)}"
    if str(rel) in VALIDATOR:
        banned = {m for m in mrgc_imports(path) if not_for_the_validator(m)}
        assert not banned, f"the validator's {rel} imports {banned}"


def test_nothing_of_the_planner_is_reachable_from_the_validator() -> None:
    """The validator's independence, transitively: following every import (in functions and
    ``TYPE_CHECKING`` blocks too) from each module of validator/ reaches nothing of the planner or the
    compiler, nor phase 1, grounding, coal, the numpy kinematics, OMPL, the lattice or the planar planner model
    (a module it imports may not pull them in either)."""
    assert len(VALIDATOR) >= 12 and "validator/validate.py" in VALIDATOR
    seen: dict[str, list[str]] = {}  # module -> the import chain that reached it
    todo = [(module_name(Path(rel)), [rel]) for rel in VALIDATOR]
    while todo:
        module, chain = todo.pop()
        if module in seen:
            continue
        seen[module] = chain
        for nxt in sorted(mrgc_imports(MODULES[module]) - {module}):
            todo.append((nxt, [*chain, nxt]))
    reached = {m: seen[m] for m in sorted(seen) if not_for_the_validator(m)}
    assert not reached, "the validator reaches " + "; ".join(" -> ".join(c) for c in reached.values())


def test_no_module_imports_itself_through_others() -> None:
    """No import cycle between modules, counting every import (in functions and TYPE_CHECKING blocks too)."""
    assert import_cycles() == []


def test_the_import_reader_sees_relative_and_late_imports(tmp_path: Path) -> None:
    """The reader behind these rules: relative imports resolved, imports inside functions and
    TYPE_CHECKING blocks read, ``from package import module`` naming the module."""
    path = tmp_path / "probe.py"
    path.write_text(
        "from typing import TYPE_CHECKING\n"
        "from . import transforms\n"
        "from ..planner import search\n"
        "if TYPE_CHECKING:\n"
        "    from .scene import SceneSpec\n"
        "def f():\n"
        "    from mrgc.geometry.ik import solve_ik\n",
        encoding="utf-8",
    )
    rel = Path("geometry", "probe.py")
    assert mrgc_imports(path, rel) == {
        "mrgc.geometry.transforms",
        "mrgc.planner.search",
        "mrgc.geometry.scene",
        "mrgc.geometry.ik",
    }
    assert [top for m, top in imports(path, rel) if m.startswith("mrgc.")] == [True, True, False, False]


@pytest.mark.parametrize("path", code_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_heavy_libraries_are_imported_lazily(path: Path) -> None:
    rel = path.relative_to(ROOT)
    for module, top_level in imports(path):
        if module.split(".")[0] in HEAVY:
            assert not top_level, f"{rel} imports {module} at module level"


def test_importing_mrgc_loads_no_heavy_library() -> None:
    code = "import sys, mrgc, mrgc.cli, mrgc.language; print(sorted(m for m in %r if m in sys.modules))" % sorted(HEAVY)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_skeleton_oracle_shares_no_code_with_the_compiler() -> None:
    """mrgc.testing.oracle reads the task graph's data types and nothing else of mrgc.compiler."""
    mrgc_imports = {m for m, _ in imports(ROOT / "testing" / "oracle.py") if m.startswith("mrgc.")}
    assert mrgc_imports == {"mrgc.compiler.task_graph", "mrgc.language.model"}
    source = (ROOT / "testing" / "oracle.py").read_text(encoding="utf-8")
    assert "from mrgc.compiler.task_graph import Action, TaskGraph\n" in source


def test_importing_mrgc_testing_loads_neither_hypothesis_nor_a_solver() -> None:
    code = (
        "import sys, mrgc.testing, mrgc.testing.oracle, mrgc.testing.conformance; "
        "print(sorted(m for m in %r if m in sys.modules))" % sorted([*HEAVY, "hypothesis"])
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
