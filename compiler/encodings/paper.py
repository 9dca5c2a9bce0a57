"""The paper's MIP (Section "Key Component 1"), constraint by constraint, for a horizon of exactly T steps.

Variables X[a]@t (1 <= t <= T) mean "action a is executed at step t or later", so a's step is the number
of t with X[a]@t = 1.  Each action moves exactly one object, so the block-edge variables of constraint (2)
are aliases of the action's own variables and are not created.  "R in a" is the set {pick robot, place
robot}.  Constraints (11)/(12) are conditional rows; their MIP translation uses the paper's big-M,
T+1 and T, which are tight: they read step(a) >= step(M) + 1 (pick) and step(a) >= step(M) (place).
"""

from __future__ import annotations

from typing import Sequence

from mrgc.compiler.encodings.base import Encoded, Encoding
from mrgc.compiler.ir import SkeletonModel
from mrgc.compiler.skeleton import Skeleton, skeleton_from_schedule
from mrgc.compiler.task_graph import TaskGraph


def action_label(graph: TaskGraph, i: int) -> str:
    """The action's label in model names: object, region, robots and grasps (and a relay's region)."""
    a = graph.actions[i]
    via = f",via {a.via}" if a.via is not None else ""
    return f"{a.obj},{a.region},{a.pick_robot},{a.place_robot},{a.pick_grasp},{a.place_grasp}{via}"


class PaperEncoding(Encoding):
    """The paper's skeleton model: one boolean per action and step; the horizon grows until the model is feasible."""

    name = "paper"
    horizon_loop = True

    def build(self, graph: TaskGraph, horizon: int) -> Encoded:
        """The model of horizon ``horizon`` (steps) for ``graph``."""
        T = horizon
        m = SkeletonModel(name=f"{self.name}-T{T}")
        A = range(len(graph.actions))
        X = [[m.bool_var(f"X({action_label(graph, a)})@{t}") for t in range(1, T + 1)] for a in A]
        of = {o: graph.actions_of(o) for o in graph.objects}
        uses = {r: [a for a in A if r in graph.actions[a].robots] for r in graph.robots}
        must = set(graph.must_move)

        _monotone_and_pending(m, graph, X, of, must, T)
        _per_step(m, graph, X, uses, T)
        _moved(m, graph, X, of, must)
        self.precedence(m, graph, X, of, T)
        m.objectives.append(tuple((X[a][0], 1) for a in A))  # the number of moved objects

        select = [X[a][0] for a in A]

        def decode(values: Sequence[int]) -> Skeleton:
            schedule = [(a, sum(values[v] for v in X[a])) for a in A if values[X[a][0]]]
            return skeleton_from_schedule(graph, schedule)

        return Encoded(m, select, T, decode)

    def precedence(
        self, m: SkeletonModel, graph: TaskGraph, X: list[list[int]], of: dict[str, list[int]], T: int
    ) -> None:
        """(11) pick obstacles strictly earlier, (12) place obstacles no later, as conditional rows."""
        for a in range(len(graph.actions)):
            for o, strict in graph.obstacles(a):
                terms = [(v, 1) for v in X[a]] + [(v, -1) for a2 in of[o] for v in X[a2]]
                m.add_if(
                    [(X[a][0], True)],
                    terms,
                    lo=1 if strict else 0,
                    name=f"c{11 if strict else 12}[{a},{o}]",
                    big_m=T + 1 if strict else T,
                )


def _monotone_and_pending(
    m: SkeletonModel, graph: TaskGraph, X: list[list[int]], of: dict[str, list[int]], must: set[str], T: int
) -> None:
    """(1) "at or after t" is monotone; (3) objects outside M* move only while an action they block is
    pending."""
    A = range(len(graph.actions))
    for a in A:
        for t in range(T - 1):
            m.add([(X[a][t], 1), (X[a][t + 1], -1)], lo=0, name=f"c1[{a},{t + 1}]")
    for o in graph.objects:
        if o in must:
            continue
        blocked = graph.blocked_by(o)
        for a2 in of[o]:
            for t in range(T):
                m.add([(X[a2][t], 1)] + [(X[a][t], -1) for a in blocked], hi=0, name=f"c3[{o},{a2},{t + 1}]")


def _per_step(m: SkeletonModel, graph: TaskGraph, X: list[list[int]], uses: dict[str, list[int]], T: int) -> None:
    """(4)-(7): each robot at most one action per step, no step empty; with one handover point, at most one
    handover per step."""
    A = range(len(graph.actions))
    for r, acts in uses.items():  # (4) each robot at most one action at the last step
        m.add([(X[a][T - 1], 1) for a in acts], hi=1, name=f"c4[{r}]")
    m.add([(X[a][T - 1], 1) for a in A], lo=1, name="c5")  # (5) the last step is not empty
    for t in range(T - 1):
        for r, acts in uses.items():  # (6) each robot at most one action per step
            m.add([(X[a][t], 1) for a in acts] + [(X[a][t + 1], -1) for a in acts], hi=1, name=f"c6[{r},{t + 1}]")
        m.add([(X[a][t], 1) for a in A] + [(X[a][t + 1], -1) for a in A], lo=1, name=f"c7[{t + 1}]")  # (7)
    handovers = [a for a in A if graph.actions[a].handover]
    if graph.single_handover_point and len(handovers) > 1:  # one handover point: one handover per step
        m.add([(X[a][T - 1], 1) for a in handovers], hi=1, name="handover-point")
        for t in range(T - 1):
            m.add(
                [(X[a][t], 1) for a in handovers] + [(X[a][t + 1], -1) for a in handovers],
                hi=1,
                name=f"handover-point[{t + 1}]",
            )


def _moved(m: SkeletonModel, graph: TaskGraph, X: list[list[int]], of: dict[str, list[int]], must: set[str]) -> None:
    """(8) M* is moved; (9) the obstacles of a selected action are moved; (10) each object at most once."""
    for o in graph.must_move:
        m.add([(X[a][0], 1) for a in of[o]], lo=1, hi=1, name=f"c8[{o}]")
    for a in range(len(graph.actions)):
        for o in graph.blockers(a):
            m.add([(X[a2][0], 1) for a2 in of[o]] + [(X[a][0], -1)], lo=0, name=f"c9[{a},{o}]")
    for o in graph.objects:
        if o not in must and of[o]:
            m.add([(X[a][0], 1) for a in of[o]], hi=1, name=f"c10[{o}]")
