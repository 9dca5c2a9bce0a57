"""No input may crash or hang the front end.

Every input (hypothesis-generated text, token soups, random bytes, structurally valid but semantically random
files, and a list of nasty specific cases) goes through :func:`sweep`, which asserts that

- ``parse_string`` and ``parse_file`` either return or raise :class:`InputError` whose diagnostics all carry
  a catalogued code and, when located, a 1-based line and column;
- ``mrgc check FILE`` exits 0 (exactly when ``parse_file`` succeeds) or 2, without an internal error;
- ``mrgc fmt FILE`` exits 0 (exactly when the file decodes and parses) or 2, and what it prints parses and
  is a fixed point of formatting.

Each case runs under a wall-clock alarm so a hang fails the test instead of the run.
"""

from __future__ import annotations

import contextlib
import signal
import time
from pathlib import Path
from typing import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import run_cli

import mrgc
from mrgc.errors import Diagnostic, InputError
from mrgc.language import ast
from mrgc.language.codes import CODES
from mrgc.language.loader import MAX_BYTES, decode, parse_file, parse_string
from mrgc.language.model import PREDICATES
from mrgc.language.parser import parse_text
from mrgc.language.printer import format_source
from mrgc.language.props import SCHEMAS

SETTINGS = settings(
    max_examples=120,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


# ---------------------------------------------------------------- helpers
class TookTooLong(BaseException):
    """Raised by the alarm; a BaseException so that cli.main's `except Exception` cannot swallow it."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    def on_alarm(signum: int, frame: object) -> None:
        raise TookTooLong(f"took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def check_error(exc: InputError) -> set[str]:
    """Assert ``exc`` is well formed; return its codes."""
    assert exc.diagnostics, "an InputError must carry at least one diagnostic"
    for d in exc.diagnostics:
        assert isinstance(d, Diagnostic)
        assert d.code in CODES, d
        assert d.message and "\n" not in d.message, d
        if d.span is not None:
            assert d.span.line >= 1 and d.span.column >= 1, d
            assert (d.span.end_line, d.span.end_column) >= (d.span.line, d.span.column), d
    assert exc.render()  # drawing the carets must not fail either
    return {d.code for d in exc.diagnostics}


def try_load(fn, *args, **kwargs) -> tuple[mrgc.MrgFile | None, set[str]]:
    try:
        mf = fn(*args, **kwargs)
    except InputError as exc:
        return None, check_error(exc)
    assert isinstance(mf, mrgc.MrgFile)
    return mf, set()


def sweep(
    capsys: pytest.CaptureFixture[str], folder: Path, data: str | bytes, *, limit: float = 10.0, name: str = "f.mrg"
) -> set[str]:
    """Feed ``data`` to every entry point; return the diagnostic codes parse_file reported."""
    path = folder / name
    raw = data.encode("utf-8", "surrogatepass") if isinstance(data, str) else data
    path.write_bytes(raw)
    with time_limit(limit):
        if isinstance(data, str):
            try_load(parse_string, data, str(path), base_dir=str(folder))
        mf, codes = try_load(parse_file, path)

        rc, out, err = run_cli(capsys, "check", str(path))
        assert rc in (0, 2)
        if mf is not None:
            assert rc == 0 and "ok" in out
        else:
            assert rc == 2 and "error[E" in err

        rc, out, err = run_cli(capsys, "fmt", str(path))
        assert rc in (0, 2)
        text, diag = decode(raw, str(path)) if len(raw) <= MAX_BYTES else (None, "too big")
        tree = parse_text(text, str(path)) if text is not None else None
        parses = isinstance(tree, ast.SourceFile)
        assert (rc == 0) == parses, (rc, err[-500:])
        if parses:
            again = parse_text(out, "out.mrg")
            assert isinstance(again, ast.SourceFile), f"fmt printed text that does not parse: {again}\n{out}"
            assert format_source(again, out) == out  # fmt output is a fixed point
        else:
            assert "error[E" in err
    return codes


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("robust")
    (d / "dom.mrg").write_text("(define (domain e) (:grasps top side))\n", encoding="utf-8")
    (d / "m.obj").write_text("v 0 0 0\n", encoding="utf-8")
    return d


# ---------------------------------------------------------------- hypothesis: arbitrary input
@SETTINGS
@given(st.text(max_size=300))
def test_arbitrary_unicode_text(capsys, folder, text: str) -> None:
    sweep(capsys, folder, text)


@SETTINGS
@given(st.text(alphabet=st.characters(min_codepoint=32, max_codepoint=126), max_size=300))
def test_arbitrary_printable_text(capsys, folder, text: str) -> None:
    sweep(capsys, folder, text)


@SETTINGS
@given(st.binary(max_size=300))
def test_arbitrary_bytes(capsys, folder, data: bytes) -> None:
    sweep(capsys, folder, data)


TOKENS = [
    "(",
    ")",
    "(",
    ")",
    "(define",
    "(domain",
    "(problem",
    "define",
    "domain",
    "problem",
    "and",
    "(and",
    ":goal",
    ":init",
    ":domain",
    ":robots",
    ":fixed",
    ":regions",
    ":movable",
    ":handover-points",
    ":include",
    ":grasps",
    ":requirements",
    ":robot-kind",
    ":shape",
    ":pose",
    ":kind",
    ":base",
    ":position",
    ":handover",
    ":urdf",
    ":end-effector",
    ":home",
    ":footprint",
    ":carry",
    ":reach",
    ":",
    "::",
    ":9",
    "box",
    "sphere",
    "cylinder",
    "mesh",
    "fixed",
    "planar",
    *PREDICATES,
    "r1",
    "o1",
    "a",
    "Z9_+-",
    "x",
    "-",
    "+",
    ".",
    "1.2.3",
    "1e",
    "--1",
    "9x",
    "0",
    "-0",
    "1",
    "-2.5",
    ".5",
    "5.",
    "1e-5",
    "+3E+2",
    "1e999",
    "-1e999",
    "nan",
    "inf",
    "-inf",
    "NaN",
    '"x"',
    '"m.obj"',
    '"dom.mrg"',
    '"../x.mrg"',
    '"f.mrg"',
    '"a\\"b"',
    '"\\',
    '"',
    '"unterminated',
    '""',
    ";",
    "; comment",
    ";(",
    "\n",
    "\n",
    "\t",
    "\r\n",
    "\r",
    "\\",
    "\ufeff",
    "\x00",
    "é",
    "😀",
    "#",
    "\u2028",
]
token_soup = st.lists(st.tuples(st.sampled_from(TOKENS), st.sampled_from(["", " ", " ", "\n", "  "])), max_size=80).map(
    lambda parts: "".join(t + sep for t, sep in parts)
)


@SETTINGS
@given(token_soup)
def test_token_soup(capsys, folder, text: str) -> None:
    sweep(capsys, folder, text)


@SETTINGS
@given(token_soup, st.integers(0, 300), st.binary(min_size=1, max_size=4))
def test_token_soup_with_corrupted_bytes(capsys, folder, text: str, at: int, junk: bytes) -> None:
    raw = text.encode("utf-8")
    at = min(at, len(raw))
    sweep(capsys, folder, raw[:at] + junk + raw[at:])


# ---------------------------------------------------------------- hypothesis: valid syntax, random meaning
POOL = ["r1", "r2", "o1", "o2", "a", "b", "t", "h", "top", "side", "panda", "cart", "d", "e", "x"]
ALL_KEYS = sorted({k for schema in SCHEMAS.values() for k in schema} | {"bogus", "shap"})

names = st.sampled_from(POOL)
num = st.one_of(
    st.sampled_from(["0", "1", "-1", "0.5", "2", "1e999", "-1e999", "1e-300", "360", "-0"]),
    st.floats(allow_nan=False, allow_infinity=False).map(repr).filter(lambda s: "inf" not in s),
)
item = st.one_of(num, names, st.sampled_from(["box", "sphere", "cylinder", "mesh", "nan", "inf", '"m.obj"', '"x"']))
value = st.one_of(
    num,
    names,
    item,
    st.sampled_from(
        [
            "fixed",
            "planar",
            "nan",
            '"m.obj"',
            '"u.urdf"',
            "(box 1 1 1)",
            "(sphere 0)",
            "(cylinder 1)",
            '(mesh "m.obj" 2)',
            '(mesh "m.obj")',
            '(mesh "missing.obj")',
            "(mesh 1)",
            "(cone 1)",
            "()",
            "(0 0 0)",
            "(0 0 0 0)",
            "(1 2 3 4 5)",
            "(top side)",
            "(top bogus)",
            "(h)",
        ]
    ),
    st.lists(item, max_size=6).map(lambda xs: "(" + " ".join(xs) + ")"),
)
prop = st.tuples(st.sampled_from(ALL_KEYS), value).map(lambda kv: f":{kv[0]} {kv[1]}")
decl = st.one_of(names, st.tuples(names, st.lists(prop, max_size=4)).map(lambda t: f"({t[0]} {' '.join(t[1])})"))
atom = st.tuples(st.sampled_from([*PREDICATES, "at", "and"]), st.lists(names, max_size=5)).map(
    lambda t: "(" + " ".join([t[0], *t[1]]) + ")"
)
include = st.sampled_from(['"dom.mrg"', '"../x.mrg"', '"missing.mrg"', '"f.mrg"', '"."', '""', '"sub/../dom.mrg"'])
problem_section = st.one_of(
    st.sampled_from(["d", "e", "zz"]).map(lambda n: f"(:domain {n})"),
    st.tuples(
        st.sampled_from(["robots", "fixed", "regions", "movable", "handover-points"]), st.lists(decl, max_size=4)
    ).map(lambda t: f"(:{t[0]} {' '.join(t[1])})"),
    st.lists(atom, max_size=5).map(lambda xs: f"(:init {' '.join(xs)})"),
    atom.filter(lambda a: not a.startswith("(and")).map(lambda a: f"(:goal {a})"),
    st.lists(atom.filter(lambda a: not a.startswith("(and")), max_size=4).map(
        lambda xs: f"(:goal (and {' '.join(xs)}))"
    ),
    include.map(lambda p: f"(:include {p})"),
)
domain_section = st.one_of(
    st.lists(st.sampled_from(["handover", "planar-base", "symbolic", "bogus"]), max_size=3).map(
        lambda fs: "(:requirements " + " ".join(":" + f for f in fs) + ")"
    ),
    st.tuples(names, st.lists(prop, max_size=5)).map(lambda t: f"(:robot-kind {t[0]} {' '.join(t[1])})"),
    st.lists(names, max_size=4).map(lambda ns: f"(:grasps {' '.join(ns)})"),
    include.map(lambda p: f"(:include {p})"),
)
definition = st.one_of(
    st.tuples(st.sampled_from(["d", "e"]), st.lists(domain_section, max_size=4)).map(
        lambda t: f"(define (domain {t[0]}) {' '.join(t[1])})"
    ),
    st.tuples(names, st.lists(problem_section, max_size=9)).map(
        lambda t: f"(define (problem {t[0]}) {' '.join(t[1])})"
    ),
)
semantic_files = st.lists(definition, max_size=4).map("\n".join)


@SETTINGS
@given(semantic_files)
def test_syntactically_valid_files_with_random_meaning(capsys, folder, text: str) -> None:
    assert isinstance(parse_text(text), ast.SourceFile)  # the generator makes valid syntax
    sweep(capsys, folder, text)


# ---------------------------------------------------------------- specific cases
PROBLEM = """(define (domain d) (:grasps top))
(define (problem p)
  (:domain d)
  (:robots r)
  (:regions a b)
  (:movable o)
  (:init (in-region o a) (reachable-pick o top r)) ; facts
  (:goal (in-region o b)))
"""


def test_empty_file(capsys, tmp_path) -> None:
    assert sweep(capsys, tmp_path, "") == {"E004"}


def test_only_comments(capsys, tmp_path) -> None:
    assert sweep(capsys, tmp_path, "; one\n;two\n   ; three\n;") == {"E004"}


def test_only_whitespace(capsys, tmp_path) -> None:
    assert sweep(capsys, tmp_path, " \n\t\r\n\f ") == {"E004"}


@pytest.mark.parametrize(
    "text",
    [
        "(" * 20000,
        ")" * 20000,
        "(" * 20000 + ")" * 20000,
        "(define (problem p) (:robots (r :x " + "(" * 20000,
        "(define (problem p) (:robots (r :x " + "(" * 20000 + ")" * 20000,
        "(define (problem p) (:goal (and " + "(" * 20000 + ")" * 20000 + ")))",
        "(define (problem p) (:init " + "(" * 20000,
    ],
    ids=["open", "close", "balanced", "in-value", "in-value-balanced", "in-goal", "in-init"],
)
def test_deep_nesting(capsys, tmp_path, text: str) -> None:
    codes = sweep(capsys, tmp_path, text, limit=5)
    assert codes and codes <= {"E100", "E101", "E102", "E104"}


def test_one_megabyte_comment_line(capsys, tmp_path) -> None:
    text = PROBLEM + ";" + "x" * (1 << 20) + "\n"
    assert sweep(capsys, tmp_path, text, limit=10) == set()


def test_one_megabyte_line_of_code(capsys, tmp_path) -> None:
    """A valid problem written on a single 1 MB line."""
    atoms = " (reachable-pick o top r)" * ((1 << 20) // 25)
    text = (
        "(define (domain d) (:grasps top)) (define (problem p) (:domain d) (:robots r) (:regions a b) "
        "(:movable o) (:init (in-region o a)" + atoms + ") (:goal (in-region o b)))"
    )
    assert "\n" not in text and len(text) > 1 << 20
    path = tmp_path / "big.mrg"
    path.write_text(text, encoding="utf-8")
    with time_limit(15):
        p = parse_file(path).problem()
        rc, out, _ = run_cli(capsys, "check", str(path))
    assert rc == 0 and "2 facts" in out
    assert p.initial_regions == {"o": "a"}


def test_one_megabyte_line_of_errors(capsys, tmp_path) -> None:
    """A 1 MB single line holding 5,000 errors must be reported promptly.

    Regression test: ``Diagnostic.render`` -> ``errors._snippet`` used to split the *whole* source and expand
    tabs on the whole 1 MB line once per diagnostic, so `mrgc check` was quadratic: ~7 s here for a file
    checked in 0.1 s (and ~9 minutes for 500,000 duplicate one-letter names on a 1 MB line).
    """
    text = (
        "(define (domain d)) (define (problem p) (:domain d) (:robots" + (" " + "r" * 200) * 5000 + ") (:goal (and)))"
    )
    path = tmp_path / "dups.mrg"
    path.write_text(text, encoding="utf-8")
    with time_limit(20):
        start = time.perf_counter()
        with pytest.raises(InputError) as info:
            parse_file(path)
        assert len(info.value.diagnostics) == 5000  # 4,999 duplicates + the empty goal
        parsed_in = time.perf_counter() - start
        start = time.perf_counter()
        rc, _, err = run_cli(capsys, "check", str(path))
        checked_in = time.perf_counter() - start
    assert rc == 2 and "5000 errors" in err
    # the alarm above catches a hang; speed itself is measured in benchmarks/, not asserted here
    assert err.count("\n") >= 3 * 5000 and parsed_in >= 0 and checked_in >= 0


def test_just_over_max_bytes(capsys, tmp_path) -> None:
    path = tmp_path / "huge.mrg"
    with open(path, "wb") as fh:
        fh.write(b"; " + b"x" * (MAX_BYTES - 2) + b"\n")  # MAX_BYTES + 1 bytes
    assert path.stat().st_size == MAX_BYTES + 1
    with time_limit(10):
        with pytest.raises(InputError) as info:
            parse_file(path)
        assert check_error(info.value) == {"E002"}
        for cmd in ("check", "fmt"):
            rc, _, err = run_cli(capsys, cmd, str(path))
            assert rc == 2 and "E002" in err
        # decode guards in-memory input too
        text, diag = decode(b" " * (MAX_BYTES + 1), "x")
        assert text is None and diag is not None and diag.code == "E002"


def test_exactly_max_bytes_is_accepted(capsys, tmp_path) -> None:
    path = tmp_path / "limit.mrg"
    body = PROBLEM.encode()
    with open(path, "wb") as fh:
        fh.write(body + b";" + b"x" * (MAX_BYTES - len(body) - 2) + b"\n")
    assert path.stat().st_size == MAX_BYTES
    with time_limit(10):
        assert parse_file(path).problem().name == "p"


def test_nul_bytes(capsys, tmp_path) -> None:
    codes = sweep(capsys, tmp_path, b"(define (domain d))\n(define\x00 (problem p))")
    assert codes == {"E003"}
    with pytest.raises(InputError) as info:
        parse_file(tmp_path / "f.mrg")
    span = info.value.diagnostics[0].span
    assert span is not None and (span.line, span.column) == (2, 8)
    # in-memory text with a NUL: a syntax error, not a crash
    with pytest.raises(InputError) as info:
        parse_string("(define (domain d)) \x00")
    check_error(info.value)


def test_nul_in_include_path_of_in_memory_text(tmp_path) -> None:
    """Regression test: parse_string used to raise ValueError('embedded null byte') from os.path.realpath."""
    text = '(define (domain d) (:include "a\x00b.mrg"))'
    with pytest.raises(InputError) as info:
        parse_string(text, "t.mrg", base_dir=str(tmp_path))
    assert check_error(info.value) <= {"E233", "E234"}


def test_invalid_utf8(capsys, tmp_path) -> None:
    assert sweep(capsys, tmp_path, b"(define (domain d))\n  \xff\xfe(define") == {"E003"}
    with pytest.raises(InputError) as info:
        parse_file(tmp_path / "f.mrg")
    span = info.value.diagnostics[0].span
    assert span is not None and (span.line, span.column) == (2, 3)
    # a truncated multi-byte character at the very end
    assert sweep(capsys, tmp_path, PROBLEM.encode() + "é".encode()[:1]) == {"E003"}


def test_utf8_bom_is_skipped(capsys, tmp_path) -> None:
    assert sweep(capsys, tmp_path, b"\xef\xbb\xbf" + PROBLEM.encode()) == set()
    rc, out, _ = run_cli(capsys, "fmt", str(tmp_path / "f.mrg"))
    assert rc == 0 and not out.startswith("\ufeff")


def test_crlf_line_endings(capsys, tmp_path) -> None:
    crlf = PROBLEM.replace("\n", "\r\n")
    assert sweep(capsys, tmp_path, crlf.encode()) == set()
    mf = parse_file(tmp_path / "f.mrg")
    assert mf.problem().initial_regions == {"o": "a"}
    rc, out, _ = run_cli(capsys, "fmt", str(tmp_path / "f.mrg"))
    assert rc == 0 and "\r" not in out and "; facts" in out
    assert parse_text(out) == parse_text(PROBLEM)


def _refused(capsys, tmp_path, text: str, code: str) -> tuple[Diagnostic, ...]:
    """The diagnostics of ``text``, which the sweep and parse_string both refuse with ``code``."""
    assert sweep(capsys, tmp_path, text) == {code}
    with pytest.raises(InputError) as info:
        parse_string(text)
    return info.value.diagnostics


@pytest.mark.parametrize(
    "text",
    [
        '(define (domain d) (:include "abc))',
        '(define (domain d) (:include "abc',
        '(define (domain d) (:include "ab\nc"))',
        '(define (domain d) (:include "abc\\"))',
    ],
)
def test_unterminated_string(capsys, tmp_path, text: str) -> None:
    assert "unterminated string" in _refused(capsys, tmp_path, text, "E100")[0].message


@pytest.mark.parametrize(
    "text",
    [
        '(define (domain d) (:robot-kind k :urdf "u" :end-effector "e" :reach 1e999))',
        '(define (domain d) (:robot-kind k :urdf "u" :end-effector "e" :home (0 -1e999 0)))',
    ],
)
def test_overflowing_number_is_E251(capsys, tmp_path, text: str) -> None:
    assert [d.code for d in _refused(capsys, tmp_path, text, "E251")] == ["E251"]
    rc, _, err = run_cli(capsys, "check", str(tmp_path / "f.mrg"))
    assert rc == 2 and "error[E251]" in err


def test_overflowing_number_in_a_geometric_problem(capsys, tmp_path) -> None:
    text = """(define (domain d) (:robot-kind k :urdf "u" :end-effector "e") (:grasps top))
(define (problem p) (:domain d)
  (:robots (r :kind k :base (0 0 0 0)))
  (:regions (a :shape (box 1 1 1) :pose (0 0 0 0)) (b :shape (box 1 1 1) :pose (2 0 0 0)))
  (:movable (o :shape (box 1e999 1 1) :pose (0 0 1e999 0)))
  (:goal (in-region o b)))"""
    assert sweep(capsys, tmp_path, text) == {"E251"}


@pytest.mark.parametrize("word", ["nan", "inf", "-inf", "NaN", "Infinity"])
def test_nan_and_inf_are_not_numbers(capsys, tmp_path, word: str) -> None:
    text = f'(define (domain d) (:robot-kind k :urdf "u" :end-effector "e" :reach {word} :home (1 {word})))'
    codes = sweep(capsys, tmp_path, text)
    if word.startswith("-"):  # '-inf' is not a name either: a syntax error
        assert codes == {"E100"}
    else:
        assert codes == {"E253"}


def test_cli_check_reports_every_file(capsys, tmp_path) -> None:
    good, bad = tmp_path / "good.mrg", tmp_path / "bad.mrg"
    good.write_text(PROBLEM, encoding="utf-8")
    bad.write_bytes(b"\xff")
    rc, out, err = run_cli(capsys, "check", str(good), str(bad), str(tmp_path / "missing.mrg"))
    assert rc == 2
    assert "good.mrg: ok" in out and "E003" in err and "E001" in err


# ---------------------------------------------------------------- URDF and mesh files (issue 9)
def _fresh(folder: Path, name: str, data: str | bytes) -> str:
    """A new file per example: the readers cache by path."""
    path = folder / f"{len(list(folder.iterdir()))}-{name}"
    path.write_bytes(data.encode("utf-8", "surrogatepass") if isinstance(data, str) else data)
    return str(path)


def _urdf_error(exc: InputError, path: str) -> None:
    from mrgc.language.codes import CLI_CODES

    codes = {d.code for d in exc.diagnostics}
    assert codes and codes <= {"E400", "E403", "E236"} and codes <= set(CLI_CODES) | set(CODES), codes
    assert all(d.message and "\n" not in d.message for d in exc.diagnostics)
    assert all(d.span is not None and d.span.file == path for d in exc.diagnostics if d.code == "E400")


links = st.lists(st.sampled_from(["a", "b", "c", "d", "e"]), min_size=1, max_size=5, unique=True)
numbers = st.sampled_from(["0", "1", "-0.5", "nan", "inf", "-inf", "1e999", "1e300", "x", ""])


@st.composite
def urdf_texts(draw: st.DrawFn) -> str:
    """URDFs with random links and joints: cycles, two parents, unknown links, bad numbers."""
    names = draw(links)
    joints = draw(
        st.lists(
            st.tuples(
                st.sampled_from(names + ["zz"]),
                st.sampled_from(names),
                st.sampled_from(["revolute", "fixed", "prismatic", "continuous", "bogus"]),
                numbers,
                numbers,
            ),
            max_size=6,
        )
    )
    body = [
        f'<link name="{n}"><collision><geometry><box size="0.1 0.1 {draw(numbers)}"/></geometry></collision></link>'
        for n in names
    ]
    for k, (parent, child, kind, x, lim) in enumerate(joints):
        body.append(
            f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{x} 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="{lim}"/></joint>'
        )
    return '<robot name="r">\n' + "\n".join(body) + "\n</robot>\n"


@SETTINGS
@given(urdf_texts())
def test_random_urdfs_are_read_or_refused_at_a_line(folder: Path, text: str) -> None:
    from mrgc.geometry.urdf import parse_urdf

    path = _fresh(folder, "r.urdf", text)
    with time_limit(10):  # a joint cycle used to loop forever
        try:
            urdf = parse_urdf(path)
        except InputError as exc:
            _urdf_error(exc, path)
            return
    assert sorted(urdf.order) == sorted(urdf.links)  # every link once, each after its parent
    for pos, name in enumerate(urdf.order[1:], 1):
        assert urdf.order.index(urdf.joint_of[name].parent) < pos


@SETTINGS
@given(st.one_of(st.text(max_size=300), st.binary(max_size=300)))
def test_arbitrary_urdf_bytes(folder: Path, data: str | bytes) -> None:
    from mrgc.geometry.urdf import parse_urdf

    path = _fresh(folder, "x.urdf", data)
    with time_limit(10):
        try:
            parse_urdf(path)
        except InputError as exc:
            _urdf_error(exc, path)


@SETTINGS
@given(
    st.lists(
        st.one_of(
            st.tuples(st.just("v"), numbers, numbers, numbers).map(" ".join),
            st.tuples(
                st.just("f"), st.integers(-5, 8).map(str), st.integers(-5, 8).map(str), st.integers(-5, 8).map(str)
            ).map(" ".join),
            st.text(max_size=20),
        ),
        max_size=20,
    ).map("\n".join)
)
def test_random_meshes_are_finite_or_refused_at_a_line(folder: Path, text: str) -> None:
    import numpy as np

    from mrgc.geometry.meshes import MAX_COORD, read_mesh

    path = _fresh(folder, "m.obj", text)
    try:
        v, f = read_mesh(path)
    except InputError as exc:
        assert [d.code for d in exc.diagnostics] == ["E403"] and exc.diagnostics[0].span is not None
        return
    assert np.isfinite(v).all() and (np.abs(v) <= MAX_COORD).all()
    assert f.size == 0 or (f.min() >= 0 and f.max() < len(v))


def test_a_fifo_include_does_not_block(tmp_path: Path) -> None:
    import os

    os.mkfifo(tmp_path / "dom.mrg")
    (tmp_path / "p.mrg").write_text(
        '(define (problem p) (:domain d) (:include "dom.mrg") (:robots r) (:movable o)'
        " (:regions a b) (:init (in-region o a)) (:goal (in-region o b)))\n",
        encoding="utf-8",
    )
    with time_limit(10):
        _, codes = try_load(parse_file, tmp_path / "p.mrg")
    assert codes == {"E234", "E230"}  # the include is refused (not read), so the domain is missing too
    with pytest.raises(InputError) as info:
        parse_file(tmp_path / "p.mrg")
    assert "'dom.mrg' is not a regular file" in info.value.render()
