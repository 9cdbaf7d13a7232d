"""Theorem 5.2.4: every word up to length 7, both built-in LBAs, model vs simulator.

For ``anbncn`` ({a^n b^n c^n : n >= 1}, 3280 words) and ``ww`` ({w w}, 255 words): the
direct simulator against the language's definition, and "the model with the input on row 1
is consistent" (arc consistency; SAT when it leaves a choice) against the simulator. Writes
experiments/results/issue5/lba.json.

Run from the repository root:  python experiments/lba_theorem_5_2_4.py [--max-len 7]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from csplab.complexity.lba import BUILTIN, LANGUAGES, all_words, lba_consistent, load_lba

OUT = Path(__file__).resolve().parent / "results" / "issue5"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-len", type=int, default=7)
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    res = {}
    for name in BUILTIN:
        M = load_lba(name)
        t0 = time.perf_counter()
        words = all_words(M.input_alphabet, args.max_len)
        sim_ok = model_ok = accepted = 0
        decided: dict[str, int] = {}
        max_shape = (0, 0)
        labels = 0
        for w in words:
            acc = M.accepts(w)
            sim_ok += acc == LANGUAGES[name](w)
            v = lba_consistent(M, w)
            model_ok += bool(v.holds) == acc
            accepted += acc
            decided[v.stats["decided_by"]] = decided.get(v.stats["decided_by"], 0) + 1
            max_shape = max(max_shape, tuple(v.stats["shape"]))
            labels = v.stats["labels"]
            if bool(v.holds) != acc:
                print("DISAGREEMENT", name, repr(w))
        res[name] = {
            "words": len(words),
            "accepted": accepted,
            "simulator_matches_language": sim_ok,
            "model_matches_simulator": model_ok,
            "decided_by": decided,
            "labels": labels,
            "largest_model": list(max_shape),
            "time_s": time.perf_counter() - t0,
        }
        print(name, json.dumps(res[name]))
    (OUT / "lba.json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
