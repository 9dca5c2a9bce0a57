"""How a run ended, as recorded: the status of a run and the measures of its plan.

:func:`classify` judges a :class:`~mrgc.bench.execute.RawRun`.  A run **succeeds only as** ``solved``:
the planner said solved *and* the separate ``mrgc validate`` process accepted the plan (for a
compile-only method: at least one skeleton was generated; there is no plan to validate).

============  ==========================================================================================
status        meaning
============  ==========================================================================================
solved        plan found and accepted by ``mrgc validate`` (compile-only: a skeleton was generated)
invalid       the planner said solved but the validator rejected the plan (or could not read it)
infeasible    the planner proved there is no skeleton under the facts (exit 1)
exhausted     every skeleton was tried, none grounded (exit 5)
time limit    the planner's own time limit ended the search (exit 3)
timeout       the runner killed the process group at the wall-clock limit
memout        the runner killed the process group at the memory limit
crash         killed by a signal, an internal error, an exit code that disagrees with the plan file, no plan
              file, or the validator itself failed (timeout, memout, crash); the stderr tail says more
error         the command was rejected as input (exit 2: bad file or option; exit 4: missing backend)
============  ==========================================================================================

Measures (of the plan the planner returned; the report averages them over solved runs):

- **planning time**: the plan's ``stats.seconds`` (phase 1, skeletons, grounding and the planner's own
  validation: what ``mrgc plan`` reports); compile-only: ``stats.total_seconds`` (skeleton generation;
  phase 1 is ``facts_seconds``, stored apart).  ``wall_seconds`` is the runner's clock for the process;
  ``cpu_seconds`` the CPU time of the planner's process and its workers (start-up and the planner's own
  validation included, the separate ``mrgc validate`` not): what ``bench report --time cpu`` shows.
- **makespan**: the plan's number of steps; **objects moved**: its number of actions (the plan's
  ``motion_cost``, which is what the paper calls motion cost).
- **path length**: the length of every motion the plan lists, summed over robots: each ``paths`` entry
  and each ``configs.pick`` / ``configs.place`` approach sequence, as the polyline through its
  configurations: Euclidean joint-space length for arms (radians, ``arm_path``), x–y length for planar
  bases (metres, ``base_path``; yaw ignored).  Motions a plan leaves out (arms' transits in packaging,
  where the paper omits motion planning) count zero: compare path lengths between methods on one domain.
"""

from __future__ import annotations

import enum
import json
import math
from dataclasses import asdict, dataclass
from typing import Any

from mrgc.bench.execute import ATTEMPT, RawRun


class RunStatus(str, enum.Enum):
    """How a run ended (module docstring)."""

    SOLVED = "solved"
    INVALID = "invalid"
    INFEASIBLE = "infeasible"
    EXHAUSTED = "exhausted"
    TIME_LIMIT = "time limit"
    TIMEOUT = "timeout"
    MEMOUT = "memout"
    CRASH = "crash"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value


#: the plan statuses mrgc plan writes, their exit codes, and what they are as a run
PLAN_STATUS = {
    "solved": (0, RunStatus.SOLVED),
    "infeasible": (1, RunStatus.INFEASIBLE),
    "time limit": (3, RunStatus.TIME_LIMIT),
    "exhausted": (5, RunStatus.EXHAUSTED),
}
#: exit codes of a command rejected as input
INPUT_EXITS = {2, 4}


@dataclass
class RunResult:
    """One row of the results database (docs/bench.md lists the columns)."""

    study: str
    instance: str
    instance_set: str
    set_index: int
    instance_file: str
    instance_sha256: str
    method: str
    method_index: int
    seed: int
    status: str
    success: bool
    detail: str
    exit_code: int | None
    signal: int | None
    planning_seconds: float | None
    facts_seconds: float | None
    wall_seconds: float
    validate_seconds: float | None
    cpu_seconds: float | None
    peak_mb: float
    makespan: int | None
    objects_moved: int | None
    arm_path: float | None
    base_path: float | None
    valid: bool | None
    plan_status: str | None
    stderr_tail: str
    command: str
    time_limit: float
    wall_limit: float
    memory_limit_mb: float
    mrgc_version: str
    host: str
    started: str
    finished: str
    plan_file: str | None = None

    def to_row(self) -> dict[str, Any]:
        """The result as a database row (column -> value)."""
        return asdict(self)


def classify(raw: RawRun, method_index: int = 0, plan_file: str | None = None) -> RunResult:
    """Judge a run (module docstring)."""
    task, proc = raw.task, raw.plan
    inst = task.instance
    data = _json(raw.plan_text)
    status, detail = _plan_status(raw, data)
    valid: bool | None = None
    validate_seconds = None
    if raw.validate is not None:
        v = raw.validate
        validate_seconds = round(v.seconds, 3)
        report = _json(raw.validate_text)
        if v.killed is not None:
            status, detail = RunStatus.CRASH, f"the validator was killed ({v.killed}) after {v.seconds:.1f} s"
        elif v.exit_code == 0 and report is not None and report.get("ok") is True:
            valid = True
        elif v.exit_code == 1 and report is not None and report.get("ok") is False:
            valid = False
            lines = [str(x.get("message", x)) if isinstance(x, dict) else str(x) for x in report.get("violations", [])]
            status, detail = RunStatus.INVALID, f"{len(lines)} violation(s): " + "; ".join(lines[:3])
        elif v.exit_code == 2:
            valid = False
            status = RunStatus.INVALID
            detail = "the validator could not use the plan file: " + _last_line(raw.validate_stderr)
        else:
            status = RunStatus.CRASH
            detail = f"the validator ended with {_ending(v.exit_code, v.signal)}: {_last_line(raw.validate_stderr)}"
    elif status is RunStatus.SOLVED and not task.compile_only:
        status, detail = RunStatus.CRASH, "the plan says solved but was not validated"
    measures = (
        _measures(data, task.compile_only, dict(inst.bases))
        if data is not None
        else dict.fromkeys(("planning_seconds", "facts_seconds", "makespan", "objects_moved", "arm_path", "base_path"))
    )
    tail = raw.plan_stderr if raw.validate is None or status is not RunStatus.CRASH else raw.validate_stderr
    return RunResult(
        study=task.study,
        instance=inst.name,
        instance_set=inst.set,
        set_index=inst.set_index,
        instance_file=inst.path,
        instance_sha256=inst.sha256,
        method=task.method,
        method_index=method_index,
        seed=task.seed,
        status=status.value,
        success=status is RunStatus.SOLVED,
        detail=detail,
        exit_code=proc.exit_code,
        signal=proc.signal,
        wall_seconds=round(proc.seconds, 3),
        cpu_seconds=proc.cpu_seconds,
        validate_seconds=validate_seconds,
        peak_mb=round(max(proc.peak_mb, raw.validate.peak_mb if raw.validate else 0), 1),
        valid=valid,
        plan_status=(data or {}).get("status") if not task.compile_only else (data or {}).get("status"),
        stderr_tail=tail,
        command=" ".join(["mrgc", *proc.argv[3:]]).replace(
            task.stem + ATTEMPT, task.stem
        ),  # the files' names once recorded
        time_limit=task.limits.time,
        wall_limit=task.limits.wall_seconds,
        memory_limit_mb=task.limits.memory_mb,
        mrgc_version=str((data or {}).get("mrgc_version") or raw.mrgc_version),
        host=raw.host,
        started=raw.started,
        finished=raw.finished,
        plan_file=plan_file,
        **measures,
    )


def _plan_status(raw: RawRun, data: dict[str, Any] | None) -> tuple[RunStatus, str]:
    proc = raw.plan
    if proc.killed == "timeout":
        return RunStatus.TIMEOUT, f"killed at the wall-clock limit of {raw.task.limits.wall_seconds:g} s"
    if proc.killed == "memout":
        return RunStatus.MEMOUT, f"killed at the memory limit of {raw.task.limits.memory_mb:g} MiB"
    code = proc.exit_code
    if raw.task.compile_only:
        if code == 0 and data is not None and data.get("skeletons"):
            return RunStatus.SOLVED, f"{len(data['skeletons'])} skeleton(s), {data.get('status')}"
        if code == 1:
            return RunStatus.INFEASIBLE, "; ".join(map(str, (data or {}).get("reasons", [])))[:500]
        if code == 3:
            return RunStatus.TIME_LIMIT, ""
    elif data is not None and data.get("status") in PLAN_STATUS:
        expected, status = PLAN_STATUS[data["status"]]
        if code == expected:
            return status, why_detail(data.get("why") or {}) if status is not RunStatus.SOLVED else ""
        return RunStatus.CRASH, f"exit code {code} disagrees with the plan's status '{data['status']}'"
    if code in INPUT_EXITS:
        return RunStatus.ERROR, _last_line(raw.plan_stderr)
    what = "no plan file" if not raw.task.compile_only else "no skeleton output"
    return RunStatus.CRASH, f"{what}; ended with {_ending(code, proc.signal)}: {_last_line(raw.plan_stderr)}"


def why_detail(why: dict[str, Any], failures: int = 3, limit: int = 1000) -> str:
    """A failed plan's reasons in one line for the ``detail`` column: the plan's ``why`` summary, the facts
    and blocking cycles that prove it infeasible, the complete plans the validator rejected, and the
    ``failures`` most frequent grounding failures (docs/planner.md), cut at ``limit`` characters."""
    parts = [str(why.get("summary", ""))] if why.get("summary") else []
    parts += [str(f) for f in why.get("facts") or []][:3]
    cycles = why.get("cycles") or []
    if cycles:
        parts.append(
            f"{len(cycles)} blocking cycle(s): "
            + ", ".join(" -> ".join(map(str, c.get("objects", []))) for c in cycles[:3] if isinstance(c, dict))
        )
    if why.get("rejected_plans"):
        parts.append(f"{why['rejected_plans']} complete plan(s) rejected by the validator")
    top = [f for f in why.get("grounding_failures") or [] if isinstance(f, dict)][:failures]
    if top:
        parts.append(
            "most frequent grounding failures: "
            + "; ".join(
                f"{f.get('count')} x step {f.get('step')}, {f.get('action')}: {f.get('check')}"
                + (f" ({f['detail']})" if f.get("detail") else "")
                for f in top
            )
        )
    text = "; ".join(parts)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _ending(code: int | None, sig: int | None) -> str:
    if sig is not None:
        import signal as signals

        try:
            return f"signal {sig} ({signals.Signals(sig).name})"
        except ValueError:
            return f"signal {sig}"
    return f"exit code {code}"


def _last_line(text: str) -> str:
    lines = [ln.strip() for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1][:300] if lines else "(nothing on standard error)"


def _json(text: str | None) -> dict[str, Any] | None:
    if not text:
        return None
    try:
        data = json.loads(text)
    except ValueError:
        return None
    return data if isinstance(data, dict) else None


def _measures(data: dict[str, Any], compile_only: bool, bases: dict[str, str]) -> dict[str, Any]:
    stats = data.get("stats") or {}
    if compile_only:
        skeletons = data.get("skeletons") or []
        first = skeletons[0] if skeletons else {}
        return {
            "planning_seconds": _num(stats.get("total_seconds")),
            "facts_seconds": _num(stats.get("facts_seconds")),
            "makespan": first.get("makespan"),
            "objects_moved": len(first["moved"]) if first else None,
            "arm_path": None,
            "base_path": None,
        }
    arm, base = path_lengths(data, bases)
    return {
        "planning_seconds": _num(stats.get("seconds")),
        "facts_seconds": _num(stats.get("facts_seconds")),
        "makespan": data.get("makespan"),
        "objects_moved": data.get("motion_cost"),
        "arm_path": arm,
        "base_path": base,
    }


def _num(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


#: which robot of an action follows each named path (docs/validator.md, the execution model)
PATH_ROBOT = {
    "to-pick": "pick_robot",
    "to-handover": "pick_robot",
    "taker-to-handover": "place_robot",
    "to-place": "place_robot",
    "home": "place_robot",
    "giver-home": "pick_robot",
}


def path_lengths(plan: dict[str, Any], bases: dict[str, str]) -> tuple[float | None, float | None]:
    """(arm joint-space length in radians, planar base x-y length in metres) of the motions ``plan`` lists
    (module docstring); None for a kind of robot the problem does not have, both None for a plan without
    steps or a symbolic problem."""
    if not plan.get("steps") or not any(bases.values()):
        return None, None
    totals = {"fixed": 0.0, "planar": 0.0}
    for step in plan["steps"]:
        for action in step.get("actions", []):
            motions: list[tuple[str, list[list[float]]]] = []
            configs = action.get("configs") or {}
            for phase, who in (("pick", "pick_robot"), ("place", "place_robot")):
                if phase in configs:
                    motions.append((action[who], configs[phase]))
            for name, qs in (action.get("paths") or {}).items():
                motions.append((action[PATH_ROBOT.get(name, "place_robot")], qs))
            for robot, qs in motions:
                kind = bases.get(robot, "")
                if kind not in totals:
                    continue
                dims = 2 if kind == "planar" else None
                totals[kind] += sum(math.dist(a[:dims], b[:dims]) for a, b in zip(qs, qs[1:]))
    kinds = set(bases.values())
    return (
        round(totals["fixed"], 4) if "fixed" in kinds else None,
        round(totals["planar"], 4) if "planar" in kinds else None,
    )
