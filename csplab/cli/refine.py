"""``csplab refine``: look for an infallible refinement E_I of a fallible example (Sec. 3.3.8).

Search label splits (rename the occurrences of a label whose neighbour in one direction
lies in a set) for an example E_I with f(E_I) = E_F that the region prover shows
infallible and whose models map onto the example's (Eq. 3.13, checked by enumeration).

Exit codes: 0 found (E_I printed as a .grid file, or written with ``--out``), 3 none found
within the search bounds, 2 bad input.
"""

from __future__ import annotations

import argparse

from csplab.analysis import to_infallible
from csplab.cli._analysis import ORDER_HELP, load_example_model, print_verdict
from csplab.cli.common import add_model_args, check_output_path


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_args(p, help="built-in example name or example file")
    p.add_argument("--order", default="scanline", help=ORDER_HELP)
    p.add_argument("--regions", default="2x2,3x2,4x2",
                   help="region sizes the prover tries, comma separated")  # fmt: skip
    p.add_argument("--max-splits", type=int, default=2, help="new labels at most (default 2)")
    p.add_argument("--beam", type=int, default=20, help="search width (default 20)")
    p.add_argument("--out", help="write E_I to this .grid (or any example format) file")
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    if args.out:
        from csplab.io.registry import output_format

        output_format(args.out, gives="ExampleModel")  # a format that reads back as an example
        check_output_path(args.out, "--out")
    E = load_example_model(
        args.model, args.model_option,
        needs="refine splits the labels of an example grid's cells (Sec. 3.3.8)",
    )  # fmt: skip
    regions = [r.strip() for r in args.regions.split(",") if r.strip()]
    if E.ndim == 3 and args.regions == "2x2,3x2,4x2":
        regions = ["2x2x2"]
    v = to_infallible(
        E, order=args.order, regions=regions, max_splits=args.max_splits, beam=args.beam
    )
    print_verdict(v, args.json)
    if v.holds:
        EI = v.witness["example"]
        if not args.json:
            for s in v.witness["splits"]:
                print(
                    f"  label {s['new_label']} = the {E.label_name(s['label'])} with "
                    f"{s['where']} ({len(s['cells'])} cells)"
                )
            print(f"  f: {v.witness['map']} (new label -> label of {E.name or args.model})")
        if args.out:
            from csplab.io import write_example

            write_example(EI, args.out)
        elif not args.json:
            from csplab.io.gridtext import format_grid

            print(format_grid(EI))
        return 0
    return 3
