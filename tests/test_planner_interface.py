"""The planner interface (planner/method.py, harness.py, registry.py): a method is a class and one registry
line; the harness gives it phase 1, the referee, statuses, summary and statistics; ``mrgc plan`` takes the
options it declares (typed, bounded) and refuses them for the other methods."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from support import ROOT

from mrgc import cli
from mrgc.planner import registry
from mrgc.planner.method import Context, Option, Planner, Result
from mrgc.planner.outcome import PlanStatus
from mrgc.planner.search import planned_steps

CHAIN = str(ROOT / "domains" / "symbolic" / "chain-3.mrg")


class Toy(Planner):
    """Moves the goal objects one by one, each with its first action nothing obstructs (``--refuse``: finds
    nothing)."""

    name = "toy"
    title = "a test method"
    options = (
        Option("steps_cap", "count", 9, "at most this many steps", metavar="N"),
        Option("refuse", "flag", False, "find nothing"),
    )
    exhausted = "the toy found nothing"

    def solve(self, context: Context, deadline: float) -> Result:
        from mrgc.compiler.task_graph import actions_for

        if context.options["refuse"]:
            return Result(PlanStatus.EXHAUSTED, stats={"toy_steps": 0})
        base = context.base

        def free(o: str) -> Any:
            return next(a for a in actions_for(base, o) if not base.occludes_pick.get((o, a.pick_grasp, a.pick_robot)))

        steps = [planned_steps((free(o),))[0] for o in context.goals]
        steps = steps[: context.options["steps_cap"]]
        failure = context.referee(steps)
        return Result(PlanStatus.SOLVED if failure is None else PlanStatus.EXHAUSTED, steps if not failure else None)


@pytest.fixture()
def toy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(registry.PLANNERS, "toy", f"{__name__}:Toy")


def test_a_new_method_is_a_class_and_a_registry_line(toy: None, tmp_path: Path) -> None:
    out = tmp_path / "plan.json"
    assert cli.main(["plan", CHAIN, "--planner", "toy", "--steps-cap", "3", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["status"] == "solved" and doc["stats"]["planner"] == "toy" and doc["validation"]["valid"]
    assert doc["backend"] == "none" and doc["why"]["summary"] == "solved"
    assert cli.main(["validate", CHAIN, str(out)]) == 0


def test_the_harness_gives_statuses_summaries_and_statistics(toy: None, tmp_path: Path, capsys: Any) -> None:
    out = tmp_path / "plan.json"
    assert cli.main(["plan", CHAIN, "--planner", "toy", "--refuse", "-o", str(out)]) == 5  # exhausted
    doc = json.loads(out.read_text())
    assert doc["status"] == "exhausted" and doc["why"]["summary"] == "the toy found nothing"
    assert doc["stats"]["toy_steps"] == 0 and {"robots", "facts", "seconds"} <= set(doc["stats"])


def test_declared_options_are_typed_and_belong_to_their_method(toy: None, capsys: Any) -> None:
    assert cli.main(["plan", CHAIN, "--planner", "toy", "--steps-cap", "many"]) == 2  # a count
    assert cli.main(["plan", CHAIN, "--planner", "mcts", "--refuse"]) == 2  # the toy's option
    assert cli.main(["plan", CHAIN, "--planner", "toy", "--anytime"]) == 2  # mcts' option
    err = capsys.readouterr().err
    assert "--refuse is not an option of the mcts planner" in err
    assert "--anytime is not an option of the toy planner" in err and "Traceback" not in err
    assert cli.main(["plan", "--help"]) == 0
    shown = capsys.readouterr().out
    assert "--steps-cap N" in shown and "(toy; default 9)" in shown and "--refuse" in shown


def test_the_defaults_have_one_home() -> None:
    """The planning method, backend, encoding and time limit used when nothing is given are
    planner/defaults.py's, wherever they are read: the API, both commands' parsers, the paper's method's
    declared options."""
    import inspect

    import mrgc.api as api
    from mrgc.commands import build_parser
    from mrgc.planner import defaults
    from mrgc.planner.search import Mcts

    plan = inspect.signature(api.plan).parameters
    assert plan["planner"].default == defaults.DEFAULT_PLANNER
    assert plan["time_limit"].default == defaults.DEFAULT_TIME_LIMIT
    compile_ = inspect.signature(api.compile).parameters
    assert (compile_["backend"].default, compile_["encoding"].default) == (
        defaults.DEFAULT_BACKEND,
        defaults.DEFAULT_ENCODING,
    )
    parser = build_parser()
    planned = parser.parse_args(["plan", CHAIN])
    assert (planned.planner, planned.time_limit) == (defaults.DEFAULT_PLANNER, defaults.DEFAULT_TIME_LIMIT)
    compiled = parser.parse_args(["compile", CHAIN])
    assert (compiled.backend, compiled.encoding) == (defaults.DEFAULT_BACKEND, defaults.DEFAULT_ENCODING)
    declared = {o.name: o.default for o in Mcts.options}
    assert (declared["backend"], declared["encoding"]) == (defaults.DEFAULT_BACKEND, defaults.DEFAULT_ENCODING)


def test_the_verbose_timing_line_shows_what_the_method_recorded() -> None:
    """``mrgc plan -v``'s line of times and counts: mcts' statistics as before, another method's own (Ap2's
    task plans), nothing a method did not record shown as zero."""
    from mrgc.commands import _timing_line

    mcts = {"seconds": 3.2, "facts_seconds": 1.1, "skeleton_seconds": 0.2, "grounding_seconds": 1.1}
    mcts |= {"skeletons": 5, "groundings": 1, "nodes": 1}
    assert (
        _timing_line(mcts)
        == "  3.20 s: facts 1.10 s, skeletons 0.20 s, grounding 1.10 s; 5 skeletons, 1 grounded, 1 nodes"
    )
    ap2 = {"seconds": 2.8, "facts_seconds": 0.8, "task_seconds": 0.02, "task_plans": 1, "groundings": 2}
    assert _timing_line(ap2) == "  2.80 s: facts 0.80 s, task plans 0.02 s; 1 task plans, 2 grounded"
    assert _timing_line({"seconds": 0.1, "facts_seconds": 0.0}) == "  0.10 s: facts 0.00 s"


def test_the_scene_is_built_once_per_problem(monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 25 ("built once"): the layout checks, phase 1, the method, the referee and the summary of one run
    share the problem's scene, which is immutable (poses read-only)."""
    import numpy as np

    import mrgc
    from mrgc.geometry import scene as scene_module

    built: list[str] = []
    build = scene_module._build

    def counted(problem: Any) -> Any:
        built.append(problem.name)
        return build(problem)

    monkeypatch.setattr(scene_module, "_build", counted)
    problem = mrgc.load_problem(ROOT / "domains" / "packaging" / "pa3-handover.mrg")
    plan = mrgc.plan(problem, seed=0, time_limit=120)
    assert plan.status is mrgc.PlanStatus.SOLVED, plan.summary()
    assert built == ["pa3-handover"]
    scene = scene_module.scene_from_problem(problem)
    assert scene is scene_module.scene_from_problem(problem) and built == ["pa3-handover"]
    with pytest.raises(ValueError):
        scene.movable[0].pose[0, 3] = 1.0
    assert not any(b.pose.flags.writeable for b in (*scene.movable, *scene.fixed, *scene.regions))
    # another problem object (parsed again) gets its own scene, equal in content
    again = scene_module.scene_from_problem(mrgc.load_problem(ROOT / "domains" / "packaging" / "pa3-handover.mrg"))
    assert again is not scene and built == ["pa3-handover", "pa3-handover"]
    assert all(np.array_equal(a.pose, b.pose) for a, b in zip(again.movable, scene.movable))
