"""Issue 26 cross-check: >= 10^5 random Alg. 3.1 runs per proved model, affordable.

    python benchmarks/bench_infallibility_runs.py [--runs N] [MODEL[@BOUNDARY][:ORDER] ...]

For each model setting, in this process, per output size of the experiment's fixed mix
(:data:`csplab.experiments.infallibility.RUN_MIX`): the CPU cost of one run through
``solve(P, "catalog")`` (the reference: what each run cost before, solver dispatch and
``Problem.violations`` included), of the engine alone
(:func:`~csplab.engine.alg31.run_alg31`, what the experiment calls now) and of the check
(:meth:`Problem.violations`), each the mean over runs adding up to about 0.2 s. Then the
CPU seconds of 10^5 runs, estimated from those costs, for the mix now and for the previous
schedule (6 sizes round-robin, through ``solve``), each with "meets" or the shortfall
against the bound of 10 min on one core per model. With ``--runs N`` the experiment's
:func:`~csplab.experiments.infallibility.random_runs` also runs N times for real and its
measured CPU per run is printed beside the estimate. CPU seconds of this thread: the
machine is shared, and wall clock would count the waits.
"""

from __future__ import annotations

import argparse
import time
import warnings
from typing import Any

import numpy as np

from csplab.analysis.witness import model_problem
from csplab.engine.alg31 import jit_warmup, run_alg31
from csplab.example import ExampleModel
from csplab.experiments.base import load_examples
from csplab.experiments.infallibility import RUN_MIX, RUNS_TARGET, random_runs
from csplab.grids import parse_boundary
from csplab.solvers import solve

DEFAULT = ["fig3_10@auto", "fig3_1a:scan:yx", "loops@auto", "pillar@auto", "pillar",
           "tests/io/data/pipes.xml", "tests/io/data/pipes3d.xml",
           "tests/io/data/tiny_poms.json"]  # fmt: skip
# the schedule before: these sizes round-robin, one solve() each
PREVIOUS = {
    2: [(2, 2), (3, 3), (5, 5), (8, 8), (16, 16), (40, 40)],
    3: [(2, 2, 2), (3, 3, 3), (5, 5, 5), (8, 8, 10), (16, 16, 10), (40, 40, 10)],
}
BOUND = 600.0  # CPU seconds per model on one core


def per_run(fn: Any, budget: float = 0.2, most: int = 2000) -> float:
    """Mean CPU seconds of ``fn(i)`` over runs adding up to about ``budget`` s."""
    c0, i = time.thread_time(), 0
    while i < most and (i < 3 or time.thread_time() - c0 < budget):
        fn(i)
        i += 1
    return (time.thread_time() - c0) / i


def setting(spec: str) -> tuple[str, str, str]:
    spec, _, order = spec.partition(":")
    name, _, bnd = spec.partition("@")
    return name, bnd or "none", order or "scanline"


def main(specs: list[str], runs: int) -> int:
    jit_warmup()
    worst_new = total_new = 0.0
    for spec in specs:
        name, bname, order = setting(spec)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ((_, E),) = load_examples([name], tilesets=True)
        auto = bname == "auto" or not isinstance(E, ExampleModel)
        bnd = parse_boundary("auto") if auto else None
        cost: dict[tuple[int, ...], tuple[float, float, float]] = {}
        sizes = [s for s, _ in RUN_MIX[E.ndim]] + PREVIOUS.get(E.ndim, [])
        print(f"\n{name} boundary {'auto' if auto else 'none'} order {order}")
        print(f"  {'size':>9} {'solve() ms':>10} {'engine ms':>9} {'violations ms':>13}")
        for s in dict.fromkeys(sizes):
            P = model_problem(E, s, bnd)
            grid = run_alg31(P, np.random.default_rng(0), order=order).grid
            sv = per_run(lambda i, P=P, o=order: solve(P, "catalog", rng=i, order=o))
            en = per_run(lambda i, P=P, o=order: run_alg31(P, np.random.default_rng(i), order=o))
            vi = per_run(lambda i, P=P, g=grid: P.violations(g))
            cost[s] = (sv, en, vi)
            print(f"  {'x'.join(map(str, s)):>9} {sv * 1e3:10.3f} {en * 1e3:9.3f} "
                  f"{vi * 1e3:13.3f}")  # fmt: skip
        new = sum(w / 100 * RUNS_TARGET * (cost[s][1] + cost[s][2]) for s, w in RUN_MIX[E.ndim])
        prev = PREVIOUS.get(E.ndim, [])
        old = sum(RUNS_TARGET / len(prev) * cost[s][0] for s in prev) if prev else float("nan")
        worst_new, total_new = max(worst_new, new), total_new + new
        verdict = "meets" if new <= BOUND else f"shortfall {new - BOUND:.0f} s"
        print(f"  10^5 runs, estimated CPU: now (mix, engine + violations) {new:.1f} s: "
              f"{verdict} (bound {BOUND:.0f} s); before (6 sizes round-robin, solve()) "
              f"{old:.1f} s")  # fmt: skip
        if runs:
            out = random_runs(E, order, "auto" if auto else None, runs=runs, seed=0,
                              time_limit=BOUND)  # fmt: skip
            got = out["runs_cpu_s"] / max(out["runs_done"], 1) * 1e3
            print(f"  random_runs: {out['runs_done']} runs, {out['failed']} failed, "
                  f"{out['invalid']} invalid, {out['runs_cpu_s']:.1f} s CPU = {got:.3f} "
                  f"ms/run (estimate {new / RUNS_TARGET * 1e3:.3f} ms/run)")  # fmt: skip
    print(f"\nall {len(specs)} settings: {total_new:.0f} s CPU estimated for 10^5 runs each; "
          f"slowest {worst_new:.0f} s: " + ("meets" if worst_new <= BOUND else "shortfall")
          + f" (bound {BOUND:.0f} s per model)")  # fmt: skip
    return 0


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="*", default=DEFAULT)
    ap.add_argument("--runs", type=int, default=0, help="also run random_runs this many times")
    a = ap.parse_args()
    raise SystemExit(main(a.models, a.runs))
