"""Task skeletons: which robot moves which object to which region, with which grasps, at which step."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from mrgc.compiler.task_graph import Action, TaskGraph


@dataclass(frozen=True)
class Skeleton:
    """A sequence of partially grounded joint actions: ``steps[t]`` holds the actions of step t+1.

    Every step is non-empty; within a step actions are in the task graph's object order.
    """

    steps: tuple[tuple[Action, ...], ...]

    @property
    def makespan(self) -> int:
        """The number of steps."""
        return len(self.steps)

    @property
    def moved(self) -> tuple[str, ...]:
        """Objects moved, in the order of their steps."""
        return tuple(a.obj for step in self.steps for a in step)

    @property
    def actions(self) -> frozenset[Action]:
        """Every action of every step."""
        return frozenset(a for step in self.steps for a in step)

    @property
    def key(self) -> tuple[int, int]:
        """The order skeletons are generated in: makespan first, then number of moved objects."""
        return (self.makespan, len(self.moved))

    def to_json(self) -> dict[str, Any]:
        """The skeleton as ``mrgc compile --format json`` prints it."""
        return {
            "makespan": self.makespan,
            "moved": sorted(self.moved),
            "steps": [
                [
                    {
                        "object": a.obj,
                        "region": a.region,
                        "pick_robot": a.pick_robot,
                        "place_robot": a.place_robot,
                        "pick_grasp": a.pick_grasp,
                        "place_grasp": a.place_grasp,
                        **({"via": a.via} if a.via is not None else {}),
                    }
                    for a in step
                ]
                for step in self.steps
            ],
        }

    def describe(self) -> list[str]:
        """Readable lines, e.g. ``step 1: r1 moves o2 to start (top)``."""
        return [f"step {t}: " + "; ".join(str(a) for a in step) for t, step in enumerate(self.steps, 1)]


def skeleton_from_schedule(graph: TaskGraph, schedule: Sequence[tuple[int, int]]) -> Skeleton:
    """Build a skeleton from (action index, step) pairs; empty steps are squeezed out."""
    order = {o: i for i, o in enumerate(graph.objects)}
    by_step: dict[int, list[Action]] = {}
    for i, t in schedule:
        by_step.setdefault(t, []).append(graph.actions[i])
    steps = tuple(tuple(sorted(by_step[t], key=lambda a: order[a.obj])) for t in sorted(by_step))
    return Skeleton(steps)
