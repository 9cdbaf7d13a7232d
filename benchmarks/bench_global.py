"""Benchmark: global constraints at scale (issue 29, item 4).

Two problems, each with one connected structure and a count:

- ``city`` 40x40x10 (``boundary="auto"``): every non-background label (not air, not
  ground) one connected component, and 5-30 % of the cells non-background (the
  ``constraints`` experiment's constraints);
- the WFC pipes (knot) tileset of the test data at 128x128: every non-empty tile one
  connected network, at most 2 crossings.

Each is solved by ``catalog`` (with restarts), ``sat``, ``asp`` and ``cpsat`` with a time
limit; the output is re-checked by :meth:`~csplab.problem.Problem.violations`. Beside each
figure: the same solver on the same problem without the global constraints, in the same
process (the reference: the machine's load inflates both alike), and the load average.

``catalog`` runs with its defaults and ``restarts=50``: its default ``order="auto"`` is
min-entropy under global constraints (:func:`csplab.engine.alg31.auto_order`; city's one
object of at least 800 cells grows from where it started), scanline on the references
without them; a refuted choice is withdrawn and the cell chooses again
(:func:`csplab.engine.alg31.run_alg31`). ``--catalog-order`` gives it another order.

``sat+catalog`` and ``asp+catalog`` are ``sat`` with ``choice="catalog"`` and ``asp`` with
``diversity="catalog"``: each starts from a seeded Alg. 3.1 solution
(:func:`csplab.engine.alg31.solution_hint`: under global constraints min-entropy runs,
then scanline runs) as its decision phases / preferred labels -- what ``cpsat`` does by
default with its solution hint. The plain lines keep each solver's defaults; ``asp``'s default
(``diversity="auto"``) is that start under global constraints, so its two lines differ only
in their references without constraints (random signs against the catalog start).

``sat``'s default is ``choice="auto"``: under global constraints an attempt from uniform
phases of at most 300 conflicts per solver call (the knot network needs 37-53), then the
seeded Alg. 3.1 solution, which the solver confirms as assumptions over every label variable
(0 conflicts); its note says which phases gave the output (``choice``). ``sat+catalog`` is
that solution at once, without the uniform attempt.

Targets: ``catalog``, ``sat``, ``asp`` <= 10 s each, ``cpsat`` <= 30 s, every output valid.

Usage::

    python benchmarks/bench_global.py [--cases city pipes] [--solvers catalog sat asp cpsat]
                                      [--time-limit 60] [--seed 1] [--catalog-order ORDER]

Idle run with every solver's defaults of 2026-11-27 (``--time-limit 35``, load average
0.9-1.0; catalog ``order="auto"``, sat ``choice="auto"``, asp ``diversity="auto"``): city:
catalog 0.88 s (min-entropy, first attempt), sat 3.44 s (300 conflicts in the uniform
attempt, then the confirmed hint), sat+catalog 3.22 s, asp 5.28 s, asp+catalog 5.34 s, cpsat
4.53 s; pipes: catalog 2.16 s, sat 1.57 s (uniform phases, 53 conflicts), sat+catalog
4.55 s, asp 5.44 s, asp+catalog 5.54 s, cpsat 4.24 s; every target meets, every output
valid. The idle run before these defaults (load average 0.3-1.0): city: catalog 0.86 s
(``restarts=50``, min-entropy given), sat timeout (8,604 conflicts), sat+catalog 3.68 s, asp
timeout, asp+catalog 10.59 s, cpsat 4.41 s; pipes: catalog 2.05 s, sat 1.48 s,
sat+catalog 5.21 s, asp 3.58 s, asp+catalog 7.38 s, cpsat 4.22 s.

``sat``'s default ``choice="auto"`` (``--solvers catalog sat sat+catalog --time-limit 35``,
load average 3.7-4.1, then the code before it in the same session, load average 3.6-4.0):
city: sat 5.27 s (300 conflicts, all in the uniform attempt; before: 12.40 s after 2,117
conflicts, and a timeout after 8,365 in another run), sat+catalog 5.54 s (0 conflicts;
before: timeout after 6,601 conflicts, 5.65 s after 1,102 in another run: the labels as
phases left the count's auxiliary variables to the search), catalog 1.28 s; pipes: sat 1.91 s
(uniform phases, 53 conflicts; before 2.69 s), sat+catalog 6.70 s (before 10.66 s), catalog
2.89 s; every output valid. The ``catalog`` figures above are min-entropy order on city and
scanline on pipes, given per case: scanline order fails on city for seeds 1-3 (1.1-1.2 CPU s
each; ``restarts=10``: 1 of 3 solved in 35 s, load average 5).

``catalog``'s default ``order="auto"`` (``--solvers catalog --time-limit 35``, load average
5.0-5.1; then ``--catalog-order scanline`` in the next run, load average 5.3): city solved in
3.46 s (min-entropy, first attempt, 10 choices withdrawn; scanline: timeout after 8
attempts), pipes in 9.13 s (min-entropy, first attempt; scanline 8.97 s); every output
valid. With ``restarts=50`` and ``time_limit=35`` per run, seeds 1-3 in one process (load
average 3.8-5.5), CPU seconds: city min-entropy 0.82-0.90 (first attempt each), scanline a
timeout for seeds 1 and 2 (7 and 6 attempts) and 4 attempts (4.96 s) for seed 3; pipes
min-entropy 2.25-2.37, scanline 2.17-2.25 (first attempt each). The command line's default
path (``csplab synthesize city --size 40x40x10 --boundary auto --seed 1 --constraints FILE``
with this city's constraints: catalog, 10 restarts, then sat; load average 5.0 for both):
before, catalog gave up after 11 attempts (57.0 s) and sat finished, 64.3 s in all; with
``order="auto"`` catalog solved on the first attempt in 3.7 s (6.9 s process wall time).

Measured (2-core machine shared by other jobs, load average 9-12; ``--time-limit 60``):
catalog meets both targets (city 3.05 s, 10 choices withdrawn; pipes 7.45 s); asp's
figures are in the last paragraph below.
``sat`` and ``cpsat`` (``--cases city pipes --solvers sat cpsat --time-limit 60``, load
average 4.6-5.2): they meet on pipes (2.63 s against 0.40 s without the constraints; 3.93 s
against 0.73 s) and time out on city (8,901 conflicts; 103 cuts; references 3.23 and 2.47 s).

Where ``sat`` is stuck on city (profiled with ``perf``; CPU seconds, the wall time was about
three times as long on the loaded machine):

- with the connectivity propagator attached (CaDiCaL 1.9.5's IPASIR-UP, not lazy), 78 % of
  the time is CaDiCaL's ``explain_external_propagations``/``explain_reason``: before every
  conflict analysis it walks the whole implication cone back to the decisions, which on
  the support encoding (arc consistency chains across the grid) is most of the trail. A
  no-op propagator observing nothing is as slow (2,000 conflicts in 23 CPU seconds, no
  restart); without a propagator CaDiCaL made 5,100 conflicts in 9.4 s. CaDiCaL 3.0 has
  the option ``exteagerreasons=0`` (reasons only when needed), but pysat's ``cadical300``
  took 12 CPU seconds for a 0-conflict answer (connectivity alone) unless ``fastelim``,
  ``inprocessing`` and the other preprocessing are switched off (then 0.2 s); so set, it
  made 12,600 conflicts in 17 CPU seconds with the propagator, without an answer in 25 s;
- without the propagator (the cut loop alone) the profile is dominated by inprocessing
  (SCC decomposition, watch flushing, subsumption, probing, elimination over 2.6 M
  clauses) and its allocations; with ``inprocessing=0`` 30,000 conflicts in 10 s and no
  model meeting the count; on a quieter machine (CPU time = wall time) the cut loop with
  uniform phases added 49 cuts in 30 s (16,900 conflicts) without an answer, the
  propagator 5,172 exclusions (3,622 conflicts) without one either;
- the count is hard by itself: CaDiCaL decides the set literals ``y`` true by default
  (with background phases on the labels only, connectivity alone put all 11,552 possible
  cells in the set), and with background phases on both the adder found no model of "at
  least 800" in 20 s, nor with background outside a box of 1,183 cells (uniform phases:
  1.0 s, with 2,052 cells in 34 components); pysat's ``kmtotalizer`` and ``cardnetwrk``
  (3.5 M and 4.9 M constraint clauses) found none for [800, 4800] with background
  phases in 20 s (uniform phases: 10.9 and 12.1 s, after 15-16 s of building);
- reason clauses were the boundary of the whole region (1,289 literals); they are now the
  walls of the stray pocket when fewer (median 50 literals): correct, but not what limits
  the search.

So a connected object of 800 cells (one building in City) is what CDCL does not find; the
catalog solver finds it by growing one object under the count's propagation.

``asp`` (``--cases city pipes --solvers asp --time-limit 60``, load average 5.7--6.6):
pipes solved in 5.72 s (reference 4.64 s), 0 conflicts, where it timed out before the
counts became cardinality rules, connectivity got a fixed root and the label atoms are
decided first (same run set-up: timeout at 60 s, reference 5.31 s); city still times out
(reference 14.76 s; before 21.90 s). See :mod:`csplab.solvers.asp`, "Global constraints".

``asp`` now starts from the seeded Alg. 3.1 solution by default under global constraints,
loads only the forward supports then, and defines "in the set" by one rule per cell
(``--solvers asp asp+catalog --time-limit 35``, one session, 2-core machine shared with
other jobs). Before, load average 2.9--3.1: city asp timeout (35.35 s; reference 12.36 s),
asp+catalog 19.34 s (8.74 s); pipes asp 3.74 s (2.25 s), asp+catalog 7.57 s (2.30 s).
After, load 2.9--3.3: city asp 7.56 s (reference with random signs 10.16 s), asp+catalog
5.88 s (4.89 s); pipes asp 5.74 s (2.45 s), asp+catalog 6.31 s (1.29 s); at load 5.2--5.5:
city 8.10 s (12.57 s) and 7.87 s (4.75 s), pipes 8.71 s (2.65 s) and 8.44 s (1.78 s); all
valid, 0 conflicts. On the pipes the start costs: Alg. 3.1 takes about 2 CPU seconds a run
at 128x128 and its min-entropy runs fail about half of the time.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


ROOT = Path(__file__).resolve().parents[1]
TARGET = {"catalog": 10.0, "sat": 10.0, "sat+catalog": 10.0, "asp": 10.0,
          "asp+catalog": 10.0, "cpsat": 30.0}  # fmt: skip
#: ``SOLVER+catalog``: the solver started from a seeded Alg. 3.1 solution (sat's
#: ``choice="catalog"`` phases, asp's ``diversity="catalog"`` preferred labels; cpsat's
#: default hint is the same)
VARIANT = {"sat+catalog": {"choice": "catalog"}, "asp+catalog": {"diversity": "catalog"}}


def city(size: tuple[int, ...] = (40, 40, 10)) -> tuple[Any, Any]:
    from csplab.testing.synthetic import connected_city

    return connected_city(size)


def pipes(size: tuple[int, ...] = (128, 128)) -> tuple[Any, Any]:
    import csplab.examples
    from csplab.constraints import parse_constraints

    P = csplab.examples.load_model(ROOT / "tests" / "io" / "data" / "pipes.xml").problem(size)
    cons = [
        {"type": "connected", "labels": ["line", "corner", "tee", "cross"]},
        {"type": "count", "labels": ["cross"], "min": 0, "max": 2},
    ]
    return P, P.with_constraints(parse_constraints(cons, P))


CASES = {"city": (city, "city 40x40x10, connected + count"),
         "pipes": (pipes, "pipes (knot) 128x128, one network + at most 2 crossings")}  # fmt: skip


def run(
    problem: Any, solver: str, seed: int, limit: float, order: str | None = None
) -> tuple[str, float, bool, str]:
    """Status, seconds, validity (re-checked here) and a note of the run's figures
    (``catalog``: its defaults and ``restarts=50``, or the ``order`` given)."""
    import csplab

    kw: dict[str, Any] = {"restarts": 50} if solver == "catalog" else {}
    if solver == "catalog" and order is not None:
        kw["order"] = order
    kw.update(VARIANT.get(solver, {}))
    t = time.perf_counter()
    r = csplab.solve(problem, solver.partition("+")[0], rng=seed, time_limit=limit, **kw)
    dt = time.perf_counter() - t
    ok = r.status == "solved" and r.grid is not None and not problem.violations(r.grid)
    keys = ("order", "attempts", "constraint_probes", "cuts", "conflicts", "choice",
            "probe_conflicts")
    note = ", ".join(f"{k} {r.stats[k]}" for k in keys if k in r.stats)
    return r.status, dt, ok, note


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--solvers", nargs="+", default=list(TARGET), choices=list(TARGET))
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument(
        "--catalog-order",
        default=None,
        help="order of the catalog solver for every case (default: its own, auto)",
    )
    args = ap.parse_args()

    from csplab.solvers import available_solvers

    have = {s["name"] for s in available_solvers() if s["installed"]}
    small = {"city": (6, 6, 4), "pipes": (8, 8)}
    for case in args.cases:
        build, title = CASES[case]
        print(f"== {title}", flush=True)
        P, Q = build()
        for solver in args.solvers:
            if solver.partition("+")[0] not in have:
                print(f"  {solver:11s} not installed")
                continue
            order = args.catalog_order
            run(build(small[case])[1], solver, args.seed, args.time_limit, order)  # warm: JIT
            ref = run(P, solver, args.seed, args.time_limit, order)
            st, dt, ok, note = run(Q, solver, args.seed, args.time_limit, order)
            target = TARGET[solver]
            verdict = (
                "meets" if ok and dt <= target
                else f"shortfall: {dt / target:.1f}x the {target:.0f} s target"
                if ok else f"shortfall: {st}, no valid output"
            )  # fmt: skip
            how = f" [{note}]" if note else ""
            print(
                f"  {solver:11s} constrained {st:8s} {dt:7.2f} s  valid={ok}{how}  "
                f"(reference without constraints: {ref[0]} {ref[1]:.2f} s; "
                f"load {os.getloadavg()[0]:.1f})  target <= {target:.0f} s: {verdict}",
                flush=True,
            )


if __name__ == "__main__":
    main()
