"""Every exported model loads in its own solver and solves to the optimum the backend finds for it: .smt2 in
z3 (``Optimize.from_file``, the script's own (check-sat)/(get-objectives)), .lp and .mps in HiGHS
(``readModel``), .pbtxt in CP-SAT (the text proto).  ``--horizon T`` / ``horizon=`` chooses the model, and
by default it is the first skeleton's makespan, whose optimum is that skeleton.
"""

from __future__ import annotations

import runpy
import shutil
from pathlib import Path
from typing import Any

import pytest

import mrgc
from mrgc import cli
from mrgc.backends.registry import backend_class
from mrgc.compiler.facts import FactBase
from mrgc.compiler.ir import Solution, SolveStatus
from mrgc.planner.skeletons import SkeletonSource, must_move

SYMBOLIC = Path(__file__).resolve().parent.parent / "domains" / "symbolic"
PROBLEMS = ["chain-3", "handover", "medium", "parallel", "infeasible"]
KINDS = [("mip", "lp"), ("mip", "mps"), ("smt", "smt2"), ("cpsat", "pbtxt")]
ENCODINGS = ["paper", "disaggregated", "time-of-move"]


def reference(problem: Any, backend: str, encoding: str, horizon: int) -> Solution:
    """The backend's own solve of the model of that horizon (what the file must reload to)."""
    src = SkeletonSource(FactBase.from_problem(problem), must_move(problem), (), backend, encoding)
    enc = src.generator.encoding.build(src.generator.graph, horizon)
    solver = backend_class(backend)()
    solver.load(enc.model)
    return solver.solve()


def reload(path: Path) -> tuple[SolveStatus, tuple[int, ...]]:
    """(status, objective values) of the model file solved by its own solver, read the solver's way."""
    ext = path.suffix.lstrip(".")
    if ext == "smt2":
        import z3

        opt = z3.Optimize()
        opt.from_file(str(path))
        result = opt.check()
        if result == z3.unsat:
            return SolveStatus.INFEASIBLE, ()
        assert result == z3.sat, result
        model = opt.model()
        return SolveStatus.OPTIMAL, tuple(model.eval(o, model_completion=True).as_long() for o in opt.objectives())
    if ext in ("lp", "mps"):
        import highspy

        h = highspy.Highs()
        h.setOptionValue("output_flag", False)
        assert h.readModel(str(path)) == highspy.HighsStatus.kOk
        h.run()
        status = h.getModelStatus()
        if status in (highspy.HighsModelStatus.kInfeasible, highspy.HighsModelStatus.kUnboundedOrInfeasible):
            return SolveStatus.INFEASIBLE, ()
        assert status == highspy.HighsModelStatus.kOptimal, h.modelStatusToString(status)
        return SolveStatus.OPTIMAL, (round(h.getInfo().objective_function_value),)
    from ortools.sat.python import cp_model

    model = cp_model.CpModel()
    model.proto.parse_text_format(path.read_text(encoding="utf-8"))
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    status = solver.Solve(model)
    if status == cp_model.INFEASIBLE:
        return SolveStatus.INFEASIBLE, ()
    assert status == cp_model.OPTIMAL, solver.StatusName(status)
    return SolveStatus.OPTIMAL, (round(solver.ObjectiveValue()),)


@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize(("backend", "ext"), KINDS)
@pytest.mark.parametrize("name", PROBLEMS)
def test_every_export_reloads_to_the_same_optimum(
    name: str, backend: str, ext: str, encoding: str, tmp_path: Path
) -> None:
    problem = mrgc.parse_file(SYMBOLIC / f"{name}.mrg").problem()
    path = tmp_path / f"{name}.{ext}"
    horizon = mrgc.export_model(problem, path, backend=backend, encoding=encoding)
    want = reference(problem, backend, encoding, horizon)
    status, values = reload(path)
    assert status == want.status, (status, want)
    if status == SolveStatus.OPTIMAL:
        assert values == want.objective, (values, want.objective)


@pytest.mark.parametrize("name", ["chain-3", "medium", "handover"])
def test_the_default_model_is_the_first_skeletons(name: str, tmp_path: Path) -> None:
    """time-of-move in z3: the objectives are (makespan, objects moved), the first skeleton's key."""
    problem = mrgc.parse_file(SYMBOLIC / f"{name}.mrg").problem()
    first = mrgc.compile(problem, backend="smt").skeletons[0]
    path = tmp_path / "m.smt2"
    assert mrgc.export_model(problem, path, backend="smt") == first.makespan
    assert reload(path) == (SolveStatus.OPTIMAL, first.key)


def test_an_infeasible_problem_exports_the_horizon_limit(tmp_path: Path) -> None:
    problem = mrgc.parse_file(SYMBOLIC / "pick-cycle.mrg").problem()
    assert mrgc.compile(problem).status == "infeasible"
    horizon = mrgc.export_model(problem, tmp_path / "m.lp", backend="mip", encoding="paper")
    assert horizon == len(problem.movable) and reload(tmp_path / "m.lp")[0] == SolveStatus.INFEASIBLE


@pytest.mark.parametrize(("backend", "ext"), KINDS)
def test_the_horizon_option_chooses_the_model(
    backend: str, ext: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """medium: the first skeleton has makespan 3; the paper model of exactly 4 steps is another model."""
    target = tmp_path / f"m.{ext}"
    path = str(SYMBOLIC / "medium.mrg")
    assert (
        cli.main(
            ["compile", path, "--backend", backend, "--encoding", "paper", "--emit", str(target), "--horizon", "4"]
        )
        == 0
    )
    assert capsys.readouterr().out.splitlines()[-1] == f"model written to {target} (horizon 4)"
    problem = mrgc.parse_file(path).problem()
    four, three = reference(problem, backend, "paper", 4), reference(problem, backend, "paper", 3)
    assert reload(target) == (four.status, four.objective)
    assert len(four.values) > len(three.values)  # more steps, more variables: the option changed the model
    default = tmp_path / f"default.{ext}"
    assert mrgc.export_model(problem, default, backend=backend, encoding="paper") == 3
    assert default.read_bytes() != target.read_bytes() and reload(default) == (three.status, three.objective)


def test_a_horizon_below_one_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        cli.main(["compile", str(SYMBOLIC / "chain-3.mrg"), "--emit", str(tmp_path / "m.pbtxt"), "--horizon", "0"]) == 2
    )
    assert "error[E000]" in capsys.readouterr().err and not (tmp_path / "m.pbtxt").exists()
    with pytest.raises(mrgc.InputError):
        mrgc.export_model(SYMBOLIC / "chain-3.mrg", tmp_path / "m.pbtxt", horizon=0)


def test_goals_that_hold_at_the_start_have_no_model_to_export(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The first skeleton is empty: no model of a step or more has it as its optimum (the paper encoding's
    model of one step, written before, had no solution while compile said "optimal, makespan 0").  E304,
    nothing written; ``--horizon`` still writes the model of that many steps."""
    shutil.copy(SYMBOLIC / "domain.mrg", tmp_path / "domain.mrg")
    problem = tmp_path / "done.mrg"
    problem.write_text(
        "(define (problem done) (:domain abstract) (:robots r1) (:movable o1 o2) (:regions start goal)\n"
        "  (:init (in-region o1 goal) (in-region o2 start) (reachable-pick o1 top r1)\n"
        "    (reachable-place o1 goal top r1) (reachable-pick o2 top r1) (reachable-place o2 goal top r1))\n"
        "  (:goal (in-region o1 goal)))\n",
        encoding="utf-8",
    )
    doc = runpy.run_path(str(SYMBOLIC.parent.parent / "docs" / "build_errors_doc.py"), run_name="not_main")
    shown = doc["SPECIAL"]["E304"][1]
    for encoding in ("paper", "disaggregated"):
        target = tmp_path / f"{encoding}.lp"
        argv = ["compile", str(problem), "--backend", "mip", "--encoding", encoding, "--emit", str(target)]
        assert cli.main(argv) == 2
        err = capsys.readouterr().err
        assert err.strip() == shown.replace("paper", encoding) and not target.exists()  # docs/errors.md's example
        with pytest.raises(mrgc.InputError, match="E304"):
            mrgc.export_model(problem, target, backend="mip", encoding=encoding)
    # time-of-move's model of at most one step has the empty skeleton as its optimum: it is written
    target = tmp_path / "time-of-move.lp"
    assert mrgc.export_model(problem, target, backend="mip", encoding="time-of-move") == 1
    assert reload(target) == (SolveStatus.OPTIMAL, (0,))
    assert cli.main(["compile", str(problem), "--backend", "mip", "--emit", str(target), "--horizon", "1"]) == 0
    assert target.exists()


def test_the_smt2_script_has_no_option_z3_rejects(tmp_path: Path) -> None:
    path = tmp_path / "m.smt2"
    mrgc.export_model(SYMBOLIC / "chain-3.mrg", path, backend="smt")
    lines = path.read_text(encoding="utf-8").splitlines()
    assert not any("opt.random_seed" in line for line in lines)
    assert "(set-option :random-seed 0)" in lines and lines[-2:] == ["(check-sat)", "(get-objectives)"]
    # the seed given is the seed written (it was always 0: the export made its backend without it)
    mrgc.export_model(SYMBOLIC / "chain-3.mrg", path, backend="smt", seed=7)
    assert "(set-option :random-seed 7)" in path.read_text(encoding="utf-8").splitlines()


@pytest.mark.parametrize("ext", ["lp", "mps"])
def test_an_lp_or_mps_export_maps_the_names_it_changed_back_to_the_model_s(tmp_path: Path, ext: str) -> None:
    """Two model names that differ only in a character the file format does not allow (``o+1``, ``op1``) get
    unique legal names in the file, and comment lines at its top say which is which; HiGHS still reads the
    file and finds the same optimum."""
    from mrgc.compiler.ir import SkeletonModel

    m = SkeletonModel(name="names")
    a, b = m.bool_var("o+1"), m.bool_var("op1")
    m.add([(a, 1), (b, 1)], lo=1, name="one of(o+1,op1)")
    m.objectives.append(((a, 2), (b, 1)))
    solver = backend_class("mip")()
    solver.load(m)
    path = tmp_path / f"names.{ext}"
    solver.export(str(path))
    comment = "*" if ext == "mps" else "\\"
    lines = [line for line in path.read_text(encoding="utf-8").splitlines() if line.startswith(comment + "   ")]
    table = dict(line[len(comment) + 3 :].split(" = ", 1) for line in lines)
    # o+1 became op1, so the model's own op1 is op1_2 in the file: the table says which is which
    assert table == {"col op1": "o+1", "col op1_2": "op1", "row one_of_op1_op1__0": "one of(o+1,op1) (row 0)"}, lines
    assert reload(path) == (SolveStatus.OPTIMAL, (1,))


def test_an_export_highs_wrote_nothing_of_is_reported_as_such(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """When HiGHS leaves no file (or an empty one), the name table is not written on top of nothing: the export
    fails with its own error, not a FileNotFoundError or a file of comments alone."""
    from mrgc.backends.highs import HighsBackend
    from mrgc.compiler.ir import SkeletonModel
    from mrgc.errors import MrgcError

    m = SkeletonModel(name="names")
    a = m.bool_var("o+1")
    m.objectives.append(((a, 1),))
    for leaves in ("nothing", "empty"):
        solver = backend_class("mip")()
        solver.load(m)
        path = tmp_path / f"{leaves}.lp"
        empty = leaves == "empty"
        monkeypatch.setattr(
            HighsBackend, "_write", lambda self, p, empty=empty: Path(p).write_text("") if empty else None
        )
        with pytest.raises(MrgcError, match="wrote nothing"):
            solver.export(str(path))
