"""Sec. 3.2 and Theorems 5.2.1 / 5.2.3: exact counts D_E(n), bounds, entropy, grammars.

* D_E0 = 1 and D_E1 = 2 at sizes up to 30x30; D_E3 = 0 above 3x3;
* Theorem 3.2.1's lower bound and Theorem 3.2.2's upper bound on ``line`` (H = 2x1);
* entropy per cell of the built-in 2D examples from strips of growing width;
* transfer matrix vs Ganak on the same problems (agreement and time);
* Theorem 5.2.1: every consistent model of the abc example inside empty space, enumerated,
  has only rows a^i b^i c^i;
* Theorem 5.2.3: the regular grammar of 1D examples generates exactly the consistent
  models up to length 12.

Writes experiments/results/issue5/counting.json. Run from the repository root:
python experiments/counting_sec_3_2.py
"""

from __future__ import annotations

import importlib.util
import json
import math
import time
from pathlib import Path

import numpy as np

from csplab import ExampleModel, example_names, load_example
from csplab.complexity.grammar import RegularGrammar, abc_example, abc_rows_ok
from csplab.count import count_solutions, entropy_per_cell, lower_bound_3_2_1
from csplab.engine.sat import enumerate_solutions
from csplab.grids import from_example

OUT = Path(__file__).resolve().parent / "results" / "issue5"


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    res: dict[str, object] = {}
    sizes = [(1, 1), (2, 3), (5, 5), (8, 13), (16, 9), (30, 30)]
    res["D_E0"] = {
        f"{a}x{b}": int(count_solutions(from_example(load_example("fig3_1a"), (a, b))))
        for a, b in sizes
    }
    res["D_E1"] = {
        f"{a}x{b}": int(count_solutions(from_example(load_example("fig3_1b"), (a, b))))
        for a, b in sizes
    }
    E3 = load_example("fig3_1d")
    res["D_E3"] = {
        f"{a}x{b}": int(count_solutions(from_example(E3, (a, b))))
        for a, b in [(3, 3), (2, 3), (4, 3), (3, 4), (5, 5), (10, 10)]
    }
    E = load_example("line")
    rows = []
    for shape in [(3, 2), (6, 4), (9, 6), (12, 8), (6, 30), (12, 40)]:
        t0 = time.perf_counter()
        c = count_solutions(from_example(E, shape))
        lo = lower_bound_3_2_1(E, shape)
        rows.append({
            "size": f"{shape[0]}x{shape[1]}",
            "log2_D": c.log2(),
            "log2_lower_3_2_1": math.log2(lo),
            "log2_upper_3_2_2": math.prod(shape) * math.log2(E.K),
            "holds": lo <= int(c) <= E.K ** math.prod(shape),
            "time_s": time.perf_counter() - t0,
            "max_states": c.stats.get("max_states"),
        })  # fmt: skip
    res["bounds_line"] = rows
    ent = {}
    for name in example_names():
        Ex = load_example(name)
        if Ex.ndim != 2 and not (Ex.ndim == 3 and Ex.shape[2] == 1):
            continue
        ent[name] = [
            round(entropy_per_cell(Ex, (w,), (12, 24))["bits_per_cell"], 5) for w in (2, 4, 6, 8)
        ]
    res["entropy_bits_per_cell_widths_2_4_6_8"] = ent
    if importlib.util.find_spec("pyganak") is not None:
        cmp = []
        for shape in [(6, 6), (8, 8), (10, 10)]:
            P = from_example(E, shape)
            a = count_solutions(P, "transfer")
            b = count_solutions(P, "ganak")
            cmp.append({"size": f"{shape[0]}x{shape[1]}", "equal": int(a) == int(b),
                        "transfer_s": a.time_s, "ganak_s": b.time_s})  # fmt: skip
        res["transfer_vs_ganak_line"] = cmp
    abc = []
    faces = {f: 0 for f in ("x-", "x+", "y-", "y+")}
    for shape in [(5, 5), (8, 7), (9, 9), (11, 9), (12, 11)]:
        P = from_example(abc_example(), shape, boundary=faces)
        n, iset = 0, set()
        for g in enumerate_solutions(P):
            iset.update(abc_rows_ok(g))
            n += 1
        abc.append({"size": f"{shape[0]}x{shape[1]}", "models": n,
                    "count": int(count_solutions(P)), "i_values": sorted(iset)})  # fmt: skip
    res["theorem_5_2_1_abc"] = abc
    gram = []
    rng = np.random.default_rng(5)
    for t in range(20):
        E1 = ExampleModel(rng.integers(0, 2 + t % 3, size=4 + t % 5))
        G = RegularGrammar.from_example(E1)
        counts = G.count(12)
        same_counts = all(
            counts[n] == int(count_solutions(from_example(E1, (n,)))) for n in range(1, 13)
        )
        checked_sets = 0
        same_sets = True
        for n in range(1, 13):
            if counts[n] <= 5000:
                sols = {
                    tuple(int(v) for v in g) for g in enumerate_solutions(from_example(E1, (n,)))
                }
                same_sets &= sols == G.generate(n)[n]
                checked_sets += 1
        gram.append(
            {
                "example": E1.labels.tolist(),
                "counts_equal": same_counts,
                "sets_equal": same_sets,
                "lengths_with_sets_compared": checked_sets,
            }
        )
    res["theorem_5_2_3_grammar"] = gram
    (OUT / "counting.json").write_text(json.dumps(res, indent=1))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
