"""The independent plan validator (``mrgc validate``; docs/validator.md): does a plan really solve its problem?

It reads a plan through the plan format (:mod:`mrgc.planfile`), checks it against the problem
(:mod:`mrgc.validator.validate`: names, structure, facts, goals) and replays a geometric plan in pybullet
(:mod:`mrgc.validator.replay`), with its own world (:mod:`~mrgc.validator.world`), kinematics
(:mod:`~mrgc.validator.fk`), motion bounds (:mod:`~mrgc.validator.bounds`, :mod:`~mrgc.validator.phase_bounds`),
continuous collision checks (:mod:`~mrgc.validator.sweep`, :mod:`~mrgc.validator.certify`) and stability
test (:mod:`~mrgc.validator.stability`).  Every way a plan fails is a :class:`~mrgc.validator.violation.Violation`.

It imports nothing of the planner (:mod:`mrgc.planner`), of phase 1, grounding, coal, the numpy kinematics,
OMPL or the placement lattice, not even through another module (tests/test_layout.py follows every import);
the planner's referee calls it, never the other way round.
"""
