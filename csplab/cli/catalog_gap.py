"""``csplab catalog-gap``: run Alg. 3.1 and check every chosen label against C* (Eq. 3.4).

For each step it prints the cell, the label and whether the label was in the exact catalog
C* (the partial model stayed completable); the first label that was in the catalog C but
not in C* is the moment the run was doomed (Fig. 3.5), and the report says how many steps
later Alg. 3.1 noticed (Fig. 3.6). ``--sizes`` also prints ``|C(p)|`` and ``|C*(p)|`` (one
SAT call per label). Exit codes: 0 every chosen label was in C*, 1 some was not (or the
problem is unsatisfiable), 2 bad input, 3 time limit.
"""

from __future__ import annotations

import argparse
import json

from csplab.cli.common import add_problem_args
from csplab.cli.explain import add_fixed_args, problem_with_fixed
from csplab.engine.alg31 import CHOICES, ORDERS
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_problem_args(p, size_required=True)
    add_fixed_args(p)
    p.add_argument("--seed", type=int, help="random seed of Alg. 3.1 (default: fresh, printed)")
    p.add_argument(
        "--order",
        default="scanline",
        help=f"cell order of Alg. 3.1: {', '.join(ORDERS)} (e.g. scan:yx)",
    )
    p.add_argument("--choice", choices=CHOICES, default="uniform")
    p.add_argument("--backend", help="pysat backend (default cadical195)")
    p.add_argument("--sizes", action="store_true", help="also count |C(p)| and |C*(p)|")
    p.add_argument("--steps", choices=["all", "summary"], default="all",
                   help="print every step (default) or only the summary")  # fmt: skip
    p.add_argument("--time-limit", type=float, help="seconds")
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from csplab.exact import catalog_gap

    if args.seed is not None and args.seed < 0:
        raise InputError("--seed must be non-negative")
    model, problem = problem_with_fixed(args)
    v = catalog_gap(problem, args.seed, order=args.order, choice=args.choice,
                    backend=args.backend, sizes=args.sizes, time_limit=args.time_limit)  # fmt: skip
    code = 3 if v.holds is None else (0 if v.holds else 1)
    if args.json:
        print(json.dumps(v.to_dict()))
        return code
    st = v.stats
    size = "x".join(map(str, problem.shape))
    print(f"{model.name or args.model} {size} (K={problem.K}), Alg. 3.1 {args.order}/"
          f"{args.choice}, seed {st.get('seed')}: {st.get('alg31_status')} after "
          f"{st.get('steps_taken', 0)} steps")  # fmt: skip
    if args.steps == "all":
        for t, row in enumerate(st.get("per_step", [])):
            cell, lab, inside = row[0], row[1], row[2]
            extra = f"  |C|={row[3]} |C*|={row[4]}" if len(row) > 3 and row[3] is not None else ""
            mark = "in C*" if inside else "NOT in C*"
            print(f"  step {t:>5}  cell {tuple(cell)}  label {problem.label_name(lab)}: "
                  f"{mark}{extra}")  # fmt: skip
    print(("ok: " if v.holds else "gap: " if v.holds is False else "undecided: ") + v.message)
    if "sat_calls" in st:
        print(f"  ({st['sat_calls']} SAT calls, {st.get('time_s', 0.0):.3f} s)")
    return code
