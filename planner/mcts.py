"""Monte-Carlo tree search over task skeletons, exactly as the paper's "Searching for task-and-motion plans".

Nodes hold grounded suffixes S (D.S); edges hold task skeletons.  Selection follows the PUCT value
``value/(visits+1) + c·prior·sqrt(node visits)/(visits+1)`` with ``prior = 1/|objects moved by the
skeleton|``; expansion creates the edge's head node; evaluation grounds the skeleton given the node's suffix:
failure → reward 0; a full plan S* → ``1 + α/|S*|``; a grounded suffix S' with objects M* → new skeletons for
M* (the suffix's objects excluded) and reward ``|S'|/(|S'|+|S̄*|) + α/(objects(S') + objects(S̄*))`` in steps
and objects, S̄* the new skeleton with the fewest steps (0 and a terminal node when there is none);
backpropagation adds the reward to the selected edges and counts visits.  Grounding failures are memoised
(suffix, skeleton actions) so known-infeasible branches are skipped.  Beyond the paper: a node whose
skeletons are all used up asks its skeleton source for more instead of becoming terminal, unless a grounding
under it showed its suffix a dead end (:attr:`Grounding.dead_end <mrgc.planner.ground.Grounding.dead_end>`:
a goal object left no room in its goal region), which ends the node and the edge into it.

A node's K skeletons are made lazily (beyond the paper, the same search): a new node gets its first skeleton
only, the one its first selection picks anyway (every edge of an unvisited node has the value 0 and the
first, fewest steps and objects, wins the tie), and the other K - 1 when the node is selected again.  Where
the first skeleton grounds to a plan (most of PA5-PA10) the other solves are never paid for (0.06-0.08 s of
CPU of a 1.1-1.6 s PA10 run); where it does not, they are made after its grounding, so the deferrals that
grounding caused already shape them.

Shared nodes (beyond the paper, session 31): a partial grounding whose suffix does what ``SHAPE_NODES`` (2)
grounded before do -- the same objects to the same regions by the same robots (:func:`_shape`, the failures'
memo's notion of the same suffix), the same objects left to move -- leads to the last of their nodes instead
of a new one.  On the 6-arm, 40-object instance of seed 1 the root grounded one 4-step suffix from a dozen
skeletons (they differed in the steps before it, which failed), each a node of its own with its own skeleton
source: 195 nodes and 1.4 GB in 300 s without a plan; with every such suffix sharing the first node, a plan
in 70 s at 440 MB, but seed 2 lost its plan: its second 6-step suffix of one shape, another geometry of the
same moves, is where the plan was found (a node per shape: a time limit; two: both solved).  Only a suffix
that moves more than its node's does shares (a suffix only grows, so every node then reaches only nodes that do
more than it): the search stays a graph without cycles.  Sharing without that rule hung the test suite in
session 31 -- a suffix moving an object again, where and by whom its node's suffix had, shared that very node,
and the selection descended it forever.

Progressive widening (beyond the paper, :meth:`MCTS._wider`): a node whose open edges are all visited asks
for one more skeleton when the selection rule would pick it (unvisited, with its last skeleton's prior) over
each of them -- the search selects as if the node held all its source's skeletons -- so a node whose subtree
keeps failing is offered skeletons of its own, not only more under the failing suffix.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

from mrgc.compiler.skeleton import Skeleton
from mrgc.planner.ground import GroundedStep, Grounding, Outcome, moved_objects
from mrgc.planner.outcome import DeadlineReached

#: nodes made for suffixes of one shape (the same moves, the same objects left) before the next such suffix
#: shares the last of them: a second geometry of a suffix may ground what the first did not (6-arm seed 2)
SHAPE_NODES = 2

# makes a skeleton source for (M*, moved objects): returns a callable giving the next k skeletons
SourceFactory = Callable[[set[str], set[str]], Callable[[int], list[Skeleton]]]


@dataclass
class Edge:
    """An edge of the search tree: a skeleton for the steps before a node, with its value and visits."""

    skeleton: Skeleton
    value: float = 0.0
    visits: int = 0
    child: "Node | None" = None
    dead: bool = False

    @property
    def prior(self) -> float:
        """The edge's prior: skeletons moving fewer objects first."""
        return 1.0 / max(1, len(self.skeleton.moved))


@dataclass
class Node:
    """A node of the search tree: the grounded suffix of the plan so far and the skeletons that may precede it."""

    suffix: list[GroundedStep]
    more: Callable[[int], list[Skeleton]]
    edges: list[Edge] = field(default_factory=list)
    visits: int = 0
    exhausted: bool = False  # the source has no more skeletons
    dead_end: bool = False  # a grounding showed that no skeleton can come before this node's suffix

    def refill(self, k: int) -> None:
        """Ask for up to ``k`` more skeletons for this node's edges (none once exhausted)."""
        if self.exhausted:
            return
        new = self.more(k)
        if not new:
            self.exhausted = True
        self.edges.extend(Edge(s) for s in new)

    @property
    def open_edges(self) -> list[Edge]:
        """The edges not yet known to fail."""
        return [e for e in self.edges if not e.dead]


@dataclass
class SearchResult:
    """The best plan found (None if none) and why the search ended: ``solved`` (first plan, or the anytime
    search ran until the tree was used up with a plan in hand), ``exhausted`` (the root ran out of
    skeletons), ``time limit``, ``iteration limit`` or ``interrupted`` (KeyboardInterrupt)."""

    steps: list[GroundedStep] | None
    iterations: int
    stats: dict[str, float]
    ended: str = "exhausted"


class MCTS:
    """The search; ``ground(skeleton, suffix)`` evaluates, ``sources(M*, moved)`` makes skeleton sources."""

    def __init__(
        self,
        ground: Callable[[Skeleton, list[GroundedStep]], Grounding],
        sources: SourceFactory,
        must_move: set[str],
        c: float = 1.0,
        alpha: float = 1.0,
        k: int = 5,
    ) -> None:
        self.ground = ground
        self.sources = sources
        self.c, self.alpha, self.k = c, alpha, k
        t0 = time.perf_counter()
        self.root = Node([], sources(must_move, set()))
        self.root.refill(1)  # the other k - 1 when the root is selected again (the module docstring)
        first_skeletons = time.perf_counter() - t0
        self.memo: set[tuple[frozenset[tuple[str, ...]], frozenset[object]]] = set()
        #: the nodes made, by their suffix's shape (:func:`_shape`) and the objects that must move before it
        self.nodes: dict[tuple[frozenset[tuple[str, ...]], frozenset[str]], list[Node]] = {}
        #: the best full plan found so far (by makespan, then objects moved)
        self.best: list[GroundedStep] | None = None
        self.stats: dict[str, float] = {
            "groundings": 0,
            "grounding_seconds": 0.0,
            "skeleton_seconds": first_skeletons,
            "skeletons": len(self.root.edges),
            "nodes": 1,
            "memo_hits": 0,
            "shared_nodes": 0,
        }

    def q(self, node: Node, e: Edge) -> float:
        """The edge's upper confidence bound (PUCT with the skeleton prior)."""
        return e.value / (e.visits + 1) + self.c * e.prior * math.sqrt(node.visits) / (e.visits + 1)

    def run(self, deadline: float, max_iterations: int = 10_000, anytime: bool = False) -> SearchResult:
        """Search until a plan is found (or, ``anytime``, until the deadline or the end of the tree, keeping
        the best plan by (makespan, objects moved)); Ctrl-C ends the search with what it has."""
        it = 0
        try:
            for it in range(1, max_iterations + 1):
                if time.perf_counter() >= deadline:
                    return SearchResult(self.best, it - 1, self.stats, "time limit")
                if not self._iterate(anytime):
                    return SearchResult(self.best, it, self.stats, "solved" if self.best is not None else "exhausted")
                if self.best is not None and not anytime:
                    return SearchResult(self.best, it, self.stats, "solved")
        except KeyboardInterrupt:
            return SearchResult(self.best, it, self.stats, "interrupted")
        except DeadlineReached:  # the time limit passed during a grounding
            return SearchResult(self.best, it, self.stats, "time limit")
        return SearchResult(self.best, max_iterations, self.stats, "iteration limit")

    def _iterate(self, anytime: bool) -> bool:
        """One selection-expansion-backpropagation round; False when the root has nothing left to try."""
        path: list[tuple[Node, Edge]] = []
        node = self.root
        reward = 0.0
        while True:
            short = self.k - len(node.edges) if node.visits else 0  # a visited node's K skeletons, made lazily
            wider = short <= 0 and self._wider(node)
            if not node.open_edges or short > 0 or wider:  # beyond the paper: more skeletons before giving up
                t0 = time.perf_counter()
                before = len(node.edges)
                node.refill(short if short > 0 and node.open_edges else 1 if wider else self.k)
                self.stats["skeleton_seconds"] += time.perf_counter() - t0
                self.stats["skeletons"] += len(node.edges) - before
            edges = node.open_edges
            if not edges:
                if path:
                    path[-1][1].dead = True  # nothing left below this edge
                break
            edge = max(edges, key=lambda e: self.q(node, e))
            path.append((node, edge))
            if edge.child is None:
                done, reward = self._expand(node, edge)
                if node.dead_end and len(path) > 1:
                    path[-2][1].dead = True  # nothing left below the edge into this node
                if done is not None:
                    edge.dead = True  # a full plan: nothing more to ground below this edge
                    if self.best is None or _cost(done) < _cost(self.best):
                        self.best = done
                        self.stats["plans"] = self.stats.get("plans", 0) + 1
                break
            node = edge.child
            if any(node is n for n, _ in path):  # the nodes' sharing keeps the graph acyclic (_expand)
                raise RuntimeError("the search graph has a cycle: a node is its own descendant")
        if not path:
            return False  # the root ran out of skeletons
        self._backprop(path, reward)
        return True

    def _wider(self, node: Node) -> bool:
        """Progressive widening: whether ``node``, its open edges all visited, should ask its source for one
        more skeleton -- when the selection rule would pick that skeleton, unvisited, over every open edge
        (its prior taken as the node's last skeleton's: the source gives them in (makespan, moved) order,
        though a deferral lifted starts that order again).  So the search selects as if the node held every
        skeleton of its source from the start (with equal priors, exactly: tests/test_planner.py), each made
        only when it would be selected.  Like PUCT over so many children, a node widens once ``c·prior·
        sqrt(visits)`` exceeds its open edges' mean rewards: soon under a subtree whose groundings keep failing
        (the mean falls towards 0), and after about ``(reward/(c·prior))²`` visits under one that keeps
        grounding suffixes without a plan, then at most of its visits (the paper's fixed K never widens).
        Without it a node whose open edges lead only into a subtree that keeps failing was never offered
        another skeleton of its own: that subtree's node asked its source for more, failure after failure,
        and the search never came back up (the 6-arm, 40-object instance of seed 6: the root's 5 skeletons
        used up at 83 s, then the rest of the run's 208 under the suffix of 8 steps the fifth had grounded)."""
        edges = node.open_edges
        if node.exhausted or not edges or any(e.visits == 0 for e in edges):
            return False
        fresh = self.c * node.edges[-1].prior * math.sqrt(node.visits)
        return fresh > max(self.q(node, e) for e in edges)

    def _expand(self, node: Node, edge: Edge) -> tuple[list[GroundedStep] | None, float]:
        here = _shape(node.suffix)
        memo_key = (here, edge.skeleton.actions)
        if memo_key in self.memo:
            self.stats["memo_hits"] += 1
            edge.dead = True
            return None, 0.0
        t0 = time.perf_counter()
        try:
            result = self.ground(edge.skeleton, node.suffix)
        finally:  # a grounding stopped by the time limit counts its time too
            self.stats["grounding_seconds"] += time.perf_counter() - t0
        self.stats["groundings"] += 1
        if result.outcome is Outcome.FAIL:
            self.memo.add(memo_key)
            edge.dead = True
            if result.dead_end:  # no skeleton can come before this node's suffix: the node is used up
                node.exhausted = node.dead_end = True
                for e in node.edges:
                    e.dead = True
            return None, 0.0
        if result.outcome is Outcome.SUCCESS:
            plan = result.steps
            return plan, 1.0 + self.alpha / max(1, len(moved_objects(plan)))
        moved = moved_objects(result.steps)
        shape = _shape(result.steps)
        same = (shape, frozenset(result.must_move))
        twins = self.nodes.setdefault(same, [])
        # only a suffix that adds moves to its node's shares: every node reached from a node then does more
        # than it, so no node can be its own descendant (a suffix moving an object again, to where and by whom
        # its node's suffix did, would have shared that node or an ancestor: a cycle the selection never left)
        grows = not shape <= here
        child = twins[-1] if grows and len(twins) >= SHAPE_NODES else None
        if child is not None:  # the same moves grounded often enough: the last such node, not another one
            self.stats["shared_nodes"] += 1
        else:
            t0 = time.perf_counter()
            child = Node(result.steps, self.sources(result.must_move, moved))
            child.refill(1)  # the first of its k skeletons: the others when it is selected again
            self.stats["skeleton_seconds"] += time.perf_counter() - t0
            self.stats["skeletons"] += len(child.edges)
            self.stats["nodes"] += 1
            twins.append(child)
        edge.child = child
        if not child.edges:
            edge.dead = True
            return None, 0.0
        best = min(child.edges, key=lambda e: e.skeleton.key)
        s_len, b_len = len(result.steps), best.skeleton.makespan
        reward = s_len / (s_len + b_len) + self.alpha / (len(moved) + len(best.skeleton.moved))
        return None, reward

    def _backprop(self, path: list[tuple[Node, Edge]], reward: float) -> None:
        for node, edge in path:
            edge.value += reward
            edge.visits += 1
            node.visits += 1


def _shape(suffix: list[GroundedStep]) -> frozenset[tuple[str, ...]]:
    """What a grounded suffix does, without its geometry: each object moved, where to and by which robots
    (the failures' memo and the nodes' sharing compare suffixes by it)."""
    return frozenset((a.object, a.region, a.pick_robot, a.place_robot) for s in suffix for a in s.actions)


def _cost(steps: list[GroundedStep]) -> tuple[int, int]:
    """The paper's order of plans: makespan, then the number of objects moved."""
    return (len(steps), len(moved_objects(steps)))
