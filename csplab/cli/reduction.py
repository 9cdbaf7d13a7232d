"""``csplab reduction``: the thesis' reductions to model consistency, generated and checked.

``csplab reduction planar3sat`` builds Theorem 3.3.4's incomplete model for a random planar
3-SAT formula (Fig. 3.7); ``csplab reduction lba`` runs Theorem 5.2.4's construction for a
linear-bounded automaton on one input.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from csplab.cli.common import check_output_path
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    rs = p.add_subparsers(dest="which", metavar="REDUCTION", parser_class=type(p))
    rs.required = True
    q = rs.add_parser(
        "planar3sat",
        help="a random planar 3-SAT formula as an incomplete model (Fig. 3.7)",
        description="Draw a random planar 3-SAT formula as an incomplete model M_t over the "
        "gadget labels (Theorem 3.3.4, Fig. 3.7). With --check: the formula is satisfiable "
        "iff M_t is completable, a completion decodes to a satisfying assignment and every "
        "satisfying assignment encodes to a completion; exit 0 when all of that holds, 1 "
        "when something disagrees, 2 on bad input.",
    )
    q.add_argument("--vars", type=int, default=6, help="number of variables (>= 3)")
    q.add_argument("--clauses", type=int, default=8, help="number of clauses (<= 2 vars - 4)")
    q.add_argument("--seed", type=int, help="random seed (default: fresh, printed)")
    q.add_argument(
        "--signs",
        choices=["random", "unsat", "near"],
        default="random",
        help="literal signs: random, chosen to make the formula unsatisfiable, or "
        "unsatisfiable with one clause redrawn (few satisfying assignments)",
    )
    q.add_argument("--png", help="picture of M_t (Fig. 3.7(c)): white = free")
    q.add_argument("--solution-png", help="picture of a completion (Fig. 3.7(d)), if any")
    q.add_argument("--labels-png", help="picture of every gadget label and its sockets")
    q.add_argument("--scale", type=int, default=10, help="pixels per cell")
    q.add_argument("--check", action="store_true", help="verify the reduction on this formula")
    q.add_argument("--json", action="store_true")
    q.set_defaults(_sub=_run_planar)
    l = rs.add_parser(
        "lba",
        help="Theorem 5.2.4: an LBA run as a consistency problem",
        description="Build Theorem 5.2.4's model for a deterministic LBA with the input on "
        "row 1 and decide its consistency; compare with a direct simulation. SPEC is a "
        "built-in automaton (anbncn, ww) or a spec file (see csplab.complexity.lba). Exit 0 "
        "when the model is consistent and the automaton accepts, 1 when it is inconsistent "
        "(or the two disagree), 2 on bad input.",
    )
    l.add_argument("spec", metavar="SPEC", help="anbncn, ww or an LBA spec file")
    l.add_argument("--input", required=True, help="the input word, e.g. aabbcc ('' = empty)")
    l.add_argument("--rows", type=int, help="model height (default 2 max_steps(n) + 2)")
    l.add_argument("--show", action="store_true", help="print the computation row by row")
    l.add_argument("--png", help="picture of the completed model")
    l.add_argument("--json", action="store_true")
    l.set_defaults(_sub=_run_lba)


def run(args: argparse.Namespace) -> int:
    code: int = args._sub(args)
    return code


def _run_planar(args: argparse.Namespace) -> int:
    from csplab.complexity.draw import label_sheet, save_reduction_png
    from csplab.complexity.planar3sat import random_planar3sat
    from csplab.complexity.reduction import reduce_planar3sat, verify_instance
    from csplab.rng import make_rng

    if args.scale < 1:
        raise InputError("--scale must be positive")
    for flag in ("png", "solution_png", "labels_png"):
        if getattr(args, flag):
            check_output_path(getattr(args, flag), "--" + flag.replace("_", "-"))
    gen, seed = make_rng(args.seed)
    f = random_planar3sat(args.vars, args.clauses, rng=seed, signs=args.signs)
    red = reduce_planar3sat(f)
    out: dict[str, Any] = {"seed": seed, "formula": str(f), **red.stats()}
    if args.png:
        save_reduction_png(red.fixed, args.png, args.scale)
        out["png"] = args.png
    if args.labels_png:
        label_sheet().save(args.labels_png)
        out["labels_png"] = args.labels_png
    code = 0
    if args.check:
        v = verify_instance(f, rng=gen)
        out["check"] = {k: v[k] for k in (
            "sat", "models", "completable", "decoded_ok", "encoded_ok", "catalog_nonempty",
            "alg31", "planar", "agree", "t_grid_sat",
        )}  # fmt: skip
        code = 0 if v["agree"] else 1
    if args.solution_png:
        from csplab.complexity import complete_model

        models = f.models()
        grid = red.encode(models[0]) if len(models) else None
        if grid is None:
            r = complete_model(red.problem(), rng=gen)
            grid = r.grid if r.ok else None
        if grid is not None:
            save_reduction_png(grid, args.solution_png, args.scale)
            out["solution_png"] = args.solution_png
        else:
            out["solution_png"] = None
            print(f"  no completion: the formula is unsatisfiable; {args.solution_png} "
                  "not written", file=sys.stderr)  # fmt: skip
    if args.json:
        print(json.dumps(out, default=str))
        return code
    print(f"formula (seed {seed}): {f}")
    print(f"  M_t: {out['nx']}x{out['ny']} = {out['area']} cells, {out['free_cells']} free, "
          f"{out['not_gates']} NOT gates, {out['labels']} labels")  # fmt: skip
    for k in ("png", "labels_png", "solution_png"):
        if out.get(k):
            print(f"  wrote {out[k]}")
    if args.check:
        c = out["check"]
        comp = "completable" if c["completable"] else "not completable"
        print(
            f"  check: formula {'satisfiable' if c['sat'] else 'unsatisfiable'} "
            f"({c['models']} models), M_t {comp}"
            f", decoded ok: {c['decoded_ok']}, encodings ok: {c['encoded_ok']}/{c['models']}, "
            f"catalog C non-empty: {c['catalog_nonempty']}, Alg. 3.1: {c['alg31']}"
        )
        print("  reduction verified" if c["agree"] else "  REDUCTION DISAGREES")
    return code


def _run_lba(args: argparse.Namespace) -> int:
    from csplab.complexity.lba import lba_consistent, load_lba

    if args.png:
        check_output_path(args.png, "--png")
    M = load_lba(args.spec)
    sim = M.run(args.input)
    v = lba_consistent(M, args.input, args.rows)
    agree = bool(v.holds) == bool(sim["accepted"])
    out: dict[str, Any] = {
        "lba": M.name,
        "input": args.input,
        "accepted": sim["accepted"],
        "steps": sim["steps"],
        "rows_used": sim["rows"],
        "consistent": v.holds,
        "agree": agree,
        **v.stats,
    }
    if args.png and v.witness is not None:
        from csplab.render import save_png

        save_png(v.witness, args.png, names=None)
        out["png"] = args.png
    if args.json:
        print(json.dumps(out, default=str))
    else:
        shape = "x".join(map(str, v.stats["shape"]))
        print(f"{M.name} on {args.input!r}: simulator {'accepts' if sim['accepted'] else 'rejects'}"
              f" after {sim['steps']} steps; model {shape} (K={v.stats['labels']}) is "
              f"{'consistent' if v.holds else 'inconsistent'} "
              f"(decided by {v.stats['decided_by']})")  # fmt: skip
        if not agree:
            print("  SIMULATOR AND MODEL DISAGREE", file=sys.stderr)
        if args.show and v.witness is not None:
            from csplab.complexity.lba import build_construction

            con = build_construction(M)
            g = v.witness
            last = None
            for y in range(g.shape[1] - 1, -1, -1):
                row = " ".join(con.names[int(b)] for b in g[:, y])
                if row == last:
                    print("  ...")
                    break
                print(f"  {row}")
                last = row
        if out.get("png"):
            print(f"  wrote {out['png']}")
    return 0 if (v.holds and agree) else 1
