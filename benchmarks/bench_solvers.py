"""Benchmark: time to a valid 40x40x10 model for every solver on the built-in 3D examples.

For each example (the built-in 3D examples from :func:`csplab.example_names`, or, when there
are none, csplab's synthetic box towns with 56 and 110 labels) and each solver, runs
``--seeds`` seeds and prints the median times split into

* ``encode``: arc consistency + building the CNF / CP-SAT model,
* ``load``: handing the clauses to the SAT solver (the direct CaDiCaL loader or pysat's API),
* ``solve``: the search itself (for ``catalog``/``blocks``/``backtrack``: the whole run),

plus the total (everything the call costs, e.g. also freeing the SAT solver), the ratio of
the total to Alg. 3.1 (``catalog``, run in the same process on the same problems: the
baseline), how many seeds were solved, and the diversity: the mean
fraction of cells that differ between the outputs of two seeds (Hamming distance), with the
fraction of non-empty cells (labels other than the most frequent one) for context.
Solvers that need more than ``--time-limit`` seconds report ``timeout``. The numba JIT
(or its on-disk cache) is loaded before timing.

Usage::

    python benchmarks/bench_solvers.py [--size 40x40x10] [--seeds 3] [--boundary none]
        [--examples city castle] [--solvers catalog sat cpsat ...] [--time-limit 120]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np


def default_solvers() -> list[tuple[str, dict[str, Any]]]:
    """Every registered solver with each option variant it declares in ``bench``
    (``backend`` in a variant selects ``name:backend``)."""
    from csplab.solvers import solver_class, solver_names

    out = []
    for name in solver_names():
        for variant in solver_class(name).bench:
            opts = dict(variant)
            backend = opts.pop("backend", None)
            out.append((f"{name}:{backend}" if backend else name, opts))
    return out


def _label(spec: str, opts: dict[str, Any]) -> str:
    return spec + "".join(f" {k}={v}" for k, v in opts.items())


def _split(r: Any) -> tuple[float | None, float | None, float]:
    """(encode, load, solve) seconds from a Result's stats."""
    s = r.stats
    sub = s.get("sat")
    if "load_s" in s:  # sat
        return float(s["encode_s"]), float(s["load_s"]), float(s.get("solve_s", 0.0))
    if "build_s" in s:  # cpsat: build includes the encoding
        return float(s["build_s"]), None, float(s.get("solve_s", 0.0))
    if isinstance(sub, dict) and "load_s" in sub:  # hybrid / perfect: their SAT oracle
        enc, load = float(sub["encode_s"]), float(sub["load_s"])
        return enc, load, r.time_s - enc - load
    return None, None, float(r.time_s)


def _fmt(x: float | None) -> str:
    return "-" if x is None else f"{x:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="40x40x10")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--boundary", default="none", choices=["none", "auto"])
    ap.add_argument("--examples", nargs="+", default=None)
    ap.add_argument("--solvers", nargs="+", default=None, help="solver specs (default: all)")
    ap.add_argument("--time-limit", type=float, default=120.0, help="seconds per run")
    args = ap.parse_args()

    import csplab
    from csplab.engine.alg31 import jit_warmup
    from csplab.solvers import available_solvers
    from csplab.testing.synthetic import box_town

    t_jit = jit_warmup()
    print(
        f"csplab {csplab.__version__}, JIT/cache load {t_jit:.2f} s, size {args.size}, "
        f"boundary {args.boundary}, {args.seeds} seeds, time limit {args.time_limit} s"
    )

    examples: list[tuple[str, Any]] = []
    for n in args.examples or csplab.example_names():
        if n.startswith("box_town_"):
            examples.append((n, box_town(int(n.rsplit("_", 1)[1]), rng=0)))
            continue
        E = csplab.load_example(n)
        if args.examples or (E.ndim == 3 and min(E.shape) > 1):
            examples.append((n, E))
    if not examples:
        print("(no built-in 3D examples yet: using the synthetic box towns of "
              "csplab.testing.synthetic)")  # fmt: skip
        examples = [(f"box_town_{m}", box_town(m, rng=0)) for m in (2, 4)]
    installed = {s["name"] for s in available_solvers() if s.get("installed")}
    specs = default_solvers()
    if args.solvers:
        specs = [(s, {}) for s in args.solvers]
    specs = [(s, o) for s, o in specs if s.split(":")[0] in installed]

    # warm every solver's compiled code on a tiny problem
    tiny = csplab.from_example(box_town(1, rng=0), (3, 3, 3))
    for spec, opts in specs:
        csplab.solve(tiny, spec, rng=0, **opts)

    head = (f"{'example':<12}{'K':>4}  {'solver':<28}{'solved':>7}{'encode':>8}{'load':>7}"
            f"{'solve':>8}{'total':>8}{'x catalog':>10}{'differ':>8}{'non-empty':>10}")  # fmt: skip
    for name, E in examples:
        P = csplab.from_example(E, args.size, boundary=args.boundary)
        common = int(np.argmax(E.counts()))
        print()
        print(head)
        print("-" * len(head))
        base = None
        totals: dict[str, float] = {}
        for spec, opts in specs:
            rows, grids = [], []
            ok = 0
            for seed in range(args.seeds):
                kw = dict(opts)
                kw.setdefault("time_limit", args.time_limit)
                try:
                    r = csplab.solve(P, spec, rng=seed, **kw)
                except csplab.CsplabError as e:
                    print(f"{name:<12}{P.K:>4}  {_label(spec, opts):<28} error: {e}")
                    break
                ok += r.status == "solved"
                rows.append((*_split(r), r.time_s))
                if r.status == "solved":
                    grids.append(r.grid)
            if not rows:
                continue
            enc = [x[0] for x in rows if x[0] is not None]
            load = [x[1] for x in rows if x[1] is not None]
            tot = statistics.median(x[3] for x in rows)
            sol = statistics.median(x[2] for x in rows)
            if spec == "catalog" and not opts:
                base = tot
            if not opts and ok == args.seeds:
                totals[spec] = tot
            ratio = f"{tot / base:.1f}" if base else "-"
            diffs = [np.mean(grids[i] != grids[j]) for i in range(len(grids))
                     for j in range(i + 1, len(grids))]  # fmt: skip
            differ = f"{np.mean(diffs):.3f}" if diffs else "-"
            nonempty = f"{np.mean([np.mean(g != common) for g in grids]):.3f}" if grids else "-"
            print(
                f"{name:<12}{P.K:>4}  {_label(spec, opts):<28}{ok:>4}/{args.seeds:<2}"
                f"{_fmt(statistics.median(enc) if enc else None):>8}"
                f"{_fmt(statistics.median(load) if load else None):>7}{sol:>8.2f}{tot:>8.2f}"
                f"{ratio:>10}{differ:>8}{nonempty:>10}",
                flush=True,
            )
        _targets(name, P.K, totals)
        time.sleep(0)


def _targets(name: str, K: int, totals: dict[str, float]) -> None:
    """The issue's targets for the exact solvers at this size (every seed solved)."""
    sat, cp = totals.get("sat"), totals.get("cpsat")
    if sat is not None:
        print(f"  target sat end to end <= 1 s ({name}, K={K}): {sat:.2f} s, "
              f"{'meets' if sat <= 1 else 'misses'}")  # fmt: skip
    if sat is not None and cp is not None:
        print(f"  target cpsat <= 2x sat ({name}, K={K}): {cp:.2f} s = {cp / sat:.1f}x, "
              f"{'meets' if cp <= 2 * sat else 'misses'}")  # fmt: skip


if __name__ == "__main__":
    main()
