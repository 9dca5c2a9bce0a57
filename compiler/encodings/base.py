"""What an encoding produces: a model, the literal that selects each action, and a decoder."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Callable, Sequence

from mrgc.compiler.ir import Row, SkeletonModel
from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import TaskGraph


@dataclass
class Encoded:
    """A built model.  ``select[i]`` is the bool variable that is 1 iff action i is in the skeleton."""

    model: SkeletonModel
    select: list[int]
    horizon: int
    decode: Callable[[Sequence[int]], Skeleton]

    def cut(self, chosen: frozenset[int], name: str = "cut") -> Row:
        """The row excluding exactly the action set ``chosen`` (a no-good on the selection literals)."""
        terms = [(v, -1 if i in chosen else 1) for i, v in enumerate(self.select)]
        return Row(tuple(terms), lo=1 - len(chosen), name=name)


class Encoding(ABC):
    """Builds the skeleton model of a task graph for a horizon.

    With ``horizon_loop`` the generator builds one model per horizon T = 1, 2, ... (a model's skeletons
    have exactly T non-empty steps); without it, one model of horizon T covers every makespan up to T, so
    one model up to the limit would do (the generator grows the horizon anyway for most solvers,
    :mod:`mrgc.compiler.enumerate`).
    """

    name: str = ""
    horizon_loop: bool = True

    @abstractmethod
    def build(self, graph: TaskGraph, horizon: int) -> Encoded:
        """The model for ``graph``: exactly ``horizon`` steps (loop encodings) or at most (the others)."""
