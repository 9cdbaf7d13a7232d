"""Benchmark: modify in blocks streamed slab by slab (issue 29 item 5, ledger R9).

Every run is a child process; its wall time and peak memory (``ru_maxrss`` of that child
alone, from ``os.wait4``) are printed:

1. **Reference** (same bytes, memory that grows): castle at ``--ref-size`` via blocks on the
   whole problem (``csplab.solve`` on ``from_example``, the path ``csplab synthesize`` takes
   below :data:`csplab.solvers.blocks.STREAM_BYTES`), then the same run streamed
   (``BlocksSolver().stream`` on ``GridWindows``); both outputs checked with the whole
   problem's ``Problem.violations``, their SHA-256 compared.
2. **Targets**: ``csplab synthesize castle --size S --boundary auto --solver blocks --block
   10 --out S.npy --json`` (the command streams these sizes) at ``--size`` (1000x1000x10:
   <= 30 s and <= 1.5 GB) and ``--big`` (10^8 cells: completes within 1.5 GB); each
   output checked again by a separate child reading the ``.npy`` as a memory map,
   :meth:`GridWindows.violations` (``Problem.violations`` of overlapping slabs).

The machine's load average is printed before and after (the machine is shared: times are
inflated by load, compare them with the reference printed beside them). Times and memory
are printed with "meets" or the shortfall, never asserted.

Usage::

    python benchmarks/bench_stream.py [--example castle] [--ref-size 200x200x10]
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--example", default="castle")
    ap.add_argument("--ref-size", default="200x200x10")
    ap.add_argument("--size", default="1000x1000x10")
    ap.add_argument("--big", default="10000x1000x10", help="'' to skip the 10^8-cell run")
    ap.add_argument("--block", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    print(f"load average before: {' '.join(f'{v:.1f}' for v in os.getloadavg())} "
          f"({os.cpu_count()} cores)")  # fmt: skip
    # warm numba's cache (a first run compiles csplab's kernels into it)
    child([sys.executable, "-m", "csplab", "synthesize", args.example, "--size", "12x12x10",
           "--boundary", "auto", "--solver", "blocks", "--seed", "0"])  # fmt: skip

    ref = shape_of(args.ref_size)
    fill = {"example": args.example, "shape": ref, "seed": args.seed, "block": args.block}
    print(f"\nreference: {args.example} {args.ref_size} via blocks of {args.block}, seed "
          f"{args.seed}")  # fmt: skip
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

    with tempfile.TemporaryDirectory() as tmp:
        for label, size, timed in (("target", args.size, True), ("10^8 cells", args.big, False)):
            if not size:
                continue
            path = str(Path(tmp) / f"{size}.npy")
            argv = [sys.executable, "-m", "csplab", "synthesize", args.example, "--size", size,
                    "--boundary", "auto", "--solver", "blocks", "--block", str(args.block),
                    "--seed", str(args.seed), "--out", path, "--json"]  # fmt: skip
            print(f"\n{label}: csplab synthesize {' '.join(argv[4:])}")
            wall, gb, text, rc, cpu = child(argv)
            lines = [ln for ln in text.splitlines() if ln.startswith("{")]
            d = json.loads(lines[-1]) if lines else {}
            st = d.get("stats", {})
            solve_s = d.get("time_s", math.nan)
            print(f"  {wall:.1f} s wall ({cpu:.1f} s CPU; solve {solve_s:.1f} s), peak "
                  f"{gb:.2f} GB, {d.get('status')}, {st.get('blocks_tried')} blocks, "
                  f"slab problems {st.get('slab_problems')}, final_violations "
                  f"{st.get('final_violations')} (exit {rc})")  # fmt: skip
            if timed:  # one process on one core: its CPU time is its wall time on an idle core
                print(f"  time, wall: {verdict(wall, TIME_S, 's')}")
                print(f"  time, CPU (the wall time on an idle core): {verdict(cpu, TIME_S, 's')}")
            print(f"  memory: {verdict(gb, MEMORY_GB, 'GB')}")
            if rc == 0:
                cw, cgb, c, crc, _ = python(_CHECK.format(path=path, example=args.example,
                                                       shape=shape_of(size)))  # fmt: skip
                print(f"  separate check of the .npy (memory map, slabs): violations "
                      f"{c.get('violations')} in {cw:.1f} s, peak {cgb:.2f} GB (exit {crc})")
            Path(path).unlink(missing_ok=True)
    print(f"\nload average after: {' '.join(f'{v:.1f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
