"""Benchmark: the WFC overlapping model, time per valid output at 48x48 and 200x200.

The model is ``tests/io/data/sample.png`` read as an overlapping model (N=3, periodic input,
its 69 patterns: inside the 40-170 patterns of the issue's figures), solved with ``catalog``
and the overlapping defaults (minimum entropy, weighted choice: WFC's own). Per size it runs
as many seeds as fit in ``--seconds`` (after one warm-up run) and prints the runs, the valid
outputs (checked with ``Problem.violations``) and the wall time per valid output (failed runs
count: that is what a user waits for), with the in-process reference run: the same problem in
scanline order (the thesis' order, no entropy maintenance), and their ratio.

Targets (performance issues 16 and 29): <= 6 ms per valid output at 48x48 (>= 2x fast-wfc's
12-26 ms) and <= 0.3 s at 200x200. Each target line says "meets" or the shortfall. Issue 29
item 1 asks for >= 2x fast-wfc per valid 48x48 output (N=3, periodic input, 8 symmetries)
against its quoted figures City 5.6 ms, Rooms 15.0 ms, Knot 13.9 ms, and >= 3x at 200x200,
where neither issue quotes an absolute fast-wfc figure (issue 29 only ratios: csplab 2.7x on
City, 5.3x on Qud); issue 16 pairs its 0.3 s target with ">= 3x fast-wfc", so 0.9 s is the
200x200 figure used here. Those samples are not in the repository (WaveFunctionCollapse's
sample pictures), and fast-wfc is on no package registry, so this sample's time is set
against the quoted figures: a comparison across samples of 40-170 patterns, not a run of
fast-wfc. CPU time per valid output is printed beside the wall time (the machine is shared:
its load average is printed too).

``--split`` first prints where the time of one small output goes (issue 29, item 1: measure
before optimising): reading the sample and extracting its patterns, building the problem,
the first solve (loading the compiled kernels), and per output the compiled Alg. 3.1 kernel
against everything around it (``solve``'s Python: rng, arrays, result), from a profile of
``--split-runs`` seeded runs at 48x48. The machine's load average is printed with it.

Measured (``results/overlapping.md``, a shared 2-core machine, CPU time per valid output):
48x48 3.66 ms after the kernel changes of issue 29 round three (4.57 ms before, load average
6); after round four (a two-word propagation loop compiled with its word count constant,
no reference counting in Alg. 3.1's step loop) 2.59-2.68 ms against 3.43-3.51 ms for the
commit before, interleaved runs at load average 2.7-3.8: City (<= 2.80 ms) meets with
2.09-2.16x, Rooms 5.60-5.78x, Knot 5.19-5.36x; 200x200 60.4-61.3 ms (77.8-83.4 before).
Idle (load average 0.6-0.8): 48x48 2.57 ms, City 2.18x, Rooms 5.85x, Knot 5.42x; 200x200
57.9 ms, 15.5x.

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
#: fast-wfc's seconds per valid output quoted by issue 29 (48x48) and implied by issue 16's
#: "<= 0.3 s (>= 3x fast-wfc)" (200x200), with the speed-up each target asks for
FAST_WFC = {48: ({"City": 0.0056, "Rooms": 0.0150, "Knot": 0.0139}, 2.0),
            200: ({"issue 16: 0.3 s = 3x": 0.9}, 3.0)}  # fmt: skip


def _per_valid(P: object, order: str, seconds: float) -> tuple[int, int, float, float]:
    """Runs, valid outputs, wall and CPU seconds per valid output."""
    from csplab.solvers import solve

    solve(P, "catalog", rng=0, order=order, choice="weighted")  # warm-up
    runs = valid = 0
    wall = cpu = 0.0  # of the solve calls (each checks its grid); the bench's check is extra
    while wall < seconds or valid == 0:
        t, c = time.perf_counter(), time.process_time()
        r = solve(P, "catalog", rng=runs + 1, order=order, choice="weighted")
        wall += time.perf_counter() - t
        cpu += time.process_time() - c
        runs += 1
        valid += int(r.ok and len(P.violations(r.grid)) == 0)  # type: ignore[attr-defined]
        if runs > 10_000:
            break
    return runs, valid, wall / max(valid, 1), cpu / max(valid, 1)


def verdict(t: float, target: float) -> str:
    """``meets`` or the shortfall of ``t`` seconds against ``target`` seconds.

    Examples
    --------
    >>> verdict(0.005, 0.006)
    'meets'
    >>> verdict(0.009, 0.006)
    'misses by 3.00 ms (1.50x the target)'
    """
    if t <= target:
        return "meets"
    return f"misses by {1000 * (t - target):.2f} ms ({t / target:.2f}x the target)"


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
        if name in ("alg31", "alg31_flat") and path.endswith("_kernels.py")
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
    import os

    from csplab.examples import load_model

    model = load_model(a.sample)
    print(f"{Path(a.sample).name}: overlapping model, K={model.K} patterns; load average "  # type: ignore[union-attr]
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")  # fmt: skip
    print("size      order         runs  valid  per valid: wall       cpu   ref (scanline) "
          "wall/cpu   ratio")  # fmt: skip
    for side, target in TARGETS.items():
        P = model.problem((side, side))  # type: ignore[union-attr]
        runs, valid, t, c = _per_valid(P, "min-entropy", a.seconds)
        _, _, rt, rc = _per_valid(P, "scanline", a.seconds)
        print(
            f"{side}x{side:<5} min-entropy {runs:>6} {valid:>6} {1000 * t:>12.2f} ms "
            f"{1000 * c:>6.2f} ms {1000 * rt:>8.2f}/{1000 * rc:.2f} ms {t / rt:>7.2f}",
            flush=True,
        )
        print(f"  target <= {1000 * target:g} ms per valid output: {verdict(t, target)} "
              f"(wall {1000 * t:.2f} ms; cpu {1000 * c:.2f} ms: {verdict(c, target)})")  # fmt: skip
        figures, times = FAST_WFC[side]
        for name, fw in figures.items():
            need = fw / times
            print(f"  target >= {times:g}x fast-wfc {name} ({1000 * fw:g} ms, so <= "
                  f"{1000 * need:.2f} ms): {fw / t:.2f}x, {verdict(t, need)} (cpu: "
                  f"{fw / c:.2f}x, {verdict(c, need)})")  # fmt: skip


if __name__ == "__main__":
    main()
