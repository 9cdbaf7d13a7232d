"""Run every full experiment behind the thesis ledger (papers/merrell-2009-thesis/README.md).

Each entry is one ``csplab experiment`` sweep; the reports go to ``experiments/results/<run>/``
and all trials into one results store (default ``results/thesis.sqlite``, not committed).
Re-running continues where a previous run stopped; ``--report-only`` only redraws.

    python experiments/run_all.py                      # everything (hours on 2 cores)
    python experiments/run_all.py --only fig3_8 blocksize --jobs 2
    python experiments/run_all.py --scheduler tcp://host:8786
    python experiments/run_all.py --quick              # the tiny versions (seconds)

Runs whose examples or solvers are not available here are skipped with a message.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent

# run name -> (experiment, overrides)
RUNS: dict[str, tuple[str, dict[str, Any]]] = {
    "fig3_8": ("fig3_8", {}),
    "fig3_8_noboundary": ("fig3_8", {"boundary": "none"}),
    "fig3_8_orders": (
        "fig3_8",
        {
            "examples": ["castle"],
            "solvers": [
                "catalog",
                "catalog@order=random",
                "catalog@order=min-entropy",
                "catalog@choice=weighted",
            ],
        },
    ),
    "fig3_8_solvers": (
        "fig3_8",
        {
            "examples": ["castle"],
            "sizes": "5:25:5",
            "seeds": 30,
            "solvers": ["catalog", "perfect", "hybrid", "backtrack", "sat", "cpsat"],
            "time_limit": 60.0,
        },
    ),
    "fig3_8_2d": (
        "fig3_8",
        {
            "examples": ["line", "fig3_4a", "fig3_5a", "fig3_15", "fig3_6a", "fig3_16", "fig3_10"],
            "boundary": "none",
            "order": "scan:yx",
        },
    ),
    "blocksize": ("blocksize", {}),
    "table3_1": ("table3_1", {"seeds": 3, "time_limit": 60.0}),
    "catalog_gap": ("catalog_gap", {}),
    "catalog_gap_castle": (
        "catalog_gap",
        {"examples": ["castle"], "order": "scanline", "boundary": "auto", "sizes": "6:14:2"},
    ),
    "sampling_bias": ("sampling_bias", {}),
    "table1_continuous": ("table1_continuous", {}),
    "baselines": ("baselines", {}),
    "table1_continuous_solvers": (
        "table1_continuous",
        {
            "solvers": ["catalog", "blocks", "sat"],
            "sizes_3d": dict.fromkeys(
                ["skyscrapers", "terrain", "fractals", "arches", "houses", "pentagons"], "20x20x8"
            ),
            "seeds": 2,
            "choices": ["weighted"],
            "grounds": ["auto"],
        },
    ),
    "constraints": ("constraints", {}),
}


def main(argv: list[str] | None = None) -> int:
    from csplab.errors import CsplabError
    from csplab.examples import ALIASES, EXAMPLES
    from csplab.experiments import run
    from csplab.solvers import available_solvers

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", nargs="+", choices=list(RUNS), help="run only these")
    p.add_argument("--jobs", type=int)
    p.add_argument("--scheduler")
    p.add_argument("--store", default="results/thesis.sqlite")
    p.add_argument("--out", default=str(ROOT / "results"))
    p.add_argument("--quick", action="store_true")
    p.add_argument("--report-only", action="store_true")
    p.add_argument("--rerun", action="store_true", help="run the sweeps' trials again")
    p.add_argument("--rerun-stale", action="store_true",
                   help="run again the stored trials that other code computed")  # fmt: skip
    a = p.parse_args(argv)
    installed = {s["name"] for s in available_solvers() if s.get("installed")}
    code = 0
    for name in a.only or list(RUNS):
        exp, over = RUNS[name]
        over = dict(over)
        if a.quick:  # keep the tiny sizes and seed counts of --quick
            for k in ("sizes", "size", "seeds", "blocks", "time_limit"):
                over.pop(k, None)
        missing = [e for e in over.get("examples", []) if e not in EXAMPLES and e not in ALIASES]
        if missing and len(missing) == len(over["examples"]):
            print(f"{name}: skipped, examples not available here: {', '.join(missing)}")
            continue
        if missing:
            over["examples"] = [e for e in over["examples"] if e not in missing]
            print(f"{name}: without {', '.join(missing)} (not available here)")
        if "solvers" in over:
            sol = [s for s in over["solvers"] if s.partition("@")[0].partition(":")[0] in installed]
            if sol != over["solvers"]:
                gone = sorted(set(over["solvers"]) - set(sol))
                print(f"{name}: without solvers {', '.join(gone)} (not installed here)")
            over["solvers"] = sol
        t0 = time.perf_counter()
        try:
            summary, report = run(
                exp, quick=a.quick, store=a.store, out=Path(a.out) / name, jobs=a.jobs,
                scheduler=a.scheduler, report_only=a.report_only, rerun=a.rerun,
                rerun_stale=a.rerun_stale,
                command=f"experiments/run_all.py --only {name}", **over,
            )  # fmt: skip
        except CsplabError as e:
            print(f"{name}: error: {e}", file=sys.stderr)
            code = 1
            continue
        print(f"{summary.line()} ({time.perf_counter() - t0:.0f} s)")
        stale = summary.stale_line()
        if stale:
            print(stale, file=sys.stderr)
        if summary.errors or report.missing:
            code = 1
    return code


if __name__ == "__main__":
    raise SystemExit(main())
