"""Ap2, the paper's second baseline: a constraint-based task and motion planner for several manipulators
(Pan, Wells, Shome and Kavraki, IROS 2021, in the style of IDTMP: Dantam et al., RSS 2016).

Three layers, as that paper builds them:

1. **Task planner, optimal, on z3.**  The task is the project's own model: the collaborative manipulation
   task graph of the facts (:func:`~mrgc.compiler.task_graph.build_task_graph`, without relays: Ap2 moves
   each object once, by one robot or by a handover) in the paper's horizon-indexed encoding
   (:class:`~mrgc.compiler.encodings.paper.PaperEncoding`: one boolean per action and step, several
   manipulators acting in one step, each robot at most once per step), solved by z3's Optimize through the
   ``smt`` backend.  Iterative deepening: horizon T = ceil(|M*| / |robots|), T+1, ... up to the horizon
   limit; at each horizon the model's optimum (exactly T steps, then the fewest moved objects) is the next
   task plan.
2. **Motion failures become constraints.**  Each task plan is grounded *forwards*, step by step in time
   order (:class:`ForwardSteps`): the objects moved so far stand at their new placements, placements are
   sampled in the target region with the project's grasps, IK, collision checks and handover points
   (:meth:`ReverseGrounder.ground_step <mrgc.planner.ground.ReverseGrounder.ground_step>`, with nothing
   later to keep clear of).  When step t cannot be grounded, the task-plan prefix that led there (steps
   1..t as z3 chose them) is forbidden by a no-good row added to the loaded model (:class:`TaskPlanner`:
   z3's incremental ``add``; the model of a horizon is built once, and a new horizon's model starts with
   every no-good learnt so far).  A complete plan the referee rejects is forbidden whole.
3. **The scheduler** (:class:`Scheduler`), between the two: before a failure goes back to z3, the failing
   step is grounded again with other robot assignments of the same actions (the same objects to the same
   regions, by other robots, grasps or handovers, each robot once in the step), up to
   :data:`REASSIGNMENTS` of them.

Packaging only (as the paper: "Ap2 is restricted to manipulators"): a problem with planar robots is refused
(exit code 2).  Deterministic: z3's seed is the run's, and each step's random stream is keyed by the task
plan's prefix, so nothing but the time limit reads the clock.  Decisions the papers leave open:
docs/baselines.md, "Ap2".
"""

from __future__ import annotations

import hashlib
import itertools
import math
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Sequence

from mrgc.compiler.encodings.paper import PaperEncoding
from mrgc.compiler.ir import SkeletonModel, SolveStatus
from mrgc.compiler.skeleton import Skeleton, skeleton_from_schedule
from mrgc.compiler.task_graph import Action, TaskGraph, build_task_graph
from mrgc.errors import Diagnostic, InputError
from mrgc.planner.method import HORIZON_LIMIT, Context, Planner, Result
from mrgc.planner.outcome import DeadlineReached, Failure, PlanStatus

if TYPE_CHECKING:
    from mrgc.compiler.encodings.base import Encoded
    from mrgc.compiler.facts import FactBase
    from mrgc.compiler.ir import Row, Solver
    from mrgc.language.model import Problem
    from mrgc.planfile.format import PlannedAction

#: alternate robot assignments the scheduler grounds per failing step before the task planner is asked again
REASSIGNMENTS = 8

#: a task plan's decision: (action index, step), steps counted from 1
Decision = tuple[int, int]


def without_relays(graph: TaskGraph) -> TaskGraph:
    """``graph`` without its relay actions (Ap2 moves each object once, by one action)."""
    keep = [i for i, a in enumerate(graph.actions) if a.via is None]
    return replace(
        graph,
        actions=tuple(graph.actions[i] for i in keep),
        block_pick=tuple(graph.block_pick[i] for i in keep),
        block_place=tuple(graph.block_place[i] for i in keep),
    )


class _Encoding(PaperEncoding):
    """The paper's encoding, keeping the step variables X[a]@t of the model it builds (for the no-goods)."""

    def __init__(self) -> None:
        self.steps: list[list[int]] = []

    def precedence(
        self, m: SkeletonModel, graph: TaskGraph, X: list[list[int]], of: dict[str, list[int]], T: int
    ) -> None:
        """The paper's precedence rows; the variables are kept."""
        self.steps = X
        super().precedence(m, graph, X, of, T)


@dataclass
class TaskPlan:
    """A task plan z3 found: its skeleton and its decisions, step by step (action indices)."""

    skeleton: Skeleton
    steps: list[list[int]]

    def prefix(self, t: int) -> tuple[Decision, ...]:
        """The decisions of steps 1..t."""
        return tuple((a, s) for s in range(1, t + 1) for a in self.steps[s - 1])


class TaskPlanner:
    """The optimal task planner: the horizon-indexed model on z3, iterative deepening, no-goods added
    incrementally (see the module docstring)."""

    def __init__(self, graph: TaskGraph, seed: int = 0, max_makespan: int | None = None) -> None:
        from mrgc.compiler.diagnose import prune

        self.graph = prune(without_relays(graph))
        self.seed = seed
        objects = max(1, len(self.graph.objects))
        self.limit = min(max_makespan, objects) if max_makespan is not None else objects
        robots = max(1, len(self.graph.robots))
        self.horizon = max(1, math.ceil(len(self.graph.must_move) / robots))
        self.nogoods: list[tuple[Decision, ...]] = []
        self.solver: Solver | None = None
        self.encoded: Encoded | None = None
        self.encoding = _Encoding()
        self.stats: dict[str, float] = {"task_solves": 0, "task_seconds": 0.0, "horizons": 0, "nogoods": 0}

    def next(self, deadline: float) -> TaskPlan | None:
        """The next task plan: the optimum of the smallest horizon with one left (None: no horizon up to the
        limit has one).  Raises :class:`DeadlineReached` when z3 ran out of time."""
        if not self.graph.must_move:  # nothing to move: the empty plan, once
            self.horizon, done = self.limit + 1, self.horizon > self.limit
            return None if done else TaskPlan(Skeleton(()), [])
        while self.horizon <= self.limit:
            if self.solver is None:
                self._load()
            assert self.solver is not None and self.encoded is not None
            left = deadline - time.perf_counter()
            if left <= 0:
                raise DeadlineReached()
            sol = self.solver.solve(left)
            self.stats["task_solves"] += 1
            self.stats["task_seconds"] += sol.seconds
            if sol.status is SolveStatus.OPTIMAL:
                return self._decode(sol.values)
            if sol.status is not SolveStatus.INFEASIBLE:
                raise DeadlineReached()
            self.horizon += 1
            self.solver = None
        return None

    def forbid(self, decisions: tuple[Decision, ...]) -> None:
        """Never again these decisions together (a failed prefix): a no-good row in the loaded model now, and
        in the model of every later horizon."""
        self.nogoods.append(decisions)
        self.stats["nogoods"] += 1
        if self.solver is not None:
            row = self._row(decisions, len(self.nogoods) - 1)
            if row is not None:
                self.solver.add_rows([row])

    def _load(self) -> None:
        from mrgc.backends.registry import backend_class

        self.encoded = self.encoding.build(self.graph, self.horizon)
        self.solver = backend_class("smt")(seed=self.seed)
        self.solver.load(self.encoded.model)
        rows = [r for i, d in enumerate(self.nogoods) if (r := self._row(d, i)) is not None]
        if rows:
            self.solver.add_rows(rows)
        self.stats["horizons"] += 1

    def _row(self, decisions: tuple[Decision, ...], i: int) -> Row | None:
        """``not all of decisions`` in this horizon's model (None when a decision's step is past the horizon:
        the model cannot take them all anyway).  Action a at step s is X[a]@s and not X[a]@(s+1)."""
        from mrgc.compiler.ir import Row

        X, T = self.encoding.steps, self.horizon
        if any(s > T for _, s in decisions):
            return None
        ones = [X[a][s - 1] for a, s in decisions]
        zeros = [X[a][s] for a, s in decisions if s < T]
        terms = tuple([(v, 1) for v in ones] + [(v, -1) for v in zeros])
        return Row(terms, hi=len(ones) - 1, name=f"nogood{i}")

    def _decode(self, values: Sequence[int]) -> TaskPlan:
        X = self.encoding.steps
        schedule = [(a, sum(values[v] for v in X[a])) for a in range(len(X)) if values[X[a][0]]]
        steps: list[list[int]] = [[] for _ in range(self.horizon)]
        order = {o: k for k, o in enumerate(self.graph.objects)}
        for a, s in sorted(schedule, key=lambda d: (d[1], order[self.graph.actions[d[0]].obj])):
            steps[s - 1].append(a)
        return TaskPlan(skeleton_from_schedule(self.graph, schedule), steps)


class ForwardSteps:
    """Joint actions grounded forwards in time (see the module docstring): objects moved by the steps
    grounded so far stand at their placements; placements avoid every other object where it stands."""

    def __init__(self, context: Context, deadline: float) -> None:
        from mrgc.geometry.grounding import Grounder
        from mrgc.geometry.scene import scene_from_problem
        from mrgc.planner.ground import ReverseGrounder

        problem = context.problem
        self.grounder = Grounder(scene_from_problem(problem), seed=context.seed)
        self.ground_steps = ReverseGrounder(self.grounder, problem.goal_regions, full=context.full, deadline=deadline)
        self.movable = {m.name for m in problem.movable}

    def ground(
        self, actions: tuple[Action, ...], done: list[list[PlannedAction]], key: str, index: int
    ) -> list[PlannedAction] | Failure:
        """Ground ``actions`` as step ``index`` after the steps ``done``."""
        import numpy as np

        from mrgc.planner.ground import swept

        poses = {a.object: np.array(a.place_pose) for step in done for a in step if a.place_pose is not None}
        same = {a.obj for a in actions}
        with self.grounder.moved(poses):
            self.ground_steps.grounded = set(poses)
            got = self.ground_steps.ground_step(actions, self.movable - same, swept(()), key, index)
        if self.grounder.cut:
            raise DeadlineReached()
        return got if isinstance(got, Failure) else got.actions


class SymbolicSteps:
    """A symbolic problem's steps: the task model holds the facts' obstacles, so a step is what it says."""

    def ground(
        self, actions: tuple[Action, ...], done: list[list[PlannedAction]], key: str, index: int
    ) -> list[PlannedAction] | Failure:
        """The step's actions, without geometry."""
        from mrgc.planner.search import planned_action

        return [planned_action(a) for a in actions]


@dataclass
class Scheduler:
    """Between task and motion planner: grounds a task plan's step, and when it fails, the same actions with
    other robot assignments (see the module docstring)."""

    graph: TaskGraph
    steps: ForwardSteps | SymbolicSteps
    one_handover: bool = False
    stats: dict[str, int] = field(default_factory=lambda: {"groundings": 0, "reassignments": 0, "reassigned": 0})

    def alternatives(self, step: Sequence[int]) -> list[tuple[Action, ...]]:
        """The other robot assignments of the actions ``step`` (indices): each action replaced by one moving
        the same object to the same region (itself first), the robots of the step all different, at most one
        handover when there is one handover point; in the graph's order, up to :data:`REASSIGNMENTS`."""
        acts = [self.graph.actions[i] for i in step]
        choices = [
            [a] + [b for b in self.graph.actions if b.obj == a.obj and b.region == a.region and b != a] for a in acts
        ]
        out: list[tuple[Action, ...]] = []
        for combo in itertools.product(*choices):
            robots = [r for b in combo for r in b.robots]
            if combo == tuple(acts) or len(robots) != len(set(robots)):
                continue
            if self.one_handover and sum(b.handover for b in combo) > 1:
                continue
            out.append(combo)
            if len(out) >= REASSIGNMENTS:
                break
        return out

    def ground(
        self, step: Sequence[int], done: list[list[PlannedAction]], key: str, index: int
    ) -> tuple[list[PlannedAction] | None, Failure | None]:
        """The grounded step (None when no assignment grounds) and the failure of the task plan's own."""
        first: Failure | None = None
        own = tuple(self.graph.actions[i] for i in step)
        for k, actions in enumerate([own, *self.alternatives(step)]):
            self.stats["groundings"] += 1
            self.stats["reassignments"] += k > 0
            got = self.steps.ground(actions, done, f"{key}:{k}", index)
            if not isinstance(got, Failure):
                self.stats["reassigned"] += k > 0
                return got, first
            first = first or got
        return None, first


class Ap2(Planner):
    """Ap2 as a planning method (see the module docstring)."""

    name = "ap2"
    title = "baseline Ap2: optimal task planning on z3 (IDTMP style) with a scheduler"
    options = (HORIZON_LIMIT,)
    exhausted = "every task plan up to the horizon limit was tried; none could be grounded into a valid plan"

    def check(self, problem: Problem) -> None:
        """Refuse planar-base robots (the paper's Ap2 plans for manipulators only)."""
        kinds = {k.name: k.base for k in problem.domain.robot_kinds}
        planar = [r.name for r in problem.robots if r.kind is not None and kinds.get(r.kind) == "planar"]
        if planar:
            raise InputError(
                [
                    Diagnostic(
                        "E000",
                        f"the ap2 planner plans for manipulators only (as the paper's Ap2); problem {problem.name} "
                        f"has planar-base robots ({', '.join(planar)}): use --planner mcts or ap1",
                    )
                ]
            )

    def solve(self, context: Context, deadline: float) -> Result:
        """Task plans from z3, each grounded forwards through the scheduler; failures back as no-goods."""
        from mrgc.compiler.diagnose import explain_infeasible

        graph = build_task_graph(context.base, context.goals)
        reasons = explain_infeasible(graph, context.base)
        if reasons:
            context.why.facts = reasons
            return Result(PlanStatus.INFEASIBLE)
        tasks = TaskPlanner(graph, context.seed, context.options["max_makespan"])
        steps: ForwardSteps | SymbolicSteps = (
            SymbolicSteps() if context.problem.symbolic else ForwardSteps(context, deadline)
        )
        scheduler = Scheduler(tasks.graph, steps, one_handover=_one_handover(context.base))
        search = _Search(context, tasks, scheduler)
        try:
            found = search.run(deadline)
            status = PlanStatus.SOLVED if found is not None else PlanStatus.EXHAUSTED
        except DeadlineReached:
            found, status = None, PlanStatus.TIME_LIMIT
        except KeyboardInterrupt:  # the statistics of the search so far are kept
            found, status = None, PlanStatus.INTERRUPTED
        stats: dict[str, Any] = {k: round(v, 4) if isinstance(v, float) else int(v) for k, v in tasks.stats.items()}
        stats.update(scheduler.stats, task_plans=search.plans)
        if isinstance(steps, ForwardSteps):
            stats["geometric_queries"] = steps.grounder.queries
        if status is PlanStatus.EXHAUSTED and search.plans == 0:
            status = PlanStatus.INFEASIBLE  # no task plan at any horizon: the model itself is infeasible
            context.why.facts = ["no task plan exists under the facts within the horizon limit"]
        return Result(status, found, stats=stats)


def _one_handover(base: FactBase) -> bool:
    return base.handover_capacity == 1


@dataclass
class _Search:
    """The loop of the three layers (see the module docstring)."""

    context: Context
    tasks: TaskPlanner
    scheduler: Scheduler
    plans: int = 0

    def run(self, deadline: float) -> list[list[PlannedAction]] | None:
        """Task plans until one grounds and the referee accepts it (None: no task plan left)."""
        while True:
            plan = self.tasks.next(deadline)
            if plan is None:
                return None
            self.plans += 1
            done = self._ground(plan)
            if done is None:
                continue
            failure = self.context.referee(done)
            if failure is None:
                self._say(plan, f"plan found, makespan {len(done)}, valid")
                return done
            self.context.why.add(failure)
            self.tasks.forbid(plan.prefix(len(plan.steps)))
            self._say(plan, f"rejected by the validator: {failure.line()}")

    def _ground(self, plan: TaskPlan) -> list[list[PlannedAction]] | None:
        """The task plan grounded forwards (None: a step failed, and its prefix is forbidden)."""
        done: list[list[PlannedAction]] = []
        for t, step in enumerate(plan.steps, 1):
            key = hashlib.sha256(repr(plan.prefix(t)).encode()).hexdigest()[:16]
            got, failure = self.scheduler.ground(step, done, key, t)
            if got is None:
                assert failure is not None
                self.context.why.add(failure)
                self.tasks.forbid(plan.prefix(t))
                self._say(plan, f"fails at {failure.line()}; prefix of {t} step(s) forbidden")
                return None
            done.append(got)
        return done

    def _say(self, plan: TaskPlan, what: str) -> None:
        elapsed = time.perf_counter() - self.context.started
        moves = len(plan.skeleton.moved)
        self.context.log(
            f"[t={elapsed:.1f}s] task plan {self.plans} (horizon {self.tasks.horizon}, {moves} moves): {what}"
        )
