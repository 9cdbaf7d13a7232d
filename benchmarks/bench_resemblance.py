"""Benchmark: how much 3D continuous outputs resemble their examples (issue 25 targets).

For each built-in polyhedral example it synthesizes one output with csplab's defaults
(weighted choice, the example's own infinite ground) and, as the reference in the same
process, one with the thesis' setting (uniform choice, no ground), and prints the
resemblance figures of :func:`~csplab.continuous.resemblance.resemblance` (computed from
the solids alone): solids, median solid volume over the example's, share of the example's
edge kinds and face orientations present, floating solids. The targets
(:data:`~csplab.experiments.table1_continuous.TARGETS`: 0 floating solids with a ground,
median volume >= 25% of the example's, >= 80% of its edge kinds) are printed as "meets" or
the shortfall (:func:`~csplab.experiments.table1_continuous.targets_met`), never asserted.
Sizes are Table 1's (the paper's output polygons), or 20x20x8 with ``--quick``.

``--polygons`` does the same for the built-in polygon (2D) examples with
:func:`~csplab.continuous.resemblance.resemblance`: for each example, size and choice
(weighted, csplab's default, and uniform, the thesis', in the same process) over
``--seeds`` seeds, the share solved on the first attempt (no restarts), the mean solve
time, and the medians of the figures over the solved seeds.

Usage::

    python benchmarks/bench_resemblance.py [--quick] [--examples skyscrapers,terrain] [--seed 1]
    python benchmarks/bench_resemblance.py --polygons [--sizes 20x20,40x40] [--seeds 5]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from csplab.experiments.table1_continuous import PAPER_TABLE1, SIZES, targets_met

SETTINGS = (("csplab", "weighted", "auto"), ("thesis", "uniform", None))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", default=",".join(PAPER_TABLE1))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="20x20x8 for every example")
    ap.add_argument("--polygons", action="store_true", help="the 2D examples instead")
    ap.add_argument("--sizes", default="20x20,40x40", help="2D sizes (--polygons)")
    ap.add_argument("--seeds", type=int, default=5, help="seeds 1..N (--polygons)")
    a = ap.parse_args()
    if a.polygons:
        polygons(a.sizes.split(","), a.seeds)
        return

    from csplab.continuous.resemblance import resemblance
    from csplab.continuous.synthesis import synthesize
    from csplab.examples.continuous3d import load_polyhedral_example
    from csplab.grids import parse_shape

    print(f"{'example':<12} {'size':<9} {'setting':<29} {'solids':>6} {'med.vol':>8} "
          f"{'edges':>6} {'faces':>6} {'float':>6} {'s':>6}  target")  # fmt: skip
    for name in a.examples.split(","):
        E = load_polyhedral_example(name)
        size = (20, 20, 8) if a.quick else parse_shape(SIZES[name])
        for who, choice, ground in SETTINGS:
            t = time.perf_counter()
            s = synthesize(E, size, rng=a.seed, restarts=10, choice=choice, ground=ground)
            dt = time.perf_counter() - t
            setting = f"{who}: {choice}, ground {','.join(s.csp.ground) or 'none'}"
            if s.model is None:
                print(f"{name:<12} {'x'.join(map(str, size)):<9} {setting:<29} "
                      f"{s.result.status}")  # fmt: skip
                continue
            floor = s.csp.region()[2] if "z-" in s.csp.ground else None
            r = resemblance(s.csp.example, s.model, ground=floor)
            verdict = targets_met(r.to_dict(), bool(s.csp.ground))
            print(f"{name:<12} {'x'.join(map(str, size)):<9} {setting:<29} {r.solids:>6} "
                  f"{r.median_volume_ratio:>8.3f} {r.edge_kinds:>6.2f} "
                  f"{r.face_orientations:>6.2f} {r.floating:>6} {dt:>6.1f}  "
                  f"{verdict if who == 'csplab' else '(reference)'}")  # fmt: skip


def polygons(sizes: list[str], seeds: int) -> None:
    """The 2D comparison of ``--polygons`` (module docstring)."""
    import statistics

    from csplab.continuous.resemblance import resemblance
    from csplab.continuous.synthesis import synthesize
    from csplab.examples.continuous import CONTINUOUS_EXAMPLES, load_polygon_example
    from csplab.grids import parse_shape

    print(f"{'example':<14} {'size':<6} {'choice':<9} {'solved':>6} {'s/run':>6} "
          f"{'polys':>6} {'med.area':>8} {'corners':>7} {'dirs':>5} {'float':>6}")  # fmt: skip
    for name in CONTINUOUS_EXAMPLES:
        E = load_polygon_example(name)
        for size in sizes:
            shape = parse_shape(size)
            for choice in ("weighted", "uniform"):
                got, times = [], []
                for seed in range(1, seeds + 1):
                    t = time.perf_counter()
                    s = synthesize(E, shape, rng=seed, restarts=0, choice=choice)
                    times.append(time.perf_counter() - t)
                    if s.ok and s.model is not None:
                        floor = s.csp.region()[1] if "y-" in s.csp.ground else None
                        got.append(resemblance(s.csp.example, s.model, ground=floor))

                def med(key: str, rs: list = got) -> float:  # type: ignore[type-arg]
                    return statistics.median(getattr(r, key) for r in rs) if rs else float("nan")

                print(f"{name:<14} {size:<6} {choice:<9} {len(got):>3}/{seeds:<2} "
                      f"{statistics.mean(times):>6.2f} {med('solids'):>6.0f} "
                      f"{med('median_volume_ratio'):>8.3f} {med('edge_kinds'):>7.2f} "
                      f"{med('face_orientations'):>5.2f} {med('floating'):>6.0f}")  # fmt: skip


if __name__ == "__main__":
    main()
