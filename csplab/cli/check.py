"""``csplab check``: count the violations of a grid or polygon output file against an example.

Check a grid against an example model or a tileset's rules, or an output polygon model
against a polygon example (Eq. 4.1 on the polygons).

Exit codes: 0 consistent, 1 it violates something or has unassigned cells (-1 in the .npy
of a failed or timed-out run), 2 bad input.
"""

from __future__ import annotations

import argparse
import json

from csplab.cli.common import (
    add_constraints_arg,
    add_problem_args,
    load_grid,
    model_from_args,
    problem_from_args,
)
from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    from csplab.io.registry import formats

    exts = ", ".join(e for f in formats(gives="ExampleModel", exact=True) for e in f.extensions)
    add_problem_args(p, size_required=False)
    p.add_argument(
        "grid",
        metavar="GRID",
        help=f"grid file to check ({exts}: label ids kept; .vox: colour b + 1 = label b)",
    )
    add_constraints_arg(p)
    p.add_argument(
        "--ground",
        default="auto",
        help="the faces (polyhedral models) or sides (polygon models) past which example and "
        "output continue, as synthesize --ground (the output's own box stands for its "
        "region); default auto: the example's own",
    )
    p.add_argument(
        "--spacing",
        type=float,
        help="polyhedral examples: the plane spacing the output was synthesized with (the "
        "example is compared as synthesize snaps it; default: what synthesize recorded in "
        "the output (.obj, .glb), else derived, as synthesize). --snap/--no-snap and --lines "
        "also default to the recorded settings; given options win",
    )
    p.add_argument(
        "--snap",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="polyhedral examples: as synthesize --snap (default: recorded, else no)",
    )
    p.add_argument(
        "--lines",
        choices=("auto", "lattice", "equal"),
        default=None,
        help="polyhedral examples: as synthesize --lines (how the example's faces were "
        "snapped; default: recorded, else auto)",
    )
    p.add_argument("--json", action="store_true")
    p.add_argument("--limit", type=int, default=10, help="violations to list")


def run(args: argparse.Namespace) -> int:
    if args.limit < 0:
        raise InputError("--limit must be >= 0")
    model = model_from_args(args)
    if isinstance(model, PolygonModel | PolyhedralModel):
        from csplab.cli import _continuous

        return _continuous.check(args, model)
    if args.spacing is not None or args.snap is not None or args.lines is not None:
        raise InputError("--spacing, --snap and --lines apply to continuous (polyhedral) models")
    grid = load_grid(args.grid, model.ndim, model)
    problem = problem_from_args(args, model, shape=tuple(grid.shape))
    unassigned = int((grid < 0).sum())
    v = problem.violations(grid)
    if args.json:
        print(
            json.dumps(
                {
                    "violations": len(v),
                    "arcs": int(v.arcs.size),
                    "cells": int(v.cells.size),
                    "constraints": list(v.constraints),
                    "unassigned": unassigned,
                    "shape": list(problem.shape),
                }
            )
        )
    else:
        print(f"{len(v)} violations in {args.grid} ({'x'.join(map(str, problem.shape))})")
        if unassigned:
            print(
                f"  {unassigned} of {grid.size} cells are unassigned (-1: the run that wrote "
                "the grid failed or timed out); they count as violations"
            )
        if len(v):
            print(v.describe(args.limit))
    return 0 if len(v) == 0 else 1
