"""Theorem 3.3.4 / Fig. 3.7: verify the planar 3-SAT -> model-consistency reduction.

For 300 random planar 3-SAT formulas (3..8 variables, up to 12 clauses; 150 with signs
chosen to make them unsatisfiable, 75 "near" (unsatisfiable with one clause redrawn, few
models), 75 with random signs) check:

* formula satisfiable (pysat on the CNF)  <=>  M_t completable (SAT on the grid),
* a completion decodes to a satisfying assignment,
* every satisfying assignment (all enumerated) encodes to a grid with zero violations,

and measure what the thesis predicts: how often the catalog C (arc consistency) stays
non-empty on unsatisfiable instances and how often one run of Alg. 3.1 (scanline order)
fails on satisfiable ones. Writes experiments/results/issue5/planar3sat.json (one record per
instance and a summary) and the pictures fig3_7c.png, fig3_7d.png, gadget_labels.png.

Run from the repository root:  python experiments/reduction_planar3sat.py [--n 300]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from csplab.complexity.draw import label_sheet, save_reduction_png
from csplab.complexity.planar3sat import random_planar3sat
from csplab.complexity.reduction import reduce_planar3sat, verify_instance

OUT = Path(__file__).resolve().parent / "results" / "issue5"
UNSAT_SHAPES = [(6, 8), (7, 9), (7, 10), (8, 10), (8, 11), (8, 12)]


def plan(n: int) -> list[tuple[str, int, int, int]]:
    cases = []
    for i in range(n // 2):
        v, m = UNSAT_SHAPES[i % len(UNSAT_SHAPES)]
        cases.append(("unsat", v, m, 10_000 + i))
    for i in range(n // 4):
        v, m = UNSAT_SHAPES[i % len(UNSAT_SHAPES)]
        cases.append(("near", v, m, 20_000 + i))
    for i in range(n - len(cases)):
        v = 3 + i % 6
        m = 1 + (i * 7) % min(12, 2 * (v - 2))
        cases.append(("random", v, m, 30_000 + i))
    return cases


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=300)
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    records = []
    t_all = time.perf_counter()
    for mode, v, m, seed in plan(args.n):
        t0 = time.perf_counter()
        f = random_planar3sat(v, m, rng=seed, signs=mode)
        t_gen = time.perf_counter() - t0
        r = verify_instance(f, rng=seed)
        r.update(mode=mode, t_generate=t_gen)
        records.append(r)
        if not r["agree"]:
            print("DISAGREEMENT", json.dumps(r, default=str))
    sat = [r for r in records if r["sat"]]
    uns = [r for r in records if not r["sat"]]
    summary = {
        "instances": len(records),
        "satisfiable": len(sat),
        "unsatisfiable": len(uns),
        "agree": sum(r["agree"] for r in records),
        "sat_iff_completable": sum(r["sat"] == r["completable"] for r in records),
        "decoded_ok": sum(bool(r["decoded_ok"]) for r in sat),
        "assignments_encoded_ok": sum(r["encoded_ok"] for r in records),
        "assignments_total": sum(r["models"] for r in records),
        "catalog_nonempty_on_unsat": sum(r["catalog_nonempty"] for r in uns),
        "alg31_failed_on_sat": sum(r["alg31"] != "solved" for r in sat),
        "max_vars": max(r["nvars"] for r in records),
        "max_clauses": max(r["nclauses"] for r in records),
        "area_min": min(r["area"] for r in records),
        "area_max": max(r["area"] for r in records),
        "area_mean": float(np.mean([r["area"] for r in records])),
        "t_grid_sat_mean_s": float(np.mean([r["t_grid_sat"] for r in records])),
        "t_grid_sat_max_s": float(np.max([r["t_grid_sat"] for r in records])),
        "t_total_s": time.perf_counter() - t_all,
    }
    # area vs size: least squares area ~ a (n + m) m, reported per (n, m)
    by: dict[str, list[int]] = {}
    for r in records:
        by.setdefault(f"{r['nvars']}x{r['nclauses']}", []).append(r["area"])
    summary["area_by_vars_x_clauses"] = {k: float(np.mean(a)) for k, a in sorted(by.items())}
    # pictures: a satisfiable instance like Fig. 3.7(c)/(d)
    f = random_planar3sat(6, 8, rng=1, signs="near")
    red = reduce_planar3sat(f)
    save_reduction_png(red.fixed, OUT / "fig3_7c.png", 10)
    save_reduction_png(red.encode(f.models()[0]), OUT / "fig3_7d.png", 10)  # type: ignore[arg-type]
    label_sheet().save(OUT / "gadget_labels.png")
    summary["pictures"] = {
        "formula": str(f),
        "M_t": "experiments/results/issue5/fig3_7c.png",
        "solution": "experiments/results/issue5/fig3_7d.png",
        "labels": "experiments/results/issue5/gadget_labels.png",
    }
    (OUT / "planar3sat.json").write_text(
        json.dumps({"summary": summary, "instances": records}, indent=1, default=str)
    )
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
