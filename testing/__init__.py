"""Testing with mrgc: what its own test suite uses, for backend plug-ins and users' own domains.

- :mod:`mrgc.testing.oracle`: an independent brute-force reference for task skeletons (check a skeleton
  against the model's definitions, enumerate every feasible action set of a small task graph);
- :mod:`mrgc.testing.conformance`: the backend conformance kit (:func:`check_backend`, :data:`CHECKS`)
  a solver backend, a third-party plug-in too, runs against itself;
- :mod:`mrgc.testing.strategies`: hypothesis strategies for random symbolic problems with a knob for the
  share of feasible ones (needs hypothesis: ``pip install mrgc[testing]``; import it by its name).

docs/testing.md shows each in use.  Importing ``mrgc.testing`` loads neither hypothesis nor a solver.
"""

from __future__ import annotations

from mrgc.testing import oracle
from mrgc.testing.conformance import CHECKS, ConformanceError, ConformanceReport, check_backend

__all__ = ["CHECKS", "ConformanceError", "ConformanceReport", "check_backend", "oracle"]
