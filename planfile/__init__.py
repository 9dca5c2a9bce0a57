"""The plan format: what a plan file holds (:mod:`mrgc.planfile.format`, the data types the planner writes
and the validator reads) and the one strict way to read it back (:mod:`mrgc.planfile.reader`: limits, JSON,
``docs/plan.schema.json``, typed values).

Both sides of the plan file use this package and nothing else of each other: the planner
(:mod:`mrgc.planner.plan`) writes plans with these types, the validator (:mod:`mrgc.validator`) reads them.
It imports nothing of mrgc but :mod:`mrgc.errors`.
"""
