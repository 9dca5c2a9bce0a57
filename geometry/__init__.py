"""Geometry on pybullet, coal and OMPL: scenes, kinematics, collisions, motions, predicates."""
