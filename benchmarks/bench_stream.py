"""Benchmark: modify in blocks streamed slab by slab (issue 29 item 5, ledger R9).

Every run is a child process; its wall time, CPU time and peak memory (``ru_maxrss`` of
that child alone, from ``os.wait4``) are printed. For each example (``--examples``, default
castle and city):

1. **Reference** (same bytes, memory that grows): the example at ``--ref-size`` via blocks
   on the whole problem (``csplab.solve`` on ``from_example``, the path ``csplab
   synthesize`` takes below :data:`csplab.solvers.blocks.STREAM_BYTES`), then the same run
   streamed (``BlocksSolver().stream`` on ``GridWindows``); both outputs checked with the
   whole problem's ``Problem.violations``, their SHA-256 compared.
2. **Targets**: ``csplab synthesize EXAMPLE --size S --boundary auto --solver blocks --block
   10 --out S.npy --json`` (the command streams these sizes) at ``--size`` (1000x1000x10:
   <= 30 s and <= 1.5 GB) and, for the first example, ``--big`` (10^8 cells: completes
   within 1.5 GB); each output checked again by a separate child reading the ``.npy`` as a
   memory map, :meth:`GridWindows.violations` (``Problem.violations`` of overlapping slabs).

The last lines repeat every target line, example by example, with "meets" or the
shortfall. The machine's load average is printed before and after every timed run (the
machine may be shared: wall times are inflated by load, CPU times much less; the CPU time
of the one-threaded run is its wall time on an idle core). Times and memory are printed,
never asserted.

Measured (details in ``benchmarks/results/stream.md``): castle 1000x1000x10 took 33.2 s
wall, 33.4 s CPU, 0.68 GB on an idle machine before the block catalog's cells were looked
up in a table, one-word domains propagated in registers and the check's windows made
smaller; after, on the shared machine at load average about 3 (not idle): castle 18.1 s
wall, 18.0 s CPU, 0.39 GB; city 18.0 s wall, 17.9 s CPU, 0.46 GB; 0 violations, the same
bytes as before. The old code on the same machine at load 5-6: castle 33.9 s CPU (74.7 s
wall) against 20.0 s CPU (42.7 s wall) for the new kernels. With Alg. 3.1's propagation
also inlined with 8-label table slices, at load average about 1.7: castle 13.6 s wall,
13.5 s CPU, 0.39 GB; city 14.9 s wall, 15.1 s CPU, 0.46 GB. With the two-word propagation
loop and Alg. 3.1's step loop without reference counting (idle, load average 0.5-1.0):
castle 11.9 s wall, 12.1 s CPU, 0.40 GB; city 8.9 s wall, 9.1 s CPU, 0.46 GB; castle
10000x1000x10 (10^8 cells) 112.8 s wall and CPU, 0.73 GB, its separate check 0 violations
in 4.6 s at 0.58 GB; the same bytes as the whole-problem reference.

Usage::

    python benchmarks/bench_stream.py [--examples castle city] [--ref-size 200x200x10]
        [--size 1000x1000x10] [--big 10000x1000x10 | --big ''] [--seed 1]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

TIME_S = 30.0
MEMORY_GB = 1.5

_WHOLE = """
import hashlib, json, resource, sys, time
import csplab
from csplab.examples import load_example
E = load_example({example!r})
t = time.perf_counter()
P = csplab.from_example(E, {shape!r}, boundary="auto")
r = csplab.solve(P, "blocks", rng={seed}, block={block})
t = time.perf_counter() - t
gb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
print(json.dumps({{"s": t, "status": r.status, "violations": len(P.violations(r.grid)),
                  "sha": hashlib.sha256(r.grid.tobytes()).hexdigest(), "gb": gb}}))
"""

_STREAMED = """
import hashlib, json, resource, time
import numpy as np
import csplab
from csplab.examples import load_example
from csplab.grids import GridWindows
from csplab.solvers.blocks import BlocksSolver
E = load_example({example!r})
t = time.perf_counter()
W = GridWindows(E, {shape!r}, boundary="auto")
r = BlocksSolver().stream(W, rng=np.random.default_rng({seed}), seed={seed}, block={block})
t = time.perf_counter() - t
gb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # before the whole check
P = csplab.from_example(E, {shape!r}, boundary="auto")  # the whole check (small size)
print(json.dumps({{"s": t, "status": r.status, "violations": len(P.violations(r.grid)),
                  "sha": hashlib.sha256(r.grid.tobytes()).hexdigest(), "gb": gb}}))
"""

_CHECK = """
import json, time
import numpy as np
from csplab.examples import load_example
from csplab.grids import GridWindows
t = time.perf_counter()
g = np.load({path!r}, mmap_mode="r")
W = GridWindows(load_example({example!r}), {shape!r}, boundary="auto")
print(json.dumps({{"violations": W.violations(g), "s": time.perf_counter() - t}}))
"""


def child(argv: list[str]) -> tuple[float, float, str, int, float]:
    """Run ``argv``; its wall seconds, peak RSS in GB (this child alone), stdout, exit
    code and CPU seconds (user + system: what the run costs whatever the machine's load)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    t = time.perf_counter()
    with tempfile.TemporaryFile() as out:
        p = subprocess.Popen(argv, stdout=out, stderr=subprocess.DEVNULL, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t
        out.seek(0)
        text = out.read().decode()
    code = os.waitstatus_to_exitcode(status)
    cpu = usage.ru_utime + usage.ru_stime
    return wall, usage.ru_maxrss / 2**20, text, code, cpu  # Linux: kB


def python(code: str) -> tuple[float, float, dict[str, Any], int, float]:
    wall, gb, text, rc, cpu = child([sys.executable, "-c", code])
    lines = [ln for ln in text.splitlines() if ln.startswith("{")]
    return wall, gb, (json.loads(lines[-1]) if lines else {}), rc, cpu


def verdict(value: float, limit: float, unit: str) -> str:
    if value <= limit:
        return f"meets (<= {limit:g} {unit})"
    return f"NOT met: {value:.2f} {unit} against {limit:g} {unit} ({value / limit:.1f}x)"


def shape_of(text: str) -> tuple[int, ...]:
    return tuple(int(v) for v in text.split("x"))


def load() -> str:
    """The machine's load average (1, 5 and 15 minutes)."""
    return " ".join(f"{v:.1f}" for v in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--examples", "--example", nargs="+", default=["castle", "city"],
                    help="the examples, each with its reference and target runs")
    ap.add_argument("--ref-size", default="200x200x10")
    ap.add_argument("--size", default="1000x1000x10")
    ap.add_argument("--big", default="10000x1000x10",
                    help="the 10^8-cell run, of the first example; '' to skip it")
    ap.add_argument("--block", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    print(f"load average before: {load()} ({os.cpu_count()} cores)")
    # warm numba's cache (a first run compiles csplab's kernels into it)
    child([sys.executable, "-m", "csplab", "synthesize", args.examples[0], "--size",
           "12x12x10", "--boundary", "auto", "--solver", "blocks", "--seed", "0"])  # fmt: skip
    summary: list[str] = []
    for k, example in enumerate(args.examples):
        summary += run_example(args, example, big=args.big if k == 0 else "")
    print(f"\ntargets ({args.size} via blocks of {args.block}: <= {TIME_S:g} s, <= "
          f"{MEMORY_GB:g} GB):")  # fmt: skip
    for line in summary:
        print(f"  {line}")
    print(f"\nload average after: {load()}")


def run_example(args: argparse.Namespace, example: str, big: str) -> list[str]:
    """The reference and target runs of one example; its target lines."""
    ref = shape_of(args.ref_size)
    fill = {"example": example, "shape": ref, "seed": args.seed, "block": args.block}
    print(f"\nreference: {example} {args.ref_size} via blocks of {args.block}, seed "
          f"{args.seed} (load average {load()})")  # fmt: skip
    runs = {}
    for name, code in (("whole problem", _WHOLE), ("streamed", _STREAMED)):
        wall, gb, d, rc, cpu = python(code.format(**fill))
        runs[name] = d
        print(f"  {name:<14} {d.get('s', math.nan):7.2f} s solve ({wall:6.2f} s wall, "
              f"{cpu:6.2f} s CPU), "
              f"peak {d.get('gb', math.nan):.2f} GB at the end of the solve ({gb:.2f} GB "
              f"with the whole check), {d.get('status')}, Problem.violations "
              f"{d.get('violations')} (exit {rc})")  # fmt: skip
    same = runs["whole problem"].get("sha") == runs["streamed"].get("sha")
    sha = str(runs["streamed"].get("sha"))[:16]
    print(f"  same bytes: {'yes' if same else 'NO'} (sha256 {sha})")

    summary = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, size, timed in (("target", args.size, True), ("10^8 cells", big, False)):
            if not size:
                continue
            path = str(Path(tmp) / f"{size}.npy")
            argv = [sys.executable, "-m", "csplab", "synthesize", example, "--size", size,
                    "--boundary", "auto", "--solver", "blocks", "--block", str(args.block),
                    "--seed", str(args.seed), "--out", path, "--json"]  # fmt: skip
            print(f"\n{label}: csplab synthesize {' '.join(argv[4:])}")
            before = load()
            wall, gb, text, rc, cpu = child(argv)
            lines = [ln for ln in text.splitlines() if ln.startswith("{")]
            d = json.loads(lines[-1]) if lines else {}
            st = d.get("stats", {})
            solve_s = d.get("time_s", math.nan)
            print(f"  {wall:.1f} s wall ({cpu:.1f} s CPU; solve {solve_s:.1f} s), peak "
                  f"{gb:.2f} GB, {d.get('status')}, {st.get('blocks_tried')} blocks, "
                  f"slab problems {st.get('slab_problems')}, final_violations "
                  f"{st.get('final_violations')} (exit {rc}); load average {before} before, "
                  f"{load()} after")  # fmt: skip
            verdicts = []
            if timed:  # one process on one core: its CPU time is its wall time on an idle core
                verdicts = [f"time, wall: {verdict(wall, TIME_S, 's')}",
                            f"time, CPU (the wall time on an idle core): "
                            f"{verdict(cpu, TIME_S, 's')}"]  # fmt: skip
            verdicts.append(f"memory: {verdict(gb, MEMORY_GB, 'GB')}")
            for v in verdicts:
                print(f"  {v}")
            ok = rc == 0 and d.get("status") == "solved"
            summary += [f"{example} {size}: {v}" for v in verdicts]
            if not ok:
                summary.append(f"{example} {size}: NOT met: exit {rc}, status {d.get('status')}")
            if rc == 0:
                cw, cgb, c, crc, _ = python(_CHECK.format(path=path, example=example,
                                                       shape=shape_of(size)))  # fmt: skip
                print(f"  separate check of the .npy (memory map, slabs): violations "
                      f"{c.get('violations')} in {cw:.1f} s, peak {cgb:.2f} GB (exit {crc})")
                if c.get("violations") != 0:
                    summary.append(f"{example} {size}: NOT met: {c.get('violations')} "
                                   "violations in the written file")  # fmt: skip
            Path(path).unlink(missing_ok=True)
    return summary


if __name__ == "__main__":
    main()
