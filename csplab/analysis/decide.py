"""Deciding infallibility within a time budget: region refinement plus a search for failures.

:func:`decide_infallibility` combines the two one-sided tools into a decision procedure
that stops at the first verdict:

* **proof** -- :func:`~csplab.analysis.infallible.prove_infallible` (Alg. 3.6/3.7,
  Theorem 3.3.6) on a ladder of regions, fewest cells first: sizes 2 .. ``max_region`` per
  axis, reaching 1 .. ``max_back`` cells before the point (Alg. 3.7 reaches 1), each with
  no frame history and then with ``history``; then once more with one more cell of
  history. Frame labels are recorded by class
  (:func:`~csplab.analysis.infallible.label_classes`), which with no history proves the
  3D pipes rule set (MarkovJunior's Knots3D) with 2x2x3 regions in a fraction of a
  second. The ladder is *refined by the spurious failures*:
  when Alg. 3.6 with a region fails for real on a concrete output, a region that sees the
  same cells of that output at every point (equal on each axis, or covering the output on
  that axis) fails on it the same way, so it is skipped.
* **refutation** -- a failing run of Alg. 3.1. A realised Alg. 3.6 failure whose labels
  Alg. 3.1 also allows is one; otherwise :func:`~csplab.analysis.witness.find_failure`
  (every run on small outputs, then seeded random runs on growing outputs up to
  ``max_size``, shrunk to the smallest output and fewest choices) runs in slices between
  the region attempts (3 s, then twice as long each time the ladder has spent as long) and
  gets the rest of the time at the end. A refutation is as good as its
  replay: :func:`~csplab.analysis.witness.replay` and ``csplab check-certificate`` re-run it.

A verdict names its method (``stats["method"]``): ``"region RxS (Alg. 3.6)"``,
``"Alg. 3.6 run = Alg. 3.1 run"`` or ``"failure search"``. Undecided verdicts say what was
tried, and whether all outputs up to a size were searched exhaustively (a bounded result).

Examples
--------
>>> from csplab.examples import load_example
>>> v = decide_infallibility(load_example("fig3_4a"), order="scan:yx", time_limit=30)
>>> v.holds, v.stats["method"]
(True, 'region 3x2 history 0 (Alg. 3.6)')
>>> v = decide_infallibility(load_example("fig3_5a"), order="scan:yx", time_limit=30)
>>> v.holds, v.stats["method"] in ("Alg. 3.6 run = Alg. 3.1 run", "failure search")
(False, True)

(Which of the two finds the failing run first depends on the time slices, so on the load.)
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from csplab.analysis.infallible import (
    proof_scope,
    prove_infallible,
    run_certificate,
    scan_axes,
)
from csplab.analysis.witness import find_failure
from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.result import Verdict

if TYPE_CHECKING:
    from csplab.io.ruleset import RuleSet

__all__ = ["decide_infallibility", "region_ladder"]


Shape = tuple[int, ...]


def region_ladder(ndim: int, max_region: int, max_back: int = 1) -> list[tuple[Shape, Shape]]:
    """Regions to try as ``(size, back)`` pairs, fewest cells in the box first (ties: the
    smaller largest side first). ``size`` per axis is 2 .. ``max_region``, ``back`` (how far
    the box reaches before its point) 1 .. ``max_back``.

    Parameters
    ----------
    ndim : int
        Number of axes.
    max_region : int
        Largest size on an axis (at least 2).
    max_back : int
        Largest reach before the point (1: Alg. 3.7's region).

    Returns
    -------
    list of (tuple, tuple)

    Examples
    --------
    >>> [r for r, b in region_ladder(2, 3)]
    [(2, 2), (2, 3), (3, 2), (3, 3)]
    >>> region_ladder(1, 2, 2)
    [((2,), (1,)), ((2,), (2,))]
    """
    sizes = itertools.product(range(2, max(2, max_region) + 1), repeat=ndim)
    backs = list(itertools.product(range(1, max(1, max_back) + 1), repeat=ndim))
    pairs = [(r, b) for r in sizes for b in backs]

    def cells(rb: tuple[Shape, Shape]) -> tuple[int, int, Shape, Shape]:
        r, b = rb
        box = tuple(x + y - 1 for x, y in zip(r, b, strict=True))
        return (math.prod(box), max(box), b, r)

    return sorted(pairs, key=cells)


def _same_on(r: Sequence[int], s: Sequence[int], out: Sequence[int]) -> bool:
    """Regions of sizes ``r`` and ``s`` reach equally far past every point of an output
    of shape ``out`` (the region of Alg. 3.7 reaches ``r - 2`` cells past the point, so a
    region of at least ``n + 1`` cells covers an axis of ``n``)."""
    return all(a == b or min(a, b) >= n + 1 for a, b, n in zip(r, s, out, strict=True))


def _same_back(r: Sequence[int], s: Sequence[int], out: Sequence[int]) -> bool:
    """Regions reaching ``r`` and ``s`` cells back reach equally far before every point of
    an output of shape ``out``."""
    return all(a == b or min(a, b) >= n - 1 for a, b, n in zip(r, s, out, strict=True))


def decide_infallibility(
    example: ExampleModel | RuleSet,
    *,
    order: str = "scanline",
    boundary: Mapping[str, int] | str | None = None,
    time_limit: float = 600.0,
    max_region: int | None = None,
    max_back: int | None = None,
    history: int = 1,
    max_states: int = 5_000_000,
    max_size: Sequence[int] | str | None = None,
    rng: int = 0,
    certificate: bool = False,
    classes: bool = True,
) -> Verdict:
    """Decide whether Alg. 3.1 (scan ``order``) can fail on ``example``, within a budget.

    Parameters
    ----------
    example : ExampleModel or RuleSet
        An example or a tileset's rules, within
        :func:`~csplab.analysis.infallible.proof_scope`.
    order : str
        A scan order (``"scanline"`` or ``"scan:AXES"``).
    boundary : mapping, "auto", "none" or None
        An example's boundary (as in :func:`prove_infallible`); a tileset's is its own.
    time_limit : float
        Seconds for the whole decision.
    max_region : int, optional
        Largest region side tried (default 8 in 1D/2D, 4 in 3D).
    max_back : int, optional
        Largest reach of a region before its point (default 6 in 1D/2D, 2 in 3D; Alg. 3.7
        reaches 1: a region reaching further still holds the point's backward neighbours,
        so Theorem 3.3.6 holds for it, and it sees more of what was assigned).
    history : int
        Frame history of the region prover; the ladder is tried with it, then with one
        more (regions whose Alg. 3.6 failure was real are not tried again).
    max_states : int
        State budget of each region attempt.
    max_size : shape or str, optional
        Largest output of the failure search (default 40 in 1D, 12x12 in 2D; in 3D the
        outputs grow up to the example's proportions scaled up, as in
        :func:`find_failure`).
    rng : int
        Seed of the failure search's random runs (recorded in the witness).
    certificate : bool
        Put a certificate in ``witness["certificate"]`` (see :func:`prove_infallible`).
    classes : bool
        Let the region prover record frame labels by class
        (:func:`~csplab.analysis.infallible.label_classes`).

    Returns
    -------
    Verdict
        ``holds`` True (proved; ``witness`` as :func:`prove_infallible`'s), False
        (``witness["alg31"]`` a failing run of Alg. 3.1) or None (undecided).
        ``stats``: ``method``, ``time_s``, ``attempts`` (one line per region tried),
        ``states`` (of the proving attempt), ``search`` (the failure searches' stats).

    Raises
    ------
    InputError
        A model outside the proof's scope, or a bad order, boundary or time limit.
    """
    t0 = time.perf_counter()
    if not (isinstance(time_limit, int | float) and math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"time limit must be a positive number of seconds, not {time_limit!r}")
    why = proof_scope(example)
    if why is not None:
        raise InputError(f"{example.name or 'the model'}: {why}")
    ndim = example.ndim
    scan_axes(ndim, order)
    deadline = t0 + float(time_limit)
    top = max_region or (8 if ndim <= 2 else 4)
    max_back = max_back or (6 if ndim <= 2 else 2)
    regions = region_ladder(ndim, top, max_back)
    # each region with no history first (the smallest frames: with label classes often
    # enough, and fast), then ``history``; then the ladder once more with one more
    ladder = [(r, b, h) for r, b in regions for h in sorted({0, history})]
    ladder += [(r, b, history + 1) for r, b in regions]
    if max_size is None and ndim <= 2:
        max_size = (40,) if ndim == 1 else (12, 12)
    attempts: list[str] = []
    searches: list[dict[str, Any]] = []
    spurious: list[tuple[Shape, Shape, Shape]] = []  # (region, back, output)
    bnd = None if boundary in (None, "none") else boundary

    def done(v: Verdict, method: str) -> Verdict:
        v.stats["method"] = method
        v.stats["attempts"] = attempts
        v.stats["search"] = searches
        v.stats["time_s"] = time.perf_counter() - t0
        cert = (v.witness or {}).get("certificate") if isinstance(v.witness, dict) else None
        if cert is not None:  # the time to find it: the whole decision, not the last step
            cert["prover"] = dict(cert.get("prover") or {}, time_s=v.stats["time_s"],
                                  method=method)  # fmt: skip
        return v

    def search(seconds: float) -> Verdict | None:
        left = deadline - time.perf_counter()
        if left < 1.0:
            return None
        # small outputs exhaustively once (find_failure's default), then random runs only
        later: dict[str, Any] = {"exhaustive_cells": 0} if searches else {}
        ff = find_failure(
            example, order=order, max_size=max_size, rng=rng + len(searches), boundary=bnd,
            time_limit=max(1.0, min(seconds, left)), **later,
        )  # fmt: skip
        searches.append({
            k: ff.stats.get(k) for k in ("random_runs", "exhaustive_sizes", "states", "time_s")
        } | {"holds": ff.holds, "message": ff.message})  # fmt: skip
        if ff.holds is False and ff.witness is not None:
            return ff
        return None

    slice_s, last_search = 3.0, t0
    ladder_end = t0 + 0.7 * float(time_limit)  # the rest: the failure search
    for i, (r, b, hist) in enumerate(ladder):
        if time.perf_counter() > ladder_end:
            break
        if any(_same_on(r, s, out) and _same_back(b, sb, out) for s, sb, out in spurious):
            continue
        left = ladder_end - time.perf_counter()
        v = prove_infallible(
            example, r, order=order, history=hist, max_states=max_states,
            refute=False, certificate=certificate, boundary=boundary, back=b, classes=classes,
            time_limit=max(0.5, 0.5 * left if i else 0.25 * left),
        )  # fmt: skip
        rt = "x".join(map(str, r)) + ("" if set(b) == {1} else " back " + "x".join(map(str, b)))
        attempts.append(f"{rt} history {hist}: {v.message}")
        if v.holds is True:
            hx = f" history {hist}" if hist != 1 else ""
            return done(v, f"region {rt}{hx} (Alg. 3.6)")
        wit = v.witness or {}
        if v.holds is False:
            return done(v, "Alg. 3.6 run = Alg. 3.1 run")
        a36 = wit.get("alg36") or {}
        if a36.get("realized"):
            spurious.append((r, b, tuple(a36["run"]["shape"])))
        # slices of failure search between the attempts, each twice as long as the last,
        # once the ladder has spent as long as the last slice (at most 15 % of what is left)
        now = time.perf_counter()
        if not searches or now - last_search >= slice_s:
            ff = search(min(slice_s, 0.15 * (deadline - now)))
            last_search, slice_s = time.perf_counter(), 2 * slice_s
            if ff is not None:
                return done(_refuted(example, ff, v, certificate, boundary), "failure search")
    ff = search(deadline - time.perf_counter())
    if ff is not None:
        return done(_refuted(example, ff, None, certificate, boundary), "failure search")
    bounded = [s["message"] for s in searches if s["holds"] is True]
    msg = (
        f"undecided: no region up to {top} per axis proves it ({len(attempts)} tried) and no "
        f"failure of Alg. 3.1 was found ({sum(int(s['random_runs'] or 0) for s in searches)} "
        "random runs" + (f"; {bounded[-1]}" if bounded else "") + ")"
    )
    return done(Verdict(None, None, {}, msg), "none")


def _refuted(
    example: ExampleModel | RuleSet,
    ff: Verdict,
    last: Verdict | None,
    certificate: bool,
    boundary: Mapping[str, int] | str | None,
) -> Verdict:
    run = dict(ff.witness or {})
    wit: dict[str, Any] = {"alg31": run}
    if last is not None and last.witness and "alg36" in last.witness:
        wit["alg36"] = last.witness["alg36"]
    stats = dict(ff.stats)
    if certificate:
        wit["certificate"] = run_certificate(example, run, stats, boundary)
    return Verdict(False, wit, stats, f"fallible: {ff.message}")
