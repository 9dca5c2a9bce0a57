"""The one table of the ``mrgc`` command's exit codes.

:class:`ExitCode` names each code; :data:`MEANINGS` says what it means, and is the table of docs/errors.md
(``docs/build_errors_doc.py`` writes it from here).  The CLI (:mod:`mrgc.cli`), the exception classes
(:mod:`mrgc.errors`), the statuses of results (a plan's, a compilation's) and the signal policy
(:mod:`mrgc.signals`) all take their codes from this table.  It imports nothing.
"""

from __future__ import annotations

import enum


class ExitCode(enum.IntEnum):
    """An exit code of the ``mrgc`` command."""

    OK = 0
    #: no skeleton or plan exists; fmt --check: a file would change; validate: the plan is invalid
    NO_PLAN = 1
    INPUT = 2
    TIME_LIMIT = 3
    MISSING_BACKEND = 4
    EXHAUSTED = 5
    INTERNAL = 70
    INTERRUPTED = 130
    TERMINATED = 143


#: exit code -> what it means (the table of docs/errors.md, in this order)
MEANINGS: dict[ExitCode, str] = {
    ExitCode.OK: "success (`check`: every file is fine; `fmt --check`: every file is canonical)",
    ExitCode.NO_PLAN: "infeasible: no task skeleton exists under the facts (`plan`, `compile`; the reasons are "
    "printed and, for `plan`, in the plan's `why`); `fmt --check`: some file would be "
    "reformatted; `validate`: the plan is invalid (a plan whose status is not `solved`, a record of a run that "
    "found no plan, is invalid: violation `[status]`); `render`: the plan's status is not `solved` (nothing is "
    "drawn unless `--force`)",
    ExitCode.INPUT: "input error: a bad `.mrg` file (any `E0xx`–`E2xx` code below), a bad plan file (`E5xx`), a "
    "bad study file or results database (`E6xx`, `mrgc bench`) or a bad command line (`E000`)",
    ExitCode.TIME_LIMIT: "time limit reached before an answer",
    ExitCode.MISSING_BACKEND: "a needed backend (solver or geometry library) is not installed; `bench run "
    "--executor ray` without Ray",
    ExitCode.EXHAUSTED: "`plan`: every skeleton was tried and none could be grounded into a plan the validator "
    "accepts (the grounding-failure summary says why)",
    ExitCode.INTERNAL: "internal error (`E070`): a bug in mrgc",
    ExitCode.INTERRUPTED: "interrupted (Ctrl-C, SIGINT): the command stops, says what it was doing, and writes "
    "nothing (no output file is created or changed); `plan` also prints what its search had "
    "(best plan, statistics, reasons)",
    ExitCode.TERMINATED: "terminated (SIGTERM): as 130",
}


def markdown_table() -> str:
    """:data:`MEANINGS` as the Markdown table of docs/errors.md."""
    return "\n".join(["| code | meaning |", "| --- | --- |", *(f"| {int(c)} | {m} |" for c, m in MEANINGS.items())])
