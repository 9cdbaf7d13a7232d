"""Benchmark: meshes with curved parts through bounding volumes (thesis Sec. 4.6.4).

Target (issue 25): a box with cylindrical holes, a dome on a cube and a lathe solid, made
with manifold3d (:mod:`csplab.testing.cad`) and exported as STL, each synthesize
40x40x20 plane spacings with default settings in at most 30 s end to end
(``csplab synthesize PART.stl --size 40x40x20 --seed 1 --out out.obj``, run in this
process: reading, bounding volumes, CSP, solving with the default chain, geometry, the
check on the proxy, substituting the curved geometry back, writing). Each line prints the
time with "meets" or the shortfall, the solver's outcome and the bounding-volume line,
then the time of :func:`~csplab.continuous.boundcheck.bounded_violations` on the output
(what ``csplab check`` runs; no target).

Machines are shared: a reference run in the same process comes first (the built-in
``houses`` example, 20x20x8, ``catalog``, seed 1), so that a slow figure can be read
against the machine's speed at the time. Timings are printed, never asserted.

Usage::

    python benchmarks/bench_bounding.py [--parts holes dome lathe] [--size 40x40x20]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

TARGET_S = 30.0
PARTS = ("holes", "dome", "lathe")


def reference() -> float:
    """The reference run's time (s)."""
    from csplab.continuous.synthesis import synthesize
    from csplab.examples.continuous3d import load_polyhedral_example

    t = time.perf_counter()
    synthesize(load_polyhedral_example("houses"), (20, 20, 8), rng=1, restarts=10)
    return time.perf_counter() - t


def run_part(name: str, size: str, folder: Path) -> None:
    from csplab.cli import main
    from csplab.continuous.boundcheck import bounded_violations
    from csplab.continuous.bounding import bounding_volumes
    from csplab.io import read_model
    from csplab.testing import cad

    part = cad.export(cad.build(name), folder / f"{name}.stl")
    out = folder / f"{name}.out.obj"
    buf = io.StringIO()
    t = time.perf_counter()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        code = main(["synthesize", str(part), "--size", size, "--seed", "1", "--out", str(out)])
    took = time.perf_counter() - t
    lines = buf.getvalue().splitlines()
    head = lines[0] if lines else "(no output)"
    bv = next((x.strip() for x in lines if x.strip().startswith("bounding volumes:")),
              "no bounding volumes")  # fmt: skip
    verdict = "meets" if took <= TARGET_S else f"shortfall {took - TARGET_S:.1f} s"
    print(f"{name}: {took:.1f} s end to end (target <= {TARGET_S:.0f} s: {verdict}); "
          f"exit {code}; {head.split(' with ')[0]}")  # fmt: skip
    print(f"  {bv}")
    if code != 0 or not out.exists():
        return
    E = read_model(str(part))
    b = bounding_volumes(E)
    assert b is not None
    from csplab.continuous.polyhedra import PolyhedralModel

    M = read_model(str(out)) if _small(out) else None
    if not isinstance(M, PolyhedralModel):
        print("  check: the output has more faces than csplab reads back (mesh_repair limit)")
        return
    t = time.perf_counter()
    v = bounded_violations(b, M)
    print(f"  check (csplab check's bounded_violations): {len(v)} violations, "
          f"{time.perf_counter() - t:.1f} s, {len(M.solids)} solids")  # fmt: skip


def _small(path: Path) -> bool:
    from csplab.io.mesh_repair import MAX_FACES

    with path.open() as f:
        return sum(1 for line in f if line.startswith("f ")) <= MAX_FACES


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", nargs="*", default=list(PARTS))
    ap.add_argument("--size", default="40x40x20")
    a = ap.parse_args()
    print(f"reference: houses 20x20x8 catalog seed 1 in {reference():.1f} s (this machine, now)")
    with tempfile.TemporaryDirectory() as d:
        for name in a.parts:
            run_part(name, a.size, Path(d))


if __name__ == "__main__":
    main()
