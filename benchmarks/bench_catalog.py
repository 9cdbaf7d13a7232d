"""Benchmark: Alg. 3.1 (solver ``catalog``) on 40x40x10 models of built-in 3D examples.

Prints, per example: K, the median wall time of a full Alg. 3.1 run from a warm start (JIT
already loaded), the success count, and the ratio against the slow reference implementation
(:func:`csplab.engine.alg31.alg31_reference`, pure Python arc consistency) run in the same
process on the same problems with the same seeds -- at a reduced size, because the reference
would take hours at 40x40x10 -- after checking that both produce identical grids.
The JIT compile (or numba cache load) time of the first call is reported separately.

Target (issue 2): <= 0.35 s for ~60 labels and <= 1.0 s for ~120 labels at 40x40x10,
half of what a mature C++ AC-4 implementation of Alg. 3.1 needs on this class of machine.

Usage::

    python benchmarks/bench_catalog.py [--seeds 21] [--examples castle city] [--boundary auto]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=21)
    ap.add_argument("--examples", nargs="+", default=None)
    ap.add_argument("--size", default="40x40x10")
    ap.add_argument("--ref-size", default="8x8x10", help="size for the reference comparison")
    ap.add_argument("--ref-seeds", type=int, default=3)
    ap.add_argument("--boundary", default="none", choices=["none", "auto"])
    args = ap.parse_args()

    t0 = time.perf_counter()
    import csplab
    import csplab.grids
    from csplab import _kernels as kern
    from csplab.engine.alg31 import alg31_reference, jit_warmup

    t_import = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:  # a cold compile in a fresh numba cache
        code = "from csplab.engine.alg31 import jit_warmup; print(jit_warmup())"
        env = {**os.environ, "NUMBA_CACHE_DIR": tmp, "PYTHONPATH": str(Path(__file__).parents[1])}
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, check=True)  # fmt: skip
        t_cold = float(out.stdout.strip().splitlines()[-1])
    print(f"JIT compile from scratch (empty numba cache): {t_cold:.2f} s")
    t_jit = jit_warmup()
    hits = sum(len(f.stats.cache_hits) for f in (kern.alg31, kern.propagate))
    misses = sum(sum(f.stats.cache_misses.values()) for f in (kern.alg31, kern.propagate))
    print(f"csplab {csplab.__version__}: import {t_import:.2f} s, first call (JIT) {t_jit:.2f} s "
          f"({'loaded from numba cache' if hits and not misses else 'compiled'})")  # fmt: skip

    names = (
        args.examples
        or [n for n in csplab.example_names() if n in ("castle", "city", "towers")][:2]
    )
    size = csplab.grids.parse_shape(args.size)
    rsize = csplab.grids.parse_shape(args.ref_size)
    header = (
        f"{'example':<10} {'K':>4} {'size':>10} {'median s':>9} {'solved s':>9} {'min s':>7}"
        f" {'solved':>7}"
        f" | {'ref size':>8} {'ref s':>8} {'fast s':>8} {'ratio':>7} same"
    )
    print(header)
    print("-" * len(header))
    for name in names:
        E = csplab.load_example(name)
        P = csplab.from_example(E, size, boundary=args.boundary)
        times, solved_times = [], []
        for s in range(args.seeds):
            r = csplab.solve(P, "catalog", rng=s)
            times.append(r.time_s)
            if r.status == "solved":
                solved_times.append(r.time_s)
        ok = len(solved_times)
        med_solved = f"{statistics.median(solved_times):>9.3f}" if solved_times else f"{'-':>9}"
        Pr = csplab.from_example(E, rsize, boundary=args.boundary)
        tr, tf, same = [], [], True
        for s in range(args.ref_seeds):
            a = time.perf_counter()
            st, g = alg31_reference(Pr, np.random.default_rng(s))
            tr.append(time.perf_counter() - a)
            r = csplab.solve(Pr, "catalog", rng=s)
            tf.append(r.time_s)
            same &= st == r.status and (st != "solved" or bool(np.array_equal(g, r.grid)))
        mr, mf = statistics.median(tr), statistics.median(tf)
        print(
            f"{name:<10} {E.K:>4} {args.size:>10} {statistics.median(times):>9.3f} "
            f"{med_solved} {min(times):>7.3f} {ok:>3}/{args.seeds:<3} | {args.ref_size:>8} "
            f"{mr:>8.3f} {mf:>8.4f} {mr / mf:>7.0f} {'yes' if same else 'NO'}"
        )


if __name__ == "__main__":
    main()
