"""`synthesize`: continuous model synthesis end to end (Alg. 4.1) with any csplab solver.

Build the arrangement and the CSP (:class:`~csplab.continuous.csp.ContinuousCSP`), solve it
with a registered solver (``catalog`` is Alg. 4.1 steps 5-9, i.e. Alg. 3.1; ``blocks``
modifies the model in boxes of line spacings, Fig. 4.23; the exact solvers work unchanged),
turn the solution into polygons and check them with the independent checker
(:func:`~csplab.continuous.check.violations`).

Examples
--------
>>> from csplab.continuous import PolygonModel, synthesize
>>> E = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [4, 0], [2, 3]]}]})
>>> s = synthesize(E, (12, 9), rng=1)
>>> s.result.status, len(s.violations), s.model.labels
('solved', 0, (1,))
>>> s.csp.problem.meta["vertices"] > 0
True
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import numpy as np

from csplab.continuous.check import Violations, violations
from csplab.continuous.csp import ContinuousCSP
from csplab.continuous.model import PolygonModel
from csplab.result import Result
from csplab.rng import RngLike
from csplab.solvers import solve

if TYPE_CHECKING:
    from csplab.continuous.csp3d import ContinuousCSP3
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.continuous.user3d import UserConstraints3

__all__ = ["Synthesis", "synthesize", "synthesize3"]


CSP = TypeVar("CSP")
Model = TypeVar("Model")


@dataclass
class Synthesis(Generic[CSP, Model]):
    """What :func:`synthesize` returns: the solver's ``result`` (its grid holds the CSP
    values), the ``csp``, the output ``model`` (``None`` unless solved), the checker's
    ``violations`` of it, and the time of each phase in seconds (``times``)."""

    result: Result
    csp: CSP
    model: Model | None
    violations: Violations
    times: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.result.ok and self.model is not None and not self.violations


def synthesize(
    example: PolygonModel,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int = 0,
    lines: str = "lattice",
    restarts: int = 0,
    check: bool = True,
    **options: Any,
) -> Synthesis[ContinuousCSP, PolygonModel]:
    """Continuous model synthesis of ``example`` in a ``W x H`` region (line spacings).

    Parameters
    ----------
    example : PolygonModel
    size : (int, int)
    solver : str
        Any registered solver name (``NAME:BACKEND`` too); ``options`` go to it.
    rng : int or numpy Generator, optional
        Seed (recorded in the result).
    spacing, snap, boundary, lines
        See :class:`~csplab.continuous.csp.ContinuousCSP`.
    restarts : int
        Run an incomplete solver again with a fresh derived seed while it fails.
    check : bool
        Run the checker on the output (default; it is the truth, not the CSP).
    """
    t0 = time.perf_counter()
    csp = ContinuousCSP(example, size, spacing=spacing, snap=snap, boundary=boundary, lines=lines)
    t1 = time.perf_counter()
    result = solve(csp.problem, solver, rng=rng, restarts=restarts, **options)
    t2 = time.perf_counter()
    model = csp.model(result.grid) if result.ok else None
    t3 = time.perf_counter()
    v = (
        violations(csp.example, model, region=csp.region(), outside=boundary)
        if (check and model is not None)
        else Violations([])
    )
    t4 = time.perf_counter()
    times = {"csp": t1 - t0, "solve": t2 - t1, "geometry": t3 - t2, "check": t4 - t3}
    return Synthesis(result, csp, model, v, times)


def synthesize3(
    example: PolyhedralModel,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | dict[str, int] = 0,
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    **options: Any,
) -> Synthesis[ContinuousCSP3, PolyhedralModel]:
    """Continuous model synthesis in 3D of a polyhedral ``example`` in an ``A x B x C``
    box of plane spacings (:class:`~csplab.continuous.csp3d.ContinuousCSP3`); the output
    solids are checked with :func:`~csplab.continuous.check3d.violations3`. Parameters as
    for :func:`synthesize`; ``constraints`` are user constraints of thesis Sec. 4.6
    (:class:`~csplab.continuous.user3d.UserConstraints3`): dimensional and large-scale
    ones restrict the CSP's domains, connectivity is a
    :class:`~csplab.constraints.Connected` constraint on its problem (exact in ``sat``,
    ``cpsat`` and ``asp``, propagated or checked by the others, as on grids), all through
    :func:`csplab.solvers.solve` with its ``restarts``. The output is checked against all of
    them on its solids (:func:`~csplab.continuous.check3d.user_violations3`): one that
    still breaks one is ``failed`` (its ``stats["broken"]`` says which), never ``solved``.

    Examples
    --------
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> tet = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [4, 0, 0], [0, 4, 0],
    ...     [0, 0, 4]], "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}])
    >>> s = synthesize3(tet, (5, 5, 4), solver="sat", rng=1)
    >>> s.result.status, len(s.violations), s.model.labels
    ('solved', 0, (1,))
    """
    from dataclasses import replace

    from csplab.continuous.check3d import user_violations3, violations3
    from csplab.continuous.csp3d import ContinuousCSP3

    t0 = time.perf_counter()
    csp = ContinuousCSP3(
        example, size, spacing=spacing, snap=snap, boundary=boundary, constraints=constraints
    )
    t1 = time.perf_counter()
    result = solve(csp.problem, solver, rng=rng, restarts=restarts, **options)
    t2 = time.perf_counter()
    model = csp.model(result.grid) if result.ok else None
    t3 = time.perf_counter()
    lat = csp.lattice
    lo = lat.to_world(np.zeros(3))
    hi = lat.to_world(np.array(csp.arrangement.size, dtype=np.float64))
    defects = []
    if check and model is not None:
        region = (*lo.tolist(), *hi.tolist())
        defects = list(violations3(example, model, region=region, outside=csp.boundary))
    broken = (
        user_violations3(model, constraints, origin=lo.tolist(), spacing=float(lat.spacing))
        if (constraints and model is not None)
        else []
    )
    t4 = time.perf_counter()
    if broken:
        result = replace(result, status="failed", stats={**result.stats, "broken": str(broken[0])})
    times = {"csp": t1 - t0, "solve": t2 - t1, "geometry": t3 - t2, "check": t4 - t3}
    return Synthesis(result, csp, model, Violations([*defects, *broken]), times)
