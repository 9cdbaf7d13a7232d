"""``csplab world``: a rectangle of an endless, chunked, seed-deterministic world.

Generate the region X0:X1,Y0:Y1 of an endless world of MODEL (:class:`csplab.World`):
chunks of ``--chunk`` cells, infinite in x and y (a 3D world has the chunk's height), whose
content depends only on the model, the seed, the settings and the coordinates -- not on
the visit order, the number of ``--jobs`` or earlier runs. Blocks that random choice cannot
complete are completed exactly (SAT with their border fixed); the path the seams take is
printed (``proved-infallible`` when every cell has a label whatever its neighbours hold, so
no block can fail; else ``general``). The stitched region is
checked against the model (its violations are printed). Constraints file entries with
``"per": "chunk"`` (count and connected) hold in every chunk; other entries are refused with
the reason.

Exit codes: 0 the region is consistent (and every chunk meets its per-chunk constraints),
1 it has violations, 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import re
import time

from csplab.cli.common import (
    add_constraints_arg,
    add_model_args,
    check_output_path,
    model_from_args,
)
from csplab.errors import InputError
from csplab.grids import parse_boundary, parse_shape


def add_arguments(p: argparse.ArgumentParser) -> None:
    from csplab.io.registry import formats

    add_model_args(p)
    p.add_argument("--chunk", default="32x32", help="chunk size XxY or XxYxZ (default 32x32)")
    p.add_argument("--seed", type=int, default=0, help="the world's seed (default 0)")
    p.add_argument(
        "--region",
        required=True,
        help="cells X0:X1,Y0:Y1 (half-open; a negative start needs --region=-64:64,0:64)",
    )
    kinds = ", ".join(f"{f.extensions[0]}" for f in formats(writable=True))
    p.add_argument("--out", help=f"output file, format by extension: {kinds}")
    p.add_argument(
        "--boundary",
        default="auto",
        help="3D worlds: z faces, 'auto' (ground and sky of the model), 'none' or "
        "'z-=1,z+=0' (x/y faces do not exist in an endless world)",
    )
    p.add_argument(
        "--block", help="the blocks' size BXxBY (default: the chunk's, at most 12x12)"
    )
    p.add_argument(
        "--passes", type=int, default=1,
        help="shifted colour passes of blocks after the isolated blocks (1)",
    )  # fmt: skip
    p.add_argument("--retries", type=int, default=20, help="Alg. 3.1 retries per block (20)")
    p.add_argument(
        "--seams", choices=("auto", "general"), default="auto",
        help="auto (default): when every cell of the model has a label whatever its "
        "neighbours hold, no block can fail: one Alg. 3.1 run each, no retry or exact "
        "completion (the same bytes); general: always keep them ready",
    )  # fmt: skip
    p.add_argument(
        "--exact",
        choices=("sat", "backtrack", "none"),
        default="sat",
        help="exact completion of a block random choice cannot complete (sat)",
    )
    p.add_argument(
        "--order", help="Alg. 3.1's cell order in a block (default: the model format's, else "
        "scanline)"
    )  # fmt: skip
    p.add_argument(
        "--choice", help="Alg. 3.1's label choice (default: the model format's, else uniform)"
    )
    p.add_argument("--jobs", type=int, default=1, help="worker processes (same output)")
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="solve blocks on Dask: 'local' (a LocalCluster "
        "of --jobs processes) or a scheduler address such as tcp://host:8786 (same output)"
    )  # fmt: skip
    p.add_argument("--store", help="SQLite file keeping generated chunks across runs")
    add_constraints_arg(p)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")


def parse_region(text: str) -> tuple[tuple[int, int], tuple[int, int]]:
    """``"X0:X1,Y0:Y1"`` as ``((X0, X1), (Y0, Y1))``.

    Examples
    --------
    >>> parse_region("0:512,-64:64")
    ((0, 512), (-64, 64))
    """
    m = re.fullmatch(r"\s*(-?\d+):(-?\d+)\s*,\s*(-?\d+):(-?\d+)\s*", text)
    if not m:
        raise InputError(f"--region must be X0:X1,Y0:Y1 such as 0:512,0:512, not {text!r}")
    x0, x1, y0, y1 = (int(v) for v in m.groups())
    if x1 <= x0 or y1 <= y0:
        raise InputError(f"--region {text!r} is empty (X1 > X0 and Y1 > Y0 needed)")
    return (x0, x1), (y0, y1)


def run(args: argparse.Namespace) -> int:
    import sys

    from csplab.io import write_labels
    from csplab.world import World

    xs, ys = parse_region(args.region)
    chunk = parse_shape(args.chunk, what="--chunk")
    if args.jobs < 1:
        raise InputError("--jobs must be >= 1")
    if args.out:
        check_output_path(args.out, "--out")
    model = model_from_args(args)
    from csplab.io.registry import synthesis_defaults

    suggested, _ = synthesis_defaults(model)
    order = args.order or suggested.get("order", "scanline")
    choice = args.choice or suggested.get("choice", "uniform")
    constraints, per_chunk = [], []
    if args.constraints:  # read against the chunk's grid; the world refuses global ones
        from csplab.io.constraints import read_world_constraints
        from csplab.world import world_problem, world_zfaces

        zfaces = world_zfaces(model, chunk, parse_boundary(args.boundary) or "none")
        height = chunk[2] if len(chunk) == 3 else None
        on, _ = world_problem(model, chunk[:2], height, zfaces)
        for path in args.constraints:
            whole, per = read_world_constraints(path, on)
            constraints += whole
            per_chunk += per
    t0 = time.perf_counter()
    world = World(
        model, seed=args.seed, chunk=chunk, boundary=parse_boundary(args.boundary) or "none",
        passes=args.passes, retries=args.retries, exact=args.exact, order=order,
        choice=choice, workers=args.jobs if args.jobs > 1 else 0, store=args.store,
        scheduler=args.scheduler, constraints=constraints, chunk_constraints=per_chunk,
        block=parse_shape(args.block, what="--block") if args.block else None,
        seams=args.seams,
    )  # fmt: skip
    try:
        grid = world.region(xs, ys, progress=True)
        unmet = world.unmet_chunks(xs, ys)  # chunks breaking a per-chunk constraint
    finally:
        world.close()
    seconds = time.perf_counter() - t0
    violations = len(world.problem(grid.shape).violations(grid))
    n_chunks = len(list(world.chunks_in(xs, ys)))
    summary = {
        "model": getattr(model, "name", "") or args.model,
        "seed": args.seed,
        "chunk": list(chunk),
        "region": [list(xs), list(ys)],
        "shape": list(grid.shape),
        "chunks": n_chunks,
        "order": order,
        "choice": choice,
        "blocks": dict(world.stats),
        "seams": world.seams,
        "seams_why": world.seams_why,
        "violations": violations,
        "chunks_breaking_constraints": [list(c) for c in unmet],
        "dropped_constraints": world.dropped,
        "seconds": round(seconds, 3),
        "out": args.out,
    }
    if args.out:
        write_labels(grid, args.out, model=model, periodic=False)
    if args.json:
        print(json.dumps(summary))
    else:
        st = world.stats
        print(
            f"world {summary['model']} seed {args.seed}: region {args.region} "
            f"{'x'.join(map(str, grid.shape))}, {n_chunks} chunks of "
            f"{'x'.join(map(str, chunk))}, {violations} violations ({seconds:.2f} s; blocks: "
            f"{st['alg31']} Alg. 3.1, {st['exact']} exact, {st['kept']} kept, "
            f"{st['stored']} chunks from the store)"
        )
        print(f"  seams: {world.seams} ({world.seams_why})")
        if per_chunk:
            print(f"  per-chunk constraints: {len(unmet)} of {n_chunks} chunks break them"
                  + (f" {unmet[:5]}" if unmet else ""))  # fmt: skip
        if args.out:
            print(f"  written: {args.out}", file=sys.stderr)
    return 1 if violations or unmet else 0
