"""The "time of move" encoding: one integer step per object instead of a step-indexed copy of every action.

y[a] = 1 iff action a is selected; tau[M] in 0..H is M's step (0 = not moved); makespan C >= tau[M].
Each object moves at most once (M* exactly once); an object outside M* moves only if it obstructs a
selected action, and every obstacle of a selected action moves; pick obstacles strictly earlier
(y[a] => tau[obj a] >= tau[M] + 1), place obstacles no later (y[a] => tau[obj a] >= tau[M]); per robot the
objects it handles occupy distinct steps (no-overlap of unit tasks).  The objective is lexicographic:
makespan, then number of moved objects.  At an optimum no step is empty (an empty step could be squeezed
out, lowering the makespan), so the model ranks skeletons exactly like the horizon loop of the paper.
One model of horizon H covers every makespan up to H; the skeleton generator still builds one per horizon
H = T0, T0 + 1, ... for most solvers (:mod:`mrgc.compiler.enumerate`, ``grow_horizon``).
"""

from __future__ import annotations

from typing import Sequence

from mrgc.compiler.encodings.base import Encoded, Encoding
from mrgc.compiler.encodings.paper import action_label
from mrgc.compiler.ir import NoOverlap, SkeletonModel
from mrgc.compiler.skeleton import Skeleton, skeleton_from_schedule
from mrgc.compiler.task_graph import TaskGraph


class TimeOfMoveEncoding(Encoding):
    """The time-of-move encoding (module docstring): one integer step per object; a model of horizon H holds
    every skeleton of makespan at most H (no horizon loop needed, :attr:`horizon_loop` False)."""

    name = "time-of-move"
    horizon_loop = False

    def build(self, graph: TaskGraph, horizon: int) -> Encoded:
        """The model for ``graph`` with steps up to ``horizon``."""
        H = horizon
        m = SkeletonModel(name=f"{self.name}-H{H}")
        A = range(len(graph.actions))
        y = [m.bool_var(f"y({action_label(graph, a)})") for a in A]
        tau = {o: m.int_var(f"tau({o})", 0, H) for o in graph.objects}
        makespan = m.int_var("makespan", 0, H)
        of = {o: graph.actions_of(o) for o in graph.objects}
        must = set(graph.must_move)

        for o in graph.objects:
            moved = [(y[a], 1) for a in of[o]]
            if o in must:
                m.add(moved, lo=1, hi=1, name=f"move[{o}]")
            else:
                m.add(moved, hi=1, name=f"once[{o}]")
                # moves only if it obstructs a selected action
                m.add(moved + [(y[a], -1) for a in graph.blocked_by(o)], hi=0, name=f"needed[{o}]")
            m.add([(tau[o], 1)] + [(v, -1) for v, _ in moved], lo=0, name=f"tau-lo[{o}]")  # moved => tau >= 1
            m.add([(tau[o], 1)] + [(v, -H) for v, _ in moved], hi=0, name=f"tau-hi[{o}]")  # unmoved => tau = 0
            m.add([(makespan, 1), (tau[o], -1)], lo=0, name=f"makespan[{o}]")
        for a in A:
            me = graph.actions[a].obj
            for o, strict in graph.obstacles(a):
                m.add([(y[a2], 1) for a2 in of[o]] + [(y[a], -1)], lo=0, name=f"obstacle[{a},{o}]")
                m.add_if(
                    [(y[a], True)],
                    [(tau[me], 1), (tau[o], -1)],
                    lo=1 if strict else 0,
                    name=f"{'pick' if strict else 'place'}-before[{a},{o}]",
                )
        _one_object_per_step(m, graph, y, tau, of)
        handovers = [a for a in A if graph.actions[a].handover]
        if graph.single_handover_point and len(handovers) > 1:  # one handover point: one handover per step
            m.no_overlap.append(
                NoOverlap(tuple((y[a], tau[graph.actions[a].obj]) for a in handovers), name="handover-point")
            )
        # redundant capacity rows (valid for every skeleton, they tighten the makespan bound): a robot
        # acts at most once per step, and all robots together at most |R| times per step
        for r in graph.robots:
            acts = [(y[a], 1) for a in A if r in graph.actions[a].robots]
            if acts:
                m.add([*acts, (makespan, -1)], hi=0, name=f"load[{r}]")
        m.add(
            [*((y[a], len(graph.actions[a].robots)) for a in A), (makespan, -len(graph.robots))], hi=0, name="load[all]"
        )
        m.objectives.append(((makespan, 1),))
        m.objectives.append(tuple((y[a], 1) for a in A))

        def decode(values: Sequence[int]) -> Skeleton:
            schedule = [(a, values[tau[graph.actions[a].obj]]) for a in A if values[y[a]]]
            return skeleton_from_schedule(graph, schedule)

        return Encoded(m, list(y), H, decode)


def _one_object_per_step(
    m: SkeletonModel, graph: TaskGraph, y: list[int], tau: dict[str, int], of: dict[str, list[int]]
) -> None:
    """Per robot, the objects it handles occupy distinct steps: a no-overlap of unit tasks, one per object,
    present when one of the robot's actions on it is selected."""
    for r in graph.robots:
        tasks = []
        for o in graph.objects:
            mine = [a for a in of[o] if r in graph.actions[a].robots]
            if not mine:
                continue
            busy = m.bool_var(f"busy({r},{o})")
            m.add([(busy, 1)] + [(y[a], -1) for a in mine], lo=0, hi=0, name=f"busy[{r},{o}]")
            tasks.append((busy, tau[o]))
        if len(tasks) > 1:
            m.no_overlap.append(NoOverlap(tuple(tasks), name=f"robot[{r}]"))
