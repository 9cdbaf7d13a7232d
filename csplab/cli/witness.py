"""``csplab witness``: find a failing run of Alg. 3.1 (smallest size, shortest prefix).

Search every choice sequence of Alg. 3.1 on small outputs (exhaustive, memoised), then
random runs on growing outputs within ``--time-limit``; shrink a failing run (output size
first, then choices) and print it, its seed, the first choice outside the exact catalog C*
and what was searched.

Exit codes: 0 no failure exists up to ``--max-size`` (exhaustive), 1 a failing run was
found (printed; ``--out`` saves it), 3 nothing found but the search was not exhaustive,
2 bad input.
"""

from __future__ import annotations

import argparse

from csplab.analysis import find_failure
from csplab.analysis.witness import searched
from csplab.cli._analysis import (
    ORDER_HELP,
    add_witness_out,
    open_analysis,
    print_verdict,
    report_run,
)
from csplab.cli.common import add_model_args, check_time_limit


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_args(p)
    p.add_argument("--max-size", default=None,
                   help="largest output searched (default: 4x4 for 2D examples; 3D: growing "
                   "sizes until the time limit)")  # fmt: skip
    p.add_argument("--time-limit", type=float, default=60.0,
                   help="seconds for the whole search and shrinking (default 60)")  # fmt: skip
    p.add_argument(
        "--boundary",
        default=None,
        help="boundary of the outputs: auto, none or face=label,... (default none; a "
        "tileset: its own boundary rules)",
    )
    p.add_argument("--order", default="scanline", help=ORDER_HELP + "; or random, min-entropy")
    p.add_argument("--exhaustive-cells", type=int, default=20,
                   help="outputs up to this many cells are searched exhaustively")  # fmt: skip
    p.add_argument("--runs", type=int, default=30, help="random runs per larger size")
    p.add_argument("--late", action="store_true",
                   help="look for a late failure: inconsistent while C is not empty")  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of the random runs")
    add_witness_out(p)
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    check_time_limit(args.time_limit)
    E = open_analysis(args)
    v = find_failure(
        E,
        order=args.order,
        max_size=args.max_size,
        exhaustive_cells=args.exhaustive_cells,
        random_runs=args.runs,
        rng=args.seed,
        late=args.late,
        time_limit=args.time_limit,
        boundary=args.boundary,
    )
    print_verdict(v, args.json)
    if not args.json:
        print(f"  searched: {searched(v.stats)}")
    if v.holds is False:
        report_run(v.witness, E, args)
        return 1
    return 0 if v.holds else 3
