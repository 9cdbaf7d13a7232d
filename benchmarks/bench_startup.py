"""Benchmark: wall time of small ``csplab`` commands, start-up included (issue target:
``csplab synthesize`` on a built-in 2D example at 20x20 in <= 0.3 s with a warm cache).

Each command runs ``--runs`` times as a fresh process (after one untimed run that warms
Python's bytecode cache and numba's cache); the median wall time is printed. The reference
in the same run is the same synthesis with the compiled kernels forced
(``CSPLAB_ENGINE=kernels``: numba is imported and its cached machine code loaded, as every
command did before the interpreted engine), and a bare ``python -c pass``.

Usage::

    python benchmarks/bench_startup.py [--runs 7] [--example fig3_10] [--size 20x20]
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

ROOT = Path(__file__).resolve().parents[1]


def wall(cmd: list[str], env: dict[str, str], runs: int) -> float:
    """Median wall seconds of ``cmd`` over ``runs`` runs, after one untimed run."""
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        subprocess.run(cmd, env=env, check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--example", default="fig3_10")
    ap.add_argument("--size", default="20x20")
    args = ap.parse_args()
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # a user's Python keeps its bytecode cache
    env.pop("CSPLAB_ENGINE", None)
    exe = [sys.executable, "-m", "csplab"]
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "out.png")
        synth = [*exe, "synthesize", args.example, "--size", args.size, "--seed", "1", "--out", out]
        rows = [
            ("python -c pass", [sys.executable, "-c", "pass"], env),
            ("csplab --help", [*exe, "--help"], env),
            ("csplab info", [*exe, "info"], env),
            (f"synthesize {args.example} {args.size}", synth, env),
            ("  same, kernels forced (reference)", synth, {**env, "CSPLAB_ENGINE": "kernels"}),
        ]
        print(f"median wall time of {args.runs} runs each (warm caches), {os.cpu_count()} CPUs")
        res = {}
        for label, cmd, e in rows:
            res[label] = wall(cmd, e, args.runs)
            print(f"  {label:<40} {res[label]:6.3f} s")
    t = res[f"synthesize {args.example} {args.size}"]
    ref = res["  same, kernels forced (reference)"]
    verdict = "meets" if t <= 0.3 else "misses"
    print(f"\n  target <= 0.3 s for synthesize {args.example} {args.size}: {t:.3f} s, {verdict}"
          f" ({ref / t:.1f}x faster than with the kernels loaded: {ref:.3f} s)")  # fmt: skip


if __name__ == "__main__":
    main()
