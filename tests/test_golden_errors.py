"""Golden diagnostics: every error code has an input that triggers it and the exact text mrgc prints.

Set MRGC_UPDATE_GOLDEN=1 to rewrite the .out files after an intended change of wording.
"""

from __future__ import annotations

import os
import runpy
from pathlib import Path

import pytest
from support import ROOT

from mrgc import cli
from mrgc.language.codes import CODES, WARNINGS
from mrgc.language.loader import MAX_BYTES

GOLDEN = ROOT / "tests" / "golden" / "errors"
CASES = sorted(p.stem for p in GOLDEN.glob("E*.mrg"))
WARNING_CASES = sorted(p.stem for p in GOLDEN.glob("W*.mrg"))


def test_every_code_has_a_golden_file() -> None:
    special = {"E001", "E002"}  # made on the fly below: a missing file, an oversized one
    assert sorted(set(CODES) - special) == sorted(CASES + WARNING_CASES)
    assert set(WARNING_CASES) == WARNINGS


def command_of(path: Path) -> str:
    """The command a golden file is checked with: ``check``, unless its first line says ``; command: mrgc
    facts`` (diagnostics that need the robots' models)."""
    first = path.read_bytes().split(b"\n", 1)[0].decode("utf-8", errors="replace")
    return first.split("; command: mrgc ", 1)[1].strip() if first.startswith("; command: mrgc ") else "check"


@pytest.mark.parametrize("code", CASES + WARNING_CASES)
def test_golden_diagnostics(code: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """Exactly the golden text; an error makes the command exit 2, a warning (W###) leaves the file accepted."""
    monkeypatch.chdir(ROOT)
    rel = f"tests/golden/errors/{code}.mrg"
    severity = "warning" if code in WARNINGS else "error"
    assert cli.main([command_of(ROOT / rel), rel]) == (0 if severity == "warning" else 2)
    err = capsys.readouterr().err
    codes = {line.split("[", 1)[1][:4] for line in err.splitlines() if "error[" in line or "warning[" in line}
    assert codes == {code}, f"{rel} should trigger exactly {code}, got {sorted(codes)}"
    first = err.splitlines()[0]
    assert first.count(":") >= 3 and f"{severity}[{code}]" in first
    out = GOLDEN / f"{code}.out"
    if os.environ.get("MRGC_UPDATE_GOLDEN"):
        out.write_text(err, encoding="utf-8")
    assert err == out.read_text(encoding="utf-8")


def test_missing_file_e001(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert cli.main(["check", str(tmp_path / "nope.mrg")]) == 2
    assert "error[E001]: cannot read" in capsys.readouterr().err


def test_oversized_file_e002(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    big = tmp_path / "huge.mrg"
    big.write_bytes(b"; padding\n" * (MAX_BYTES // 10 + 1))
    assert cli.main(["check", str(big)]) == 2
    assert "error[E002]" in capsys.readouterr().err


def test_usage_error_e000(capsys: pytest.CaptureFixture[str]) -> None:
    """Exactly what docs/errors.md shows for E000 (its example had check's usage line, which argparse never
    prints there: the unknown option is the top parser's)."""
    assert cli.main(["check", "--frobnicate", "x.mrg"]) == 2
    special = runpy.run_path(str(ROOT / "docs" / "build_errors_doc.py"), run_name="not_main")["SPECIAL"]
    command, shown = special["E000"]
    assert command == "mrgc check --frobnicate x.mrg" and capsys.readouterr().err.strip() == shown


def test_internal_errors_are_one_line(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    def boom(path: str, **options: object) -> None:
        raise KeyError("x")

    monkeypatch.setattr("mrgc.language.loader.parse_file", boom)
    assert cli.main(["check", str(tmp_path / "a.mrg")]) == 70
    err = capsys.readouterr().err
    assert err.startswith("mrgc: internal error[E070]: KeyError") and "Traceback" not in err


def test_errors_doc_is_current(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr("sys.argv", ["build_errors_doc.py", "--check"])
    result = runpy.run_path(str(ROOT / "docs" / "build_errors_doc.py"), run_name="not_main")
    assert result["main"]() == 0
