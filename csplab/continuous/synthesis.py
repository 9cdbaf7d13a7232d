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
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.check import Violations, violations
from csplab.continuous.csp import ContinuousCSP
from csplab.continuous.model import PolygonModel
from csplab.result import Result
from csplab.rng import RngLike
from csplab.solvers import solve

__all__ = ["Synthesis", "synthesize", "synthesize3"]


@dataclass
class Synthesis:
    """What :func:`synthesize` returns: the solver's ``result`` (its grid holds the CSP
    values), the ``csp``, the output ``model`` (``None`` unless solved), the checker's
    ``violations`` of it, and the time of each phase in seconds (``times``)."""

    result: Result
    csp: Any
    model: Any
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
) -> Synthesis:
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
    example: Any,
    size: Sequence[int],
    *,
    solver: str = "catalog",
    rng: RngLike = None,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | dict[str, int] = 0,
    restarts: int = 0,
    check: bool = True,
    constraints: Any = None,
    progress: bool = False,
    **options: Any,
) -> Synthesis:
    """Continuous model synthesis in 3D of a polyhedral ``example`` in an ``A x B x C``
    box of plane spacings (:class:`~csplab.continuous.csp3d.ContinuousCSP3`); the output
    solids are checked with :func:`~csplab.continuous.check3d.violations3`. Parameters as
    for :func:`synthesize`; ``constraints`` are user constraints of thesis Sec. 4.6
    (:class:`~csplab.continuous.user3d.UserConstraints3`): dimensional and large-scale
    ones restrict the CSP, and while the output breaks one (a connectivity constraint) the
    synthesis runs again with a fresh derived seed, at most ``restarts`` times (for every
    solver); an output that still breaks one is ``failed`` (its ``stats["broken"]`` says
    which), never ``solved``. ``progress`` shows the exact connectivity search's rounds, or
    the solver's bar when it takes one (``blocks``, ``perfect``).

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

    from csplab.continuous.check3d import violations3
    from csplab.continuous.csp3d import ContinuousCSP3
    from csplab.continuous.user3d import user_violations3
    from csplab.rng import make_rng

    t0 = time.perf_counter()
    csp = ContinuousCSP3(
        example, size, spacing=spacing, snap=snap, boundary=boundary, constraints=constraints
    )
    t1 = time.perf_counter()
    lat = csp.lattice
    lo = lat.to_world(np.zeros(3))
    hi = lat.to_world(np.array(csp.arrangement.size, dtype=np.float64))
    times = {"csp": t1 - t0, "solve": 0.0, "geometry": 0.0, "check": 0.0}
    gen, seed = make_rng(rng)
    attempts = 0
    while True:
        attempts += 1
        t1 = time.perf_counter()
        run_seed = seed if attempts == 1 else int(gen.integers(2**63))
        if constraints and constraints.connected and solver.split(":")[0] == "sat":
            result = connected_sat(csp, constraints.connected, solver, rng=run_seed,
                                   time_limit=options.get("time_limit"),
                                   progress=progress)  # fmt: skip
        else:
            from csplab.solvers import solver_class

            takes = solver_class(solver.partition(":")[0]).takes("progress")
            extra = {"progress": progress} if takes else {}
            result = solve(csp.problem, solver, rng=run_seed, restarts=restarts, **options, **extra)
        t2 = time.perf_counter()
        model = csp.model(result.grid) if result.ok else None
        t3 = time.perf_counter()
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
        times["solve"] += t2 - t1
        times["geometry"] += t3 - t2
        times["check"] += t4 - t3
        if not broken or attempts > restarts:
            break
    if broken:
        stats = {**result.stats, "constraint_attempts": attempts, "broken": str(broken[0])}
        result = replace(result, status="failed", stats=stats)
    elif attempts > 1:
        result = replace(result, stats={**result.stats, "constraint_attempts": attempts})
    return Synthesis(result, csp, model, Violations([*defects, *broken]), times)


def _touches(states: list[tuple[int, ...]], outside: NDArray[np.int64], b: int) -> list[int]:
    """The states with label ``b`` in a group inside the region."""
    inside = np.asarray(outside) < 0
    return [k for k, st in enumerate(states) if any(x == b and inside[j] for j, x in enumerate(st))]


def connected_sat(
    csp: Any, labels: Sequence[int], solver: str = "sat", *, rng: RngLike = None,
    time_limit: float | None = None, progress: bool = False,
) -> Result:  # fmt: skip
    """Exact connectivity (thesis Sec. 4.6.2) with the SAT oracle: a lazy cut loop.

    The objects of a label ``b`` form one connected group exactly when the arrangement
    vertices whose state touches ``b`` (inside the region), joined by the edges whose state
    touches ``b``, form one component (so some vertex touches ``b``: one clause). Solve;
    while the output has several components, add for every ordered pair of components
    ``(C, D)`` the cut "if some vertex of ``C`` and some vertex of ``D`` touch ``b``, some
    edge leaving ``C`` does" (sound: every path from ``C`` to ``D`` leaves ``C`` by such an
    edge; "some vertex of C touches b" is one new variable implied by each of their
    states), and solve again. The answer is ``solved`` with a connected output, ``unsat``
    (no connected output exists) or ``timeout``. The solver tends to remove objects rather
    than join them, so outputs are connected but often small. ``progress`` shows the rounds
    on stderr once they take over 2 s.
    """
    import itertools

    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from csplab.engine.sat import SatOracle, preferred_labels
    from csplab.progress import progress_bar
    from csplab.rng import make_rng

    gen, seed = make_rng(rng)
    backend = solver.split(":", 1)[1] if ":" in solver else None
    P, A = csp.problem, csp.arrangement
    index = {b: i for i, b in enumerate(csp.labels)}
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    nv = A.n_vertices
    src, dst = A.edge_src, A.edge_dst
    stats: dict[str, Any] = {"cuts": 0, "rounds": 0}
    grid = np.full(P.shape, -1, dtype=np.int32)
    status = "timeout"
    with SatOracle(P, backend=backend, deadline=deadline, seed=int(gen.integers(2**31 - 1))) as o:
        touch_v, touch_e = [], []
        for b in labels:
            bi = index[b]
            tv = [np.zeros(len(st), dtype=bool) for _, st, _ in csp.vtypes]
            for t, (_, st, _) in enumerate(csp.vtypes):
                tv[t][_touches(st, csp.vertex_outside[t], bi)] = True
            te = [np.zeros(len(st), dtype=bool) for _, st, _ in csp.etypes]
            for t, (_, st, _) in enumerate(csp.etypes):
                te[t][_touches(st, csp.edge_outside[t], bi)] = True
            touch_v.append(tv)
            touch_e.append(te)
        if not o.enc.ok:
            status = "unsat"
        else:  # random decision phases, as the sat solver's default (diverse outputs)
            o.set_phases(preferred_labels(o.enc.catalog, None, gen))
            # one group means at least one object: some vertex touches each label
            for li in range(len(labels)):
                some_b = []
                for t, mask in enumerate(touch_v[li]):
                    for v in np.flatnonzero(csp.vertex_type == t).tolist():
                        cell = int(csp.var_vertex[v])
                        for s in np.flatnonzero(mask & P.domains[cell, : len(mask)]).tolist():
                            some_b.append(o.literal(cell, s))
                o.add_clause(some_b)
        rounds = progress_bar(itertools.count(), total=None, desc="connectivity cuts",
                              enabled=progress, unit="round")  # fmt: skip
        for _ in rounds if o.enc.ok else ():
            if deadline is not None and time.perf_counter() > deadline:
                break
            r = o.solve(deadline=deadline)
            stats["rounds"] += 1
            if r != "sat" or o.grid is None:
                status = r
                break
            g = np.asarray(o.grid).reshape(-1)
            cuts = 0
            for li in range(len(labels)):
                vs = g[csp.var_vertex]
                es = g[csp.var_edge]
                av = np.zeros(nv, dtype=bool)
                for t, mask in enumerate(touch_v[li]):
                    sel = csp.vertex_type == t
                    av[sel] = mask[vs[sel]]
                ae = np.zeros(A.n_edges, dtype=bool)
                for t, mask in enumerate(touch_e[li]):
                    sel = csp.edge_type == t
                    ae[sel] = mask[es[sel]]
                idx = np.flatnonzero(av)
                if idx.size <= 1:
                    continue
                graph = coo_matrix((np.ones(int(ae.sum())), (src[ae], dst[ae])), shape=(nv, nv))
                _, comp = connected_components(graph, directed=False)
                labs, counts = np.unique(comp[idx], return_counts=True)
                if len(labs) <= 1:
                    continue
                big = int(labs[np.argmax(counts)])

                def some(vs: NDArray[np.int64], li: int = li) -> int:
                    """A variable implied by every state touching b at the vertices vs."""
                    y = o.new_var()
                    for a in vs.tolist():
                        t = int(csp.vertex_type[a])
                        cell = int(csp.var_vertex[a])
                        for s in np.flatnonzero(touch_v[li][t]).tolist():
                            if P.domains[cell, s]:
                                o.add_clause([-o.literal(cell, s), y])
                    return y

                # one "touches b somewhere in it" variable per component; for every pair
                # (C, D): some vertex of C and some vertex of D touch b -> an edge leaves C
                ys, exits = {}, {}
                for c in labs.tolist():
                    inC = (comp == c) & av
                    ys[c] = some(np.flatnonzero(inC))
                    lits = []
                    for e in np.flatnonzero(inC[src] != inC[dst]).tolist():
                        cell = int(csp.var_edge[e])
                        t = int(csp.edge_type[e])
                        for s in np.flatnonzero(touch_e[li][t]).tolist():
                            if P.domains[cell, s]:
                                lits.append(o.literal(cell, s))
                    exits[c] = lits
                del big
                for c in labs.tolist():
                    for d in labs.tolist():
                        if c != d:
                            o.add_clause([-ys[c], -ys[d], *exits[c]])
                            cuts += 1
            stats["cuts"] += cuts
            if cuts == 0:
                status = "sat"
                grid = np.asarray(o.grid, dtype=np.int32).reshape(P.shape)
                break
        stats.update(o.solver_stats())
    final: Any = {"sat": "solved", "unsat": "unsat"}.get(status, "timeout")
    if final == "unsat":
        stats["proof"] = "refutation by the SAT solver with connectivity cuts"
    return Result(final, grid, solver, seed=seed, time_s=time.perf_counter() - t0, stats=stats,
                  problem=P)  # fmt: skip
