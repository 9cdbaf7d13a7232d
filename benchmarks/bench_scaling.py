"""Benchmark: time and peak memory against output size, 10^4 ... 10^7 cells.

For each method the same model is synthesized at 100x100, 316x316, 1000x1000 and 3162x3162
cells (10^4 ... 10^7), each size in a fresh process so that its peak memory
(``ru_maxrss``) is its own; the kernels are compiled (or loaded from the cache) and warmed up on
a small problem before the timed run. Methods:

* ``catalog`` -- Alg. 3.1 on ``fig3_16`` (thesis Fig. 3.16, infallible: one run always
  succeeds), scanline order;
* ``blocks0`` -- Alg. 3.4 in 20x20 blocks on ``fig3_10`` (Fig. 3.10), the thesis' sweep (the
  default, one compiled kernel);
* ``blocks1`` / ``blocks2`` -- the same with the wave schedule in-process and on two worker
  processes (same output);
* ``overlapping`` -- the WFC overlapping model of ``tests/io/data/sample.png`` (N=3, periodic
  input, min-entropy order, weighted choice: its defaults), ``catalog`` with up to 10 restarts.

Each row prints the wall time of the solve (problem building reported separately), the time
per cell in microseconds, its ratio to the 10^4 run of the same method (the in-process
reference: "time per cell roughly constant" means ratios near 1), whether the output is
valid (``Problem.violations``), and the peak memory. Target (performance issue): time per
cell roughly constant from 10^4 to 10^7 cells for catalog and blocks. Timings are printed,
never asserted.

Usage::

    python benchmarks/bench_scaling.py [--max-exp 7]
        [--methods catalog blocks0 blocks1 blocks2 overlapping]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

from csplab.grids import from_example

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

ROOT = Path(__file__).resolve().parents[1]
SIDES = {4: 100, 5: 316, 6: 1000, 7: 3162}
METHODS = {
    "catalog": ("fig3_16", "catalog", {}),
    "blocks0": ("fig3_10", "blocks", {"block": 20}),
    "blocks1": ("fig3_10", "blocks", {"block": 20, "workers": 1}),
    "blocks2": ("fig3_10", "blocks", {"block": 20, "workers": 2}),
    "overlapping": (str(ROOT / "tests/io/data/sample.png"), "catalog", {"restarts": 10}),
}


def _child(method: str, side: int, seed: int) -> None:
    """In a fresh process: warm up, build, solve, check; print one JSON line."""
    from csplab import Problem
    from csplab.examples import load_model
    from csplab.solvers import solve

    spec, solver, opts = METHODS[method]
    model = load_model(spec)

    def problem(n: int) -> Problem:
        if hasattr(model, "problem"):  # a rule set (the overlapping model)
            return model.problem((n, n))
        return from_example(model, (n, n))

    from csplab.engine.alg31 import jit_warmup

    jit_warmup()  # the kernels (a 24x24 warm-up alone would run interpreted)
    solve(problem(24), solver, rng=0, **{**opts, "workers": 1} if "workers" in opts else opts)
    t0 = time.perf_counter()
    P = problem(side)
    t1 = time.perf_counter()
    r = solve(P, solver, rng=seed, **opts)
    t2 = time.perf_counter()
    valid = r.ok and len(P.violations(r.grid)) == 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # MiB
    print(json.dumps({"build_s": t1 - t0, "solve_s": t2 - t1, "status": r.status,
                      "valid": valid, "peak_mb": peak, "K": P.K}))  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max-exp", type=int, default=7, choices=[4, 5, 6, 7])
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--child", nargs=2, metavar=("METHOD", "SIDE"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        _child(a.child[0], int(a.child[1]), a.seed)
        return
    print(
        "cells       method        K   build s   solve s   us/cell  ratio  status  valid  peak MB"
    )
    for method in a.methods:
        ref = None
        for e in range(4, a.max_exp + 1):
            side = SIDES[e]
            out = subprocess.run(
                [sys.executable, __file__, "--child", method, str(side), "--seed", str(a.seed)],
                capture_output=True, text=True, check=False,
            )  # fmt: skip
            if out.returncode != 0 or not out.stdout.strip():
                print(f"{side * side:>10,}  {method:<12} error: {out.stderr.strip()[-300:]}")
                continue
            d = json.loads(out.stdout.strip().splitlines()[-1])
            us = 1e6 * d["solve_s"] / (side * side)
            ref = ref or us
            print(
                f"{side * side:>10,}  {method:<12} {d['K']:>3} {d['build_s']:>9.2f} "
                f"{d['solve_s']:>9.2f} {us:>9.3f} {us / ref:>6.2f}  {d['status']:<7} "
                f"{'yes' if d['valid'] else 'NO':<5} {d['peak_mb']:>8.0f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
