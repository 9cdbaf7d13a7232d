"""``csplab baseline``: run a baseline (texture synthesis ...) on the inputs of model synthesis.

Run a baseline method on an example grid and write its output grid, an ordinary grid:
``csplab check MODEL OUT`` then counts the adjacency constraints it breaks. Baselines:
texture (Efros & Leung 1999 sampling or Kwatra et al. 2003 graph-cut patches) on example
grids; geometry (Lagae et al. 2004) and retarget (Wu et al.) on closed meshes, writing a
mesh.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np

from csplab.cli.common import (
    add_model_args,
    check_output_path,
    input_files,
    model_from_args,
)
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    from csplab.baselines import BASELINES

    p.add_argument("name", choices=list(BASELINES), help="the baseline")
    add_model_args(p, help="built-in example name or example grid file")
    p.add_argument("--size", required=True, help="output size such as 20x20 or 20x20x10")
    p.add_argument("--seed", type=int, help="random seed (default: fresh, printed)")
    p.add_argument("--out", help="output grid (.npy, .grid, .txt, .png, ...)")
    seen: set[str] = set()
    for b in BASELINES.values():
        for o in b.options:
            if o.name in seen:
                continue
            seen.add(o.name)
            p.add_argument(f"--{o.name}", type=o.type, help=f"{o.help} (default {o.default})")
    from csplab.cli.common import add_memory_limit_arg

    add_memory_limit_arg(p)
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from csplab.baselines import BASELINES, run_baseline
    from csplab.example import ExampleModel
    from csplab.grids import from_example, parse_shape
    from csplab.io import write_labels
    from csplab.rng import make_rng

    b = BASELINES[args.name]
    example = model_from_args(args)
    if b.gives == "mesh":
        return _mesh(args, b, example)
    if not isinstance(example, ExampleModel):
        raise InputError(f"{args.model}: baseline {args.name!r} takes an example grid")
    size = parse_shape(args.size, what="--size")
    if len(size) < example.ndim:
        size = (*size, *([1] * (example.ndim - len(size))))
    if args.out:
        from csplab.io.registry import output_format

        output_format(args.out)  # a bad extension: refused before the work
        check_output_path(args.out, "--out", inputs=input_files(args))
    opts = {o.name: getattr(args, o.name) for o in b.options if getattr(args, o.name) is not None}
    _, seed = make_rng(args.seed)
    t0 = time.perf_counter()
    grid = run_baseline(args.name, example, size, rng=seed, memory_limit=args.memory_limit, **opts)
    dt = time.perf_counter() - t0
    P = from_example(example, size)
    v = P.violations(grid)
    if args.out:
        write_labels(grid, args.out, names=example.names, name=example.name, model=example)
    if args.json:
        print(json.dumps({"baseline": args.name, "example": example.name, "size": list(size),
                          "seed": seed, "time_s": dt, "violations": len(v),
                          "arcs": int(np.asarray(P.arcs).shape[0]), "out": args.out}))  # fmt: skip
    else:
        print(
            f"{args.name}: {example.name or args.model} {'x'.join(map(str, size))} in {dt:.3f} s, "
            f"seed {seed}; {len(v)} adjacency violations (of {len(P.arcs)} arcs; model "
            "synthesis has 0)"
        )
        if args.out:
            print(f"  wrote {args.out}")
    return 0


def mesh_samples(
    example: Any, spacings: tuple[int, ...], name: str, resolution: int | None
) -> tuple[tuple[int, ...], float]:
    """``--size`` of a mesh baseline, in plane spacings of the example (as ``csplab
    synthesize`` counts them: the lattice spacing of its vertices), as samples of the
    baseline's grid (``resolution`` along the example's longest side): ``(samples,
    spacing)``. Asking for more spacings always gives a larger output.

    Examples
    --------
    >>> from csplab.examples import load_model
    >>> mesh_samples(load_model("tetrahedron"), (8, 8, 8), "retarget", 24)
    ((192, 192, 192), 1.0)
    """
    import math

    from csplab.continuous.lattice import Lattice
    from csplab.continuous.polyhedra import PolyhedralModel

    if not isinstance(example, PolyhedralModel):
        raise InputError(f"the {name} baseline takes a polyhedral model (a closed mesh)")
    res = int(resolution if resolution is not None else 24)
    b = np.asarray(example.bounds, dtype=np.float64)
    longest = float((b[3:] - b[:3]).max())
    unit = float(Lattice.of_model(example).spacing)
    # retarget: ``res`` voxels along the longest side; geometry: ``res`` samples, res - 1 gaps
    per = (res if name == "retarget" else res - 1) / longest
    samples = tuple(max(1, math.ceil(s * unit * per - 1e-9)) for s in spacings)
    return samples, unit


def _mesh(args: argparse.Namespace, b: object, example: object) -> int:
    """A baseline that makes a mesh: written by extension (.obj, .stl, .off, .ply)."""
    from pathlib import Path

    from csplab.baselines import run_baseline
    from csplab.grids import parse_shape
    from csplab.rng import make_rng

    spacings = parse_shape(args.size, what="--size")
    if len(spacings) != 3:
        raise InputError(f"--size {args.size}: the {args.name} baseline needs three sides")
    size, unit = mesh_samples(example, spacings, args.name, getattr(args, "resolution", None))
    if args.out:
        check_output_path(args.out, "--out", inputs=input_files(args))
        if Path(args.out).suffix.lower() not in (".obj", ".stl", ".off", ".ply"):
            raise InputError(f"--out {args.out}: a mesh file (.obj, .stl, .off, .ply)")
    names = [o.name for o in getattr(b, "options", ())]
    opts = {k: getattr(args, k) for k in names if getattr(args, k) is not None}
    _, seed = make_rng(args.seed)
    t0 = time.perf_counter()
    mesh = run_baseline(args.name, example, size, rng=seed, **opts)
    dt = time.perf_counter() - t0
    if args.out:
        from csplab.io.common import write_atomic

        out = Path(args.out)
        write_atomic(out, mesh.export(file_type=out.suffix.lstrip(".").lower()))
    info = {"baseline": args.name, "size": list(spacings), "samples": list(size),
            "spacing": unit, "seed": seed, "time_s": dt,
            "faces": len(mesh.faces), "watertight": bool(mesh.is_watertight),
            "volume": float(mesh.volume), "out": args.out,
            **mesh.metadata.get("retarget", {})}  # fmt: skip
    if args.json:
        print(json.dumps(info))
    else:
        print(f"{args.name}: {'x'.join(map(str, spacings))} plane spacings of {unit:g} "
              f"({'x'.join(map(str, size))} samples) in {dt:.2f} s, seed {seed}; "
              f"{len(mesh.faces)} triangles, closed {info['watertight']}, volume "
              f"{info['volume']:.4g}")  # fmt: skip
        if "nodes" in info:
            print(f"  graph: {info['nodes']} nodes, {info['labels']} labels, optimized in "
                  f"{info['time_s']:.3f} s; principal offsets {info['principal']} voxels "
                  f"({info['dominant']} dominant)")  # fmt: skip
        if args.out:
            print(f"  wrote {args.out}")
    return 0
