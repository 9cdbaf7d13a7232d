"""Failure witnesses for Alg. 3.1: concrete failing runs, minimised, and bounded proofs.

A *witness* is a dict ``{"shape", "order", "choices": [[coords, label], ...], "kind", ...}``:
replaying the choices in the scan order, each label is in the catalog C when it is
chosen and the last one wipes the catalog out (``kind="failed"``), or the output size has
no consistent model at all and arc consistency empties C before any choice
(``kind="unsat"``, no choices). Random-order witnesses also carry the ``seed`` of
:func:`csplab.engine.alg31.run_alg31` that produced them. :func:`replay` re-checks a
witness.

:func:`find_failure` looks for the smallest output and the shortest prefix that fail,
within a time budget (``time_limit``, 60 s by default): exhaustively (every label of C at
every step, breadth first over distinct catalogs, so the first failure found has the
fewest choices) on outputs of up to ``exhaustive_cells`` cells, within a budget of
catalogs; then by seeded random runs on a ladder of larger sizes: up to ``max_size``, or
by default for 3D examples growing outputs round after round until the budget is spent.
A failing random run is shrunk: output size first (windows of the failing run's labels
at smaller sizes, fresh seeds), then choices (the run at the final size that fails
soonest; after the first choice outside C*, the shortest continuation found that wipes C
out). For the witness it finds the first step whose label was outside the exact catalog
C* (the model became inconsistent there;
:func:`~csplab.engine.completability.first_inconsistent_prefix`, exact by SAT or by
:class:`~csplab.engine.completability.SearchCompletability`) and how many assignments
later Alg. 3.1 noticed (Fig. 3.6: the delay can be positive). Choices are counted from 1
in the witness (``first_outside_cstar``: choice 3 is the third). ``stats`` say what was
searched (:func:`searched` as one line).

Examples
--------
>>> from csplab.examples import load_example
>>> v = find_failure(load_example("fig3_5a"), order="scan:yx", max_size=(3, 3))
>>> v.holds, v.witness["shape"], v.witness["choices"]          # 2 0 0: C* held only 6
(False, [3, 3], [[[0, 0], 2], [[1, 0], 0], [[2, 0], 0]])
>>> v.witness["first_outside_cstar"], v.witness["detection_delay"]
(3, 0)
>>> replay(load_example("fig3_5a"), v.witness).holds
True
>>> find_failure(load_example("line"), max_size=(3, 3), random_runs=0).holds
True
"""

from __future__ import annotations

import contextlib
import itertools
import math
import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.engine.alg31 import run_alg31, scan_order
from csplab.engine.completability import (
    PrefixTimeout,
    SearchCompletability,
    first_inconsistent_prefix,
)
from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.grids import from_example, parse_boundary, parse_shape
from csplab.problem import Problem
from csplab.result import Verdict
from csplab.rng import make_rng

if TYPE_CHECKING:
    from csplab.io.ruleset import RuleSet

__all__ = ["alg31_exhaustive", "find_failure", "model_problem", "replay", "searched"]


class _Budget(Exception):
    pass


def alg31_exhaustive(
    problem: Problem,
    order: str = "scanline",
    max_states: int = 1_000_000,
    *,
    late: bool = False,
    max_nodes: int = 100_000,
    deadline: float | None = None,
) -> Verdict:
    """Every run of Alg. 3.1 on one problem: does some choice sequence fail?

    Breadth first over the distinct catalogs after each step (equal catalogs have equal
    futures), so a failure found has the fewest choices. ``holds=True``: no run fails;
    ``False``: ``witness`` is a failing choice list ``[[coords, label], ...]``;
    ``None``: more than ``max_states`` catalogs, or ``time.perf_counter()`` passed
    ``deadline``.

    With ``late=True`` it looks instead for a run that makes the model inconsistent while
    C stays non-empty (Fig. 3.6): every non-wiped catalog is checked for a consistent
    completion (exact, MAC backtracking); the first inconsistent one is continued with the
    first label of C at each step until C is wiped out. ``stats["first_outside_cstar"]``
    is the choice that made the model inconsistent.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> from csplab import from_example
    >>> P = from_example(load_example("fig3_6a"), (9, 3))
    >>> v = alg31_exhaustive(P, "scan:yx", late=True)   # inconsistent, C not yet empty
    >>> v.stats["first_outside_cstar"] < len(v.witness)
    True
    """
    t0 = time.perf_counter()
    cells = scan_order(problem.shape, order)
    if cells is None:
        raise InputError("exhaustive Alg. 3.1 needs a scan order (scanline or scan:AXES)")
    eng = Propagator(problem)
    stats: dict[str, Any] = {"states": 1, "shape": list(problem.shape)}
    if not eng.ok:
        stats["time_s"] = time.perf_counter() - t0
        return Verdict(False, [], stats, "no consistent model: C is empty before any choice")
    level: dict[bytes, tuple[Propagator, list[list[Any]]]] = {eng.bits.tobytes(): (eng, [])}
    oracle = SearchCompletability(problem, max_nodes=max_nodes)  # exact, node budget
    if late and oracle.completable([], []) is not True:
        return Verdict(None, None, stats, "undecided: no consistent model found at this size")
    order_list = cells.tolist()
    for t, cell in enumerate(order_list):
        nxt: dict[bytes, tuple[Propagator, list[list[Any]]]] = {}
        coords = list(problem.coords(cell))
        for e, path in level.values():
            for b in e.domain(cell).tolist():
                e2 = e.copy()
                p2 = [*path, [coords, int(b)]]
                if not e2.assign(cell, int(b)):
                    if late:
                        continue
                    stats["time_s"] = time.perf_counter() - t0
                    return Verdict(False, p2, stats, f"fails after {len(p2)} choices")
                key = e2.bits.tobytes()
                if key in nxt:
                    continue
                if deadline is not None and time.perf_counter() > deadline:
                    stats["time_s"] = time.perf_counter() - t0
                    return Verdict(None, None, stats, "undecided: out of time")
                if late and _inconsistent(oracle, problem, p2):
                    run = _continue_to_failure(problem, e2, p2, order_list[t + 1 :])
                    stats["first_outside_cstar"] = len(p2)
                    stats["time_s"] = time.perf_counter() - t0
                    return Verdict(
                        False, run, stats,
                        f"inconsistent after {len(p2)} choices, C wiped out after {len(run)}",
                    )  # fmt: skip
                nxt[key] = (e2, p2)
        stats["states"] += len(nxt)
        if stats["states"] > max_states:
            stats["time_s"] = time.perf_counter() - t0
            return Verdict(None, None, stats, f"undecided: more than {max_states} catalogs")
        level = nxt
    stats["time_s"] = time.perf_counter() - t0
    return Verdict(True, None, stats, f"no run fails ({stats['states']} catalogs)")


def _cell_choices(problem: Problem, path: Sequence[Sequence[Any]]) -> NDArray[np.int64]:
    """``[[coords, label], ...]`` as ``(cell, label)`` rows."""
    out = [[problem.cell(tuple(int(t) for t in c)), int(b)] for c, b in path]
    return np.asarray(out, dtype=np.int64).reshape(-1, 2)


def _inconsistent(oracle: SearchCompletability, problem: Problem, path: list[list[Any]]) -> bool:
    """Proven to have no completion (``False`` also when the node budget ran out)."""
    ch = _cell_choices(problem, path)
    return oracle.completable(ch[:, 0], ch[:, 1]) is False


def _continue_to_failure(
    problem: Problem, eng: Propagator, path: list[list[Any]], rest: list[int]
) -> list[list[Any]]:
    """Continue an inconsistent partial model with the first label of C until C is wiped
    out (it must be: an inconsistent model has no completion)."""
    e = eng.copy()
    out = list(path)
    for cell in rest:
        b = int(e.domain(cell)[0])
        out.append([list(problem.coords(cell)), b])
        if not e.assign(cell, b):
            return out
    raise AssertionError("an inconsistent partial model was completed")  # pragma: no cover


def _shapes_upto(limit: tuple[int, ...], max_cells: int | None = None) -> list[tuple[int, ...]]:
    if max_cells is not None:  # prune the product: every axis <= max_cells
        limit = tuple(min(m, max_cells) for m in limit)
    out = [
        s
        for s in itertools.product(*[range(1, m + 1) for m in limit])
        if max_cells is None or math.prod(s) <= max_cells
    ]
    out.sort(key=lambda s: (math.prod(s), s))
    return out


def _ladder(limit: tuple[int, ...], steps: int = 6) -> list[tuple[int, ...]]:
    out: list[tuple[int, ...]] = []
    for k in range(1, steps + 1):
        s = tuple(max(2, math.ceil(m * k / steps)) if m > 1 else 1 for m in limit)
        if s not in out:
            out.append(s)
    return out


_SIDES = (2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32, 40, 48, 64, 80, 96, 128)
_AUTO_CELLS = 2_000_000


def _auto_ladder(example_shape: tuple[int, ...]) -> list[tuple[int, ...]]:
    """Growing outputs for ``max_size=None``: a cube of side ``n`` whose axes stop growing at
    the example's size, then the example's proportions scaled up (at most ``_AUTO_CELLS``)."""
    big = max(example_shape)
    out: list[tuple[int, ...]] = []
    for n in _SIDES:
        if n <= big:
            s = tuple(max(2, min(n, m)) for m in example_shape)
        else:
            s = tuple(max(2, math.ceil(m * n / big)) for m in example_shape)
        if math.prod(s) > _AUTO_CELLS:
            break
        if s not in out:
            out.append(s)
    return out


def _fmt(shape: Sequence[int]) -> str:
    return "x".join(map(str, shape))


class _Search:
    """The state of one :func:`find_failure` call: problems per size, seeds, budget, stats."""

    def __init__(
        self,
        example: ExampleModel | RuleSet,
        order: str,
        gen: np.random.Generator,
        stats: dict[str, Any],
        deadline: float,
        boundary: Any,
    ) -> None:
        self.example, self.order, self.gen, self.stats = example, order, gen, stats
        self.deadline, self.boundary = deadline, boundary
        self.is_scan = scan_order((1,) * example.ndim, order) is not None
        self._problems: dict[tuple[int, ...], Problem] = {}

    def left(self) -> float:
        return self.deadline - time.perf_counter()

    def problem(self, shape: tuple[int, ...]) -> Problem:
        P = self._problems.get(shape)
        if P is None:
            P = model_problem(self.example, shape, self.boundary)
            if P.n <= 200_000:
                self._problems[shape] = P
        return P

    def witness(self, shape: tuple[int, ...], choices: list[list[Any]], kind: str,
                search: str, seed: int | None = None) -> dict[str, Any]:  # fmt: skip
        w: dict[str, Any] = {"shape": list(shape), "order": self.order}
        if self.boundary is not None:
            w["boundary"] = self.boundary
        if seed is not None:
            w["seed"] = seed
        w.update(choices=choices, kind=kind, search=search)
        return w

    def seeded(self, shape: tuple[int, ...], runs: int, key: str = "random_runs"
               ) -> dict[str, Any] | None:  # fmt: skip
        """Up to ``runs`` seeded Alg. 3.1 runs at ``shape``; the first failing one."""
        P = self.problem(shape)
        per = self.stats["runs_per_size"]
        for _ in range(runs):
            if self.left() <= 0:
                return None
            seed = int(self.gen.integers(2**31))
            limit = max(self.left(), 0.01) if P.n > 50_000 else None  # big: stop in time
            r = run_alg31(P, np.random.default_rng(seed), order=self.order, time_limit=limit)
            self.stats[key] += 1
            if key == "random_runs":
                per[_fmt(shape)] = per.get(_fmt(shape), 0) + 1
            if r.status in ("failed", "unsat"):
                tr = r.trace if r.trace is not None else np.zeros((0, 2), dtype=np.int64)
                ch = [[list(P.coords(int(c))), int(b)] for c, b in tr.tolist()]
                return self.witness(shape, ch, r.status, "random runs", seed)
        return None

    def guided(
        self, shape: tuple[int, ...], want: NDArray[np.int64], near: Sequence[int] | None = None
    ) -> dict[str, Any] | None:
        """One scan-order run at ``shape`` that takes the label of ``want`` wherever it is in
        C and a uniform label of C elsewhere; the run if it fails. With ``near`` (a cell's
        coordinates) the run gives up a quarter of the output after passing that cell."""
        P = self.problem(shape)
        eng = Propagator(P)
        self.stats["shrink_runs"] += 1
        if not eng.ok:
            return None  # no consistent model at this size: not a failing run
        scan = scan_order(shape, self.order)
        assert scan is not None
        flat = want.reshape(-1)
        out: list[list[Any]] = []
        stop = P.n
        if near is not None:
            pos = int(np.flatnonzero(scan == P.cell(tuple(int(x) for x in near)))[0])
            stop = min(P.n, pos + P.n // 4 + 8)
        for cell in scan.tolist()[:stop]:
            dom = eng.domain(cell)
            b = int(flat[cell])
            if b < 0 or b not in dom:
                b = int(dom[int(self.gen.integers(dom.size))])
            out.append([list(P.coords(cell)), b])
            if not eng.assign(cell, b):
                return self.witness(shape, out, "failed", "random runs, shrunk")
        return None


def _grid(shape: Sequence[int], choices: list[list[Any]]) -> NDArray[np.int64]:
    g = np.full(tuple(shape), -1, dtype=np.int64)
    for c, b in choices:
        g[tuple(c)] = b
    return g


def _shrink_size(s: _Search, hit: dict[str, Any], runs: int) -> dict[str, Any]:
    """Smaller outputs that still fail, one axis at a time (smallest length first): the
    failing run's labels in a window at the origin, or ending at, starting at or centred
    on the failing cell (scan orders), then fresh seeds."""
    improved = True
    while improved and s.left() > 0:
        improved = False
        shp = tuple(hit["shape"])
        grid = _grid(shp, hit["choices"])
        fail = hit["choices"][-1][0] if hit["choices"] else [0] * len(shp)
        for d in range(len(shp)):
            few = (1, 2, 3, 4, 6, 8, shp[d] // 2, shp[d] - 1)
            cands = range(1, shp[d]) if shp[d] <= 16 else sorted({c for c in few if c >= 1})
            for L in cands:
                if s.left() <= 0:
                    return hit
                s2 = (*shp[:d], L, *shp[d + 1 :])
                h2 = None
                if s.is_scan and hit["kind"] == "failed":
                    f, top = int(fail[d]), shp[d] - L  # from the origin; ending at,
                    offs = sorted({min(max(o, 0), top)  # starting at, centred on the fail
                                   for o in (0, f - L + 1, f, f - L // 2)})  # fmt: skip
                    tries = 3 if math.prod(s2) <= 1000 else 1
                    for off in offs:
                        sl = [slice(None)] * len(shp)
                        sl[d] = slice(off, off + L)
                        near = None
                        if off <= f < off + L:
                            near = [*fail[:d], f - off, *fail[d + 1 :]]
                        for _ in range(tries):
                            h2 = s.guided(s2, grid[tuple(sl)], near)
                            if h2 is not None:
                                break
                        if h2 is not None:
                            break
                if h2 is None:
                    h2 = s.seeded(s2, runs, key="shrink_runs")
                if h2 is not None and (h2["kind"] == "failed" or hit["kind"] == "unsat"):
                    hit, improved = h2, True
                    break
            if improved:
                break
    return hit


def _shrink_choices(s: _Search, hit: dict[str, Any], runs: int) -> dict[str, Any]:
    """At the final size, more runs and (scan orders) a bounded exhaustive search; keep
    the run that fails after the fewest choices."""
    shp = tuple(hit["shape"])
    if not hit["choices"]:
        return hit
    if s.is_scan and s.left() > 0:
        v = alg31_exhaustive(s.problem(shp), s.order, 10_000,
                             deadline=time.perf_counter() + s.left() / 4)  # fmt: skip
        s.stats["shrink_states"] = v.stats["states"]
        if v.holds is False and v.witness and len(v.witness) < len(hit["choices"]):
            return s.witness(shp, v.witness, "failed",
                             "random runs, shrunk; exhaustive at this size")  # fmt: skip
    for _ in range(2):
        h2 = s.seeded(shp, runs, key="shrink_runs")
        if h2 is not None and len(h2["choices"]) < len(hit["choices"]):
            hit = h2
        if s.is_scan and s.left() > 0:
            h3 = s.guided(shp, _grid(shp, hit["choices"][:-1]))
            if h3 is not None and len(h3["choices"]) < len(hit["choices"]):
                hit = h3
    return hit


def _shortest_continuation(
    s: _Search, P: Problem, choices: list[list[Any]], t: int, tries: int = 8
) -> list[list[Any]]:
    """Keep the first ``t`` choices (an inconsistent partial model, so every continuation
    fails) and continue them as briefly as a few tries find (scan orders only)."""
    scan = scan_order(P.shape, s.order)
    assert scan is not None
    eng = Propagator(P)
    for c, b in choices[:t]:
        eng.assign(P.cell(tuple(c)), int(b))
    best = choices
    if not eng.ok:
        return best
    rest = scan.tolist()[t:]
    for k in range(tries):
        if s.left() <= 0:
            break
        e = eng.copy()
        out = [list(x) for x in choices[:t]]
        for cell in rest:
            dom = e.domain(cell)
            b = int(dom[0]) if k == 0 else int(dom[int(s.gen.integers(dom.size))])
            out.append([list(P.coords(cell)), b])
            if len(out) >= len(best) or not e.assign(cell, b):
                break
        if not e.ok and len(out) < len(best):
            best = out
    return best


def find_failure(
    example: ExampleModel | RuleSet,
    *,
    order: str = "scanline",
    max_size: Sequence[int] | str | None = None,
    exhaustive_cells: int = 20,
    random_runs: int = 30,
    rng: int | np.random.Generator | None = 0,
    max_states: int = 300_000,
    exact: bool = True,
    max_nodes: int = 200_000,
    late: bool = False,
    time_limit: float | None = 60.0,
    boundary: Mapping[str, int] | str | None = None,
) -> Verdict:
    """Find a failing run of Alg. 3.1 on ``example`` (smallest size, shortest prefix).

    The search escalates: every run on outputs of at most ``exhaustive_cells`` cells
    (exhaustive, at most ``max_states`` catalogs per size and half of the time, all of it
    without random runs; 3D with random runs: a third of ``max_states`` catalogs in all,
    a tenth of that per size, and a tenth of the time), then seeded
    random runs on growing outputs; a failing random run is shrunk, output size first
    (smaller windows of the failing run, then fresh seeds), then choices (the run at the
    final size that fails soonest, and after its first choice outside C* the shortest
    continuation that wipes C out).

    Parameters
    ----------
    example : ExampleModel or RuleSet
        An example, or a tileset's rules on the file's own grid (its periodicity, domain
        rules and, unless ``boundary`` says otherwise, boundary rules).
    order : str
        Alg. 3.1's cell order: a scan order (exhaustive and random search) or ``random`` /
        ``min-entropy`` (random search only).
    max_size : shape or str, optional
        Largest output searched (each axis; missing trailing axes are 1); 1D and 2D:
        each size once; 3D and higher: round after round until the time budget is spent.
        Default: ``4x4`` for 1D and 2D examples; for 3D and higher, growing outputs
        (cubes up to the example's size, then its proportions scaled up).
    exhaustive_cells : int
        Outputs with at most this many cells are searched exhaustively (scan orders).
    random_runs : int
        Seeds tried per size and round on the larger sizes (0: exhaustive only).
    rng : seed or Generator
        Seeds of the random runs are drawn from it and recorded in the witness.
    exact : bool
        Also find the first step outside C* (exact: SAT when python-sat is installed,
        else MAC backtracking with at most ``max_nodes`` nodes per check).
    late : bool
        Look for a *late* failure instead (Fig. 3.6): a run whose model becomes
        inconsistent while the catalog is still non-empty (exhaustive sizes only).
    time_limit : float, optional
        Seconds for the whole call (``None``: no limit, and one round of the growing
        sizes); the random search stops at 70 % of it, shrinking at 90 %, the exact check
        uses the rest.
    boundary : optional
        Boundary of the outputs, as in :func:`~csplab.grids.from_example` (``"auto"``, a
        mapping face -> label); recorded in the witness.

    Returns
    -------
    Verdict
        The property is "Alg. 3.1 never fails on outputs up to ``max_size``".
        ``holds=False``: ``witness`` is a failing run (see the module docstring);
        ``holds=True``: every output up to ``max_size`` was searched exhaustively and no
        run fails (a bounded proof); ``holds=None``: nothing found, search not exhaustive.
        ``stats``: ``exhaustive_sizes``, ``states``, ``random_runs``, ``runs_per_size``
        (size -> seeded runs), ``found_on`` (size of the first failing random run),
        ``shrink_runs``, ``search_s``, ``shrink_s``, ``time_s``.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> v = find_failure(load_example("castle"), boundary="auto", time_limit=20, rng=1)
    >>> v.holds, replay(load_example("castle"), v.witness).holds
    (False, True)
    """
    t0 = time.perf_counter()
    ok_limit = isinstance(time_limit, (int, float)) and math.isfinite(time_limit)
    if time_limit is not None and not (ok_limit and time_limit > 0):
        raise InputError(f"time_limit must be a positive number of seconds, not {time_limit!r}")
    deadline = math.inf if time_limit is None else t0 + float(time_limit)
    ndim = example.ndim
    auto = max_size is None and ndim >= 3
    # 3D with random runs: exhaustive phase on a budget, then rounds of random runs
    rounds = ndim >= 3 and random_runs > 0 and not late
    if max_size is None and not auto:
        max_size = (4, 4)[:ndim] if ndim <= 2 else (4,) * ndim
    own = example.shape if isinstance(example, ExampleModel) else example.shape or (4,) * ndim
    if auto:
        lim = tuple(max(s) for s in zip(*_auto_ladder(own), strict=True))
    else:
        assert max_size is not None
        lim = (
            parse_shape(max_size) if isinstance(max_size, str) else tuple(int(m) for m in max_size)
        )
        if len(lim) < ndim:
            lim = lim + (1,) * (ndim - len(lim))
        if len(lim) != ndim:
            raise InputError(f"max_size {max_size!r} has more axes than the example ({ndim})")
    is_scan = order == "scanline" or order.startswith("scan:")
    scan_order(lim, order)  # validates the order
    if boundary is None and not isinstance(example, ExampleModel):
        boundary = "auto"  # a rule set's own boundary rules
    bnd = parse_boundary(boundary) if isinstance(boundary, str) else boundary
    if boundary is not None:
        model_problem(example, (2,) * ndim, bnd)  # validates the boundary
    gen, seed0 = make_rng(rng)
    stats: dict[str, Any] = {
        "states": 0,
        "exhaustive_sizes": 0,
        "random_runs": 0,
        "runs_per_size": {},
        "shrink_runs": 0,
        "seed": seed0,
        "time_limit": time_limit,
    }
    s = _Search(example, order, gen, stats, deadline, bnd)
    complete = is_scan
    found: dict[str, Any] | None = None
    # the exhaustive phase's share of the time
    share = 1.0 if late or random_runs <= 0 else 0.1 if rounds else 0.5
    ex_deadline = t0 + share * (deadline - t0)
    for shp in _shapes_upto(lim, exhaustive_cells) if is_scan else []:
        if rounds:  # 3D: a third of max_states in all, a tenth of that per size
            budget = min(max_states // 30, max_states // 3 - stats["states"])
        else:
            budget = max_states
        if budget <= 0 or time.perf_counter() > ex_deadline:
            complete = False
            break
        v = alg31_exhaustive(s.problem(shp), order, budget, late=late, max_nodes=max_nodes,
                             deadline=ex_deadline)  # fmt: skip
        stats["states"] += v.stats["states"]
        stats["exhaustive_sizes"] += 1
        if v.holds is None:
            complete = False
            continue
        if v.holds is False:
            found = s.witness(shp, v.witness, "failed" if v.witness else "unsat",
                              "exhaustive (fewest choices at this size)")  # fmt: skip
            break
    if math.prod(lim) > exhaustive_cells:
        complete = False
    search_deadline = t0 + 0.7 * (deadline - t0)
    if found is None and random_runs > 0 and not late:
        s.deadline = search_deadline
        if rounds:
            ladder = _auto_ladder(own) if auto else _ladder(lim)
            found = _climb(s, ladder, random_runs, exhaustive_cells)
        else:
            for shp in _ladder(lim):
                if math.prod(shp) <= exhaustive_cells and is_scan:
                    continue
                found = s.seeded(shp, random_runs)
                if found is not None:
                    break
        stats["search_s"] = time.perf_counter() - t0
        s.deadline = t0 + 0.9 * (deadline - t0)  # the rest for the exact check
        if found is not None:
            stats["found_on"] = list(found["shape"])
            found = _shrink_size(s, found, random_runs)
            if found["kind"] == "failed":
                found = _shrink_choices(s, found, random_runs)
        stats["shrink_s"] = time.perf_counter() - t0 - stats["search_s"]
        s.deadline = deadline
    stats["time_s"] = time.perf_counter() - t0
    if found is None:
        if complete:
            return Verdict(
                True, None, stats,
                f"no failure of Alg. 3.1 ({order}) on any output up to "
                f"{_fmt(lim)} ({stats['states']} catalogs, exhaustive)",
            )  # fmt: skip
        msg = (
            f"no failure found ({stats['random_runs']} random runs, "
            f"{stats['exhaustive_sizes']} sizes exhaustive, {stats['time_s']:.1f} s); not a proof"
        )
        return Verdict(None, None, stats, msg)
    found["fail_step"] = len(found["choices"])
    if exact and found["kind"] == "failed":
        _first_outside(s, found, max_nodes)
    stats["time_s"] = time.perf_counter() - t0
    msg = f"Alg. 3.1 ({order}) fails on {_fmt(found['shape'])} after {found['fail_step']} choices"
    if found.get("first_outside_cstar") is not None:
        msg += f"; inconsistent from choice {found['first_outside_cstar']}"
    return Verdict(False, found, stats, msg)


def _climb(
    s: _Search, ladder: list[tuple[int, ...]], runs: int, exhaustive_cells: int
) -> dict[str, Any] | None:
    """Rounds of ``runs`` seeded runs per size up the ladder until the budget is spent; a
    round climbs no higher than the size whose runs would take a quarter of what is left.
    Without a time limit: one round."""
    ladder = [x for x in ladder if not (s.is_scan and math.prod(x) <= exhaustive_cells)]
    top = len(ladder)
    rounds = 1 if math.isinf(s.deadline) else None
    while s.left() > 0 and ladder and rounds != 0:
        rounds = None if rounds is None else rounds - 1
        for i, shp in enumerate(ladder[:top]):
            t1 = time.perf_counter()
            hit = s.seeded(shp, runs)
            if hit is not None:
                return hit
            if (time.perf_counter() - t1) > s.left() / 4:
                top = i + 1
                break
    return None


def _first_outside(s: _Search, found: dict[str, Any], max_nodes: int) -> None:
    """``first_outside_cstar`` and ``detection_delay`` of a failing run, shortening the run
    after the first choice outside C* (scan orders)."""
    from csplab.deps import available

    P = s.problem(tuple(found["shape"]))
    oracle: Any
    if available("pysat") and (P.n > 64 or P.ndim >= 3):
        from csplab.engine.completability import SatCompletability

        oracle = SatCompletability(P, deadline=None if math.isinf(s.deadline) else s.deadline)
    else:
        oracle = SearchCompletability(P, max_nodes=max_nodes)
    t = None
    try:
        if oracle.completable([], []) is True:  # else undecided (the run failed anyway)
            with contextlib.suppress(PrefixTimeout):  # undecided within the budget
                k = first_inconsistent_prefix(
                    oracle, _cell_choices(P, found["choices"]), full_inconsistent=True
                )
                t = None if k is None else k + 1  # choices count from 1 in the witness
    finally:
        close = getattr(oracle, "close", None)
        if close is not None:
            close()
    found["first_outside_cstar"] = t
    if t is not None:
        if s.is_scan and found["search"].startswith("random"):
            short = _shortest_continuation(s, P, found["choices"], t)
            if len(short) < len(found["choices"]):
                found.pop("seed", None)  # scan order: the choices replay without it
                found["choices"], found["fail_step"] = short, len(short)
                found["search"] += ", shortest continuation after C*"
        found["detection_delay"] = found["fail_step"] - t


def _searched(stats: dict[str, Any]) -> str:
    per = stats["runs_per_size"]
    sizes = ", ".join(f"{k}: {n}" for k, n in per.items())
    out = f"{stats['exhaustive_sizes']} sizes exhaustive ({stats['states']} catalogs), "
    out += f"{stats['random_runs']} random runs"
    if sizes:
        out += f" ({sizes})"
    return out + f", {stats['time_s']:.1f} s"


def searched(stats: dict[str, Any]) -> str:
    """What a :func:`find_failure` call searched, from its ``stats``, as one line.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> v = find_failure(load_example("line"), max_size=(3, 3), random_runs=0)
    >>> searched(v.stats).split(", ")[:2]
    ['9 sizes exhaustive (501 catalogs)', '0 random runs']
    """
    line = _searched(stats)
    if stats.get("shrink_runs"):
        line += f"; shrunk with {stats['shrink_runs']} runs in {stats.get('shrink_s', 0):.1f} s"
    return line


def model_problem(model: ExampleModel | RuleSet, shape: Sequence[int], boundary: Any) -> Problem:
    """The output problem of a run: :func:`~csplab.grids.from_example` for an example, the
    rule set's own problem (its periodicity, its domain rules; ``boundary="auto"`` or
    ``None`` its own boundary rules, as :meth:`RuleSet.problem`) for a tileset.

    Parameters
    ----------
    model : ExampleModel or RuleSet
    shape : sequence of int
    boundary : None, "auto", "none" or mapping face -> label

    Returns
    -------
    Problem

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> model_problem(load_example("line"), (3, 2), None).shape
    (3, 2)
    """
    shp = tuple(int(t) for t in shape)
    if isinstance(model, ExampleModel):
        return from_example(model, shp) if boundary is None else from_example(
            model, shp, boundary=boundary)  # fmt: skip
    return model.problem(shp, boundary="auto" if boundary is None else boundary)


def replay(example: ExampleModel | RuleSet, witness: dict[str, Any]) -> Verdict:
    """Re-check a witness: ``holds=True`` iff it is a failing run of Alg. 3.1.

    Every label must be in the catalog when it is chosen, cells must come in the scan
    order (random orders: the recorded seed must reproduce the run), and the catalog must
    be wiped out by the last choice (or before any choice for ``kind="unsat"``). The
    output has the witness' ``boundary`` when it records one.
    """
    shape = tuple(int(s) for s in witness["shape"])
    order = str(witness.get("order", "scanline"))
    bnd = witness.get("boundary")
    if isinstance(bnd, str):
        bnd = parse_boundary(bnd)
    P = model_problem(example, shape, bnd)
    eng = Propagator(P)
    choices = witness.get("choices", [])
    if not eng.ok:
        return Verdict(not choices, None, {}, "C is empty before any choice")
    scan = scan_order(shape, order)
    if scan is None:
        seed = witness.get("seed")
        if seed is None:
            return Verdict(False, None, {}, "a random-order witness needs its seed")
        r = run_alg31(P, np.random.default_rng(int(seed)), order=order)
        tr = r.trace.tolist() if r.trace is not None else []
        same = [[list(P.coords(int(c))), int(b)] for c, b in tr] == [
            [list(c), int(b)] for c, b in choices
        ]
        if not same:
            return Verdict(False, None, {}, "the seed does not reproduce the choices")
        scan = np.array([P.cell(tuple(c)) for c, _ in choices], dtype=np.int64)
    for t, (c, b) in enumerate(choices):
        cell = P.cell(tuple(c))
        if int(scan[t]) != cell:
            return Verdict(False, None, {}, f"choice {t + 1} at {tuple(c)} is out of order")
        if not eng.ok:
            return Verdict(False, None, {}, f"the catalog was wiped out before choice {t + 1}")
        if int(b) not in eng.domain(cell):
            return Verdict(False, None, {}, f"choice {t + 1}: label {b} not in C at {tuple(c)}")
        eng.assign(cell, int(b))
    if eng.ok:
        return Verdict(False, None, {}, "the catalog is not empty after the last choice")
    return Verdict(True, None, {"fail_cell": list(P.coords(eng.wiped))}, "replays: C wiped out")
