"""What planning uses when nothing is given, one home each: ``mrgc plan`` and ``mrgc compile``, the Python API
(:func:`mrgc.plan`, :func:`mrgc.compile`, :func:`mrgc.export_model`), the planning methods' declared options,
``mrgc render --skeleton`` and ``mrgc bench`` read these names.  The module imports nothing, so any layer
may read it at no cost (CLI start-up, ``import mrgc``)."""

#: the planning method (``mrgc plan --planner``; :data:`mrgc.planner.registry.PLANNERS`)
DEFAULT_PLANNER = "mcts"
#: the skeleton solver backend (``--backend``; ``mrgc backends``)
DEFAULT_BACKEND = "cpsat"
#: the skeleton encoding (``--encoding``: paper | disaggregated | time-of-move)
DEFAULT_ENCODING = "time-of-move"
#: the time limit of a plan (seconds, ``--time-limit``): phase 1, skeletons, grounding and the referee
DEFAULT_TIME_LIMIT = 60.0
