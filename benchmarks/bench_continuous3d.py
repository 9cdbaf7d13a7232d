"""Benchmark: continuous model synthesis in 3D on the built-in polyhedral examples, against
Table 1 of the 2008 paper.

For each built-in example (:mod:`csplab.examples.continuous3d`) it prints the paper's Table 1
row (input polygons, output polygons, minutes) next to csplab's: the input polygons
(``n_polygons``), and for the region sizes searched upwards (10x10x6, 14x14x6, 20x20x8, ...
plane spacings) until the output has at least the paper's number of polygons or a run takes
longer than ``--cap`` seconds, the output polygons and solids and the time of each phase of
:func:`~csplab.continuous.synthesis.synthesize` with ``catalog`` (restarts allowed):
building the CSP, solving, geometry (the output solids), checking (the independent checker).
A size whose predicted time (the last one's, scaled by the volume) is beyond twice the cap
is not run.

Target (continuous 3D issue): at least the paper's output size in at most 1/10 of its time
(skyscrapers >= 9,542 output polygons in <= 10.8 s, terrain >= 922 in <= 3 s, ...); the
last column says whether the first size reaching the paper's output size meets it. The time
compared is the end-to-end time (all four phases). Finally the peak memory (``ru_maxrss`` of
a fresh process) of a 40x40x20 ``blocks`` synthesis of the example with the most plane families
(ties: the most vertices)
(target < 2 GB). Timings are printed, never asserted.

Usage::

    python benchmarks/bench_continuous3d.py [--cap 60] [--examples houses] [--no-memory]
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from csplab.experiments.table1_continuous import PAPER_TABLE1

SIZES = [
    (10, 10, 6),
    (14, 14, 6),
    (20, 20, 8),
    (30, 30, 10),
    (40, 40, 12),
    (60, 60, 14),
    (80, 80, 16),
]
MEMORY_SIZE = (40, 40, 20)
MEMORY_TARGET_GB = 2.0
RESTARTS = 10


def _fmt(size: tuple[int, ...]) -> str:
    return "x".join(str(n) for n in size)


def _run(name: str, size: tuple[int, ...], seed: int, solver: str = "catalog") -> Any:
    from csplab.continuous.synthesis import synthesize
    from csplab.examples.continuous3d import load_polyhedral_example

    E = load_polyhedral_example(name)
    restarts = RESTARTS if solver == "catalog" else 0
    return synthesize(E, size, solver=solver, rng=seed, restarts=restarts)


def _memory_child(name: str) -> None:
    """In a fresh process: one 40x40x20 synthesis (``blocks``: at this size ``catalog``
    may fail on the examples with many families), then print the figures and peak RSS."""
    t = time.perf_counter()
    s = _run(name, MEMORY_SIZE, 0, solver="blocks")
    total = time.perf_counter() - t
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    polys = s.model.n_polygons if s.model is not None else 0
    phases = " ".join(f"{k} {v:.1f}" for k, v in s.times.items())
    print(
        f"blocks {s.result.status} polygons {polys} violations {len(s.violations)} "
        f"vertices {s.csp.problem.meta['vertices']} edges {s.csp.problem.meta['edges']} "
        f"time {total:.1f} s ({phases}) peak_kb {peak_kb}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    ap.add_argument("--cap", type=float, default=60.0, help="time cap per run (s)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--examples", nargs="+", default=None)
    ap.add_argument("--no-memory", action="store_true")
    ap.add_argument("--memory-child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_child:
        _memory_child(args.memory_child)
        return

    t0 = time.perf_counter()
    from csplab.continuous.csp3d import ContinuousCSP3
    from csplab.engine.alg31 import jit_warmup
    from csplab.examples.continuous3d import load_polyhedral_example, polyhedral_example_names

    print(f"import {time.perf_counter() - t0:.2f} s, JIT warm-up {jit_warmup():.2f} s")
    _run("tetrahedron", (4, 4, 3), 0)  # warm the solver and geometry paths
    print(
        f"solver catalog (restarts {RESTARTS}), seed {args.seed}; times in seconds; "
        "fam = plane families (incl. the region's sides); e2e = csp + solve + geometry + "
        "check; paper: Table 1 (input polygons, output polygons, time)"
    )
    header = (
        f"{'example':<12} {'paper in/out/time':>20} {'in':>3} {'fam':>3} {'size':>9}"
        f" {'vertices':>8} {'out poly':>8} {'solids':>6} {'csp':>6} {'solve':>6}"
        f" {'geom':>6} {'check':>6} {'e2e':>6} {'viol':>4}  target"
    )
    print(header)
    print("-" * len(header))
    names = args.examples or polyhedral_example_names()
    most: tuple[int, str] = (-1, "")
    heaviest = (-1, -1)  # (families, vertices of a 4x4x4 region): the largest arrangement
    for name in names:
        E = load_polyhedral_example(name)
        A = ContinuousCSP3(E, (4, 4, 4)).arrangement
        fam = A.F
        if (A.F, A.n_vertices) > heaviest:
            heaviest, most = (A.F, A.n_vertices), (A.F, name)
        paper = PAPER_TABLE1.get(name)
        if paper is None:
            paper_s = f"{'(Fig. 8/9 only)':>20}"
        else:
            paper_s = f"{paper[0]:>3}/{paper[1]:>6,}/{paper[2]:>4.1f} min"
        last: tuple[int, float] | None = None  # (volume, e2e) of the previous size
        verdict_done = False
        for size in SIZES:
            vol = size[0] * size[1] * size[2]
            if last is not None and last[1] * vol / last[0] > 2 * args.cap:
                print(
                    f"{'':<12} {'':>20} {'':>3} {'':>3} {_fmt(size):>9}  not run: predicted "
                    f"{last[1] * vol / last[0]:.0f} s > 2 x cap"
                )
                break
            s, e2e = None, 0.0
            t = time.perf_counter()
            s = _run(name, size, args.seed)
            e2e = time.perf_counter() - t
            tm = s.times
            polys = s.model.n_polygons if s.model is not None else 0
            solids = len(s.model) if s.model is not None else 0
            verdict = ""
            if paper is None:
                verdict = "n/a"
            elif polys >= paper[1] and not verdict_done:
                budget = paper[2] * 60 / 10
                ok = e2e <= budget and s.ok
                verdict = f"{'MEETS' if ok else 'misses'} ({e2e:.1f} s vs <= {budget:.1f} s)"
                verdict_done = True
            elif s.result.status != "solved":
                verdict = f"catalog {s.result.status}"
            print(
                f"{name:<12} {paper_s} {E.n_polygons:>3} {fam:>3} {_fmt(size):>9}"
                f" {s.csp.problem.meta['vertices']:>8} {polys:>8,} {solids:>6}"
                f" {tm['csp']:>6.2f} {tm['solve']:>6.2f} {tm['geometry']:>6.2f}"
                f" {tm['check']:>6.2f} {e2e:>6.2f} {len(s.violations):>4}  {verdict}",
                flush=True,
            )
            last = (vol, e2e)
            if paper is None or polys >= paper[1] or e2e > args.cap:
                if paper is not None and polys < paper[1]:
                    print(
                        f"{'':<12} {'':>20}  stopped: {e2e:.0f} s > cap {args.cap:.0f} s "
                        f"before reaching {paper[1]:,} polygons; target missed"
                    )
                break
    if args.no_memory or not most[1]:
        return
    print(
        f"\npeak memory: {most[1]} ({most[0]} plane families) at {_fmt(MEMORY_SIZE)}, a fresh "
        "process (ru_maxrss)",
        flush=True,
    )
    out = subprocess.run(
        [sys.executable, __file__, "--memory-child", most[1]],
        capture_output=True,
        text=True,
        check=False,
    )
    line = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else out.stderr[-500:]
    print(f"  {line}")
    if "peak_kb" in line:
        gb = int(line.rsplit(" ", 1)[1]) / 1024**2
        verdict = "meets" if gb < MEMORY_TARGET_GB else "MISSES"
        print(f"  peak {gb:.2f} GB: {verdict} the < {MEMORY_TARGET_GB:g} GB target")


if __name__ == "__main__":
    main()
