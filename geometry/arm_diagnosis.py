"""Why an arm can reach nothing: the three structural causes, each a located warning (docs/errors.md).

Phase 1 answers "no fact" for an arm that collides wherever it goes, or whose IK never converges, exactly
as for an object that is merely out of reach; without a diagnosis the user sees only "3 facts" or "the
goals are unreachable".  :func:`arm_diagnostics` looks for the causes directly, per fixed-base robot of a
geometric problem, at the robot's declaration (``mrgc check``, ``mrgc facts``, ``mrgc plan``):

- ``W274`` **every configuration collides**: of :data:`SAMPLES` configurations drawn within the joint
  limits (seeded per robot), one link collides with one fixed object in all of them, with the planner's
  rule (touching counts; the arm's mount, :attr:`~mrgc.geometry.kinematics.RobotModel.mount`, is exempt
  from what it stands on).  The line names the link, the object, how deep (or "touches") and the height:
  ``every configuration of a1 (64 drawn) collides with fixed object 'table': link 'link1' is 85.0 mm
  inside it (its lowest point at z = -0.085)``.
- ``W275`` **the home configuration collides** with a fixed object (touching counts) or with the arm
  itself (:attr:`~mrgc.geometry.kinematics.RobotModel.self_collision_pairs`): every motion of the arm
  starts and ends there, so grounding fails whatever the facts say.  Not reported with W274.
- ``W276`` **IK never converges**: the numeric solver (seeded restarts, as phase 1) finds no configuration
  for any grasp of any object within the arm's reach bound, collisions ignored, or nothing of the problem
  (no object, region or handover point) lies within that bound at all: the chain cannot put its
  end-effector link there, which usually means ``:end-effector`` names the wrong link (a short chain), or
  the TCP is far off.

Warnings, not errors: the problem may be solvable by the other robots.  Each check is cheap (tens of
milliseconds per arm besides loading its meshes) and deterministic; its answers are cached per problem,
since ``facts`` and ``plan`` ask through both tiers of :mod:`mrgc.geometry.layout`.
"""

from __future__ import annotations

import functools
import itertools
from typing import TYPE_CHECKING, Iterable, Iterator

import numpy as np

from mrgc.errors import Diagnostic, InputError
from mrgc.language.model import Problem

if TYPE_CHECKING:
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.collision import CollisionWorld
    from mrgc.geometry.scene import Body, SceneSpec

#: configurations drawn per arm for W274
SAMPLES = 64
#: how far beyond an arm's reach bound (m) phase 1 still asks IK (``predicates.py``'s pre-filter margin)
REACH_MARGIN = 0.3
#: IK targets solved per batch (the check stops at the first batch with an answer)
IK_CHUNK = 24
#: a signed distance above this (m) is "touches" rather than "inside"
TOUCH = 5e-4


def arm_diagnostics(problem: Problem) -> list[Diagnostic]:
    """W274, W275 and W276 (module docstring) for the fixed-base robots of ``problem``, in declaration
    order; none for a symbolic problem or when a robot's model cannot be loaded (E400/E401 are reported
    where the model is needed)."""
    from mrgc.geometry.kinds import approaches

    if problem.symbolic or not any(approaches(k) for k in problem.domain.robot_kinds):
        return []
    return list(_cached(problem))


@functools.lru_cache(maxsize=16)
def _cached(problem: Problem) -> tuple[Diagnostic, ...]:
    from mrgc.geometry.arm import Arm
    from mrgc.geometry.collision import scene_world
    from mrgc.geometry.kinds import approaches
    from mrgc.geometry.scene import scene_from_problem

    try:  # a model or a mesh that cannot be loaded is reported where it is needed, not as a diagnosis here
        scene = scene_from_problem(problem)
        arms = [Arm(spec) for spec in scene.robots if approaches(spec.kind)]
        world = scene_world(scene)
    except InputError:
        return ()
    spans = {r.name: r.span for r in problem.robots}
    out: list[Diagnostic] = []
    for arm in arms:
        if arm.model.dof == 0:  # no joint between the root and the end effector: nothing can move
            out.append(Diagnostic("W276", _no_chain(arm), spans.get(arm.name), severity="warning"))
            continue
        found = _everywhere(arm, world) or _home(arm, world)
        if found is not None:
            out.append(Diagnostic(found[0], found[1], spans.get(arm.name), severity="warning"))
        ik = _no_ik(arm, scene)
        if ik is not None:
            out.append(Diagnostic("W276", ik, spans.get(arm.name), severity="warning"))
    return tuple(out)


def _no_chain(arm: Arm) -> str:
    """W276 for an arm whose end-effector link is its root or fixed to it."""
    return (
        f"IK for {arm.name} has no joint to move: is :end-effector right? '{arm.model.end_effector}' is fixed to "
        f"the root link '{arm.model.links[0].name}' (a chain of 0 joints)"
    )


def _samples(arm: Arm) -> np.ndarray:
    from mrgc.geometry.conventions import seed_for

    model = arm.model
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    rng = np.random.default_rng(seed_for(arm.name, "reach-diagnosis"))
    return rng.uniform(lo, hi, size=(SAMPLES, model.dof))


def _everywhere(arm: Arm, world: CollisionWorld) -> tuple[str, str] | None:
    """W274: a (link, fixed object) that collide at every drawn configuration, with the deepest case."""
    shapes, index = arm.probes
    qs = _samples(arm)
    transforms = arm.link_transforms(qs)
    for i, (shape, k) in enumerate(zip(shapes, index)):
        always: set[str] | None = None
        for c in range(len(qs)):
            hits = world.probe_hits([(shape, transforms[c, i])], against="fixed")
            always = hits if always is None else always & hits
            if not always:
                break
        if always:
            obj = sorted(always)[0]
            depth, c = min((_distance(world, shape, transforms[c, i], obj), c) for c in range(len(qs)))
            link = arm.model.links[k]
            low = _lowest(link.points, transforms[c, i])
            return "W274", (
                f"every configuration of {arm.name} ({len(qs)} drawn within its joint limits) collides with "
                f"fixed object '{obj}': link '{link.name}' {_how(depth)} (its lowest point at z = {_z(low)}); "
                f"move the robot's :base or the object"
            )
    return None


def _home(arm: Arm, world: CollisionWorld) -> tuple[str, str] | None:
    """W275: the home configuration against the fixed objects (the deepest link), then against itself."""
    shapes, index = arm.probes
    transforms = arm.link_transforms(arm.home[None])[0]
    worst: tuple[float, str, str] | None = None
    for shape, k, t in zip(shapes, index, transforms):
        for obj in sorted(world.probe_hits([(shape, t)], against="fixed")):
            d = _distance(world, shape, t, obj)
            if worst is None or d < worst[0]:
                worst = (d, arm.model.links[k].name, obj)
    kind = arm.spec.kind.name
    if worst is not None:
        d, link, obj = worst
        return "W275", (
            f"the home configuration of {arm.name} collides with fixed object '{obj}': link '{link}' "
            f"{_how(d)}; every motion of the arm starts there: change :home of robot kind '{kind}'"
        )
    if arm.self_collides(arm.home[None]):
        return "W275", (
            f"the home configuration of {arm.name} collides with itself (two of its links closer than "
            f"{_mm(_clearance())}); every motion of the arm starts there: change :home of robot kind '{kind}'"
        )
    return None


def _no_ik(arm: Arm, scene: SceneSpec) -> str | None:
    """W276: IK finds no configuration for any grasp of the objects within the arm's reach bound, or nothing
    of the scene (objects, regions, handover points) lies within that bound at all."""
    from mrgc.geometry.conventions import seed_for
    from mrgc.geometry.ik import solve_ik_many
    from mrgc.geometry.ik_analytic import panda_chain

    model = arm.model
    first = model.links[model.joints[0].link].parent if model.joints else model.ee_link
    chain = (
        f"is :end-effector right? '{model.end_effector}' ends a chain of {model.dof} "
        f"joint{'s' * (model.dof != 1)} from '{model.links[first].name}'"
    )
    targets = _targets(arm, scene)  # the objects where they stand, then places and handovers
    chunk = list(itertools.islice(targets, IK_CHUNK))
    if not chunk:
        return (
            f"nothing of the problem lies within reach of {arm.name} (its chain reaches {model.reach:.2f} m from "
            f"its shoulder; no object, region or handover point lies within {REACH_MARGIN:g} m beyond): {chain}"
        )
    tried = 0
    while chunk:  # in chunks: a healthy arm stops at its first answer
        seed = seed_for(arm.name, "ik-diagnosis", str(tried))
        tried += len(chunk)
        # an arm of a Panda's kinematics is asked analytically first (a healthy one answers in its first chunk,
        # 24 solves in about 1 ms against 20 ms numerically); a chunk it finds nothing for is asked numerically,
        # so the diagnosis does not depend on the analytic solver
        for analytic in (True, False) if panda_chain(model) is not None else (False,):
            found = solve_ik_many(model, np.stack(chunk), seed, q_init=arm.home, restarts=4, analytic=analytic)
            if any(r.solved for r in found):
                return None
        chunk = list(itertools.islice(targets, IK_CHUNK))
    return (
        f"IK for {arm.name} found no solution for {tried:,} targets (grasps of the objects where they stand, on "
        f"the regions' placement lattices and at the handover points, within its reach; collisions ignored): "
        f"{chain}"
    )


def _targets(arm: Arm, scene: SceneSpec) -> Iterator[np.ndarray]:
    """End-effector targets (base frame) within the arm's reach bound, lazily: every grasp of every object
    where it stands; then every grasp of every object resting on phase 1's 3 × 3 placement lattice of each
    region (centres first) and held at each handover point."""
    from mrgc.geometry.conventions import lattice_offsets
    from mrgc.geometry.grasps import grasp_transform
    from mrgc.geometry.scene import half_extents
    from mrgc.geometry.transforms import translation

    def grasps(body: Body, pose: np.ndarray) -> Iterator[np.ndarray]:
        if arm.in_reach(pose[:3, 3], margin=REACH_MARGIN):
            for g in scene.grasps[body.name]:
                spec = scene.grasp_specs.get(g)
                if spec is not None:
                    yield arm.ee_target(pose @ grasp_transform(spec, body.shape))

    for m in scene.movable:
        yield from grasps(m, m.pose)
    for m in scene.movable:
        for p in scene.handover_points.values():
            yield from grasps(m, translation(*p))
    for a, b in lattice_offsets(3):
        for m in scene.movable:
            h = half_extents(m.shape)
            for r in scene.regions:
                room = half_extents(r.shape) - h
                floor = translation(a * room[0] * 0.9, b * room[1] * 0.9, float(h[2] - half_extents(r.shape)[2]))
                yield from grasps(m, r.pose @ floor)


def _distance(world: CollisionWorld, shape: object, t: np.ndarray, obj: str) -> float:
    world.add("^diagnosis", shape, t, "diagnosis")  # type: ignore[arg-type]
    try:
        return float(world.distance("^diagnosis", obj))
    finally:
        world.remove("^diagnosis")


def _lowest(points: np.ndarray, t: np.ndarray) -> float:
    return float(np.min(points @ t[:3, :3].T[:, 2] + t[2, 3])) + 0.0


def _how(depth: float) -> str:
    return "touches it" if depth > -TOUCH else f"is {_mm(-depth)} inside it"


def _mm(v: float) -> str:
    return f"{v * 1e3:.1f} mm"


def _clearance() -> float:
    from mrgc.geometry.arm import SELF_CLEARANCE

    return SELF_CLEARANCE


#: the codes of this module's diagnostics
CODES = ("W274", "W275", "W276")


def reasons(diagnostics: Iterable[Diagnostic]) -> list[str]:
    """This module's diagnostics among ``diagnostics`` as one line each, with the robot's file position
    (``FILE:LINE:COL: W274 every configuration of a1 ...``): the first reasons of a plan that found none."""
    return [
        f"{d.span}: {d.code} {d.message}" if d.span is not None else f"{d.code} {d.message}"
        for d in diagnostics
        if d.code in CODES
    ]


def _z(v: float) -> str:
    """A height in metres to the millimetre, without a negative zero."""
    text = f"{v:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "0", "") else text
