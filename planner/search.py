"""The paper's method (``mrgc plan``, planner ``mcts``): the MCTS over task skeletons with reverse-search
grounding, as a :class:`~mrgc.planner.method.Planner` (the harness, :mod:`mrgc.planner.harness`, runs phase 1
before it and makes the Plan after it).

Symbolic problems have no geometry to ground: their plan is the best skeleton (documented in
docs/planner.md).  Every outcome is a :class:`~mrgc.planner.outcome.PlanStatus` on the plan, with its
reasons (:class:`~mrgc.planner.outcome.Why`) and statistics: time per phase, skeletons generated and
grounded, tree size, geometric queries.

**Nothing is solved until the validator says so.**  Each complete plan the search grounds is replayed by
the independent validator (the harness's referee, :mod:`mrgc.planner.referee`) before it is accepted; a
rejected plan is a grounding failure like any other (reward 0, memoised) and the search goes on.  The plan records the
verdict (``validation``).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Callable

from mrgc.compiler.enumerate import BatchOutcome
from mrgc.compiler.facts import FactBase
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action, TaskGraph
from mrgc.language.model import Problem
from mrgc.planfile.format import PlannedAction
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING
from mrgc.planner.deferral import Deferrals, describe
from mrgc.planner.method import HORIZON_LIMIT, Context, Option, Planner, Result
from mrgc.planner.outcome import BlockingCycle, PlanStatus, Why
from mrgc.planner.plan import Plan
from mrgc.planner.skeletons import SkeletonSource

if TYPE_CHECKING:  # the geometric modules load numpy and coal: a symbolic problem never imports them
    from mrgc.geometry.grounding import Grounder
    from mrgc.planner.ground import GroundedStep, Grounding
    from mrgc.planner.mcts import SearchResult

#: a search log line sink (``mrgc plan --verbose`` prints them)
Log = Callable[[str], None]


class Mcts(Planner):
    """The paper's method, ``mrgc plan`` without ``--planner`` (see the module docstring)."""

    name = "mcts"
    title = "the paper's method: skeletons + MCTS + reverse grounding"
    options = (
        Option("backend", "text", DEFAULT_BACKEND, "skeleton solver backend (mrgc backends)"),
        Option("encoding", "text", DEFAULT_ENCODING, "skeleton encoding: paper | disaggregated | time-of-move"),
        Option("skeletons", "count", 5, "skeletons per generator call", metavar="K"),
        HORIZON_LIMIT,
        Option("c", "number", 1.0, "PUCT exploration constant"),
        Option("alpha", "number", 1.0, "reward weight of fewer moved objects"),
        Option(
            "anytime",
            "flag",
            False,
            "keep searching after the first plan until the time limit; return the best (makespan, then objects moved)",
        ),
        Option("max_iterations", "count", 10_000, "the search's iteration limit", cli=False),
    )
    exhausted = "every skeleton the compiler could generate was tried; none could be grounded into a valid plan"

    def record(self, options: dict[str, Any]) -> tuple[str, str]:
        """The skeleton backend and encoding."""
        return str(options["backend"]), str(options["encoding"])

    def solve(self, context: Context, deadline: float) -> Result:
        """Symbolic problems: the best skeleton; geometric ones: the MCTS over skeletons."""
        o = context.options
        sources = _Sources(
            context.base,
            _order(context.problem),
            o["backend"],
            o["encoding"],
            o["max_makespan"],
            context.seed,
            deadline,
        )
        if context.problem.symbolic:
            result = _conclude_symbolic(context.why, sources(set(context.goals), set()), context.time_limit)
            result.stats["skeleton_seconds"] = round(time.perf_counter() - context.started - context.facts_seconds, 4)
            return result
        return _search(context, sources, deadline)


def plan_problem(problem: Problem, problem_file: str, sha256: str, version: str, **options: Any) -> Plan:
    """Plan ``problem`` with the paper's method (:class:`Mcts`) through the harness: ``options`` are the
    harness's (``seed``, ``time_limit``, ``log``, ``motions``, ``started``, ``facts``: see
    :func:`mrgc.planner.harness.run`) and :attr:`Mcts.options` (``backend``, ``encoding``, ``c``, ``alpha``,
    ``skeletons``, ``max_makespan``, ``anytime``, ``max_iterations``)."""
    from mrgc.planner.harness import run

    return run(Mcts(), problem, problem_file, sha256, version, **options)


def _search(context: Context, sources: _Sources, deadline: float) -> Result:
    """The MCTS over skeletons with reverse-search grounding, each complete plan judged by the referee."""
    from mrgc.geometry.grounding import Grounder
    from mrgc.geometry.scene import scene_from_problem
    from mrgc.planner.ground import Outcome, ReverseGrounder, draw_key
    from mrgc.planner.mcts import MCTS, SearchResult

    problem, o, why, say = context.problem, context.options, context.why, context.log
    grounder = Grounder(scene_from_problem(problem), seed=context.seed)
    reverse = ReverseGrounder(grounder, problem.goal_regions, full=context.full, deadline=deadline)
    count = [0]
    timing = _Timing()
    #: each grounding's draw key -> its number in the search (the log says "as grounding N")
    numbers: dict[str, int] = {}

    def ground(skel: Skeleton, suffix: list[GroundedStep]) -> Grounding:
        count[0] += 1
        key = draw_key(skel, suffix)
        numbers.setdefault(key, count[0])
        result = reverse.ground(skel, suffix, key=key, order=sources.order_of(skel))
        if result.repeats:
            result.repeats = str(numbers.get(result.repeats, result.repeats))
        timing.grounded(skel, suffix, result)
        if result.outcome is Outcome.SUCCESS:
            result = _referee(context, result)
        for f in result.failures:
            why.add(f)
        failed = result.outcome is Outcome.FAIL and bool(result.failures)
        deferred = sources.deferrals.failed(skel, result.failures[0]) if failed else None
        say(_log_line(time.perf_counter() - context.started, count[0], skel, suffix, result))
        if deferred is not None:
            why_deferred = sources.deferrals.reason(deferred)
            say(f"  deferred {why_deferred}: {describe(deferred)} (skeletons without it first)")
        if result.dead_end:
            say(f"  dead end: {result.dead_end}: no skeleton before those steps is grounded")
        return result

    search = MCTS(ground, sources, set(context.goals), c=o["c"], alpha=o["alpha"], k=o["skeletons"])
    result = search.run(deadline, max_iterations=o["max_iterations"], anytime=o["anytime"])

    def conclude(result: SearchResult) -> Result:
        out = _conclude_search(why, result, sources.root, grounder, deadline)
        stats = out.stats
        stats.update({k: (round(v, 4) if isinstance(v, float) else v) for k, v in result.stats.items()})
        stats["iterations"] = result.iterations
        stats["geometric_queries"] = grounder.queries
        stats["deferred"] = sorted(describe(p) for p in sources.deferrals.deferred)
        stats["doomed_skeletons"] = reverse.doomed.doomed  # failed by a probe before their later steps (doomed.py)
        stats["repeated_failures"] = reverse.repeated  # failed as an earlier grounding did (ReverseGrounder._repeated)
        stats["repacked_steps"] = (
            reverse.repacked
        )  # steps packed again, an action first or last (ReverseGrounder._packed)
        stats["packings_spent"] = (
            reverse.packings_spent
        )  # skeleton steps whose packings ran out (ground.PACKINGS_PER_ACTION)
        stats.update(timing.of(result.steps))
        if out.status is PlanStatus.TIME_LIMIT and result.ended == "iteration limit":
            out.summary = f"the search's iteration limit ({o['max_iterations']}) was reached before a plan was found"
        elif out.status is PlanStatus.INFEASIBLE:
            out.summary = "infeasible by the facts: no task skeleton exists"
        return out

    try:
        return conclude(result)
    except KeyboardInterrupt:  # a signal after the search's loop, while concluding: interrupted, its counts kept
        return conclude(SearchResult(result.steps, result.iterations, result.stats, "interrupted"))


class _Timing:
    """How the grounded plans' steps compare with their skeletons' (``-v`` and the plan's statistics): per
    grounded sequence (a node's suffix, a full plan) the skeletons' makespan it grounds, the actions re-timed
    into an earlier skeleton step, and the steps split because robots were in each other's way; a plan's
    ``waits`` count the paths on which a robot waits for another of its step (``ground._waiting``)."""

    def __init__(self) -> None:
        self.of_steps: dict[int, tuple[int, int, int]] = {}  # id(steps) -> (skeleton makespan, retimed, split)

    def grounded(self, skel: Skeleton, suffix: list[GroundedStep], result: Grounding) -> None:
        if not result.steps:
            return
        span, retimed, split = self.of_steps.get(id(suffix), (len(suffix), 0, 0))
        resolved = len(result.resolved) - len(result.retimed)
        self.of_steps[id(result.steps)] = (span + skel.makespan, retimed + len(result.retimed), split + resolved)

    def of(self, steps: list[GroundedStep] | None) -> dict[str, int]:
        """The statistics of the returned plan (none without one)."""
        if steps is None or id(steps) not in self.of_steps:
            return {}
        span, retimed, split = self.of_steps[id(steps)]
        waits = sum(len(a.waits()) for step in steps for a in step.actions)
        return {
            "makespan": len(steps),
            "skeleton_makespan": span,
            "retimed_actions": retimed,
            "split_steps": split,
            "waits": waits,
        }


class _Skeletons:
    """One skeleton source as the search asks it (:class:`~mrgc.planner.mcts.Node`'s ``more``): called with
    ``k``, the next ``k`` skeletons within the time left; it counts the skeletons it gave and keeps why its
    last batch stopped."""

    def __init__(
        self, source: SkeletonSource, deadline: float, deferrals: Deferrals, graphs: dict[Skeleton, TaskGraph]
    ) -> None:
        self.source = source
        self.deadline = deadline
        #: the task graph each skeleton given came from (shared by every source)
        self.graphs = graphs
        #: the search's deferred actions (shared by every source; read at each call)
        self.deferrals = deferrals
        self.count = 0
        self.outcome: BatchOutcome | None = None

    def __call__(self, k: int) -> list[Skeleton]:
        gen = self.source.generator
        gen.defer(self.deferrals.among(gen.graph.actions))
        # past the search's deadline a source still gets one 10 ms try (a symbolic problem's first skeleton)
        batch = self.source.next(k, deadline=max(self.deadline, time.perf_counter() + 0.01))
        for skel in batch.skeletons:
            self.graphs.setdefault(skel, gen.graph)
        self.count += len(batch.skeletons)
        self.outcome = batch.outcome
        return batch.skeletons

    @property
    def infeasible(self) -> bool:
        """The source gave no skeleton and has none: the skeleton model is infeasible at every horizon."""
        return self.count == 0 and self.outcome is BatchOutcome.EXHAUSTED

    def reasons(self) -> list[str]:
        """Why no skeleton exists: the facts' explanation, or the model's infeasibility."""
        return list(self.source.reasons) or [
            "no task skeleton exists under the facts (the skeleton model is infeasible at every horizon)"
        ]


class _Sources:
    """The search's skeleton sources (``sources(M*, moved)``), one per request; the first one made (the
    root's, for M* = the objects that must move) is kept as :attr:`root`."""

    def __init__(
        self,
        base: FactBase,
        order: Callable[[str], int],
        backend: str,
        encoding: str,
        max_makespan: int | None,
        seed: int,
        deadline: float,
    ) -> None:
        self.base, self.order = base, order
        self.backend, self.encoding, self.max_makespan, self.seed = backend, encoding, max_makespan, seed
        self.deadline = deadline
        self.roots: list[_Skeletons] = []
        #: what failed groundings failed at, and what is deferred (docs/planner.md, "Deferred actions")
        self.deferrals = Deferrals()
        #: the task graph of each skeleton given (its order constraints: re-timing, planner/ground.py)
        self.graphs: dict[Skeleton, TaskGraph] = {}

    def __call__(self, need: set[str], moved: set[str]) -> _Skeletons:
        src = SkeletonSource(
            self.base,
            sorted(need, key=self.order),
            sorted(moved),
            self.backend,
            self.encoding,
            self.max_makespan,
            self.seed,
        )
        more = _Skeletons(src, self.deadline, self.deferrals, self.graphs)
        if not self.roots:
            self.roots.append(more)
        return more

    @property
    def root(self) -> _Skeletons:
        """The first source made: the root's."""
        return self.roots[0]

    def order_of(self, skel: Skeleton) -> Callable[[Action], list[tuple[str, bool]]] | None:
        """``skel``'s order constraints: each of its actions' obstacles, (object, strict)."""
        graph = self.graphs.get(skel)
        if graph is None:
            return None
        index = {a: i for i, a in enumerate(graph.actions)}
        return lambda a: graph.obstacles(index[a])


def _conclude_symbolic(why: Why, more: _Skeletons, time_limit: float) -> Result:
    """A symbolic problem's plan: the best skeleton, else why there is none."""
    first = more(1)
    if first:
        steps = [planned for step in first[0].steps for planned in planned_steps(step)]
        return Result(PlanStatus.SOLVED, steps)
    if more.infeasible:
        why.facts = more.reasons()
        return Result(PlanStatus.INFEASIBLE, summary="infeasible by the facts")
    return Result(PlanStatus.TIME_LIMIT, summary=f"skeleton generation did not finish within {time_limit:g} s")


def _conclude_search(why: Why, result: SearchResult, root: _Skeletons, grounder: Grounder, deadline: float) -> Result:
    """The status (and steps, reasons) from how the search ended."""
    if result.steps is not None:
        status = PlanStatus.SOLVED if result.ended != "interrupted" else PlanStatus.INTERRUPTED
        return Result(status, [s.actions for s in result.steps])
    if result.ended == "interrupted":
        return Result(PlanStatus.INTERRUPTED)
    if result.ended in ("time limit", "iteration limit") or time.perf_counter() >= deadline:
        return Result(PlanStatus.TIME_LIMIT)
    if root.infeasible:
        why.facts = root.reasons()
        why.cycles = _cycles_with_evidence(root.source, grounder)
        if why.cycles:  # the cycles are told with their evidence instead
            why.facts = [f for f in why.facts if not f.startswith("blocking cycle")]
        return Result(PlanStatus.INFEASIBLE)
    return Result(PlanStatus.EXHAUSTED)


def _cycles_with_evidence(source: SkeletonSource, grounder: Grounder, per_edge: int = 2) -> list[BlockingCycle]:
    """The blocking cycles of the root task graph, each obstruction shown on the geometry (bodies, depth)
    for up to ``per_edge`` of the obstructed picks."""
    from mrgc.compiler.diagnose import blocking_cycles
    from mrgc.planner.explain import pick_obstruction

    out = []
    for cycle in blocking_cycles(source.graph):
        edges = []
        for obj, blocker, _, actions in cycle:
            picks = sorted({(a.pick_robot, a.pick_grasp) for a in actions})[:per_edge]
            if not grounder.robot(picks[0][0]).approaches:  # no approach to show the obstruction on
                how = ", ".join(f"{g} by {r}" for r, g in picks)
            else:
                how = "; ".join(pick_obstruction(grounder, r, obj, g, blocker) for r, g in picks)
            edges.append((obj, blocker, how))
        out.append(BlockingCycle(tuple(o for o, _, _, _ in cycle), tuple(edges)))
    return out


def _referee(context: Context, result: Grounding) -> Grounding:
    """The validator's verdict on a complete grounded plan: SUCCESS stays SUCCESS only when it accepts it;
    otherwise the grounding is a failure (named by the validator's first violation)."""
    from mrgc.planner.ground import Grounding, Outcome

    failure = context.referee([s.actions for s in result.steps])
    if failure is None:
        return result
    return Grounding(Outcome.FAIL, reason=failure.line(), failures=[failure])


def _log_line(elapsed: float, n: int, skel: Skeleton, suffix: list[GroundedStep], result: Grounding) -> str:
    from mrgc.planner.ground import Outcome, moved_objects

    head = f"[t={elapsed:.1f}s] skeleton {n} (makespan {skel.makespan}, moves {len(skel.moved)}"
    head += f", under a suffix of {len(suffix)} step{'s' * (len(suffix) != 1)})" if suffix else ")"
    retimed = "".join(f"\n  re-timed: {what} from step {at} to step {to}" for what, at, to in result.retimed)
    resolved = "".join(f"\n  robots in each other's way, resolved: {f.line()}" for f in result.resolved)
    if result.outcome is Outcome.SUCCESS:
        span = (
            f" (the skeleton's {skel.makespan + len(suffix)})"
            if len(result.steps) != skel.makespan + len(suffix)
            else ""
        )
        moved = len(moved_objects(result.steps))
        return f"{head}: plan found, makespan {len(result.steps)}{span}, {moved} moved, valid{retimed}{resolved}"
    if result.outcome is Outcome.PARTIAL:
        f = result.failures[0] if result.failures else None
        why = f" ({f.line()})" if f else ""
        grounded = len(result.steps) - len(suffix)
        return f"{head}: grounded {grounded} step(s); must move {sorted(result.must_move)}{why}{retimed}{resolved}"
    f = result.failures[0] if result.failures else None
    again = (
        f" (as grounding {result.repeats}: the same steps from there on, not grounded again)" if result.repeats else ""
    )
    return f"{head}: fails at {f.line() if f else result.reason}{again}"


def planned_action(a: Action, relay: bool = False) -> PlannedAction:
    """A skeleton's (relay-free) action as the plan's action, without geometry."""
    return PlannedAction(a.obj, a.region, a.pick_robot, a.place_robot, a.pick_grasp, a.place_grasp, relay=relay)


def planned_steps(step: tuple[Action, ...]) -> list[list[PlannedAction]]:
    """A skeleton step as the plan's steps, without geometry: the step itself, and when it holds relays, a
    second step with their onward moves (the first step sets their objects down)."""
    first, onward = [], []
    for a in step:
        if a.via is None:
            first.append(planned_action(a))
            continue
        down, on = a.halves
        first.append(planned_action(down, relay=True))
        onward.append(planned_action(on))
    return [first, onward] if onward else [first]


def _order(problem: Problem) -> Callable[[str], int]:
    index = {m.name: i for i, m in enumerate(problem.movable)}
    return lambda o: index.get(o, len(index))
