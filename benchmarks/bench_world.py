"""Benchmark: endless chunked worlds (:class:`csplab.World`, issue 27).

Prints one line per target of issue 27 with the measured figure and ``meets`` or the
shortfall:

1. memory (resident set) after walking N chunks in a straight line: <= 200 MB, with the
   growth over the second half of the walk (flat memory: the caches are bounded);
2. 2D 32x32 chunk latency (p50/p99, one process) of each new chunk on a straight walk,
   and the mean cost per chunk of filling a square, for a WFC-style tileset
   (``tests/io/data/pipes.xml``) and an overlapping sample (``tests/io/data/sample.png``):
   p99 <= 20 ms;
3. 3D 16x16x10 city chunk latency, the same way: p99 <= 200 ms;
4. seam violations over N chunks: the chunks are stitched row by row, each row checked with
   the row before it (every seam counted once) by ``Problem.violations``: 0;
5. identical bytes for R random visit orders (fresh worlds, a 3x3-chunk square).

The issue's counts (10^5 chunks walked, 10^4 checked, 100 orders) take long on a shared
2-core machine; ``--full`` runs them, the default runs smaller counts and says so on every
line. The JIT is warmed up (one chunk) before anything is timed; timings are printed, never
asserted.

Usage::

    python benchmarks/bench_world.py [--full] [--seed 1] [--walk 1500] [--seams 1000]
        [--orders 20] [--chunks 64]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from csplab.world import World

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "io" / "data"


def rss_mb() -> float:
    """The resident set size of this process now (MB), from /proc (Linux)."""
    try:
        with open("/proc/self/statm") as f:
            pages = int(f.read().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE") / 1e6
    except OSError:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3


def verdict(ok: bool, shortfall: str) -> str:
    return "meets" if ok else f"SHORT: {shortfall}"


def latency(model: str, chunk: tuple[int, ...], n: int, seed: int) -> tuple[list[float], float]:
    """Milliseconds per new chunk on a straight walk along ``x`` (a player moving: chunks
    ``(i, 0)``, ``i = 0 .. n - 1``), after one warm-up chunk far away (JIT, start model);
    and the mean cost per chunk of filling a square of ``n`` chunks (amortized)."""
    w = World(model, seed=seed, chunk=chunk)
    w.chunk(-1000, -1000)  # warm-up
    times = []
    for i in range(n):
        t = time.perf_counter()
        w.chunk(i, 0)
        times.append((time.perf_counter() - t) * 1e3)
    side = max(2, round(n**0.5))
    w = World(model, seed=seed, chunk=chunk)
    w.chunk(-1000, -1000)
    t = time.perf_counter()
    w.region((0, side * chunk[0]), (0, side * chunk[1]))
    return times, (time.perf_counter() - t) * 1e3 / side**2


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the issue's counts (long)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--chunks", type=int, default=64, help="chunks timed per latency line")
    ap.add_argument("--walk", type=int, default=1500, help="chunks walked for memory")
    ap.add_argument("--seams", type=int, default=1024, help="chunks checked for seams")
    ap.add_argument("--orders", type=int, default=20, help="random visit orders")
    a = ap.parse_args()
    if a.full:
        a.walk, a.seams, a.orders = 100_000, 10_000, 100
    print(f"bench_world: seed {a.seed}, os.cpu_count() {os.cpu_count()}, load average "
          f"{os.getloadavg()[0]:.1f} (a shared machine: timings indicative)")  # fmt: skip

    # 1. memory (first: the latencies load more models) over a straight walk
    w = World(str(DATA / "pipes.xml"), seed=a.seed, chunk=(32, 32))
    w.chunk(0, 0)
    t0 = time.perf_counter()
    start = half = rss_mb()
    for i in range(a.walk):
        w.chunk(i, 0)
        if i == a.walk // 2:
            half = rss_mb()
    end = rss_mb()
    note = "" if a.walk >= 100_000 else " (issue: 10^5; --full)"
    secs = time.perf_counter() - t0
    print(f"memory after walking {a.walk} chunks{note}: {end:.0f} MB resident, {start:.0f} MB "
          f"after the first chunk, {end - half:+.1f} MB over the second half, {secs:.0f} s, "
          f"caches {len(w.blocks)}/{w.blocks.size} blocks {len(w.chunks)}/{w.chunks.size} "
          f"chunks "
          f"(target <= 200 MB): {verdict(end <= 200, f'{end - 200:.0f} MB over')}")  # fmt: skip

    # 2. 2D latencies
    for label, model in (("tileset pipes.xml", DATA / "pipes.xml"),
                         ("overlapping sample.png", DATA / "sample.png")):  # fmt: skip
        times, mean = latency(str(model), (32, 32), a.chunks, a.seed)
        t = np.array(times)
        p50, p99 = np.percentile(t, 50), np.percentile(t, 99)
        ok = verdict(p99 <= 20, f"{p99 - 20:.1f} ms over")
        print(f"2D 32x32 chunk, {label}: walk p50 {p50:.1f} ms, p99 {p99:.1f} ms over {t.size} "
              f"chunks; square fill {mean:.1f} ms/chunk (target p99 <= 20 ms): {ok}")  # fmt: skip

    # 3. 3D city latency
    times, mean = latency("city", (16, 16, 10), max(4, a.chunks // 2), a.seed)
    t = np.array(times)
    p50, p99 = np.percentile(t, 50), np.percentile(t, 99)
    ok = verdict(p99 <= 200, f"{p99 - 200:.1f} ms over")
    print(f"3D 16x16x10 city chunk: walk p50 {p50:.1f} ms, p99 {p99:.1f} ms over {t.size} "
          f"chunks; square fill {mean:.1f} ms/chunk (target p99 <= 200 ms): {ok}")  # fmt: skip

    # 4. seams: rows of chunks, each row checked with the previous one
    w = World(str(DATA / "pipes.xml"), seed=a.seed + 1, chunk=(32, 32), cache_chunks=256)
    cols = max(2, round(a.seams**0.5))
    rows = max(2, -(-a.seams // cols))
    P = w.problem((64, cols * 32))
    bad = 0
    for i in range(rows - 1):
        g = w.region((i * 32, (i + 2) * 32), (0, cols * 32))
        bad += len(P.violations(g))
    n = rows * cols
    note = "" if n >= 10_000 else " (issue: 10^4; --full)"
    print(f"seam violations over {n} chunks{note}: {bad} (target 0): "
          f"{verdict(bad == 0, f'{bad} violations')}")  # fmt: skip

    # 5. visit orders
    coords = [(i, j) for i in range(3) for j in range(3)]
    ref = World(str(DATA / "pipes.xml"), seed=a.seed, chunk=(32, 32))
    want = {c: ref.chunk(*c).tobytes() for c in coords}
    rng = np.random.default_rng(a.seed)
    same = 0
    for _ in range(a.orders):
        wo = World(str(DATA / "pipes.xml"), seed=a.seed, chunk=(32, 32))
        order = [coords[k] for k in rng.permutation(len(coords))]
        same += all(wo.chunk(*c).tobytes() == want[c] for c in order)
    note = "" if a.orders >= 100 else " (issue: 100; --full)"
    print(f"identical bytes for random visit orders{note}: {same}/{a.orders} "
          f"(target all): {verdict(same == a.orders, f'{a.orders - same} differ')}")  # fmt: skip


if __name__ == "__main__":
    main()
