"""A way a plan fails, as the validator reports it (shared by :mod:`mrgc.validator.validate` and the
geometric replay, :mod:`mrgc.validator.replay`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Violation:
    """One way a plan fails: the step (1-based, None for the whole plan), the robot or object concerned
    (None when none in particular), a stable code and a one-line message."""

    step: int | None
    subject: str | None
    code: str
    message: str

    def __str__(self) -> str:
        where = "".join(
            [f"step {self.step}: " if self.step is not None else "", f"{self.subject}: " if self.subject else ""]
        )
        return f"{where}{self.message} [{self.code}]"

    def to_json(self) -> dict[str, Any]:
        """The violation as a JSON object (the keys of the dataclass)."""
        return {"step": self.step, "subject": self.subject, "code": self.code, "message": self.message}


def number(x: float, places: int = 4) -> str:
    """A plan's number as a violation message shows it: ``places`` decimals, or, beyond 1e4 or non-finite,
    five significant digits in exponent form (a joint value of 1e308 is ``1e+308``, never 309 digits)."""
    if not abs(x) < 1e4:
        return f"{x:.5g}"
    return f"{x:.{places}f}"
