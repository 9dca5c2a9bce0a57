"""Every shipped .mrg file checks cleanly, is canonically formatted, and formatting is idempotent."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from support import ROOT

from mrgc import parse_file
from mrgc.language.parser import parse_text
from mrgc.language.printer import format_source

FILES = sorted((ROOT / "domains").rglob("*.mrg"))


@pytest.mark.parametrize(
    "folder,domain", [("symbolic", "abstract"), ("packaging", "packaging"), ("box-moving", "box-moving")]
)
def test_each_domain_folder_holds_its_domain_and_problems_of_it(folder: str, domain: str) -> None:
    """domains/FOLDER/domain.mrg defines the domain, and every other file there holds problems of it."""
    files = sorted((ROOT / "domains" / folder).glob("*.mrg"))
    assert [d.name for d in parse_file(ROOT / "domains" / folder / "domain.mrg").domains] == [domain]
    problems = [p for f in files if f.name != "domain.mrg" for p in parse_file(f).problems]
    assert len(problems) >= 3 and {p.domain.name for p in problems} == {domain}


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_shipped_file_checks(path: Path) -> None:
    mf = parse_file(path)
    if path.name != "domain.mrg":
        assert mf.problems, f"{path} defines no problem"


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_shipped_file_is_canonical_and_fmt_is_idempotent(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    tree = parse_text(text, str(path))
    assert not isinstance(tree, Exception) and hasattr(tree, "definitions")
    once = format_source(tree, text)
    assert once == text, f"{path} is not canonically formatted: run mrgc fmt --write"
    again = parse_text(once, str(path))
    assert format_source(again, once) == once  # type: ignore[arg-type]
    assert again == tree


SYMBOLIC = [p for p in FILES if p.name != "domain.mrg" and "symbolic" in p.parts]


@pytest.mark.parametrize("path", SYMBOLIC, ids=lambda p: p.name)
def test_symbolic_problems_state_their_expected_optimum(path: Path) -> None:
    head = path.read_text(encoding="utf-8")
    assert re.search(r"^; expect: (infeasible|makespan=\d+ moved=\d+)$", head, re.M), path


def doc_blocks() -> list[tuple[str, int, str]]:
    out = []
    for doc in sorted((ROOT / "docs").glob("*.md")):
        text = doc.read_text(encoding="utf-8")
        for m in re.finditer(r"```lisp\n(.*?)```", text, re.S):
            body = m.group(1)
            if body.lstrip().startswith("(define"):
                out.append((doc.name, text[: m.start()].count("\n") + 1, body))
    return out


@pytest.mark.parametrize(
    "doc,line,body",
    [b for b in doc_blocks() if b[0] != "errors.md"],
    ids=lambda v: str(v) if isinstance(v, (str, int)) else "",
)
def test_doc_examples_check(doc: str, line: int, body: str, tmp_path: Path) -> None:
    path = tmp_path / "example.mrg"
    path.write_text(body, encoding="utf-8")
    mf = parse_file(path)  # raises InputError with the diagnostics if the example is wrong
    assert mf.domains or mf.problems
