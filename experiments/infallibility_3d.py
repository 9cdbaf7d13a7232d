"""Issue 4 runs on the built-in 3D examples: corner condition, region prover, witnesses.

Run from the repository root: ``python experiments/infallibility_3d.py [--quick]``.
Prints one line per measurement (verdict, state counts, seconds); the figures in
papers/merrell-2009-thesis/README.md ("Ch. 3 infallibility") come from this script.
"""

from __future__ import annotations

import sys
import time

from csplab.analysis import corner_condition, find_failure, prove_infallible
from csplab.examples import load_example


def main(quick: bool = False) -> None:
    names = ["pillar", "city", "castle", "canal"]
    regions = [((2, 2, 2), 0), ((2, 2, 2), 1), ((3, 3, 2), 0)] if not quick else [((2, 2, 2), 0)]
    for name in names:
        E = load_example(name)
        v = corner_condition(E)
        print(
            f"{name} K={int((E.counts() > 0).sum())} corner: {v.holds} {v.message} "
            f"({v.stats['time_s']:.2f} s)",
            flush=True,
        )
        for r, h in regions:
            t0 = time.perf_counter()
            v = prove_infallible(E, r, history=h, refute=False, max_states=2_000_000)
            s = v.stats
            print(
                f"{name} prove region={'x'.join(map(str, r))} history={h}: holds={v.holds} "
                f"states={s['states']} windows={s['windows']} configs={s['configs']} "
                f"time={time.perf_counter() - t0:.2f}s :: {v.message}",
                flush=True,
            )
        t0 = time.perf_counter()
        v = find_failure(
            E,
            max_size=(40, 40, 10),
            exhaustive_cells=8,
            random_runs=5 if quick else 20,
            rng=1,
            max_nodes=100_000,
        )
        w = v.witness or {}
        print(
            f"{name} witness: holds={v.holds} shape={w.get('shape')} seed={w.get('seed')} "
            f"fail_step={w.get('fail_step')} first_outside_C*={w.get('first_outside_cstar')} "
            f"runs={v.stats['random_runs']} time={time.perf_counter() - t0:.1f}s :: "
            f"{v.message}",
            flush=True,
        )


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
