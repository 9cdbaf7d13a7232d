"""2007 paper Sec. 3.3 (resemblance, Eq. 2-6) and Sec. 4.2 (soft constraints, Metropolis):
what each does, measured (ledger rows P15, P17 of papers/merrell-2007-i3d).

    python experiments/soft_resemblance.py [--seeds 10] [--out experiments/results/soft_resemblance]

(a) Resemblance: the pattern-statistics distance (total variation between the 2-wide
    sub-block frequencies of output and example, ``csplab.experiments.measures``) of
    Alg. 3.1 outputs with the uniform, weighted and resemblance choices, and of
    modify-in-blocks with uniform and resemblance.
(b) Soft constraints: the energy after each sweep of modify-in-blocks with and without
    Metropolis acceptance, for a ring-shaped region on ``loops`` (the paper's Fig. 13:
    models in the shape of a symbol) and a dome height field on ``city``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import csplab
from csplab import load_example
from csplab.experiments.base import background_labels
from csplab.experiments.measures import pattern_distance
from csplab.grids import from_example
from csplab.soft import Energy, HeightField, Region


def resemblance(seeds: int) -> list[str]:
    rows = ["| example | size | solver | choice | solved | pattern distance (mean ± sd) | mean s |",
            "|---|---|---|---|---|---|---|"]  # fmt: skip
    for ex in ("loops", "fig3_10", "fig3_6a", "fig3_4a", "line"):
        E = load_example(ex)
        P = from_example(E, (32, 32))
        for solver, choice, kw in [
            ("catalog", "uniform", {"restarts": 20}),
            ("catalog", "weighted", {"restarts": 20}),
            ("catalog", "resemblance", {"restarts": 20}),
            ("blocks", "uniform", {"block": 8}),
            ("blocks", "resemblance", {"block": 8}),
        ]:
            ds, ts, ok = [], [], 0
            for seed in range(seeds):
                t = time.perf_counter()
                r = csplab.solve(P, solver, rng=seed, choice=choice, order="scan:yx", **kw)
                ts.append(time.perf_counter() - t)
                if r.ok:
                    ok += 1
                    ds.append(pattern_distance(r.grid, E.labels))
            d = f"{np.mean(ds):.3f} ± {np.std(ds):.3f}" if ds else "-"
            rows.append(f"| {ex} | 32x32 | {solver} | {choice} | {ok}/{seeds} | {d} | "
                        f"{np.mean(ts):.3f} |")  # fmt: skip
            print(rows[-1], flush=True)
    return rows


def soft(seeds: int) -> list[str]:
    rows = ["| model | energy | Metropolis | energy after each sweep (mean over seeds) | "
            "rejected | mean s |", "|---|---|---|---|---|---|"]  # fmt: skip
    loops = load_example("loops")
    P = from_example(loops, (32, 32))
    yy, xx = np.mgrid[0:32, 0:32]
    r = np.hypot(xx - 15.5, yy - 15.5)
    paths = [b for b in range(loops.K) if loops.names[b] != "empty"]
    ring = Energy([Region((r > 6) & (r < 13), paths, outside=True)])
    city = load_example("city")
    Q = from_example(city, (24, 24, 8), boundary="auto")
    yy, xx = np.mgrid[0:24, 0:24]
    dome = np.clip(7 - 0.5 * np.hypot(xx - 11.5, yy - 11.5), 1, 7)
    hf = Energy([HeightField(dome, empty=background_labels(city)[:1])])
    for name, prob, en, block, T in [("loops 32x32", P, ring, 6, 2.0),
                                     ("city 24x24x8", Q, hf, 8, 5.0)]:  # fmt: skip
        for metro in (False, True):
            traces, rej, ts = [], [], []
            for seed in range(seeds):
                t = time.perf_counter()
                kw = {"energy": en, "temperature": T, "cooling": 0.7} if metro else {}
                res = csplab.solve(prob, "blocks", rng=seed, block=block, sweeps=8, **kw)
                ts.append(time.perf_counter() - t)
                assert res.ok and prob.is_solution(res.grid)
                if metro:
                    traces.append(res.stats["energies"])
                    rej.append(res.stats["metropolis_rejected"])
                else:
                    traces.append([en(res.grid)])
            tr = np.mean(np.array(traces, dtype=float), axis=0)
            what = ", ".join(f"{x:.0f}" for x in tr) if metro else f"(final) {tr[-1]:.0f}"
            term = en.terms[0].__class__.__name__
            rej_s = f"{np.mean(rej) if rej else 0:.0f}"
            yes = "yes" if metro else "no"
            rows.append(f"| {name} | {term} | {yes} | {what} | {rej_s} | {np.mean(ts):.2f} |")
            print(rows[-1], flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "soft_resemblance"))
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    text = ["# Resemblance (2007 paper Eq. 2-6) and soft constraints (Sec. 4.2)", "",
            f"`python experiments/soft_resemblance.py --seeds {a.seeds}`; csplab "
            f"{csplab.__version__}.", "", "## Resemblance: pattern distance to the example", "",
            *resemblance(a.seeds), "", "## Soft constraints: energy over sweeps", "",
            *soft(a.seeds), "",
            f"Total {time.perf_counter() - t0:.0f} s on this machine."]  # fmt: skip
    (out / "soft_resemblance.md").write_text("\n".join(text) + "\n")
    print(f"wrote {out / 'soft_resemblance.md'}")


if __name__ == "__main__":
    main()
