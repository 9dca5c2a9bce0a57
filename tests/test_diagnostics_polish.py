"""Diagnostics that point where the mistake is: a missing ")" at the "(" it leaves open, predicates suggested
by meaning, ``fmt --check`` / ``--diff`` with a unified diff, and a plan validated against any file holding
its problem (the problem's content digest, not the file's bytes)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

import mrgc
from mrgc import cli
from mrgc.errors import Diagnostic
from mrgc.language.digest import problem_digest
from mrgc.language.model import PREDICATE_WORDS, PREDICATES
from mrgc.language.parens import unclosed_paren
from mrgc.language.parser import parse_text
from mrgc.language.suggest import by_meaning

FILES = sorted(p for p in (ROOT / "domains").glob("*/*.mrg")) + sorted((ROOT / "docs" / "tutorial").glob("*.mrg"))
CHAIN3 = ROOT / "domains" / "symbolic" / "chain-3.mrg"


# ---------------------------------------------------------------- an unclosed "(" is reported where it opens
def _pairs(text: str) -> dict[int, tuple[int, list[int]]]:
    """Offset of each ")" -> (offset of its "(", offsets of the "(" enclosing that one), outside comments
    and strings."""
    out: dict[int, tuple[int, list[int]]] = {}
    stack: list[int] = []
    i = 0
    while i < len(text):
        ch = text[i]
        if ch == ";":
            j = text.find("\n", i)
            i = len(text) if j < 0 else j
            continue
        if ch == '"':
            i += 1
            while text[i] != '"':
                i += 2 if text[i] == "\\" else 1
        elif ch == "(":
            stack.append(i)
        elif ch == ")":
            out[i] = (stack.pop(), list(stack))
        i += 1
    return out


def _offset(text: str, line: int, column: int) -> int:
    return sum(len(s) + 1 for s in text.split("\n")[: line - 1]) + column - 1


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(FILES), st.data())
def test_a_removed_closing_parenthesis_is_reported_at_its_opening_one(path: Path, data: st.DataObject) -> None:
    """Take a shipped file, delete one ")": the error is E102 (the file ends) or E104 (the next form starts)
    and points at the "(" that lost its ")" or at one enclosing it (the two are the same mistake when
    several forms close on one line)."""
    text = path.read_text(encoding="utf-8")
    pairs = _pairs(text)
    close = data.draw(st.sampled_from(sorted(pairs)))
    opener, ancestors = pairs[close]
    broken = text[:close] + text[close + 1 :]
    found = parse_text(broken, "x.mrg")
    assert isinstance(found, Diagnostic), "a file with a ')' less parsed"
    assert found.code in ("E102", "E104"), found.headline()
    assert found.span is not None
    assert _offset(broken, found.span.line, found.span.column) in (opener, *ancestors), found.headline()


CASES = {
    "atom": (
        "  (:init (in-region o1 a)\n         (reachable-pick o1 top r1\n  (:goal (in-region o1 b)))\n",
        "E104",
        (8, 10),
        "'(reachable-pick' is not closed before '(:goal' on line 9",
    ),
    "section": (
        "  (:init (in-region o1 a)\n  (:goal (in-region o1 b)))\n",
        "E104",
        (7, 3),
        "'(:init' is not closed before '(:goal' on line 8",
    ),
    "end of file": (
        "  (:init (in-region o1 a))\n  (:goal (in-region o1 b))\n",
        "E102",
        (2, 1),
        "'(define' is never closed: the file ends inside it",
    ),
}
HEAD = (
    "(define (domain d) (:requirements :symbolic) (:grasps top))\n(define (problem p)\n  (:domain d)\n"
    "  (:robots r1)\n  (:movable o1)\n  (:regions a b)\n"
)


@pytest.mark.parametrize("case", CASES)
def test_unclosed_parentheses_are_located_at_the_open_one(case: str) -> None:
    tail, code, (line, column), message = CASES[case]
    found = parse_text(HEAD + tail, "p.mrg")
    assert isinstance(found, Diagnostic) and found.code == code and found.message == message
    assert found.span is not None
    assert (found.span.line, found.span.column) == (line, column)
    assert found.notes  # where the parser stopped


def test_a_balanced_file_keeps_its_plain_syntax_error() -> None:
    found = parse_text(HEAD + "  (:init (in-region o1 a) (:goal))\n  (:goal (in-region o1 b)))\n", "p.mrg")
    assert isinstance(found, Diagnostic) and found.code in ("E101", "E103")
    assert unclosed_paren(HEAD + ")", 0) is None


def test_parentheses_in_comments_and_strings_do_not_count() -> None:
    text = '; (((\n(define (domain d) (:robot-kind k :urdf "a(b.urdf" :base fixed :end-effector "h")\n'
    paren = unclosed_paren(text, len(text))
    assert paren is not None and (paren.line, paren.column, paren.word) == (2, 1, "define")


# ---------------------------------------------------------------- predicates suggested by meaning
@pytest.mark.parametrize(
    ("word", "hint"),
    [
        ("handover", "'enable-goal-handover'"),
        ("Hand_Over", "'enable-goal-handover'"),
        ("reachable", "'reachable-pick' or 'reachable-place'"),
        ("goal-place", "'occludes-goal-place'"),
        ("in", "'in-region'"),
        ("blocks", "'occludes-pick' or 'occludes-goal-place'"),
        ("reachable-pik", "'reachable-pick'"),  # by spelling when the meaning gives nothing
        ("relay", "'enable-relay'"),
        ("regrasp", "'enable-relay'"),
        ("set-down", "'enable-relay'"),
    ],
)
def test_unknown_predicates_are_suggested_by_meaning(word: str, hint: str) -> None:
    assert by_meaning(word, PREDICATES, PREDICATE_WORDS) == f" (did you mean {hint}?)"
    assert by_meaning("frobnicate", PREDICATES, PREDICATE_WORDS) == ""


def test_every_meaning_names_real_predicates() -> None:
    assert all(set(targets) <= set(PREDICATES) for targets in PREDICATE_WORDS.values())


# ---------------------------------------------------------------- the relay fact (enable-relay)
RELAY = ROOT / "tests" / "data" / "relay.mrg"
RELAY_FACTS = """(define (domain d) (:grasps top side))
(define (problem p)
  (:domain d) (:robots r1 r2) (:movable o1 o2) (:regions start mid goal)
  (:init (in-region o1 start) (in-region o2 start)
    FACTS)
  (:goal (in-region o1 goal)))
"""


def _relay_diagnostics(facts: str) -> list[Diagnostic]:
    with pytest.raises(mrgc.InputError) as exc:
        mrgc.parse_string(RELAY_FACTS.replace("FACTS", facts), "p.mrg")
    return list(exc.value.diagnostics)


def test_relay_facts_are_read_with_their_argument_sorts() -> None:
    problem = mrgc.parse_file(str(RELAY)).problem(None)
    assert PREDICATES["enable-relay"] == ("movable", "surface", "grasp", "grasp", "robot", "robot")
    relays = sorted(f.args for f in problem.init if f.predicate == "enable-relay")
    assert relays == [("o1", "mid", "top", "side", "r1", "r1"), ("o1", "mid", "top", "side", "r1", "r2")]
    # a regrasp (one robot, two grasps) and an object without a goal are accepted
    text = RELAY_FACTS.replace("FACTS", "(enable-relay o1 mid top side r1 r1) (enable-relay o2 goal top top r1 r2)")
    assert len(mrgc.parse_string(text).problem(None).init) == 4
    # a relay on the top of a fixed object (a table between the arms, no region there)
    text = RELAY_FACTS.replace("(:regions", "(:fixed table) (:regions").replace(
        "FACTS", "(enable-relay o1 table top side r1 r2)"
    )
    assert ("o1", "table", "top", "side", "r1", "r2") in [f.args for f in mrgc.parse_string(text).problem(None).init]


@pytest.mark.parametrize(
    ("fact", "code", "column", "message"),
    [
        (
            "(enable-relay o1 mid top top r2 r2)",
            "E229",
            5,
            "'enable-relay' relates robot 'r2' with grasp 'top' to itself: a relay back to the same robot must "
            "change the grasp",
        ),
        (
            "(enable-relay o1 goal top side r1 r2)",
            "E217",
            5,
            "'enable-relay' sets 'o1' down in its goal region 'goal': a relay is a stop on the way to the goal, "
            "in another region",
        ),
        (
            "(enable-relay o1 r1 top side r1 r2)",
            "E216",
            22,
            "'r1' is a robot, but 'enable-relay' expects a region or fixed object",
        ),
        ("(enable-relay o1 nowhere top side r1 r2)", "E212", 22, "undeclared region or fixed object 'nowhere'"),
        ("(enable-relay o1 mid top grip r1 r2)", "E213", 30, "undeclared grasp 'grip'"),
        ("(enable-relay o1 mid top side r1)", "E221", 5, "'enable-relay' takes 6 arguments"),
        ("(occludes-relay o1 o1 mid top side r1 r2)", "E229", 5, "'occludes-relay' relates object 'o1' to itself"),
        (
            "(occludes-relay o2 o1 mid top top r2 r2)",
            "E229",
            5,
            "'occludes-relay' relates robot 'r2' with grasp 'top' to itself: a relay back to the same robot",
        ),
        ("(occludes-relay o2 o1 mid top side r1)", "E221", 5, "'occludes-relay' takes 7 arguments"),
        ("(occludes-relay r1 o1 mid top side r1 r2)", "E216", 21, "'r1' is a robot, but 'occludes-relay' expects"),
    ],
)
def test_relay_facts_are_checked_where_they_are_written(fact: str, code: str, column: int, message: str) -> None:
    (d,) = _relay_diagnostics(fact)
    assert (d.code, d.span.line, d.span.column) == (code, 5, column)
    assert message in d.message


def test_relay_grasps_must_be_the_objects() -> None:
    text = RELAY_FACTS.replace("(:movable o1 o2)", "(:movable (o1 :grasps (top)) o2)")
    with pytest.raises(mrgc.InputError) as exc:
        mrgc.parse_string(text.replace("FACTS", "(enable-relay o1 mid top side r1 r2)"), "p.mrg")
    assert [(d.code, d.message) for d in exc.value.diagnostics] == [
        ("E227", "grasp 'side' is not among the grasps of 'o1' (top)")
    ]


def test_fmt_keeps_relay_facts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "relay.mrg"
    squeezed = RELAY.read_text(encoding="utf-8").replace("\n    (enable-relay", " (enable-relay")
    assert squeezed.count("\n    (enable-relay") == 0 and squeezed != RELAY.read_text(encoding="utf-8")
    path.write_text(squeezed, encoding="utf-8")
    assert cli.main(["fmt", "--write", str(path)]) == 0
    capsys.readouterr()
    assert path.read_text(encoding="utf-8") == RELAY.read_text(encoding="utf-8")
    before, after = (mrgc.parse_file(str(p)).problem(None) for p in (RELAY, path))
    assert after.init == before.init and problem_digest(after) == problem_digest(before)


# ---------------------------------------------------------------- fmt --check and --diff
UGLY = "(define (domain d)   (:requirements :symbolic)\n (:grasps top))"


def test_fmt_check_prints_a_unified_diff(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "d.mrg"
    path.write_text(UGLY, encoding="utf-8")
    assert cli.main(["fmt", "--check", str(path)]) == 1
    out, err = capsys.readouterr()
    assert err.strip() == f"{path}: would reformat"
    assert out.startswith(f"--- {path}\n+++ {path}\n@@ ") and "\n-(define (domain d)   (:requirements" in out
    assert "\\ No newline at end of file" in out
    canonical = tmp_path / "canonical.mrg"
    canonical.write_text(UGLY, encoding="utf-8")
    assert cli.main(["fmt", "--write", str(canonical)]) == 0
    capsys.readouterr()
    assert cli.main(["fmt", "--check", str(canonical)]) == 0
    assert capsys.readouterr() == ("", "")


def test_fmt_diff_is_a_patch_that_formats_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "d.mrg"
    path.write_text(UGLY, encoding="utf-8")
    assert cli.main(["fmt", "--diff", str(path), str(CHAIN3)]) == 0  # a canonical file adds nothing
    patch = capsys.readouterr().out
    assert patch.count("+++ ") == 1
    subprocess.run(["patch", "-s", "-p0", str(path)], input=patch, text=True, check=True, cwd=tmp_path)
    assert cli.main(["fmt", "--check", str(path)]) == 0


# ---------------------------------------------------------------- a plan is for a problem, not for file bytes
TINY = """(define (domain cell)
  (:robot-kind panda :urdf "franka_panda/panda.urdf" :base fixed :end-effector "panda_hand"
    :tcp (0 0 0.105 0) :home (0 -0.785 0 -2.356 0 1.571 0.785))
  (:grasps top))

(define (problem one-box)
  (:domain cell)
  (:robots (r1 :kind panda :base (0 -0.6 0 90)))
  (:fixed (table :shape (box 1.2 1.2 0.05) :pose (0 0 -0.025 0)))
  (:regions
    (start :shape (box 0.2 0.2 0.3) :pose (-0.15 0 0.15 0))
    (goal :shape (box 0.2 0.2 0.3) :pose (0.15 0 0.15 0)))
  (:movable (box1 :shape (box 0.04 0.04 0.1) :pose (-0.15 0 0.05 0)))
  (:goal (in-region box1 goal)))
"""


def test_a_plan_made_from_the_facts_file_validates_against_the_problem_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    problem, facts, plan = tmp_path / "tiny.mrg", tmp_path / "out" / "tiny.facts.mrg", tmp_path / "plan.json"
    problem.write_text(TINY, encoding="utf-8")
    facts.parent.mkdir()
    assert cli.main(["facts", str(problem), "-o", str(facts), "--workers", "1"]) == 0
    assert cli.main(["plan", str(facts), "-o", str(plan)]) == 0
    capsys.readouterr()
    doc = json.loads(plan.read_text(encoding="utf-8"))
    assert doc["problem_file"] == str(facts) and doc["status"] == "solved"
    assert doc["problem_digest"] == problem_digest(mrgc.load_problem(problem))
    for target in (problem, facts):
        assert cli.main(["validate", str(target), str(plan)]) == 0, capsys.readouterr()
        assert capsys.readouterr().out.startswith("valid: ")
    moved = tmp_path / "moved.mrg"  # another problem: the box starts elsewhere
    moved.write_text(TINY.replace(":pose (-0.15 0 0.05 0)", ":pose (-0.12 0 0.05 0)"), encoding="utf-8")
    assert cli.main(["validate", str(moved), str(plan)]) == 1
    assert "[problem-changed]" in capsys.readouterr().out


def test_a_reformatted_problem_keeps_its_plans_and_edited_facts_do_not(tmp_path: Path) -> None:
    plan = mrgc.plan(CHAIN3, time_limit=30)
    assert plan.status == mrgc.PlanStatus.SOLVED
    text = CHAIN3.read_text(encoding="utf-8")
    domain = (CHAIN3.parent / "domain.mrg").read_text(encoding="utf-8")
    other = tmp_path / "chain-3.mrg"
    other.write_text("; moved, with its domain inlined and one more comment\n" + domain + "\n" + text, encoding="utf-8")
    assert mrgc.validate(other, plan).ok
    edited = tmp_path / "edited.mrg"
    edited.write_text(domain + "\n" + text.replace("(:init", "(:init (reachable-pick o2 side r2)", 1), encoding="utf-8")
    report = mrgc.validate(edited, plan)
    assert not report.ok and [v.code for v in report.violations] == ["problem-changed"]


def test_a_plan_without_a_digest_still_compares_file_bytes(tmp_path: Path) -> None:
    """Plans of earlier versions have no problem_digest: their sha256 is of the file they were made from."""
    doc = json.loads(mrgc.plan(CHAIN3, time_limit=30).dumps())
    del doc["problem_digest"]
    assert mrgc.validate(CHAIN3, doc).ok
    copy = tmp_path / "chain-3.mrg"
    copy.write_text("; another comment\n" + CHAIN3.read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "domain.mrg").write_text((CHAIN3.parent / "domain.mrg").read_text(encoding="utf-8"), encoding="utf-8")
    assert [v.code for v in mrgc.validate(copy, doc).violations] == ["problem-changed"]
