"""`synthesize`: continuous model synthesis end to end (Alg. 4.1) with any csplab solver.

Build the arrangement and the CSP (:func:`~csplab.continuous.csp.continuous_csp`: lines in
2D, planes in 3D), solve it with :func:`csplab.solvers.solve` and a registered solver
(``catalog`` is Alg. 4.1 steps 5-9, i.e. Alg. 3.1; ``blocks`` modifies the model in boxes of
line spacings, Fig. 4.23; the exact solvers work unchanged), turn the solution into polygons
or solids and check them with the independent checker
(:func:`~csplab.continuous.check.violations`). One function for both dimensions, as Alg. 4.1
is one algorithm.

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
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Generic, TypeVar, overload

from csplab.continuous.check import violations
from csplab.continuous.check3d import user_violations3
from csplab.continuous.csp import ContinuousCSP, continuous_csp
from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.defects import Defect, Violations
from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.user3d import UserConstraints3
from csplab.progress import notice_after
from csplab.result import Result
from csplab.rng import RngLike
from csplab.solvers import solve

__all__ = ["Synthesis", "synthesize", "synthesize3"]


CSP = TypeVar("CSP")
Model = TypeVar("Model")
#: the model types (the implementation of :func:`synthesize` is checked once per type)
M = TypeVar("M", PolygonModel, PolyhedralModel)


@dataclass
class Synthesis(Generic[CSP, Model]):
    """What :func:`synthesize` returns: the solver's result, the CSP, the output and its check.

    Parameters
    ----------
    result : Result
        The solver's result; its grid holds the CSP values.
    csp : ContinuousCSP or ContinuousCSP3
        The CSP that was solved.
    model : PolygonModel or PolyhedralModel or None
        The output model, ``None`` unless solved.
    violations : Violations
        The checker's violations of the output (and of the user constraints, in 3D); empty
        when it was not checked.
    times : dict of str to float, default {}
        The time of each phase in seconds (``csp``, ``solve``, ``geometry``, ``check``).
    """

    result: Result
    csp: CSP
    model: Model | None
    violations: Violations
    times: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Whether the solver succeeded and the output exists and has no violations."""
        return self.result.ok and self.model is not None and not self.violations


@overload
def synthesize(
    example: PolygonModel,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | Mapping[str, int] = 0,
    lines: str = "lattice",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    notices: bool = False,
    **options: Any,
) -> Synthesis[ContinuousCSP, PolygonModel]: ...


@overload
def synthesize(
    example: PolyhedralModel,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | Mapping[str, int] = 0,
    lines: str = "lattice",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    notices: bool = False,
    **options: Any,
) -> Synthesis[ContinuousCSP3, PolyhedralModel]: ...


def synthesize(
    example: M,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | Mapping[str, int] = 0,
    lines: str = "lattice",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    notices: bool = False,
    **options: Any,
) -> Synthesis[Any, M]:
    """Continuous model synthesis (Alg. 4.1) of a polygon or polyhedral example.

    A polygon ``example`` is synthesized in a ``W x H`` region of line spacings, a
    polyhedral one in an ``A x B x C`` box of plane spacings.

    Parameters
    ----------
    example : PolygonModel or PolyhedralModel
        The example model.
    size : (int, int) or (int, int, int)
        The region in line (plane) spacings, of the example's dimension.
    solver : str
        Any registered solver name (``NAME:BACKEND`` too); ``options`` go to it.
    rng : int or numpy Generator, optional
        Seed (recorded in the result).
    spacing, snap, boundary, lines, constraints, max_memory
        See :func:`~csplab.continuous.csp.continuous_csp` (``lines``: 2D; per-face
        ``boundary`` and user ``constraints`` of thesis Sec. 4.6: 3D).
    restarts : int
        Run an incomplete solver again with a fresh derived seed while it fails
        (:func:`csplab.solvers.solve`'s one restart loop; ``time_limit`` covers all).
    check : bool
        Run the checker on the output (default; it is the truth, not the CSP).
    notices : bool
        Say on stderr which phase is running when it takes over 2 s (building the
        arrangement and the CSP, solving, building the surface, checking:
        :func:`csplab.progress.notice_after`); the CLI turns it on.
    **options
        Solver options (``time_limit=``, ``order=``, ``block=`` ...), passed to
        :func:`csplab.solvers.solve`.

    Returns
    -------
    Synthesis
        The solver's result, the CSP, the output model (``None`` unless solved), its
        violations and the time of each phase.

    Raises
    ------
    InputError
        When the CSP cannot be built (a bad size, spacing, boundary label or
        dimension-specific argument, see :func:`~csplab.continuous.csp.continuous_csp`),
        or :func:`csplab.solvers.solve` rejects an option.
    UnknownSolverError
        When ``solver`` names no registered solver.
    DependencyError
        When the solver, or the 3D geometry, needs an optional package that is not
        installed.

    Notes
    -----
    The dimensional and large-scale user constraints restrict the CSP's domains;
    connectivity is a :class:`~csplab.constraints.Connected` constraint on its problem
    (exact in ``sat``, ``cpsat`` and ``asp``, propagated or checked by the others, as on
    grids). The output is checked against all of them on its solids
    (:func:`~csplab.continuous.check3d.user_violations3`): one that still breaks one is
    ``failed`` (its ``stats["broken"]`` says which), never ``solved``.

    Examples
    --------
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> tet = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [4, 0, 0], [0, 4, 0],
    ...     [0, 0, 4]], "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}])
    >>> s = synthesize(tet, (5, 5, 4), solver="sat", rng=1)
    >>> s.result.status, len(s.violations), s.model.labels
    ('solved', 0, (1,))
    """
    t0 = time.perf_counter()
    what = f"{example.name or 'the example'} at {'x'.join(map(str, size))}"
    with notice_after(f"{what}: building the arrangement and the CSP", enabled=notices):
        csp = continuous_csp(example, size, spacing=spacing, snap=snap, boundary=boundary,
                             lines=lines, constraints=constraints,
                             max_memory=max_memory)  # fmt: skip
    t1 = time.perf_counter()
    with notice_after(f"{what}: solving ({solver}, {csp.problem.n} cells)", enabled=notices):
        result = solve(csp.problem, solver, rng=rng, restarts=restarts, **options)
    t2 = time.perf_counter()
    with notice_after(f"{what}: building the output's surface", enabled=notices):
        model = csp.model(result.grid) if result.ok else None
    t3 = time.perf_counter()
    region = csp.region()
    defects: list[Defect] = []
    broken: list[Defect] = []
    with notice_after(f"{what}: checking the output (Eq. 4.1)", enabled=notices):
        if check and model is not None:
            defects = list(violations(csp.example, model, region=region, outside=csp.boundary))
        if constraints and isinstance(model, PolyhedralModel):
            d = len(region) // 2
            broken = user_violations3(model, constraints, origin=region[:d],
                                      spacing=float(csp.lattice.spacing))  # fmt: skip
    t4 = time.perf_counter()
    if broken:
        result = replace(result, status="failed", stats={**result.stats, "broken": str(broken[0])})
    times = {"csp": t1 - t0, "solve": t2 - t1, "geometry": t3 - t2, "check": t4 - t3}
    return Synthesis(result, csp, model, Violations([*defects, *broken]), times)


def synthesize3(
    example: PolyhedralModel, size: Sequence[int], **kwargs: Any
) -> Synthesis[ContinuousCSP3, PolyhedralModel]:
    """:func:`synthesize` of a polyhedral model (the name of its former 3D twin)."""
    return synthesize(example, size, **kwargs)
