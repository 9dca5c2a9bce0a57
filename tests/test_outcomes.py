"""Every way `mrgc plan` can end, each with its status, exit code and reasons; M* as the paper defines it;
the validator as the referee inside the search."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Iterator

import numpy as np
import pytest
from support import ROOT, run_cli

from mrgc import __version__, cli, parse_file
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.answers import BUSY, Answer, GroundStatus
from mrgc.geometry.collision import CollisionShape, Packed, Posed, collision_shape
from mrgc.geometry.stances import Stance
from mrgc.language.model import Box
from mrgc.planfile.format import PlannedAction, file_sha256
from mrgc.planner.ground import GroundedStep, Outcome, ReverseGrounder
from mrgc.planner.outcome import EXIT_CODES, PlanStatus
from mrgc.planner.search import plan_problem

PA3 = (ROOT / "domains" / "packaging" / "pa3-handover.mrg").read_text(encoding="utf-8")


def run_plan(tmp_path: Path, text: str, *extra: str) -> tuple[int, dict[str, Any], str]:
    src = tmp_path / "p.mrg"
    src.write_text(text, encoding="utf-8")
    (tmp_path / "domain.mrg").write_text(
        (ROOT / "domains" / "packaging" / "domain.mrg").read_text(encoding="utf-8"), encoding="utf-8"
    )
    out = tmp_path / "plan.json"
    proc = subprocess.run(
        [sys.executable, "-m", "mrgc.cli", "plan", str(src), "-o", str(out), *extra],
        capture_output=True,
        text=True,
        timeout=300,
    )
    data = json.loads(out.read_text(encoding="utf-8")) if out.exists() else {}
    return proc.returncode, data, proc.stdout + proc.stderr


def test_exit_codes_are_distinct_per_status() -> None:
    assert len(set(EXIT_CODES.values())) == len(PlanStatus) and EXIT_CODES[PlanStatus.SOLVED] == 0


# ------------------------------------------------------------------ infeasible by the facts
def test_a_blocking_cycle_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["plan", str(ROOT / "domains" / "symbolic" / "pick-cycle.mrg")]) == 1
    cap = capsys.readouterr()
    data = json.loads(cap.out)
    assert data["status"] == "infeasible" and data["steps"] == []
    (cycle,) = data["why"]["facts"]
    assert cycle.startswith("blocking cycle o1 -> o2 -> o1") and "top by r1" in cycle and "top by r2" in cycle
    assert "blocking cycle" in cap.err


def test_a_handover_with_the_wrong_grasps_names_pickers_placers_and_grasp_pairs(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """r1 picks o1 only by top, r2 places it only by top, and the only handover is side -> side."""
    assert cli.main(["plan", str(ROOT / "domains" / "symbolic" / "grasp-mismatch.mrg")]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "infeasible"
    assert data["why"]["facts"] == [
        "no robot that can pick o1 can also place it in goal, and no handover or relay of it is enabled (picked by r1 "
        "with top; placed in goal by r2 with top; handovers of it only between grasps side->side)"
    ]


def test_a_goal_nobody_can_reach_is_infeasible_with_the_missing_fact(tmp_path: Path) -> None:
    far = PA3.replace(
        "(bin-b :shape (box 0.2 0.2 0.3) :pose (-0.3 0.35 0.15 0))",
        "(bin-b :shape (box 0.2 0.2 0.3) :pose (-3 3.5 0.15 0))",
    )
    code, data, text = run_plan(tmp_path, far, "--time-limit", "60")
    assert code == 1 and data["status"] == "infeasible"
    # 3 m off the table its floor holds nothing up either: the layout's W277 comes first
    first, last = data["why"]["facts"]
    assert "W277 the floor of region 'bin-b'" in first and last == "no robot can reach goal region bin-b"
    assert "no robot can reach goal region bin-b" in text


def test_a_geometric_blocking_cycle_shows_the_bodies_and_the_depth(tmp_path: Path) -> None:
    """Two boxes 7 cm apart, each allowed only the side grasp whose approach comes through the other."""
    cycle = PA3.replace(
        """    (o1 :shape (box 0.05 0.05 0.12) :pose (0 -0.25 0.06 0))
    (o2 :shape (box 0.05 0.05 0.12) :pose (0.07 -0.25 0.06 0))
    (o3 :shape (box 0.05 0.05 0.12) :pose (-0.07 -0.25 0.06 0)))""",
        """    (o1 :shape (box 0.05 0.05 0.12) :pose (0 -0.25 0.06 0) :grasps (side-x+))
    (o2 :shape (box 0.05 0.05 0.12) :pose (0.07 -0.25 0.06 0) :grasps (side-x-)))""",
    ).replace("(:goal (in-region o1 bin-b))", "(:goal (and (in-region o1 bin-a) (in-region o2 bin-a)))")
    code, data, text = run_plan(tmp_path, cycle, "--time-limit", "60")
    assert code == 1 and data["status"] == "infeasible", text
    (found,) = data["why"]["cycles"]
    assert found["objects"] == ["o1", "o2"]
    for edge, blocker in zip(found["edges"], ["o2", "o1"]):
        assert edge["blocker"] == blocker
        match = re.search(rf"of r1 overlaps {blocker} by ([0-9.]+) mm", edge["how"])
        assert match and float(match.group(1)) > 1.0, edge["how"]
    assert "blocking cycle o1 -> o2 -> o1" in text and "overlaps" in text


def test_objects_waiting_for_each_other_with_alternatives_are_named(capsys: pytest.CaptureFixture[str]) -> None:
    """No single blocker is forced, so no blocking cycle: b1 blocks the doorway to the goal (every place of
    g1 and g2), and the carts leave the start room only through a doorway g1 or g2 stands in (r1's way to b1
    crosses g2, r2's crosses g1; no path avoids both, checked on a 1 cm x 128-heading lattice); g1 and g2
    may only move into the goal.  Generated: mrgc generate box-moving --robots 2 --goals 2 --others 3
    --seed 1016."""
    code, out, err = run_cli(capsys, "plan", ROOT / "tests" / "data" / "bo-doorways-wait.mrg", "--time-limit", "120")
    data = json.loads(out)
    assert code == 1 and data["status"] == "infeasible" and data["why"]["cycles"] == []
    (reason,) = data["why"]["facts"]
    assert reason.startswith("no order of moves exists for g1, g2 "), reason
    assert "b1 waits for g2 (the pick of side-x- by r1) or g1 (the pick of side-x- by r2)" in reason, reason
    assert "g1 waits for b1 (the place of side-y+ by r1" in reason, reason
    assert "no order of moves exists for g1, g2" in err


# ------------------------------------------------------------------ every skeleton tried
def test_facts_that_no_geometry_backs_exhaust_the_search(tmp_path: Path) -> None:
    """Facts claiming r1 can pick and place o1 with a grasp whose approach hits the table every time: the
    compiler finds skeletons, grounding fails each one, and the run says which check failed."""
    lying = PA3.replace(
        "(:goal (in-region o1 bin-b))",
        """(:init (in-region o1 start) (in-region o2 start)
           (in-region o3 start) (reachable-pick o1 side-x+ r2) (reachable-place o1 bin-b side-x+ r2))
    (:goal (in-region o1 bin-b))""",
    )
    code, data, text = run_plan(tmp_path, lying, "--time-limit", "60")
    assert code == 5 and data["status"] == "exhausted", text
    failures = data["why"]["grounding_failures"]
    assert failures and failures[0]["action"] == "r2 moves o1 to bin-b (side-x+)"
    assert failures[0]["check"].startswith("pick by r2:") and failures[0]["count"] >= 1
    assert "every skeleton" in data["why"]["summary"]


# ------------------------------------------------------------------ time limit, interrupt
def test_a_time_limit_names_itself(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["plan", str(ROOT / "domains" / "packaging" / "pa10.mrg"), "--time-limit", "0.05"]) == 3
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "time limit" and "time limit" in data["why"]["summary"]


@pytest.mark.parametrize(
    ("sig", "code", "word"), [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")]
)
def test_a_signal_during_the_search_reports_and_writes_nothing(tmp_path: Path, sig: int, code: int, word: str) -> None:
    out = tmp_path / "plan.json"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "mrgc.cli",
            "plan",
            str(ROOT / "domains" / "box-moving" / "bo8-two-doors.mrg"),
            "-o",
            str(out),
            "-v",
            # the search goes on after its first plan (found by the first grounding here), so the signal sent
            # after the first log line lands in the search, not in the few milliseconds after it (a race CI met)
            "--anytime",
            "--time-limit",
            "100",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    first = proc.stderr.readline()  # the first search log line: the search is running
    assert first.startswith("[t="), first
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == code, stderr
    assert word in stderr and "no plan file written" in stderr and "skeletons" in stderr
    assert not out.exists() and "Traceback" not in stderr


def test_a_signal_after_the_search_loop_still_reports_the_search_so_far(monkeypatch: pytest.MonkeyPatch) -> None:
    """A signal that lands while the search is being concluded (the plan found, its statistics being
    gathered) ends the run as interrupted with the search's counts, not as an empty run."""
    from mrgc.planner import search

    real, calls = search._Timing.of, []

    def interrupted_once(self: Any, steps: Any) -> dict[str, int]:
        calls.append(steps)
        if len(calls) == 1:
            raise KeyboardInterrupt
        return real(self, steps)

    monkeypatch.setattr(search._Timing, "of", interrupted_once)
    path = ROOT / "domains" / "packaging" / "pa3-handover.mrg"
    problem = parse_file(path).problem()
    plan = plan_problem(problem, str(path), file_sha256(str(path)), __version__, seed=1)
    assert len(calls) == 2 and plan.status == "interrupted"
    assert plan.stats["skeletons"] >= 1 and plan.stats["groundings"] >= 1 and plan.stats["makespan"] >= 1


# ------------------------------------------------------------------ the validator inside the search
def test_every_solved_plan_carries_the_validators_verdict(tmp_path: Path) -> None:
    code, data, _ = run_plan(tmp_path, PA3, "--seed", "1")
    assert code == 0 and data["status"] == "solved"
    assert data["validation"]["valid"] is True and data["validation"]["plans_checked"] >= 1


def test_a_plan_the_validator_rejects_is_a_failure_fed_back() -> None:
    from mrgc.planner.outcome import Why
    from mrgc.planner.plan import Plan
    from mrgc.planner.referee import Referee

    path = ROOT / "domains" / "packaging" / "pa3-handover.mrg"
    problem = parse_file(path).problem()
    plan = plan_problem(problem, str(path), file_sha256(str(path)), __version__, seed=1)
    assert plan.status == "solved"
    action = plan.steps[0][0]
    assert action.place_pose is not None
    moved = [row[:] for row in action.place_pose]
    moved[2][3] += 0.12  # released 12 cm higher than its place configuration puts it
    action.place_pose = moved
    why = Why()
    shell = Plan(problem.name, str(path), file_sha256(str(path)), __version__, "cpsat", "time-of-move", 1, "solved")
    failure = Referee(problem, shell, why)([[action]])  # the harness's referee, as every planner calls it
    assert failure is not None and why.rejected_plans == 1
    assert failure.check == "grasp" and failure.step == 1 and failure.action.startswith("validator (")


# ------------------------------------------------------------------ M* as the paper defines it
class ScriptedGrounder:
    """Answers the reverse grounder's geometric queries from a script: picks of an object fail while any
    object of ``blocked_by[obj]`` must be avoided; volumes are tokens (a shape each, at the origin), and
    ``hits`` reads them."""

    def __init__(
        self,
        movable: list[str],
        blocked_by: dict[str, set[str]],
        sweeps: dict[str, set[str]],
        crowded: frozenset[str] = frozenset(),
    ) -> None:
        self.scene = SimpleNamespace(
            movable=[SimpleNamespace(name=m) for m in movable], handover_of={}, handover_points={}
        )
        self.blocked_by, self.sweeps = blocked_by, sweeps
        self.crowded = crowded  # objects whose pick collides with whatever another robot of the step sweeps
        self.poses = {m: np.eye(4) for m in movable}
        self.steps: list[list[str]] = []
        self.cut = False  # no query of the script stops at a deadline
        self.tokens: dict[str, CollisionShape] = {}
        self.named: dict[int, str] = {}  # a token's shape (its id) -> its name
        self.asked: list[tuple[str, str, object]] = []  # (query, object, its avoid or its key), in order
        self.busy: list[tuple[str, bool]] = []  # each pick's object and whether it kept clear of others' sweeps

    def token(self, name: str) -> CollisionShape:
        """The shape standing for token ``name`` (one per name: boxes of distinct sizes)."""
        if name not in self.tokens:
            shape = self.tokens[name] = collision_shape(Box(0.01 * (1 + len(self.tokens)), 0.01, 0.01))
            self.named[id(shape)] = name
        return self.tokens[name]

    def robot(self, robot: str) -> Any:
        return SimpleNamespace(approaches=True, parks=False)  # the script's robots are arms

    def step(self, roles: Any, full: bool = False) -> None:
        self.steps.append(sorted(roles))  # the script has no arms at home: only the step's robots are recorded

    def stance(self, robot: str, phase: str) -> Stance:
        return Stance.HOME  # the script's arms never stand anywhere else (nothing to keep clear of)

    @contextmanager
    def standing(self, robot: str, where: Any) -> Iterator[None]:
        yield

    def pick(self, robot: str, obj: str, grasp: str, avoid: Any = (), busy: Any = (), after: Any = ()) -> Answer:
        self.asked.append(("pick", obj, frozenset(avoid)))
        self.busy.append((obj, bool(busy)))
        hit = self.blocked_by.get(obj, set()) & set(avoid)
        if hit:
            return Answer(GroundStatus.COLLISION, blockers=hit)
        if obj in self.crowded and busy:
            return Answer(GroundStatus.COLLISION, detail=BUSY)
        return Answer(GroundStatus.OK, configs=np.array([[0.0], [1.0]]))

    def place(
        self, robot: str, obj: str, grasp: str, pose: np.ndarray, avoid: Any = (), busy: Any = (), after: Any = ()
    ) -> Answer:
        return Answer(GroundStatus.OK, configs=np.array([[1.0], [0.0]]))

    def transfer(
        self,
        robot: str,
        obj: str,
        grasp: str,
        start: np.ndarray,
        goal: np.ndarray,
        avoid: Any = (),
        lift: bool = False,
        busy: Any = (),
        partner: Any = None,
        lower: bool = False,
        **where: Any,  # the phase and what stands in it: the script's paths are free anyway
    ) -> Answer:
        return Answer(GroundStatus.OK, path=[np.asarray(start), np.asarray(goal)])

    def placement(
        self,
        obj: str,
        region: str,
        avoid: Any = (),
        volume: Any = None,
        key: str = "",
        skip: int = 0,
        packed: bool = False,
    ) -> Answer:
        return Answer(GroundStatus.OK, pose=np.eye(4))

    def placements(
        self,
        obj: str,
        region: str,
        avoid: Any = (),
        volume: Any = None,
        key: str = "",
        packed: bool = False,
        prefer: Any = None,
        samples: int = 200,
    ) -> Any:
        self.asked.append(("placement", obj, key))
        yield np.eye(4)

    def comfortable(self, robot: str, obj: str, grasp: str) -> Any:
        return lambda poses: np.zeros(len(poses))

    def out_of_reach(self, robot: str, obj: str, grasp: str) -> Any:
        return lambda pose: False

    def crowded_out(
        self, objs: Any, region: str, avoid: Any = (), volume: Any = None, key: str = "", extra: Any = ()
    ) -> str | None:
        return None

    def arm_volume(self, robot: str, configs: np.ndarray, holding: Any = None, grasp: Any = None) -> list[Any]:
        return [(self.token(f"arm:{robot}:{holding[0] if holding else ''}"), np.eye(4))]

    def volumes(self, robot: str, configs: np.ndarray, holding: Any = None, fingers: Any = None) -> list[Any]:
        return [self.arm_volume(robot, configs, holding, fingers)]  # one token volume for the whole motion

    def shape(self, obj: str) -> CollisionShape:
        return self.token(f"shape:{obj}")

    def hits(self, volume: Any, among: Any = "movable", ignore: Any = ()) -> set[str]:
        shapes = [volume.shapes[k] for k in volume.kind] if isinstance(volume, Posed) else [s for s, _ in volume]
        out: set[str] = set()
        for shape in shapes:
            out |= self.sweeps.get(self.named[id(shape)], set())
        return out & set(among)


def test_m_star_keeps_the_blockers_of_an_older_suffix() -> None:
    """The suffix S (placing goal g) sweeps through b.  A skeleton meant to move b (step 1) and c (step 2)
    grounds c only with d out of the way: S' = [c] + S, and M* must still hold b (hit by S, not by c)."""
    movable = ["g", "b", "c", "d"]
    sweeps = {"suffix-volume": {"b"}, "arm:r1:": {"d"}}
    grounder = ScriptedGrounder(movable, blocked_by={"c": {"d"}}, sweeps=sweeps)
    reverse = ReverseGrounder(grounder, {"g": "goal"})  # type: ignore[arg-type]
    swept = Posed.of([(grounder.token("suffix-volume"), np.eye(4))])
    suffix = [GroundedStep([PlannedAction("g", "goal", "r1", "r1", "top", "top")], Packed.of(swept), ("g",))]
    skeleton = Skeleton(
        ((Action("b", "start", "r1", "r1", "top", "top"),), (Action("c", "start", "r1", "r1", "top", "top"),))
    )
    result = reverse.ground(skeleton, suffix)
    assert result.outcome is Outcome.PARTIAL
    assert [s.moved for s in result.steps] == [("c",), ("g",)]
    assert result.must_move == {"b", "d"}  # b from the older suffix, d from this call's step
    (failure,) = result.failures
    assert failure.step == 2 and failure.check.startswith("pick by r1") and failure.bodies == ("d",)


def test_a_step_whose_robots_collide_is_split(monkeypatch: pytest.MonkeyPatch) -> None:
    """r1 and r2 pick a and b in one skeleton step, but b's pick collides with what r1 sweeps meanwhile: the
    step is grounded as two (b alone one step later), keeping the skeleton's actions; the grounder was told
    each time which arms pick and place in the step (arms of the step are not at home then)."""
    import mrgc.planner.ground as ground_module

    # the script's volumes are tokens: the sample-paired check of the step's robots says what the script
    # says, they collide while picking
    monkeypatch.setattr(ground_module, "_phases_collide", lambda a, b: "pick" if "pick" in a and "pick" in b else "")
    grounder = ScriptedGrounder(["a", "b"], blocked_by={}, sweeps={}, crowded=frozenset({"b"}))
    reverse = ReverseGrounder(grounder, {"a": "goal", "b": "goal"})  # type: ignore[arg-type]
    skeleton = Skeleton(
        ((Action("a", "goal", "r1", "r1", "top", "top"), Action("b", "goal", "r2", "r2", "top", "top")),)
    )
    result = reverse.ground(skeleton, [])
    assert result.outcome is Outcome.SUCCESS
    assert [s.moved for s in result.steps] == [("a",), ("b",)]
    assert [a.object for s in result.steps for a in s.actions] == ["a", "b"]
    assert grounder.steps[0] == ["r1", "r2"]  # the whole step first
    assert ["r2"] in grounder.steps and ["r1"] in grounder.steps
    assert grounder.steps[-1] == []  # forgotten after each step
    # each part kept clear of the whole step's other objects and drew with the step's key, as the unsplit
    # step did: an action in the same place of a part asks the same questions (remembered answers)
    picks = [(obj, avoid) for query, obj, avoid in grounder.asked if query == "pick"]
    assert {obj for obj, _ in picks} == {"a", "b"} and len(picks) > 2
    assert all({"a", "b"} - {obj} <= avoid for obj, avoid in picks)  # type: ignore[operator]
    keys = {obj: {key for query, o, key in grounder.asked if query == "placement" and o == obj} for obj in "ab"}
    assert all(len(k) == 1 for k in keys.values()), keys


@pytest.mark.parametrize("clash", [False, True])
def test_an_action_keeps_clear_of_the_others_whole_sweep_only_after_a_clash(
    monkeypatch: pytest.MonkeyPatch, clash: bool
) -> None:
    """Each action of a step is grounded first as if the step's other robots were not there (the sample-paired
    comparison decides); only when that comparison finds a clash is it grounded again keeping clear of all
    they sweep, and kept when that one passes the comparison."""
    import mrgc.planner.ground as ground_module

    compared: list[bool] = []

    def phases_collide(a: Any, b: Any) -> str:  # the first comparison of b's pick clashes (when asked to)
        compared.append(True)
        return "pick" if clash and len(compared) == 1 else ""

    monkeypatch.setattr(ground_module, "_phases_collide", phases_collide)
    grounder = ScriptedGrounder(["a", "b"], blocked_by={}, sweeps={})
    reverse = ReverseGrounder(grounder, {"a": "goal", "b": "goal"})  # type: ignore[arg-type]
    skeleton = Skeleton(
        ((Action("a", "goal", "r1", "r1", "top", "top"), Action("b", "goal", "r2", "r2", "top", "top")),)
    )
    result = reverse.ground(skeleton, [])
    assert result.outcome is Outcome.SUCCESS and [s.moved for s in result.steps] == [("a", "b")]
    assert grounder.busy == ([("a", False), ("b", False), ("b", True)] if clash else [("a", False), ("b", False)])


def test_a_step_is_not_split_for_other_failures(monkeypatch: pytest.MonkeyPatch) -> None:
    """A pick blocked by an avoided object is not a conflict between the step's robots: no split, M* grows."""
    import mrgc.planner.ground as ground_module

    monkeypatch.setattr(ground_module, "_phases_collide", lambda a, b: "")  # the script's volumes are tokens
    grounder = ScriptedGrounder(["a", "b", "c"], blocked_by={"b": {"c"}}, sweeps={"arm:r2:": {"c"}})
    reverse = ReverseGrounder(grounder, {"a": "goal", "b": "goal"})  # type: ignore[arg-type]
    skeleton = Skeleton(
        ((Action("a", "goal", "r1", "r1", "top", "top"), Action("b", "goal", "r2", "r2", "top", "top")),)
    )
    result = reverse.ground(skeleton, [])
    assert result.outcome is Outcome.PARTIAL and result.must_move >= {"c"}
    assert len(result.steps) == 1 and result.steps[0].moved == ("a", "b")


def test_a_grounding_stops_at_the_search_deadline() -> None:
    """Past the deadline a grounding stops before its next action (the search then ends at its time limit)."""
    import time

    from mrgc.planner.outcome import DeadlineReached

    grounder = ScriptedGrounder(["a"], blocked_by={}, sweeps={})
    skeleton = Skeleton(((Action("a", "goal", "r1", "r1", "top", "top"),),))
    late = ReverseGrounder(grounder, {"a": "goal"}, deadline=time.perf_counter() - 1.0)  # type: ignore[arg-type]
    with pytest.raises(DeadlineReached):
        late.ground(skeleton, [])
    early = ReverseGrounder(grounder, {"a": "goal"}, deadline=time.perf_counter() + 3600.0)  # type: ignore[arg-type]
    assert early.ground(skeleton, []).outcome is Outcome.SUCCESS
