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

from csplab.continuous.bounding import Bounded, bounding_volumes
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

__all__ = ["Synthesis", "auto_ground", "default_choice", "synthesize", "synthesize3"]


def auto_ground(
    example: PolygonModel | PolyhedralModel, boundary: int | Mapping[str, int] = 0
) -> str | tuple[str, ...] | None:
    """``ground="auto"``: the example's own ground (``example.meta["ground"]``, as the
    built-in polyhedral examples declare it) but the faces that ``boundary`` gives a label
    (an explicit boundary wins; a polygon model's one boundary label other than 0 wins
    over every side); ``None`` for examples without one.

    Examples
    --------
    >>> from csplab.examples.continuous3d import load_polyhedral_example
    >>> E = load_polyhedral_example("terrain")
    >>> auto_ground(E), auto_ground(E, {"z-": 1}), auto_ground(E, 2)
    (('z-', 'x-', 'x+', 'y-', 'y+'), ('x-', 'x+', 'y-', 'y+'), None)
    """
    from csplab.continuous.csp import ground_sides
    from csplab.continuous.csp3d import ground_faces

    if not example.meta.get("ground"):
        return None
    if isinstance(example, PolygonModel):
        return None if boundary else ground_sides(example.meta["ground"])
    if not isinstance(boundary, Mapping):
        return None if boundary else ground_faces(example.meta["ground"])
    return tuple(f for f in ground_faces(example.meta["ground"]) if not boundary.get(f))


def default_choice(problem: Any, solver: str) -> str | None:
    """The label choice continuous synthesis gives ``solver`` when the caller names none:
    ``"weighted"`` when the problem weighs its values per cell (``value_weights``, the
    CSP's coverage of the example; polygon and polyhedral models alike) and the solver
    takes that choice, else ``None`` (the solver's own default). ``choice="uniform"`` is
    the thesis' equal choice. On the built-in polygon examples the weighted choice solves
    as often or more often, gives fewer, larger polygons and keeps every corner kind and
    edge direction (``python benchmarks/bench_resemblance.py --polygons``)."""
    from csplab.solvers import solver_class

    if getattr(problem, "value_weights", None) is None:
        return None
    o = solver_class(solver.partition(":")[0]).option("choice")
    return "weighted" if o is not None and (o.values is None or "weighted" in o.values) else None


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
    bounded : Bounded or None, default None
        The bounding volumes of the example's curved parts (thesis Sec. 4.6.4), when the
        CSP was built on their proxy example (:mod:`~csplab.continuous.bounding`).
    proxy : PolyhedralModel or None, default None
        With ``bounded``: the solved proxy output, before the original geometry went
        back into its boxes (``model``); ``violations`` are the checker's on it.
    """

    result: Result
    csp: CSP
    model: Model | None
    violations: Violations
    times: dict[str, float] = field(default_factory=dict)
    bounded: Bounded | None = None
    proxy: Model | None = None

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
    lines: str = "auto",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    ground: str | Sequence[str] | None = "auto",
    bounding: bool = True,
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
    lines: str = "auto",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    ground: str | Sequence[str] | None = "auto",
    bounding: bool = True,
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
    lines: str = "auto",
    restarts: int = 0,
    check: bool = True,
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    ground: str | Sequence[str] | None = "auto",
    bounding: bool = True,
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
        See :func:`~csplab.continuous.csp.continuous_csp` (``lines``: per family; per-face
        ``boundary`` and user ``constraints`` of thesis Sec. 4.6: 3D).
    ground : str or sequence of str or None, default "auto"
        3D: the faces past which the example and the output continue (an infinite
        ground, :func:`~csplab.continuous.csp3d.ground_faces`: ``"z-"``, ``"window"``
        ...); ``"auto"``: the example's own declaration (``example.meta["ground"]``, as
        the built-in examples have), else none; ``None``: none.
    bounding : bool, default True
        Replace the curved parts of a polyhedral example by bounding volumes (thesis
        Sec. 4.6.4, :mod:`~csplab.continuous.bounding`): the CSP is built on the proxy
        example (on the lattice of ``spacing``, or of the derived default), its output is
        checked against the proxy, and the original geometry is substituted back into
        every placed box of ``model``. An example without curved parts is unchanged.
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
        :func:`csplab.solvers.solve`. ``choice`` defaults to ``"weighted"`` for a solver
        that takes it when the CSP weighs its states (by the example each state covers,
        :func:`default_choice`); ``choice="uniform"`` is the thesis' choice.

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
    bounded = None
    if bounding and isinstance(example, PolyhedralModel):
        bounded = bounding_volumes(example, spacing)
        if bounded is not None:  # the proxy is on the lattice of bounded.spacing
            spacing, snap = bounded.spacing, False
            example = bounded.proxy
    if ground == "auto":
        ground = auto_ground(example, boundary)
    what = f"{example.name or 'the example'} at {'x'.join(map(str, size))}"
    with notice_after(f"{what}: building the arrangement and the CSP", enabled=notices):
        csp = continuous_csp(example, size, spacing=spacing, snap=snap, boundary=boundary,
                             lines=lines, constraints=constraints, max_memory=max_memory,
                             ground=ground)  # fmt: skip
    t1 = time.perf_counter()
    options = {**options}
    choice = default_choice(csp.problem, solver)
    if choice is not None and "choice" not in options:
        options["choice"] = choice
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
            defects = list(violations(csp.example, model, region=region, outside=csp.boundary,
                                      ground=getattr(csp, "ground", ())))  # fmt: skip
        if constraints and isinstance(model, PolyhedralModel):
            d = len(region) // 2
            broken = user_violations3(model, constraints, origin=region[:d],
                                      spacing=float(csp.lattice.spacing))  # fmt: skip
    t4 = time.perf_counter()
    if broken:
        result = replace(result, status="failed", stats={**result.stats, "broken": str(broken[0])})
    times = {"csp": t1 - t0, "solve": t2 - t1, "geometry": t3 - t2, "check": t4 - t3}
    proxy = None
    if bounded is not None and isinstance(model, PolyhedralModel):
        proxy = model
        model = bounded.reinsert(model)
        times["reinsert"] = time.perf_counter() - t4
    return Synthesis(result, csp, model, Violations([*defects, *broken]), times, bounded, proxy)


def synthesize3(
    example: PolyhedralModel, size: Sequence[int], **kwargs: Any
) -> Synthesis[ContinuousCSP3, PolyhedralModel]:
    """:func:`synthesize` of a polyhedral model (the name of its former 3D twin)."""
    return synthesize(example, size, **kwargs)
