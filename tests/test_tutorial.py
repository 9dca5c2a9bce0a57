"""docs/tutorial.md works as written: every ``mrgc`` command of its shell blocks runs, in order, on a copy of
docs/tutorial/, and succeeds with the file it names; every picture it shows is made by docs/make_pictures.py."""

from __future__ import annotations

import re
import runpy
import shlex
import shutil
from pathlib import Path

import pytest
from support import ROOT

from mrgc import cli

TUTORIAL = ROOT / "docs" / "tutorial.md"


def text_of() -> str:
    return TUTORIAL.read_text(encoding="utf-8")


def commands() -> list[list[str]]:
    text = text_of()
    blocks = re.findall(r"```sh\n(.*?)```", text, re.S)
    lines = [ln.strip() for b in blocks for ln in b.splitlines() if ln.strip()]
    assert lines and all(ln.startswith("mrgc ") for ln in lines), lines
    return [shlex.split(ln)[1:] for ln in lines]


def test_the_tutorials_files_are_its_code_blocks() -> None:
    """The .mrg text shown in the tutorial is the text of the shipped files (comments aside)."""
    text = TUTORIAL.read_text(encoding="utf-8")
    shown = re.findall(r"```lisp\n(.*?)```", text, re.S)

    def code(s: str) -> list[str]:
        return [ln.split(";")[0].rstrip() for ln in s.splitlines() if ln.split(";")[0].strip()]

    for name in ("domain.mrg", "two-arms.mrg"):
        body = code((ROOT / "docs" / "tutorial" / name).read_text(encoding="utf-8"))
        assert any(code(block) == body for block in shown), f"docs/tutorial/{name} differs from the tutorial's text"


def test_every_command_of_the_tutorial_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    work = tmp_path / "tutorial"
    shutil.copytree(ROOT / "docs" / "tutorial", work)
    monkeypatch.chdir(work)
    # each shell block followed by a text block: the output shown for the block's commands
    shown = {
        ln.strip(): out
        for block, out in re.findall(r"```sh\n(.*?)```\n\n```text\n(.*?)```", text_of(), re.S)
        for ln in block.splitlines()
    }
    for args in commands():
        code = cli.main(args)
        out = capsys.readouterr()
        assert code == 0, f"mrgc {' '.join(args)} exited {code}: {out.err}"
        line = "mrgc " + " ".join(args)
        if "--summary" in args:  # the output the page shows is what it prints (it said 34 facts, not 39)
            assert shown[line] == out.out, f"{line}: the tutorial shows\n{shown[line]}\nmrgc prints\n{out.out}"
        if "-o" in args:
            written = work / args[args.index("-o") + 1]
            assert written.is_file() and written.stat().st_size > 0, written
    assert (work / "two-arms.gif").stat().st_size > 10_000


def test_every_picture_is_made_by_the_pictures_script() -> None:
    text = TUTORIAL.read_text(encoding="utf-8") + (ROOT / "README.md").read_text(encoding="utf-8")
    shown = set(re.findall(r"\]\((?:docs/)?img/([\w.-]+)\)", text))
    assert shown
    script = runpy.run_path(str(ROOT / "docs" / "make_pictures.py"), run_name="not_main")
    made = set(script["PICTURES"])
    assert shown <= made, f"pictures not made by docs/make_pictures.py: {sorted(shown - made)}"
    for name in shown:
        path = ROOT / "docs" / "img" / name
        assert path.is_file() and path.stat().st_size > 1000, path
    assert (ROOT / "docs" / "img" / "pa5.gif").stat().st_size < script["MAX_README_GIF"]
