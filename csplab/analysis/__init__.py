"""Analysis tools: infallibility proofs, failure witnesses, refinement to infallible models.

Every tool returns a :class:`~csplab.result.Verdict` (``holds`` True/False/None, a witness,
stats and a one-line message).

- :mod:`csplab.analysis.infallible`: the corner condition (Eq. 3.11, corrected) and the
  region-enumeration prover of Alg. 3.6/3.7 and Theorem 3.3.6; exhaustive Alg. 3.6 runs.
- :mod:`csplab.analysis.witness`: concrete failing runs of Alg. 3.1, minimised, with the
  first step outside the exact catalog C*; bounded exhaustive "never fails" checks.
- :mod:`csplab.analysis.decide`: the decision procedure behind ``csplab prove``: region
  proofs of growing size and reach, refined by Alg. 3.6's real failures, and a search for
  a failing run of Alg. 3.1, within a time budget.
- :mod:`csplab.analysis.rings`: blocks with a fixed ring (modify in blocks, worlds): what
  the region proof covers there, and the closed-form condition under which no ring can
  make a block fail (:func:`ring_completion`).
- :mod:`csplab.analysis.refine`: label refinements E_I of a fallible E_F with
  f(E_I) = E_F (Sec. 3.3.8), checked against Eq. 3.13 and proven infallible.
"""

from __future__ import annotations

from csplab.analysis.decide import decide_infallibility
from csplab.analysis.infallible import (
    alg36_failure,
    corner_condition,
    prove_infallible,
    region_catalog,
)
from csplab.analysis.refine import lift_check, refine_labels, to_infallible
from csplab.analysis.rings import ring_completion
from csplab.analysis.witness import alg31_exhaustive, find_failure, replay

__all__ = [
    "alg31_exhaustive",
    "alg36_failure",
    "corner_condition",
    "decide_infallibility",
    "find_failure",
    "lift_check",
    "prove_infallible",
    "refine_labels",
    "region_catalog",
    "replay",
    "ring_completion",
    "to_infallible",
]
