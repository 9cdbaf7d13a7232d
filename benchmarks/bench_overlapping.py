"""Benchmark: the WFC overlapping model, time per valid output at 48x48 and 200x200.

The model is ``tests/io/data/sample.png`` read as an overlapping model (N=3, periodic input,
its 69 patterns: inside the 40-170 patterns of the issue's figures), solved with ``catalog``
and the overlapping defaults (minimum entropy, weighted choice: WFC's own). Per size it runs
as many seeds as fit in ``--seconds`` (after one warm-up run) and prints the runs, the valid
outputs (checked with ``Problem.violations``) and the wall time per valid output (failed runs
count: that is what a user waits for), with the in-process reference run: the same problem in
scanline order (the thesis' order, no entropy maintenance), and their ratio.

Targets (performance issue): <= 6 ms per valid output at 48x48 (>= 2x fast-wfc's 12-26 ms)
and <= 0.3 s at 200x200. Timings are printed, never asserted.

``--split`` first prints where the time of one small output goes (issue 29, item 1: measure
before optimising): reading the sample and extracting its patterns, building the problem,
the first solve (loading the compiled kernels), and per output the compiled Alg. 3.1 kernel
against everything around it (``solve``'s Python: rng, arrays, result), from a profile of
``--split-runs`` seeded runs at 48x48. The machine's load average is printed with it.

Usage::

    python benchmarks/bench_overlapping.py [--seconds 5] [--sample tests/io/data/sample.png]
        [--split] [--split-runs 40]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

ROOT = Path(__file__).resolve().parents[1]
TARGETS = {48: 0.006, 200: 0.3}


def _per_valid(P: object, order: str, seconds: float) -> tuple[int, int, float]:
    from csplab.solvers import solve

    solve(P, "catalog", rng=0, order=order, choice="weighted")  # warm-up
    runs = valid = 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds or valid == 0:
        r = solve(P, "catalog", rng=runs + 1, order=order, choice="weighted")
        runs += 1
        valid += int(r.ok and len(P.violations(r.grid)) == 0)  # type: ignore[attr-defined]
        if runs > 10_000:
            break
    return runs, valid, (time.perf_counter() - t0) / max(valid, 1)


def split(sample: str, runs: int, side: int = 48) -> None:
    """Print where the time of one ``side`` x ``side`` output goes (see the docstring)."""
    import cProfile
    import os
    import pstats
    import statistics

    t = time.perf_counter()
    from csplab.examples import load_model
    from csplab.solvers import solve

    t_import = time.perf_counter() - t
    t = time.perf_counter()
    model = load_model(sample)
    t_extract = time.perf_counter() - t
    t = time.perf_counter()
    P = model.problem((side, side))  # type: ignore[union-attr]
    t_problem = time.perf_counter() - t
    t = time.perf_counter()
    solve(P, "catalog", rng=0, order="min-entropy", choice="weighted")
    t_first = time.perf_counter() - t
    prof = cProfile.Profile()
    walls = []
    for seed in range(1, runs + 1):
        t = time.perf_counter()
        prof.enable()
        solve(P, "catalog", rng=seed, order="min-entropy", choice="weighted")
        prof.disable()
        walls.append(time.perf_counter() - t)
    kernel = sum(
        tt for (path, _, name), (_, _, tt, _, _) in pstats.Stats(prof).stats.items()  # type: ignore[attr-defined]
        if name == "alg31" and path.endswith("_kernels.py")
    )  # fmt: skip
    total = sum(walls)
    print(f"where the time of one {side}x{side} output goes (K={model.K}, load average "  # type: ignore[union-attr]
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs, shared machine):")  # fmt: skip
    print(f"  import {t_import:.3f} s, read + pattern extraction {t_extract:.3f} s, problem "
          f"{1000 * t_problem:.1f} ms, first solve (kernel load) {t_first:.3f} s")  # fmt: skip
    print(f"  per output, {runs} seeds: median {1000 * statistics.median(walls):.2f} ms; compiled "
          f"Alg. 3.1 kernel {100 * kernel / total:.0f}% of it, the rest of solve() "
          f"{1000 * (total - kernel) / runs:.2f} ms per call (profiled)")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--sample", default=str(ROOT / "tests/io/data/sample.png"))
    ap.add_argument("--split", action="store_true", help="first print where the time goes")
    ap.add_argument("--split-runs", type=int, default=40)
    a = ap.parse_args()
    if a.split:
        split(a.sample, a.split_runs)
    from csplab.examples import load_model

    model = load_model(a.sample)
    print(f"{Path(a.sample).name}: overlapping model, K={model.K} patterns")  # type: ignore[union-attr]
    print("size      order         runs  valid   per valid output   ref (scanline)   ratio  target")
    for side, target in TARGETS.items():
        P = model.problem((side, side))  # type: ignore[union-attr]
        runs, valid, t = _per_valid(P, "min-entropy", a.seconds)
        _, _, rt = _per_valid(P, "scanline", a.seconds)
        verdict = "meets" if t <= target else "misses"
        print(
            f"{side}x{side:<5} min-entropy {runs:>6} {valid:>6} {1000 * t:>15.2f} ms "
            f"{1000 * rt:>13.2f} ms {t / rt:>7.2f}  {verdict} (<= {1000 * target:g} ms)",
            flush=True,
        )


if __name__ == "__main__":
    main()
