"""An arm never collides with itself in what the planner answers: the rule (which link pairs are checked),
derived from the URDF and compared with pybullet's reading of it; the check against pybullet's distances;
IK answers, paths and phase-1 facts in self-collision refused; grounded plans free of self-collision.

pybullet's side is tests/doctor.py's world (its arms, the link pairs it derives from pybullet's joint info,
its signed distances with the mesh margins added back), nothing of the planner's geometry."""

from __future__ import annotations

from pathlib import Path

import doctor as d
import numpy as np
import pytest

from mrgc.compiler.skeleton import Skeleton
from mrgc.compiler.task_graph import Action
from mrgc.geometry.answers import SELF, GroundStatus
from mrgc.geometry.arm import SELF_CLEARANCE, Arm
from mrgc.geometry.arm_paths import joint_line
from mrgc.geometry.conventions import refine
from mrgc.geometry.grasps import finger_opening, grasp_transform, pregrasp_transform
from mrgc.geometry.grounding import Grounder
from mrgc.geometry.kinematics import RobotModel, load_robot_model
from mrgc.geometry.predicates import IK_SEEDS, RobotEvaluator
from mrgc.geometry.scene import SceneSpec, scene_from_problem
from mrgc.language.loader import parse_file
from mrgc.language.model import Fact
from mrgc.planner.ground import Outcome, ReverseGrounder

ROOT = Path(__file__).resolve().parents[1]
PACKAGING = ROOT / "domains" / "packaging"
PA10 = str(PACKAGING / "pa10.mrg")
#: the validator's contact tolerance: a penetration deeper than this is a self-collision
CONTACT_TOL = 0.001
#: pybullet's distances are asked up to this far (farther pairs read as this far: nothing here needs more)
FAR = 0.01
#: pa10 (seed 0) before the planner checked self-collision: step 1's last ``to-place`` configuration of r1
#: (holding o9 with side-y-), panda_link6 about 45 mm inside panda_link0
PA10_STEP1_LAST = [0.6558920029, 0.8568735203, -0.1257698754, -2.9921378644, -2.4661373292, 1.0423137323, -1.859372149]

# a toy arm whose tree has what the Panda's has not: a fixed joint inside the chain (l2 -> l2b), an off-chain
# revolute branch (side, on l1), a tool link bolted to the last link and a link without geometry
TOY = """<?xml version="1.0"?>
<robot name="toy">
  <link name="base">{body}</link>
  <link name="l1">{body}</link>
  <link name="l2">{body}</link>
  <link name="l2b">{body}</link>
  <link name="l3">{body}</link>
  <link name="tool">{body}</link>
  <link name="side">{body}</link>
  <link name="bare"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="f2" type="fixed"><parent link="l2"/><child link="l2b"/><origin xyz="0 0 0.2"/></joint>
  <joint name="j3" type="revolute"><parent link="l2b"/><child link="l3"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="ft" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0 0 0.2"/></joint>
  <joint name="js" type="revolute"><parent link="l1"/><child link="side"/><origin xyz="0.1 0 0.1"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="fb" type="fixed"><parent link="tool"/><child link="bare"/></joint>
</robot>
""".format(
    body='<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
    '<collision><origin xyz="0 0 0.05"/><geometry><box size="0.04 0.04 0.1"/></geometry></collision>'
)
TOY_PROBLEM = """
(define (domain toy)
  (:robot-kind toy :urdf "toy.urdf" :base fixed :end-effector "tool" :tcp (0 0 0 0) :home (0 0 0))
  (:grasps top))
(define (problem toy)
  (:domain toy)
  (:robots (r1 :kind toy :base (0 0 0 0)))
  (:regions (start :shape (box 0.2 0.2 0.1) :pose (1 1 0.05 0)))
  (:movable (o1 :shape (box 0.05 0.05 0.05) :pose (1 1 0.025 0)))
  (:goal (in-region o1 start)))
"""


@pytest.fixture(scope="module")
def pa10() -> SceneSpec:
    return scene_from_problem(parse_file(PA10).problem())


def _named(model: RobotModel) -> set[frozenset[str]]:
    """The model's checked pairs by link name."""
    return {frozenset((model.links[a].name, model.links[b].name)) for a, b in model.self_collision_pairs}


def _pybullet_pairs(path: str, robot: str) -> set[frozenset[str]]:
    """The checked pairs of ``robot`` of problem ``path`` as pybullet reads its URDF (tests/doctor.py)."""
    r = d.world(path).robots[robot]
    return {frozenset((r.links[a], r.links[b])) for a, b in r.pairs}


def _self_distance(w: d.World, robot: str, q: np.ndarray, opening: float | None) -> float:
    """pybullet's least distance between two checked links of ``robot`` at ``q``, its fingers ``opening``
    apart (None: open); :data:`FAR` when none is nearer."""
    w.set_q(robot, q)
    w.set_fingers(robot, opening)
    c = w.self_distance(robot, reach=FAR)
    return FAR if c is None else min(FAR, c[0])


def test_the_pandas_checked_pairs_are_those_more_than_one_chain_joint_apart(panda: RobotModel) -> None:
    checked = _named(panda)
    assert checked == _pybullet_pairs(PA10, "r1")
    solid = [link.name for link in panda.links if link.solid]
    assert len(solid) == 11 and len(checked) == 39  # of 55 pairs, 16 exempt
    for a, b in [("link0", "link1"), ("link5", "link6"), ("link6", "leftfinger"), ("link6", "hand")]:
        assert frozenset((f"panda_{a}", f"panda_{b}")) not in checked  # one chain joint between them
    for a, b in [("link7", "hand"), ("hand", "leftfinger"), ("leftfinger", "rightfinger")]:
        assert frozenset((f"panda_{a}", f"panda_{b}")) not in checked  # fixed or off-chain joints only
    for a, b in [("link0", "link6"), ("link1", "link5"), ("link5", "hand"), ("link5", "rightfinger")]:
        assert frozenset((f"panda_{a}", f"panda_{b}")) in checked
    pairs = set(panda.self_collision_pairs)
    for i, a in enumerate(solid):  # the property, pair by pair
        for b in solid[i + 1 :]:
            ia, ib = panda.link_index(a), panda.link_index(b)
            assert ((ia, ib) in pairs) == (panda.chain_joints_between(ia, ib) > 1), (a, b)


def test_fixed_and_off_chain_joints_do_not_count(tmp_path: Path) -> None:
    (tmp_path / "toy.urdf").write_text(TOY, encoding="utf-8")
    (tmp_path / "toy.mrg").write_text(TOY_PROBLEM, encoding="utf-8")
    toy = load_robot_model("toy.urdf", str(tmp_path), "tool")
    assert toy.joint_names == ("j1", "j2", "j3")
    checked = _named(toy)
    assert checked == _pybullet_pairs(str(tmp_path / "toy.mrg"), "r1")
    assert checked == {
        frozenset(p)
        for p in [
            ("base", "l2"),  # j1, j2
            ("base", "l2b"),  # j1, j2 (the fixed joint f2 does not count)
            ("base", "l3"),
            ("base", "tool"),
            ("l1", "l3"),  # j2, j3
            ("l1", "tool"),
            ("side", "l3"),  # j2, j3 (js is off the chain)
            ("side", "tool"),
        ]
    }
    assert "bare" not in {name for pair in checked for name in pair}  # no collision geometry


def test_a_known_self_colliding_configuration_is_detected(pa10: SceneSpec, panda: RobotModel) -> None:
    """pa10 seed 0 before the fix: r1 carried o9 with link6 deep inside link0; the check sees it, pybullet
    measures the same penetration, and along the straight line from home to it the check refuses exactly
    the configurations pybullet finds within the clearance."""
    arm, w = Arm(pa10.robot("r1")), d.world(PA10)
    q = np.array(PA10_STEP1_LAST)
    opening = finger_opening(pa10.grasp("side-y-"), pa10.body("o9").shape)
    assert arm.self_collides(q, opening)
    assert not arm.self_collides(arm.home)
    w.set_q("r1", q)
    w.set_fingers("r1", opening)
    r = w.robots["r1"]
    depth = w.closest("r1", "r1", r.link("panda_link0"), r.link("panda_link6"), reach=FAR)
    assert depth is not None and -0.050 < depth[0] < -0.040, depth
    line = np.linspace(arm.home, q, 40)
    verdicts = arm.self_colliding(line, opening)
    assert verdicts[-1] and not verdicts[0]
    for k in range(len(line)):
        dist = _self_distance(w, "r1", line[k], opening)
        assert verdicts[k] == (dist <= SELF_CLEARANCE) or abs(dist - SELF_CLEARANCE) < 2e-4, (k, dist)


def test_the_check_agrees_with_pybullet_on_random_configurations(pa10: SceneSpec, panda: RobotModel) -> None:
    """300 random configurations and finger openings: every one pybullet finds in self-collision (deeper
    than the validator's 1 mm) is refused, and every one refused is closer than the clearance there.  The
    batched check (whose oriented-box stage runs on this many pairs) gives the one-by-one verdicts."""
    arm, w = Arm(pa10.robot("r1")), d.world(PA10)
    rng = np.random.default_rng(7)
    qs = rng.uniform(panda.lower, panda.upper, (300, panda.dof))
    openings = rng.uniform(0.0, 0.08, 300)
    refused = 0
    for q, opening in zip(qs, openings):
        dist = _self_distance(w, "r1", q, float(opening))
        ours = arm.self_collides(q, float(opening))
        refused += ours
        if dist < -CONTACT_TOL:
            assert ours, dist
        if ours:
            assert dist <= SELF_CLEARANCE + 1e-4, dist
    assert 20 < refused < 280  # random Panda configurations often fold into themselves
    one_by_one = [arm.self_collides(q, 0.04) for q in qs]
    assert arm.self_colliding(qs, 0.04).tolist() == one_by_one


def test_one_check_of_the_arm_and_what_it_holds_answers_as_the_two_checks(pa10: SceneSpec) -> None:
    """geometry/arm.py ``collides_with_itself_at`` (the motion checks' form): holding each of three objects
    with a grasp each, at 400 configurations one by one and in batches of 25, the same verdict as the links'
    own check or the held object's; the held object's poses of :meth:`Arm.posed` are the tool poses of
    ``tool_world`` carrying it (to 1e-12 m: computed from the links' frames, not a second chain)."""
    g = Grounder(pa10, seed=0)
    arm = g.arm("r1")
    rng = np.random.default_rng(3)
    qs = rng.uniform(arm.model.lower, arm.model.upper, (400, arm.model.dof))
    held_any = 0
    for obj, grasp in (("o1", "top"), ("o5", "side-x+"), ("o9", "side-y-")):
        held = g._held("r1", (obj, grasp))
        assert held is not None
        opening = g._grip("r1", obj, grasp)[0]
        for k in list(range(400)) + [slice(s, s + 25) for s in range(0, 400, 25)]:
            _, links, poses = arm.posed(qs[k] if isinstance(k, slice) else qs[k : k + 1], held, opening)
            assert poses is not None
            two = arm.self_collides_at(links) or arm.held_collides_at(links, held[0], poses)
            assert arm.collides_with_itself_at(links, held[0], poses) == two
            held_any += not arm.self_collides_at(links) and two
        tools = arm.tool_world(qs) @ held[1]
        assert np.allclose(arm.posed(qs, held, opening)[2], tools, rtol=0, atol=1e-12)
    assert held_any > 0  # some configurations are refused for the held object alone


def test_an_ik_answer_in_self_collision_is_refused() -> None:
    """pa-basic: o2 stands so near r1's base that every IK solution of its side-y- approach folds link6 into
    link0 (60 random-start solves: none free).  Phase 1 drops the fact it used to give, grounding answers
    with the reason, and the other grasps are unaffected."""
    scene = scene_from_problem(parse_file(PACKAGING / "pa-basic.mrg").problem())
    ev = RobotEvaluator(scene, "r1", seed=0)
    body = scene.body("o2")
    g_t = grasp_transform(scene.grasp("side-y-"), body.shape)
    opening = ev.opening("o2", "side-y-")
    for attempt in range(IK_SEEDS):  # each attempt's IK solves, and its approach is in self-collision
        (q,) = ev._ik([body.pose @ g_t], "grasp", attempt=attempt)
        assert q is not None
        (pre,) = ev._ik([body.pose @ pregrasp_transform(g_t)], "pre", attempt=attempt, q_init=q[None], restarts=2)
        assert pre is not None and ev.arm.self_collides(refine(ev._approach(pre, q)), opening)
    facts = set(ev.run().facts)
    assert Fact("reachable-pick", ("o2", "side-y-", "r1")) not in facts
    assert Fact("reachable-pick", ("o2", "top", "r1")) in facts
    g = Grounder(scene, seed=0)
    answer = g.pick("r1", "o2", "side-y-")
    assert answer.status is GroundStatus.COLLISION and answer.detail == SELF and answer.static
    top = g.pick("r1", "o2", "top")
    assert top.ok and top.configs is not None
    assert not g.arm("r1").self_collides(refine(top.configs), opening=finger_opening(scene.grasp("top"), body.shape))


def test_paths_refuse_a_configuration_in_self_collision(pa10: SceneSpec) -> None:
    g = Grounder(pa10, seed=0)
    arm = g.arm("r1")
    folded = np.array(PA10_STEP1_LAST)
    assert not g.transit("r1", arm.home, folded).ok
    assert g.arm_path("r1", arm.home, folded, max_checks=200).status is GroundStatus.NO_PATH
    assert g.free_volume("r1", folded[None]) is None
    assert g.free_volume("r1", arm.home[None]) is not None


@pytest.mark.parametrize("name", ["pa5", "pa10", "pa18-4arms", "pa-basic", "pa3-handover", "pa3-place-obstacle"])
def test_every_shipped_home_is_free_of_self_collision(name: str) -> None:
    scene = scene_from_problem(parse_file(PACKAGING / f"{name}.mrg").problem())
    for spec in scene.robots:
        arm = Arm(spec)
        assert not arm.self_collides(arm.home), spec.name


def _worst_self_distance(path: str, skeleton: Skeleton, full: bool) -> tuple[float, int]:
    """Ground ``skeleton`` (seed 0) on problem ``path`` and measure with pybullet every configuration of its
    actions and the straight joint-space lines between consecutive ones at 0.01 rad, on the arm that makes
    the motion, its fingers as the validator sets them (at the grasp's opening approaching and holding, else
    open): the least distance between two checked links of one arm, and how many configurations."""
    scene = scene_from_problem(parse_file(path).problem())
    grounding = ReverseGrounder(Grounder(scene, seed=0), dict(scene.goal), full=full).ground(skeleton, [])
    assert grounding.outcome is Outcome.SUCCESS, grounding.reason
    w = d.world(path)
    checked, worst = 0, np.inf
    for step in grounding.steps:
        for a in step.actions:
            giver, taker = (a.pick_robot, a.pick_grasp), (a.place_robot, a.place_grasp)
            motions = {  # name -> (robot, grasp at whose opening the fingers stand, or None: open)
                "pick": giver,
                "to-handover": giver,
                "to-pick": (a.pick_robot, None),
                "giver-home": (a.pick_robot, None),
                "to-place": taker,
                "place": taker,
                "taker-to-handover": (a.place_robot, None),
                "home": (a.place_robot, None),
            }
            runs = [(n, c) for n, c in [*a.configs.items(), *a.paths.items()] if n != "handover"]
            if "handover" in a.configs:  # the two arms' exchange configurations, each on its own
                runs += [("to-handover", a.configs["handover"][:1]), ("place", a.configs["handover"][1:])]
            for name, configs in runs:
                robot, grasp = motions[name]
                opening = None if grasp is None else finger_opening(scene.grasp(grasp), scene.body(a.object).shape)
                for q in joint_line(np.array(configs), 0.01):
                    worst = min(worst, _self_distance(w, robot, q, opening))
                    checked += 1
    return worst, checked


def test_pa10s_carry_that_folded_link6_into_link0_is_grounded_free_of_it() -> None:
    """pa10, seed 0: r1 moves o9 aside with side-y- (step 1 of its plan).  Grounded alone, the carry ended
    with link6 45 mm inside link0 (64 of its 304 configurations within the clearance) before the planner
    checked self-collision; now no link pair comes within the validator's tolerance."""
    skeleton = Skeleton(((Action("o9", "start", "r1", "r1", "side-y-", "side-y-"),),))
    worst, checked = _worst_self_distance(PA10, skeleton, full=False)
    assert checked > 100
    assert worst > -CONTACT_TOL, worst


def test_a_grounded_pa5_is_free_of_self_collision_by_pybullet() -> None:
    """pa5's plan (seed 0: r1 hands o5 over to r2, then moves o4) grounded with every arm motion planned
    (``--motions full``: transits, the taker's way to the exchange, the giver's way home too)."""
    skeleton = Skeleton(
        (
            (Action("o5", "bin-b", "r1", "r2", "side-x+", "top"),),
            (Action("o4", "bin-a", "r1", "r1", "side-y-", "side-y-"),),
        )
    )
    worst, checked = _worst_self_distance(str(PACKAGING / "pa5.mrg"), skeleton, full=True)
    assert checked > 500
    assert worst > -CONTACT_TOL, worst
