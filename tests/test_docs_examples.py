"""The Python examples of docs/api.md and docs/testing.md run as written: each page's ``python`` blocks in
order, in one namespace, from the repository root; a block whose first line is ``# file: NAME.py`` is a
test file, written out and run by pytest."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT

PAGES = ["api.md", "testing.md"]


def blocks(page: str) -> list[str]:
    text = (ROOT / "docs" / page).read_text(encoding="utf-8")
    found = re.findall(r"```python\n(.*?)```", text, re.S)
    assert found, f"docs/{page} has no python examples"
    return found


@pytest.mark.parametrize("page", PAGES)
def test_the_examples_run(page: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    namespace: dict[str, object] = {"__name__": f"docs_{page.replace('.', '_')}"}
    files = 0
    for k, code in enumerate(blocks(page), 1):
        first = code.splitlines()[0]
        if first.startswith("# file: "):
            files += 1
            path = tmp_path / first[len("# file: ") :].strip()
            path.write_text(code, encoding="utf-8")
            out = subprocess.run(
                [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(path)],
                capture_output=True,
                text=True,
                cwd=ROOT,
                timeout=600,
            )
            assert out.returncode == 0, f"docs/{page}, block {k} ({path.name}):\n{out.stdout[-3000:]}"
            assert re.search(r"\d+ passed", out.stdout) and "failed" not in out.stdout
            continue
        exec(compile(code, f"docs/{page}:block{k}", "exec"), namespace)  # noqa: S102 - the docs' own code
    assert files == (1 if page == "testing.md" else 0)
