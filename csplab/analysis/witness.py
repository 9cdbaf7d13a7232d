"""Failure witnesses for Alg. 3.1: concrete failing runs, minimised, and bounded proofs.

A *witness* is a dict ``{"shape", "order", "choices": [[coords, label], ...], "kind", ...}``:
replaying the choices in the scan order, each label is in the catalog C when it is
chosen and the last one wipes the catalog out (``kind="failed"``), or the output size has
no consistent model at all and arc consistency empties C before any choice
(``kind="unsat"``, no choices). Random-order witnesses also carry the ``seed`` of
:func:`csplab.engine.alg31.run_alg31` that produced them. :func:`replay` re-checks a
witness.

:func:`find_failure` looks for the smallest output and the shortest prefix that fail:
exhaustively (every label of C at every step, breadth first over distinct catalogs, so the
first failure found has the fewest choices) on outputs of up to ``exhaustive_cells``
cells, then by random runs on a ladder of larger sizes up to ``max_size``, shrinking the
size again when a run fails. For the witness it finds the first step whose label was
outside the exact catalog C* (the model became inconsistent there;
:func:`~csplab.engine.completability.first_inconsistent_prefix` with the exact search
:class:`~csplab.engine.completability.SearchCompletability`) and how many assignments later
Alg. 3.1 noticed (Fig. 3.6: the delay can be positive). Choices are counted from 1 in the
witness (``first_outside_cstar``: choice 3 is the third).

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
from collections.abc import Sequence
from typing import Any

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
from csplab.grids import parse_shape
from csplab.problem import Problem
from csplab.result import Verdict
from csplab.rng import make_rng

__all__ = ["alg31_exhaustive", "find_failure", "replay"]


class _Budget(Exception):
    pass


def alg31_exhaustive(
    problem: Problem,
    order: str = "scanline",
    max_states: int = 1_000_000,
    *,
    late: bool = False,
    max_nodes: int = 100_000,
) -> Verdict:
    """Every run of Alg. 3.1 on one problem: does some choice sequence fail?

    Breadth first over the distinct catalogs after each step (equal catalogs have equal
    futures), so a failure found has the fewest choices. ``holds=True``: no run fails;
    ``False``: ``witness`` is a failing choice list ``[[coords, label], ...]``;
    ``None``: more than ``max_states`` catalogs.

    With ``late=True`` it looks instead for a run that makes the model inconsistent while
    C stays non-empty (Fig. 3.6): every non-wiped catalog is checked for a consistent
    completion (exact, MAC backtracking); the first inconsistent one is continued with the
    first label of C at each step until C is wiped out. ``stats["first_outside_cstar"]``
    is the choice that made the model inconsistent.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> P = Problem.from_example(load_example("fig3_6a"), (9, 3))
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


def _shapes_upto(limit: tuple[int, ...]) -> list[tuple[int, ...]]:
    out = list(itertools.product(*[range(1, m + 1) for m in limit]))
    out.sort(key=lambda s: (math.prod(s), s))
    return out


def _ladder(limit: tuple[int, ...], steps: int = 6) -> list[tuple[int, ...]]:
    out: list[tuple[int, ...]] = []
    for k in range(1, steps + 1):
        s = tuple(max(2, math.ceil(m * k / steps)) if m > 1 else 1 for m in limit)
        if s not in out:
            out.append(s)
    return out


def find_failure(
    example: ExampleModel,
    *,
    order: str = "scanline",
    max_size: Sequence[int] | str = (4, 4),
    exhaustive_cells: int = 20,
    random_runs: int = 30,
    rng: int | np.random.Generator | None = 0,
    max_states: int = 300_000,
    exact: bool = True,
    max_nodes: int = 200_000,
    late: bool = False,
) -> Verdict:
    """Find a failing run of Alg. 3.1 on ``example`` (smallest size, shortest prefix).

    Parameters
    ----------
    example : ExampleModel
    order : str
        Alg. 3.1's cell order: a scan order (exhaustive and random search) or ``random`` /
        ``min-entropy`` (random search only).
    max_size : shape or str
        Largest output searched (each axis); missing trailing axes are 1.
    exhaustive_cells : int
        Outputs with at most this many cells are searched exhaustively (scan orders).
    random_runs : int
        Seeds tried per size on the ladder of larger sizes (0: exhaustive only).
    rng : seed or Generator
        Seeds of the random runs are drawn from it and recorded in the witness.
    exact : bool
        Also find the first step outside C* (exact satisfiability by MAC backtracking,
        at most ``max_nodes`` nodes per check).
    late : bool
        Look for a *late* failure instead (Fig. 3.6): a run whose model becomes
        inconsistent while the catalog is still non-empty (exhaustive sizes only).

    Returns
    -------
    Verdict
        The property is "Alg. 3.1 never fails on outputs up to ``max_size``".
        ``holds=False``: ``witness`` is a failing run (see the module docstring);
        ``holds=True``: every output up to ``max_size`` was searched exhaustively and no
        run fails (a bounded proof); ``holds=None``: nothing found, search not exhaustive.
    """
    t0 = time.perf_counter()
    ndim = example.ndim
    lim = parse_shape(max_size) if isinstance(max_size, str) else tuple(int(m) for m in max_size)
    if len(lim) < ndim:
        lim = lim + (1,) * (ndim - len(lim))
    if len(lim) != ndim:
        raise InputError(f"max_size {max_size!r} has more axes than the example ({ndim})")
    is_scan = order == "scanline" or order.startswith("scan:")
    scan_order(lim, order)  # validates the order
    gen, seed0 = make_rng(rng)
    stats_seed = seed0
    stats: dict[str, Any] = {
        "states": 0,
        "exhaustive_sizes": 0,
        "random_runs": 0,
        "seed": stats_seed,
    }
    complete = is_scan
    found: dict[str, Any] | None = None
    for shp in _shapes_upto(lim) if is_scan else []:
        if math.prod(shp) > exhaustive_cells:
            complete = False
            continue
        P = Problem.from_example(example, shp)
        v = alg31_exhaustive(P, order, max_states, late=late, max_nodes=max_nodes)
        stats["states"] += v.stats["states"]
        stats["exhaustive_sizes"] += 1
        if v.holds is None:
            complete = False
            continue
        if v.holds is False:
            found = {
                "shape": list(shp),
                "order": order,
                "choices": v.witness,
                "kind": "failed" if v.witness else "unsat",
                "search": "exhaustive (fewest choices at this size)",
            }
            break
    if found is None and random_runs > 0 and not late:
        found = _random_search(example, order, lim, random_runs, gen, stats, exhaustive_cells)
    stats["time_s"] = time.perf_counter() - t0
    if found is None:
        if complete:
            return Verdict(
                True, None, stats,
                f"no failure of Alg. 3.1 ({order}) on any output up to "
                f"{'x'.join(map(str, lim))} ({stats['states']} catalogs, exhaustive)",
            )  # fmt: skip
        return Verdict(
            None, None, stats,
            f"no failure found ({stats['random_runs']} random runs, "
            f"{stats['exhaustive_sizes']} sizes exhaustive); not a proof",
        )  # fmt: skip
    found["fail_step"] = len(found["choices"])
    if exact and found["kind"] == "failed":
        P = Problem.from_example(example, tuple(found["shape"]))
        oracle = SearchCompletability(P, max_nodes=max_nodes)
        t = None
        if oracle.completable([], []) is True:  # else undecided (the run failed anyway)
            with contextlib.suppress(PrefixTimeout):  # undecided within max_nodes
                k = first_inconsistent_prefix(
                    oracle, _cell_choices(P, found["choices"]), full_inconsistent=True
                )
                t = None if k is None else k + 1  # choices count from 1 in the witness
        found["first_outside_cstar"] = t
        if t is not None:
            found["detection_delay"] = found["fail_step"] - t
    stats["time_s"] = time.perf_counter() - t0
    msg = (
        f"Alg. 3.1 ({order}) fails on {'x'.join(map(str, found['shape']))} after "
        f"{found['fail_step']} choices"
    )
    if found.get("first_outside_cstar") is not None:
        msg += f"; inconsistent from choice {found['first_outside_cstar']}"
    return Verdict(False, found, stats, msg)


def _random_search(
    example: ExampleModel,
    order: str,
    lim: tuple[int, ...],
    runs: int,
    gen: np.random.Generator,
    stats: dict[str, Any],
    exhaustive_cells: int,
) -> dict[str, Any] | None:
    def attempt(shp: tuple[int, ...]) -> dict[str, Any] | None:
        P = Problem.from_example(example, shp)
        for _ in range(runs):
            seed = int(gen.integers(2**31))
            r = run_alg31(P, np.random.default_rng(seed), order=order)
            stats["random_runs"] += 1
            if r.status in ("failed", "unsat"):
                tr = r.trace if r.trace is not None else np.zeros((0, 2), dtype=np.int64)
                ch = [[list(P.coords(int(c))), int(b)] for c, b in tr.tolist()]
                return {
                    "shape": list(shp),
                    "order": order,
                    "seed": seed,
                    "choices": ch,
                    "kind": r.status,
                    "search": "random runs",
                }
        return None

    hit: dict[str, Any] | None = None
    for shp in _ladder(lim):
        if math.prod(shp) <= exhaustive_cells and (order == "scanline" or order[:5] == "scan:"):
            continue
        hit = attempt(shp)
        if hit is not None:
            break
    if hit is None:
        return None
    # shrink: one axis at a time, halve while a failure is still found
    shp = tuple(hit["shape"])
    improved = True
    while improved:
        improved = False
        for d in range(len(shp)):
            for cand in (shp[d] // 2, shp[d] - 1):
                if cand < 1 or cand == shp[d]:
                    continue
                s2 = (*shp[:d], cand, *shp[d + 1 :])
                h2 = attempt(s2)
                if h2 is not None:
                    hit, shp, improved = h2, s2, True
                    break
    return hit


def replay(example: ExampleModel, witness: dict[str, Any]) -> Verdict:
    """Re-check a witness: ``holds=True`` iff it is a failing run of Alg. 3.1.

    Every label must be in the catalog when it is chosen, cells must come in the scan
    order (random orders: the recorded seed must reproduce the run), and the catalog must
    be wiped out by the last choice (or before any choice for ``kind="unsat"``).
    """
    shape = tuple(int(s) for s in witness["shape"])
    order = str(witness.get("order", "scanline"))
    P = Problem.from_example(example, shape)
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
