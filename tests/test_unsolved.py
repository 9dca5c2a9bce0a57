"""Tools that say so when they should (issue 24): ``render`` and ``validate`` of a plan whose status is not
``solved`` warn and exit 1 (``render --force`` draws it all the same); ``check`` of a problem whose domain is
in another file names that domain."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import ROOT, run_cli

INFEASIBLE = ROOT / "domains" / "symbolic" / "infeasible.mrg"


@pytest.fixture(scope="module")
def unsolved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from mrgc import cli

    path = tmp_path_factory.mktemp("unsolved") / "infeasible.plan.json"
    assert cli.main(["plan", str(INFEASIBLE), "-o", str(path)]) == 1  # infeasible: written, status infeasible
    assert '"status": "infeasible"' in path.read_text()
    return path


def test_render_of_an_unsolved_plan_warns_and_draws_nothing(
    unsolved: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "gantt.svg"
    code, stdout, err = run_cli(capsys, "render", INFEASIBLE, unsolved, "-o", out)
    assert code == 1 and not out.exists() and stdout == ""
    assert f"{unsolved}: warning: the plan's status is 'infeasible', not 'solved': mrgc plan found no plan" in err
    assert "nothing drawn (--force draws infeasible.plan.json)" in err
    code, stdout, err = run_cli(capsys, "render", INFEASIBLE, unsolved, "-o", out, "--force")
    assert code == 1 and out.stat().st_size > 1000 and "Gantt chart of 0 steps" in stdout and "warning:" in err


def test_validate_of_an_unsolved_plan_says_so(unsolved: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, stdout, _ = run_cli(capsys, "validate", INFEASIBLE, unsolved)
    assert code == 1 and "the plan's status is 'infeasible'" in stdout and "[status]" in stdout


def test_check_names_the_domain_it_used_from_another_file(capsys: pytest.CaptureFixture[str]) -> None:
    code, stdout, _ = run_cli(capsys, "check", INFEASIBLE, ROOT / "domains" / "symbolic" / "domain.mrg")
    assert code == 0
    first, second = stdout.splitlines()
    assert ": ok: domain abstract from " in first  # the path as given, or relative to the current folder
    assert "domains/symbolic/domain.mrg; problem infeasible (symbolic:" in first
    assert "0 domains" not in first and second.endswith(": ok: 1 domain")
