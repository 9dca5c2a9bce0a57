"""The public Python API: ``mrgc.parse_string`` / ``mrgc.parse_file``, ``MrgFile.problem()``, the checked model
values, and domain lookup across files and includes."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import mrgc
from mrgc import InputError, MrgFile
from mrgc.language.model import Box, Cylinder, Fact, Pose, Sphere

DOMAIN = """(define (domain kitchen)
  (:requirements :handover)
  (:robot-kind panda :urdf "panda.urdf" :end-effector "hand" :home (0 0 0 -90 0 90 45))
  (:robot-kind cart :base planar :footprint (box 0.6 0.4 0.3) :carry (0 0 0.5 0) :reach 1.5)
  (:grasps top side-x+))
"""

GEOMETRIC = (
    DOMAIN
    + """
(define (problem swap)
  (:domain kitchen)
  (:robots (r1 :kind panda :base (0 0 0 0)) (r2 :kind panda :base (1.5 0 0 180)))
  (:fixed (table :shape (box 2 1 0.1) :pose (0.75 0 0.35 0)))
  (:regions (left :shape (box 0.3 0.3 0.01) :pose (0.3 0 0.41 0))
            (right :shape (cylinder 0.2 0.01) :pose (1.2 0 0.41 90)))
  (:movable (o1 :shape (cylinder 0.03 0.1) :pose (0.3 0 0.46 0))
            (o2 :shape (sphere 0.04) :pose (1.2 -0.5 0.45 -30) :grasps (top) :handover (h)))
  (:handover-points (h :position (0.75 0 0.8)))
  (:init (in-region o1 left) (in-region o2 right))
  (:goal (and (in-region o1 right) (in-region o2 left))))
"""
)

SYMBOLIC = """(define (domain blocks) (:requirements :symbolic) (:grasps top side))
(define (problem tiny)
  (:domain blocks)
  (:robots r1 r2)
  (:regions a b c)
  (:movable x y)
  (:init (in-region x a) (in-region y b)
         (reachable-pick x top r1) (reachable-place x c top r1) (reachable-pick y side r2)
         (reachable-pick x top r1))
  (:goal (in-region x c)))
"""


def problem_text(name: str, domain: str = "kitchen") -> str:
    return f"""(define (problem {name})
  (:domain {domain})
  (:robots r)
  (:regions a b)
  (:movable o)
  (:init (in-region o a))
  (:goal (in-region o b)))
"""


def codes(exc: pytest.ExceptionInfo[InputError]) -> list[str]:
    return [d.code for d in exc.value.diagnostics]


# ---------------------------------------------------------------- entry points and problem()
def test_parse_string_returns_a_checked_file() -> None:
    mf = mrgc.parse_string(GEOMETRIC, "kitchen.mrg")
    assert isinstance(mf, MrgFile)
    assert mf.path == "kitchen.mrg" and mf.text == GEOMETRIC
    assert [d.name for d in mf.domains] == ["kitchen"]
    assert [p.name for p in mf.problems] == ["swap"]
    assert len(mf.syntax.definitions) == 2


def test_parse_file_matches_parse_string(tmp_path: Path) -> None:
    path = tmp_path / "kitchen.mrg"
    path.write_text(GEOMETRIC, encoding="utf-8")
    from_file = mrgc.parse_file(path)  # a PathLike works
    from_str = mrgc.parse_file(str(path))
    in_memory = mrgc.parse_string(GEOMETRIC, str(path), base_dir=str(tmp_path))
    assert from_file.problem() == from_str.problem() == in_memory.problem()
    assert from_file.syntax == in_memory.syntax
    assert from_file.problem().source == str(path)


def test_problem_with_one_problem() -> None:
    mf = mrgc.parse_string(GEOMETRIC)
    assert mf.problem().name == "swap"
    assert mf.problem("swap") is mf.problem()


def test_problem_with_several_problems() -> None:
    mf = mrgc.parse_string(DOMAIN + problem_text("alpha") + problem_text("beta"), "two.mrg")
    assert [p.name for p in mf.problems] == ["alpha", "beta"]
    assert mf.problem("beta").name == "beta"
    assert mf.problem("alpha").domain.name == "kitchen"
    with pytest.raises(InputError) as info:
        mf.problem()
    assert codes(info) == ["E230"]
    assert "2 problems" in info.value.diagnostics[0].message and "alpha, beta" in info.value.diagnostics[0].message
    with pytest.raises(InputError) as info:
        mf.problem("alpah")
    assert codes(info) == ["E230"]
    assert "did you mean 'alpha'" in info.value.diagnostics[0].message


def test_problem_with_no_problem() -> None:
    mf = mrgc.parse_string(DOMAIN, "only-domain.mrg")
    assert mf.problems == ()
    assert [d.name for d in mf.domains] == ["kitchen"]
    with pytest.raises(InputError) as info:
        mf.problem()
    assert codes(info) == ["E230"] and "0 problems (none)" in str(info.value)
    with pytest.raises(InputError) as info:
        mf.problem("swap")
    assert codes(info) == ["E230"]


def test_errors_are_input_errors_with_every_diagnostic() -> None:
    text = (
        DOMAIN
        + """(define (problem bad)
  (:domain kitchen)
  (:robots r r)
  (:regions a)
  (:movable o)
  (:init (in-region o a) (in-regoin o a))
  (:goal (in-region o nowhere)))"""
    )
    with pytest.raises(InputError) as info:
        mrgc.parse_string(text, "bad.mrg")
    assert isinstance(info.value, mrgc.MrgcError) and info.value.exit_code == 2
    assert codes(info) == ["E200", "E220", "E212"]  # in file order
    assert all(d.span is not None and d.span.file == "bad.mrg" for d in info.value.diagnostics)
    assert "did you mean 'in-region'" in info.value.diagnostics[1].message
    assert "bad.mrg:11:" in info.value.render()  # the goal line, with its source snippet
    assert "(:goal (in-region o nowhere)))" in info.value.render()


def test_syntax_error_is_located() -> None:
    with pytest.raises(InputError) as info:
        mrgc.parse_string("(define (problem p)\n  (:gaol (in-region o b)))", "s.mrg")
    (d,) = info.value.diagnostics
    assert d.code == "E103" and "did you mean ':goal'" in d.message
    assert d.span is not None and (d.span.line, d.span.column) == (2, 4)


# ---------------------------------------------------------------- the checked model
def test_geometric_problem_values() -> None:
    p = mrgc.parse_string(GEOMETRIC).problem()
    assert p.symbolic is False
    assert p.domain.name == "kitchen" and p.domain.requirements == ("handover",)
    assert p.domain.grasps == ("top", "side-x+")

    panda = p.domain.kind("panda")
    assert panda.urdf == "panda.urdf" and panda.end_effector == "hand" and panda.base == "fixed"
    assert panda.home == (0, 0, 0, -90, 0, 90, 45)
    cart = p.domain.kind("cart")
    assert cart.base == "planar" and cart.footprint == Box(0.6, 0.4, 0.3)
    assert cart.carry == Pose(0, 0, 0.5, 0) and cart.reach == 1.5 and cart.urdf is None

    r1, r2 = p.robots
    assert (r1.name, r1.kind, r1.base) == ("r1", "panda", Pose(0, 0, 0, 0))
    assert r2.base == Pose(1.5, 0, 0, 180) and r2.base.yaw_rad == pytest.approx(3.141592653589793)
    (table,) = p.fixed
    assert table.shape == Box(2, 1, 0.1) and table.pose == Pose(0.75, 0, 0.35, 0)
    assert [(r.name, r.shape) for r in p.regions] == [("left", Box(0.3, 0.3, 0.01)), ("right", Cylinder(0.2, 0.01))]
    assert p.regions[1].pose == Pose(1.2, 0, 0.41, 90)

    o1, o2 = p.movable
    assert o1.shape == Cylinder(0.03, 0.1) and o1.pose.position == (0.3, 0, 0.46)
    assert o2.shape == Sphere(0.04) and o2.pose == Pose(1.2, -0.5, 0.45, -30)
    # default grasps are the domain's grasps; an explicit :grasps narrows them
    assert o1.grasps == ("top", "side-x+") == p.grasps_of("o1")
    assert o2.grasps == ("top",) == p.grasps_of("o2")
    assert o2.handover_points == ("h",)
    assert p.object("o2") is o2
    (h,) = p.handover_points
    assert h.name == "h" and h.position == (0.75, 0, 0.8)

    assert p.goal == (Fact("in-region", ("o1", "right")), Fact("in-region", ("o2", "left")))
    assert p.goal_regions == {"o1": "right", "o2": "left"}
    assert p.initial_regions == {"o1": "left", "o2": "right"}
    assert p.init == (Fact("in-region", ("o1", "left")), Fact("in-region", ("o2", "right")))


def test_geometric_problem_needs_no_init() -> None:
    text = GEOMETRIC.replace("(:init (in-region o1 left) (in-region o2 right))", "")
    p = mrgc.parse_string(text).problem()
    assert p.init == () and p.initial_regions == {} and not p.symbolic


def test_symbolic_problem_values() -> None:
    p = mrgc.parse_string(SYMBOLIC).problem()
    assert p.symbolic is True
    assert p.domain.requirements == ("symbolic",)
    assert [(r.name, r.kind, r.base) for r in p.robots] == [("r1", None, None), ("r2", None, None)]
    assert [r.name for r in p.regions] == ["a", "b", "c"]
    assert all(r.shape is None and r.pose is None for r in p.regions)
    assert [(m.name, m.shape, m.pose, m.grasps) for m in p.movable] == [
        ("x", None, None, ("top", "side")),
        ("y", None, None, ("top", "side")),
    ]
    # facts in order of first appearance, duplicates dropped
    assert p.init == (
        Fact("in-region", ("x", "a")),
        Fact("in-region", ("y", "b")),
        Fact("reachable-pick", ("x", "top", "r1")),
        Fact("reachable-place", ("x", "c", "top", "r1")),
        Fact("reachable-pick", ("y", "side", "r2")),
    )
    assert str(p.init[3]) == "(reachable-place x c top r1)"
    assert p.goal == (Fact("in-region", ("x", "c")),)
    assert p.goal_regions == {"x": "c"}
    assert p.initial_regions == {"x": "a", "y": "b"}


def test_symbolic_problem_rejects_geometry() -> None:
    text = SYMBOLIC.replace("(:regions a b c)", "(:regions (a :pose (0 0 0 0)) b c)")
    with pytest.raises(InputError) as info:
        mrgc.parse_string(text)
    assert codes(info) == ["E261"]


def test_symbolic_problem_needs_initial_regions() -> None:
    text = SYMBOLIC.replace("(in-region y b)", "")
    with pytest.raises(InputError) as info:
        mrgc.parse_string(text)
    assert codes(info) == ["E228"] and "'y'" in info.value.diagnostics[0].message


# ---------------------------------------------------------------- domain lookup and includes
def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_domain_in_the_same_file(tmp_path: Path) -> None:
    path = write(tmp_path / "p.mrg", DOMAIN + problem_text("p"))
    mf = mrgc.parse_file(path)
    assert mf.problem().domain.name == "kitchen" and mf.problem().domain.source == str(path)
    assert [d.name for d in mf.domains] == ["kitchen"]


def test_own_domain_wins_over_domain_mrg(tmp_path: Path) -> None:
    write(tmp_path / "domain.mrg", "(define (domain kitchen) (:grasps other))")
    path = write(tmp_path / "p.mrg", DOMAIN + problem_text("p"))
    assert mrgc.parse_file(path).problem().domain.grasps == ("top", "side-x+")


def test_domain_in_domain_mrg_beside_the_file(tmp_path: Path) -> None:
    dom = write(tmp_path / "domain.mrg", DOMAIN)
    path = write(tmp_path / "p.mrg", problem_text("p"))
    mf = mrgc.parse_file(path)
    p = mf.problem()
    assert p.domain.name == "kitchen" and p.domain.grasps == ("top", "side-x+")
    assert os.path.samefile(p.domain.source, dom)
    assert mf.domains == ()  # the file itself defines no domain
    # parse_string finds domain.mrg in base_dir too
    assert mrgc.parse_string(problem_text("q"), base_dir=str(tmp_path)).problem().domain.name == "kitchen"


def test_domain_mrg_may_include_the_domain(tmp_path: Path) -> None:
    write(tmp_path / "domain.mrg", '(define (domain index) (:include "lib/kitchen.mrg"))')
    write(tmp_path / "lib" / "kitchen.mrg", DOMAIN)
    path = write(tmp_path / "p.mrg", problem_text("p"))
    assert mrgc.parse_file(path).problem().domain.grasps == ("top", "side-x+")


def test_domain_via_include(tmp_path: Path) -> None:
    write(tmp_path / "sub" / "file.mrg", DOMAIN)
    path = write(
        tmp_path / "p.mrg",
        problem_text("p").replace("(:domain kitchen)", '(:domain kitchen)\n  (:include "sub/file.mrg")'),
    )
    p = mrgc.parse_file(path).problem()
    assert p.domain.name == "kitchen"
    assert os.path.samefile(p.domain.source, tmp_path / "sub" / "file.mrg")


def test_domain_via_transitive_include(tmp_path: Path) -> None:
    write(tmp_path / "sub" / "a.mrg", '(define (domain hub) (:include "deeper/b.mrg"))')
    write(tmp_path / "sub" / "deeper" / "b.mrg", DOMAIN)  # resolved relative to a.mrg
    path = write(tmp_path / "p.mrg", '(define (domain local) (:include "sub/a.mrg"))\n' + problem_text("p"))
    assert mrgc.parse_file(path).problem().domain.name == "kitchen"


def test_ambiguous_domain(tmp_path: Path) -> None:
    write(tmp_path / "one.mrg", DOMAIN)
    write(tmp_path / "two.mrg", DOMAIN)
    path = write(
        tmp_path / "p.mrg",
        problem_text("p").replace("(:domain kitchen)", '(:domain kitchen) (:include "one.mrg") (:include "two.mrg")'),
    )
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E231"]
    msg = info.value.diagnostics[0].message
    assert "one.mrg" in msg and "two.mrg" in msg
    assert info.value.diagnostics[0].span.line == 2  # the (:domain kitchen) reference


def test_missing_domain(tmp_path: Path) -> None:
    path = write(tmp_path / "p.mrg", DOMAIN + problem_text("p", domain="kitchn"))
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E230"] and "did you mean 'kitchen'" in info.value.diagnostics[0].message


def test_problem_without_domain_reference() -> None:
    text = DOMAIN + problem_text("p").replace("(:domain kitchen)", "")
    with pytest.raises(InputError) as info:
        mrgc.parse_string(text)
    assert codes(info) == ["E230"] and "names no domain" in info.value.diagnostics[0].message


def test_include_cycle(tmp_path: Path) -> None:
    write(tmp_path / "a.mrg", '(define (domain a) (:include "b.mrg"))')
    write(tmp_path / "b.mrg", '(define (domain b) (:include "a.mrg"))')
    path = write(tmp_path / "p.mrg", '(define (domain p) (:include "a.mrg"))')
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E232"]
    assert "a.mrg -> b.mrg -> a.mrg" in info.value.diagnostics[0].message


def test_self_include_is_a_cycle(tmp_path: Path) -> None:
    path = write(tmp_path / "self.mrg", '(define (domain s) (:include "self.mrg"))')
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E232"]


def test_include_escaping_the_folder(tmp_path: Path) -> None:
    write(tmp_path / "x.mrg", DOMAIN)  # exists, but outside the checked file's folder tree
    path = write(
        tmp_path / "inner" / "p.mrg",
        problem_text("p").replace("(:domain kitchen)", '(:domain kitchen) (:include "../x.mrg")'),
    )
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert set(codes(info)) == {"E233", "E230"}  # the escape, and so the domain is not found
    (esc,) = [d for d in info.value.diagnostics if d.code == "E233"]
    assert "'../x.mrg' leaves the folder tree" in esc.message and esc.span.line == 2


def test_include_escaping_via_absolute_path(tmp_path: Path) -> None:
    outside = write(tmp_path / "x.mrg", DOMAIN)
    path = write(tmp_path / "inner" / "p.mrg", f'(define (domain d) (:include "{outside}"))')
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E233"]


def test_include_inside_the_folder_through_dotdot_is_fine(tmp_path: Path) -> None:
    write(tmp_path / "lib" / "k.mrg", DOMAIN)
    path = write(
        tmp_path / "p.mrg",
        problem_text("p").replace("(:domain kitchen)", '(:domain kitchen) (:include "lib/../lib/k.mrg")'),
    )
    assert mrgc.parse_file(path).problem().domain.name == "kitchen"


def test_include_not_found(tmp_path: Path) -> None:
    path = write(
        tmp_path / "p.mrg", DOMAIN.replace("(:grasps top side-x+)", '(:grasps top side-x+) (:include "nope.mrg")')
    )
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    assert codes(info) == ["E234"]
    d = info.value.diagnostics[0]
    assert "nope.mrg" in d.message and d.span is not None and d.span.line == 5


def test_errors_in_included_files_are_reported_with_their_file(tmp_path: Path) -> None:
    inc = write(tmp_path / "bad.mrg", "(define (domain b) (:grasps a a))")
    path = write(tmp_path / "p.mrg", '(define (domain p) (:include "bad.mrg"))')
    with pytest.raises(InputError) as info:
        mrgc.parse_file(path)
    (d,) = info.value.diagnostics
    assert d.code == "E200" and os.path.samefile(d.span.file, inc)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError) as info:
        mrgc.parse_file(tmp_path / "absent.mrg")
    assert codes(info) == ["E001"]


CHAIN = str(Path(__file__).resolve().parent.parent / "domains" / "symbolic" / "chain-3.mrg")


@pytest.mark.parametrize(
    ("call", "kwargs", "said"),
    [
        ("plan", {"seed": 2**31}, "seed=2147483648: must be a whole number from 0 to 2,147,483,647"),
        ("compile", {"seed": 2**64}, "seed="),
        ("plan", {"max_makespan": 0}, "max_makespan=0: must be a whole number from 1"),
        ("plan", {"max_makespan": -1, "planner": "ap2"}, "max_makespan=-1"),
        ("plan", {"time_limit": 0}, "time_limit=0: must be a finite number more than 0"),
        ("plan", {"time_limit": None}, "time_limit=None"),
        ("plan", {"motions": "bogus"}, "motions='bogus': must be one of configurations, full"),
        ("plan", {"c": -1}, "c=-1"),
        ("plan", {"anytime": "yes"}, "anytime='yes': must be True or False"),
        ("compile", {"max_makespan": 0}, "max_makespan=0"),
        ("compile", {"skeletons": 0}, "skeletons=0"),
        ("compile", {"time_limit": -1}, "time_limit=-1"),
        ("compile", {"time_limit": "5"}, "time_limit='5'"),
        ("compile", {"time_limit": 1e10}, "time_limit=10000000000.0"),
        ("facts_summary", {"seed": 1.5}, "seed=1.5"),
        ("plan", {"time_limit": 10**400}, "time_limit=1000000000000000000000000000000000000..."),
    ],
)
def test_api_arguments_are_checked_as_the_command_line_checks_them(call: str, kwargs: dict, said: str) -> None:
    """A bad number is InputError E000 naming the argument (a seed past 32 bits was a false 'time limit', a
    max_makespan of 0 a false 'infeasible', time_limit=None a TypeError from deep inside)."""
    with pytest.raises(mrgc.MrgcError) as err:
        getattr(mrgc, call)(CHAIN, **kwargs)
    assert err.value.diagnostics[0].code == "E000" and said in err.value.diagnostics[0].message


def test_api_defaults_and_bounds_pass() -> None:
    import numpy as np

    assert mrgc.compile(CHAIN, backend=None, seed=2**31 - 1, time_limit=1e6).status == "optimal"
    assert mrgc.plan(CHAIN, seed=np.int64(3), anytime=np.False_, c=np.float64(0.5)).status == "solved"
    assert mrgc.plan(CHAIN, max_makespan=10_000, seed=0).status == "solved"
    with pytest.raises(mrgc.MrgcError, match="a problem is a file's path or a Problem, not a NoneType"):
        mrgc.compile(None)  # type: ignore[arg-type]
