"""The README's Quick start is the contract with a new user and with CI."""

from __future__ import annotations

import re

from support import ROOT


def quick_start() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Quick start", 1)[1]
    blocks = re.findall(r"```[a-z]*\n(.*?)```", section.split("\n## ", 1)[0], re.S)
    assert len(blocks) == 1, "Quick start must hold exactly one fenced block"
    return [line for line in blocks[0].splitlines() if line.strip()]


def test_quick_start_has_two_one_line_commands() -> None:
    commands = quick_start()
    assert len(commands) == 2
    assert all(c.startswith("python3 -m venv .venv && ") for c in commands)
    assert "pytest" in commands[1] and "[test]" in commands[1]


def test_ci_runs_exactly_the_readme_test_command() -> None:
    script = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    lines = [ln for ln in script.splitlines() if ln.strip() and not ln.startswith("#")]
    assert quick_start()[1] in lines
    assert lines[-1] == quick_start()[1]


def test_the_test_command_installs_the_system_packages_the_tests_need() -> None:
    """A fresh machine has neither Chromium nor Graphviz: the test command itself installs them (one script,
    called by the README and so by .ci/run), before pytest runs."""
    command = quick_start()[1]
    assert "sh tests/system-packages.sh && " in command
    assert command.index("tests/system-packages.sh") < command.index("pytest")
    script = (ROOT / "tests" / "system-packages.sh").read_text(encoding="utf-8")
    assert "chromium" in script and "graphviz" in script and "apt-get install" in script


def test_quick_start_paths_exist() -> None:
    first = quick_start()[0]
    for path in re.findall(r"domains/[\w/*.-]+", first):
        assert list(ROOT.glob(path)), path
