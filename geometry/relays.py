"""Relays in phase 1 (beyond the paper): ``enable-relay M Re g1 g2 R1 R2``.

A goal object that no single action can take to its goal region (no robot both picks it and places it
there with one grasp, and no handover links a robot that picks it to one that places it) may still be
moved by setting it down on the way: R1 picks it with g1 and sets it down in another region Re, where R2
(another robot, or R1 with another grasp) picks it up with g2 and places it in its goal.  On generated
packaging tables this is a low box that only top grasps hold (two hands cannot both hold it from above,
so no handover exists), picked by an arm that cannot reach its bin.

The fact needs one placement of M in Re (a pose of :meth:`RobotEvaluator.placements
<mrgc.geometry.predicates.RobotEvaluator.placements>`' lattice) that R1 reaches holding M with g1 and R2
reaches with g2: grasp and pre-grasp by inverse kinematics, the arm, its fingers at the grasp's opening
and M along the approach free of the fixed objects (movable objects do not decide whether the fact holds, as
for ``reachable-place``: grounding looks for a free spot).  R1 must also pick M (``reachable-pick M g1 R1``)
and R2 place it in its goal (``reachable-place M goal g2 R2``).  Relays are looked for only for the goal
objects that need them, so a problem every goal of which has a pick-and-place or a handover gets the paper's
facts unchanged.

**In the way** (session 44).  The movable objects the two arms' approaches to a spot hit, or M on its way
there and at the spot, are what is in the way of the relay there; of the spots that make the fact, the one
with the fewest gives its ``occludes-relay M1 M Re g1 g2 R1 R2`` facts (none when one is free), and the
compiler makes them pick obstacles of the relay: a skeleton clears the spot first.

**Surfaces.**  When no region gives an object a relay with nothing in the way (a table whose regions are each
out of one arm's reach, or a crowded start region), the top of a fixed object may: ``enable-relay M table g1
g2 R1 R2`` sets M down on the table.  Spots are looked for in a STAGING square of the top
(:func:`mrgc.geometry.scene.surface`) centred between the two robots' bases (:func:`staging`), only for two
different robots, and only for those objects (so problems whose regions serve get the same facts as before).
Grounding looks in the same square (:func:`spot_region`); the validator accepts any spot on the top.

This module decides which spots to ask for and combines the answers; the per-robot inverse kinematics run
in :mod:`mrgc.geometry.predicates` (one worker per robot, like the rest of phase 1).
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from mrgc.geometry.scene import SURFACE_HEIGHT, Body, SceneSpec
from mrgc.geometry.transforms import translation
from mrgc.language.model import Box, Fact

#: side of the square of a fixed object's top where a relay between two robots looks for its spot (m)
STAGING = 0.3
#: joins a surface and a pair of robots into the name of their staging square in phase 1's asks (no
#: name of the language holds it)
PAIR = "@"

#: what one robot is asked: (object, grasp, region) triples whose spots it should try
Asks = list[tuple[str, str, str]]
#: what one robot answers: (object, grasp, region, lattice index) of each spot it reaches -> the movable objects
#: in the way there (its links along the approach, the object at the spot)
Spots = dict[tuple[str, str, str, int], frozenset[str]]


def stranded(scene: SceneSpec, facts: Iterable[Fact]) -> list[str]:
    """The goal objects no pick-and-place and no handover takes to their goal region (in goal order)."""
    by: dict[str, set[tuple[str, ...]]] = {}
    for f in facts:
        by.setdefault(f.predicate, set()).add(f.args)
    pick, place = by.get("reachable-pick", set()), by.get("reachable-place", set())
    hand = by.get("enable-goal-handover", set())
    out = []
    for obj, goal in scene.goal.items():
        picks = {(g, r) for o, g, r in pick if o == obj}
        places = {(g, r) for o, re, g, r in place if o == obj and re == goal}
        if picks & places:
            continue
        if any(o == obj and (g1, r1) in picks and (g2, r2) in places for o, g1, g2, r1, r2 in hand):
            continue
        if picks and places:
            out.append(obj)
    return out


def asks(scene: SceneSpec, facts: Iterable[Fact], objects: list[str], surfaces: bool = False) -> dict[str, Asks]:
    """Per robot, the spots to try for ``objects``: a robot that picks an object tries setting it down with
    that grasp, a robot that places it in its goal tries picking it up with that grasp, in every box region
    but the goal, or with ``surfaces`` in the staging square of every fixed box's top for each pair of it
    and another robot of the other role (sorted, so the answers are deterministic)."""
    wanted = set(objects)
    facts = list(facts)
    pickers: dict[str, set[str]] = {}
    placers: dict[str, set[str]] = {}
    roles = []
    for f in facts:
        a = f.args
        if f.predicate == "reachable-pick" and a[0] in wanted:
            roles.append((a[0], a[1], a[2], True))
            pickers.setdefault(a[0], set()).add(a[2])
        elif f.predicate == "reachable-place" and a[0] in wanted and a[1] == scene.goal[a[0]]:
            roles.append((a[0], a[2], a[3], False))
            placers.setdefault(a[0], set()).add(a[3])
    regions = sorted(r.name for r in scene.regions if isinstance(r.shape, Box))
    tops = sorted(b.name for b in scene.fixed if isinstance(b.shape, Box))
    out: dict[str, set[tuple[str, str, str]]] = {}
    for obj, grasp, robot, picks in roles:
        if surfaces:
            partners = (placers if picks else pickers).get(obj, set()) - {robot}
            where = [pair_name(top, robot, other) for top in tops for other in partners]
        else:
            where = [re for re in regions if re != scene.goal[obj]]
        out.setdefault(robot, set()).update((obj, grasp, w) for w in where)
    return {r: sorted(v) for r, v in out.items() if v}


def pair_name(surface: str, ra: str, rb: str) -> str:
    """The name phase 1 gives the staging square of ``surface`` between robots ``ra`` and ``rb``."""
    return PAIR.join((surface, *sorted((ra, rb))))


def staging(scene: SceneSpec, surface: str, ra: str, rb: str) -> Body:
    """The STAGING square of ``surface``'s top (a fixed object's, :func:`mrgc.geometry.scene.surface`)
    centred between the bases of ``ra`` and ``rb``, moved onto the top where it would overhang."""
    top = scene.region(surface)
    if not isinstance(top.shape, Box) or top.shape.sx <= 0:
        return top
    mid = (scene.robot(ra).base[:3, 3] + scene.robot(rb).base[:3, 3]) / 2
    inv = np.linalg.inv(top.pose)
    local = inv[:3, :3] @ mid + inv[:3, 3]
    half = np.minimum([STAGING / 2, STAGING / 2], [top.shape.sx / 2, top.shape.sy / 2])
    lim = np.array([top.shape.sx / 2, top.shape.sy / 2]) - half
    x, y = np.clip(local[:2], -lim, lim)
    return Body(surface, Box(2 * half[0], 2 * half[1], SURFACE_HEIGHT), top.pose @ translation(x, y, 0.0))


def spot_region(scene: SceneSpec, name: str, r1: str = "", r2: str = "") -> Body:
    """Where a relay through ``name`` by ``r1`` and ``r2`` looks for its spot: the region ``name``, the
    staging square of a fixed object's top between the two robots, or a :func:`pair_name` of one."""
    if PAIR in name:
        surface, ra, rb = name.split(PAIR)
        return staging(scene, surface, ra, rb)
    if any(f.name == name for f in scene.fixed):
        return staging(scene, name, r1, r2)
    return scene.region(name)


def relay_facts(scene: SceneSpec, facts: Iterable[Fact], spots: dict[str, Spots]) -> set[Fact]:
    """``enable-relay`` facts from each robot's reached spots (see the module docstring), and for each relay
    the ``occludes-relay`` facts of its spot that has the fewest movable objects in the way of the two arms
    (their links along the approaches, the object at the spot; the lowest lattice index among equals): none
    when one is free."""
    facts = list(facts)
    pick = {f.args for f in facts if f.predicate == "reachable-pick"}
    place = {f.args for f in facts if f.predicate == "reachable-place"}
    # robot -> (object, region, lattice index) -> the grasps it holds the object with there -> what is in the way
    grasps: dict[str, dict[tuple[str, str, int], dict[str, frozenset[str]]]] = {}
    for robot, reached in spots.items():
        for (obj, grasp, region, k), hits in reached.items():
            grasps.setdefault(robot, {}).setdefault((obj, region, k), {})[grasp] = hits
    # (M, Re, g1, g2, R1, R2) -> (objects in the way, lattice index, region asked) of its best spot
    best: dict[tuple[str, str, str, str, str, str], tuple[int, int, str, frozenset[str]]] = {}
    for r1, mine in grasps.items():
        for r2, theirs in grasps.items():
            for (obj, region, k), g1s in mine.items():
                goal = scene.goal[obj]
                where, *pair = region.split(PAIR)
                if pair and sorted((r1, r2)) != pair:
                    continue  # a staging square is the one between r1 and r2
                for g1, in_way in g1s.items():
                    for g2, also in theirs.get((obj, region, k), {}).items():
                        if (r1, g1) != (r2, g2) and (obj, g1, r1) in pick and (obj, goal, g2, r2) in place:
                            key = (obj, where, g1, g2, r1, r2)
                            spot = (len(in_way | also), k, region, in_way | also)
                            if key not in best or spot[:3] < best[key][:3]:
                                best[key] = spot
    out: set[Fact] = set()
    for key, (_, _, _, occupied) in best.items():
        out.add(Fact("enable-relay", key))
        out.update(Fact("occludes-relay", (o, *key)) for o in sorted(occupied))
    return out


def free_relays(facts: Iterable[Fact]) -> set[str]:
    """The objects with a relay (``enable-relay``) that nothing is in the way of at its spot (no
    ``occludes-relay`` fact names it)."""
    facts = list(facts)
    blocked = {f.args[1:] for f in facts if f.predicate == "occludes-relay"}
    return {f.args[0] for f in facts if f.predicate == "enable-relay" and f.args not in blocked}
