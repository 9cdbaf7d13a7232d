"""Benchmark: continuous model synthesis (thesis Alg. 4.1) on the built-in polygon examples.

Prints, per example and region size (in line spacings), the time of each phase: building the
arrangement and the vertex/edge states (``ContinuousCSP(...)``), solving (per solver: Alg. 3.1
``catalog``, ``blocks`` with 10x10 blocks, ``sat``), turning the solution into polygons
(``C.model(grid)``) and, when :mod:`csplab.continuous.check` exists, checking Eq. 4.1 on the
output. It also prints the arrangement's vertices, edges and edge directions (families), and
the end-to-end ``catalog`` time per vertex, with its ratio against the 40x40 run of the same
example in the same process (a ratio near 1 means time is linear in the number of vertices).
Solve times are medians over ``--seeds`` seeds (failed runs included; the success count is
printed); ``sat`` runs once with a 30 s limit at sizes above 40x40 and is reported as
skipped if it hits it.

Target (continuous synthesis issue): a 100x100-spacing region with up to 5 directions in under
2 s end to end (build + catalog solve + geometry) with ``catalog``; the last column says whether
each example meets it (an example on which catalog fails cannot meet it with catalog; its
``blocks`` end-to-end time is shown instead in brackets).

Usage::

    python benchmarks/bench_continuous.py [--seeds 3] [--sizes 40 100] [--examples triangle]
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

TARGET_S = 2.0
TARGET_SIZE = 100
TARGET_DIRS = 5
SAT_LIMIT_S = 30.0


def _timed(f: Any, *a: Any, **k: Any) -> tuple[Any, float]:
    t = time.perf_counter()
    out = f(*a, **k)
    return out, time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--sizes", type=int, nargs="+", default=[40, 100])
    ap.add_argument("--examples", nargs="+", default=None)
    args = ap.parse_args()

    t0 = time.perf_counter()
    from csplab.continuous.csp import ContinuousCSP
    from csplab.engine.alg31 import jit_warmup
    from csplab.examples.continuous import continuous_example_names, load_polygon_example
    from csplab.solvers import solve

    have_check = importlib.util.find_spec("csplab.continuous.check") is not None
    check: Any = None
    if have_check:
        from csplab.continuous.check import violations as check

    print(f"import {time.perf_counter() - t0:.2f} s, JIT warm-up {jit_warmup():.2f} s")
    warm = ContinuousCSP(load_polygon_example("triangle"), (6, 6))  # warm every solver path
    for s in ("catalog", "blocks", "sat"):
        solve(warm.problem, s, rng=0, **({"block": 10} if s == "blocks" else {}))
    print(f"checker: {'csplab.continuous.check.violations' if have_check else 'not available'}")
    print("times in seconds; solve = median over seeds (ok = solved/seeds); e2e = build + "
          "catalog + geometry; us/v = e2e per arrangement vertex (microseconds)")  # fmt: skip
    header = (
        f"{'example':<14} {'size':>7} {'dirs':>4} {'verts':>7} {'edges':>7} {'build':>6}"
        f" {'catalog':>7} {'ok':>5} {'blocks':>6} {'ok':>5} {'sat':>6} {'geom':>6}"
        f" {'check':>6} {'e2e':>6} {'us/v':>6} {'vs 40':>5}  target"
    )
    print(header)
    print("-" * len(header))
    names = args.examples or continuous_example_names()
    for name in names:
        E = load_polygon_example(name)
        ref_per_vertex: float | None = None
        for n in args.sizes:
            C, t_build = _timed(ContinuousCSP, E, (n, n))
            A = C.arrangement
            ndirs = int((~A.boundary_only).sum())  # the example's directions (not the sides')
            cat = [solve(C.problem, "catalog", rng=s) for s in range(args.seeds)]
            blk = [solve(C.problem, "blocks", rng=s, block=10) for s in range(args.seeds)]
            t_cat = statistics.median(r.time_s for r in cat)
            t_blk = statistics.median(r.time_s for r in blk)
            ok_cat = sum(r.status == "solved" for r in cat)
            ok_blk = sum(r.status == "solved" for r in blk)
            limit: dict[str, Any] = {} if n <= 40 else {"time_limit": SAT_LIMIT_S}
            r_sat = solve(C.problem, "sat", rng=0, **limit)
            sat_s = f"{r_sat.time_s:>6.2f}" if r_sat.status == "solved" else f"{'skip':>6}"
            good = next((r for r in cat if r.status == "solved"), None)
            via = good or next((r for r in blk if r.status == "solved"), None)
            t_geom = t_check = float("nan")
            if via is not None:
                M, t_geom = _timed(C.model, via.grid)
                if check is not None:
                    v, t_check = _timed(check, E, M)
                    if len(v):
                        print(f"  !! {name} {n}x{n}: {len(v)} violations of Eq. 4.1")
            e2e = t_build + t_cat + t_geom
            per_v = 1e6 * e2e / A.n_vertices
            if n == 40:
                ref_per_vertex = per_v
            ratio = f"{per_v / ref_per_vertex:>5.2f}" if ref_per_vertex else f"{'-':>5}"
            if n == TARGET_SIZE and ndirs <= TARGET_DIRS:
                if good is not None:
                    verdict = "meets" if e2e < TARGET_S else "MISSES"
                    verdict += f" ({e2e:.2f} s)"
                else:
                    e2e_b = t_build + t_blk + t_geom
                    verdict = f"catalog fails ({ok_cat}/{args.seeds}) [blocks {e2e_b:.2f} s]"
            elif n == TARGET_SIZE:
                verdict = f"n/a ({ndirs} dirs > {TARGET_DIRS})"
            else:
                verdict = ""
            print(
                f"{name:<14} {f'{n}x{n}':>7} {ndirs:>4} {A.n_vertices:>7} {A.n_edges:>7}"
                f" {t_build:>6.2f} {t_cat:>7.3f} {ok_cat:>2}/{args.seeds:<2} {t_blk:>6.2f}"
                f" {ok_blk:>2}/{args.seeds:<2} {sat_s} {t_geom:>6.2f} {t_check:>6.2f}"
                f" {e2e:>6.2f} {per_v:>6.1f} {ratio}  {verdict}",
                flush=True,
            )


if __name__ == "__main__":
    main()
