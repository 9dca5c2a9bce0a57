"""Every robot kind implements the robot protocol (geometry/robot.py), data-driven over the kinds' table
(geometry/kinds.py): a kind added there without an example here, or without a member of the protocol, fails."""

from __future__ import annotations

import numpy as np
import pytest
from support import ROOT

from mrgc import parse_file
from mrgc.geometry.collision import CollisionShape, collision_shape
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.kinds import KINDS, robot_for
from mrgc.geometry.robot import Rest, Robot
from mrgc.geometry.scene import SceneSpec, scene_from_problem
from mrgc.language.model import BASE_TYPES

#: base type -> a shipped problem with a robot of that kind, and a grasp it holds objects with
EXAMPLES = {
    "fixed": ("packaging/pa3-handover.mrg", "top"),
    "planar": ("box-moving/bo-doorway.mrg", "side-x+"),
}


def _scene(base: str) -> SceneSpec:
    return scene_from_problem(parse_file(ROOT / "domains" / EXAMPLES[base][0]).problem())


def test_every_base_type_of_the_language_has_a_robot_class_and_an_example() -> None:
    assert set(KINDS) == set(BASE_TYPES) == set(EXAMPLES)


@pytest.mark.parametrize("base", sorted(KINDS))
def test_each_kind_implements_the_protocol(base: str) -> None:
    scene = _scene(base)
    spec = next(r for r in scene.robots if r.kind.base == base)
    robot = robot_for(spec)
    assert isinstance(robot, Robot)  # every member is there (runtime_checkable); mypy checks the signatures
    assert robot.name == spec.name
    assert isinstance(robot.approaches, bool) and isinstance(robot.parks, bool)
    home = np.asarray(robot.home, dtype=float)
    assert home.ndim == 1 and np.all(np.isfinite(home))

    # how it holds an object, and its volume with and without it, one volume per configuration
    obj = scene.movable[0]
    opening, in_frame = robot.hold(obj.shape, EXAMPLES[base][1], scene.grasp_specs)
    assert in_frame.shape == (4, 4) and (opening is None or opening >= 0.0)
    configs = np.stack([home, home])
    empty = robot.volumes(configs)
    full = robot.volumes(configs, (collision_shape(obj.shape), in_frame), opening)
    assert len(empty) == len(full) == 2
    assert all(len(f) == len(e) + 1 for e, f in zip(empty, full))  # the held object: one piece more each
    for shape, t in (p for volume in full for p in volume):
        assert isinstance(shape, CollisionShape) and t.shape == (4, 4)

    # what it leaves in the world: itself at home (its volume there), and named parts that never move
    rest = robot.rest()
    assert isinstance(rest, Rest) and rest.home
    (at_home,) = robot.volumes(home[None])
    assert [s for s, _ in rest.home] == [s for s, _ in at_home]
    assert np.allclose([t for _, t in rest.home], [t for _, t in at_home])
    assert all(isinstance(name, str) and isinstance(shape, CollisionShape) for name, shape, _ in rest.mount)

    # its reach: it reaches where it stands, and ranks tool poses by a distance
    assert robot.in_reach(rest.home[-1][1][:3, 3]) is True
    tools = np.stack([t for _, t in rest.home])
    rank = robot.comfort(tools, 0.85)
    assert rank.shape == (len(tools),) and (rank >= 0.0).all()
    assert robot.comfort(tools[0], 0.85) == rank[0]  # one pose: the same rank as in the stack


@pytest.mark.parametrize("base", sorted(KINDS))
def test_the_grounder_makes_each_robot_of_its_kinds_class(base: str) -> None:
    """The grounder asks the robot object, made through the kinds' table (geometry/kinds.py)."""
    scene = _scene(base)
    g = Grounder(scene, seed=0)
    for spec in scene.robots:
        assert type(g.robot(spec.name)) is KINDS[spec.kind.base]
        assert g.robot(spec.name) is g.robot(spec.name)  # made once
