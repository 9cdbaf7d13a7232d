"""Benchmark: Lagae et al.'s Table 1 measure on csplab's geometry baseline.

For the built-in ``terrain`` polyhedral example sampled as a signed distance field at
several resolutions and block sizes, prints the number of blocks and tree nodes (identical
nodes grouped), the tree build time, the average time of the best-first tree search and of
a linear search over every block for the same noisy query blocks (the reference run in the
same process), the speed-up, and how often both found a block at the best distance.
Paper (2 GHz PC, their BALLS1 example): 64^3 / 8: 460x, 128^3 / 16: 1,400x, 256^3 / 32: 5,150x.
Timings are printed, never asserted.

Usage::

    python benchmarks/bench_geometry.py [--queries 20]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

SETTINGS = [(32, 8), (48, 8), (64, 8), (64, 16)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--queries", type=int, default=20)
    ap.add_argument("--example", default="terrain")
    a = ap.parse_args()
    from csplab.baselines.geometry import match_speedup
    from csplab.examples.continuous3d import load_polyhedral_example

    E = load_polyhedral_example(a.example)
    print(f"{a.example}: tree search against linear search, {a.queries} noisy queries each")
    print("resolution block   blocks    nodes  build s   tree ms  linear ms  speedup  agree")
    for res, blk in SETTINGS:
        m = match_speedup(E, resolution=res, block=blk, queries=a.queries, rng=0)
        print(
            f"{res:>10} {blk:>5} {int(m['blocks']):>8,} {int(m['nodes']):>8,} "
            f"{m['build_s']:>8.2f} {1000 * m['tree_s']:>9.2f} {1000 * m['linear_s']:>10.2f} "
            f"{m['speedup']:>8.1f} {m['agree']:>6.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
