"""``csplab count``: count the models D_E(n) consistent with an example (thesis Sec. 3.2).

Count exactly (Python integers) the models of a given size consistent with an example:
transfer matrix over slices for models narrow in one or two axes, Ganak (#SAT) or SAT
enumeration otherwise; ``--method approxmc`` gives an (epsilon, delta) approximation.

Exit codes: 0 there is at least one model, 1 there is none, 3 ``--time-limit`` ran out
first (undecided), 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from csplab.cli.common import (
    add_memory_limit_arg,
    add_problem_args,
    check_time_limit,
    model_from_args,
    problem_from_args,
)
from csplab.errors import InputError
from csplab.example import ExampleModel


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_problem_args(p)
    p.add_argument(
        "--method",
        default="auto",
        choices=["auto", "transfer", "enumerate", "ganak", "approxmc"],
        help="counting method (default auto)",
    )
    p.add_argument("--epsilon", type=float, default=0.8, help="approxmc tolerance")
    p.add_argument("--delta", type=float, default=0.2, help="approxmc failure probability")
    p.add_argument("--seed", type=int, default=0, help="seed of the randomised counters")
    add_memory_limit_arg(p)
    p.add_argument(
        "--time-limit",
        type=float,
        metavar="S",
        help="stop counting after S seconds: exit 3, undecided (default: no limit; "
        "approxmc has none)",
    )
    p.add_argument(
        "--bounds",
        action="store_true",
        help="also print Theorem 3.2.1's lower and 3.2.2's upper bound",
    )
    p.add_argument(
        "--entropy",
        metavar="L1,L2",
        help="also estimate bits per cell from strips of this cross-section and lengths "
        "L1 < L2 along the last axis",
    )
    p.add_argument("--json", action="store_true")


#: the transfer-matrix method's own cap on frontier states (csplab.count.count_solutions)
MAX_STATES = 2_000_000


def transfer_states(shape: tuple[int, ...], K: int, memory_limit: float | None) -> int:
    """The frontier states the transfer-matrix count may keep within the memory budget
    (``--memory-limit``, default :func:`csplab.limits.memory_budget`), estimated from the
    sizes before the work: a step extends each of ``S`` states by each of ``K`` labels, so
    it holds ``S K`` rows of the frontier (about the cross-section, ``n / longest side``,
    cells of 4 bytes) and their counts; at most :data:`MAX_STATES`. Beyond it the count
    moves on to another method (``auto``) or says the model is too wide.

    Examples
    --------
    >>> transfer_states((3, 12), 2, None) == MAX_STATES
    True
    >>> transfer_states((40, 40, 10), 119, 1.0) < MAX_STATES
    True
    """
    from csplab.limits import memory_budget

    n = math.prod(int(s) for s in shape)
    frontier = n // max(1, max(int(s) for s in shape)) + 1
    per_state = K * (4 * (frontier + 1) + 16)  # labels of the S x K candidates + counts
    fit = int(memory_budget(memory_limit) // max(1, per_state))
    return max(1, min(MAX_STATES, fit))


def run(args: argparse.Namespace) -> int:
    from csplab.count import (
        CountTimeoutError,
        count_solutions,
        entropy_per_cell,
        lower_bound_3_2_1,
    )

    time_limit = check_time_limit(args.time_limit)
    example = model_from_args(args)
    problem = problem_from_args(args, example)
    try:
        c = count_solutions(
            problem, args.method, rng=args.seed, epsilon=args.epsilon, delta=args.delta,
            time_limit=time_limit, progress=True,
            max_states=transfer_states(problem.shape, problem.K, args.memory_limit),
        )  # fmt: skip
    except InputError as bad:  # the library names its arguments; the user typed flags
        msg = str(bad).replace("raise max_states", "raise --memory-limit")
        raise InputError(msg.replace("method='ganak'", "--method ganak")) from None
    except CountTimeoutError as stop:
        size = "x".join(map(str, problem.shape))
        if args.json:
            print(json.dumps({"example": example.name or args.model, "size": list(problem.shape),
                              "count": None, "undecided": str(stop)}))  # fmt: skip
        else:
            print(f"D_E({size}) undecided for {example.name or args.model}: {stop} "
                  f"(--time-limit {time_limit:g} s)")  # fmt: skip
        return 3
    out: dict[str, Any] = {"example": example.name or args.model, "size": list(problem.shape)}
    out.update(c.to_dict())
    if args.bounds and not isinstance(example, ExampleModel):
        raise InputError(
            f"{args.model}: --bounds (Theorem 3.2.1) needs an example grid's enclosed sets; "
            "this is a tileset, which has none"
        )
    if args.bounds:
        lo = lower_bound_3_2_1(example, problem.shape)
        hi_log2 = problem.n * math.log2(problem.K)
        out["lower_bound_3_2_1"] = str(lo)
        out["upper_bound_3_2_2_log2"] = hi_log2
        out["bounds_hold"] = (int(c) >= lo and c.log2() <= hi_log2 + 1e-9) if c.exact else None
    if args.entropy:
        try:
            L1, L2 = (int(v) for v in args.entropy.split(","))
        except ValueError:
            raise InputError(f"--entropy {args.entropy!r}: give two lengths such as 8,16") from None
        e = entropy_per_cell(example, problem.shape[:-1], (L1, L2), periodic=bool(args.periodic))
        out["entropy_bits_per_cell"] = e["bits_per_cell"]
    if args.json:
        print(json.dumps(out))
    else:
        size = "x".join(map(str, problem.shape))
        approx = "" if c.exact else f" (approximate, epsilon={args.epsilon}, delta={args.delta})"
        print(f"D_E({size}) = {int(c)}{approx} for {out['example']}")
        if int(c) > 0:
            print(f"  log2 = {c.log2():.4f}, {c.log2() / problem.n:.4f} bits per cell")
        print(f"  method {c.method} in {c.time_s:.3f} s")
        if args.bounds:
            print(f"  Theorem 3.2.1 lower bound {out['lower_bound_3_2_1']}; Theorem 3.2.2 "
                  f"upper bound k^n = 2^{hi_log2:.2f}; hold: {out['bounds_hold']}")  # fmt: skip
        if args.entropy:
            print(f"  entropy estimate: {out['entropy_bits_per_cell']:.4f} bits per cell")
    return 0 if int(c) > 0 else 1
