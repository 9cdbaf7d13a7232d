"""The continuous-model branch of ``synthesize``, ``check`` and ``show`` (polygon models)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from csplab.continuous.model import PolygonModel
from csplab.errors import InputError
from csplab.grids import parse_shape


def region(args: argparse.Namespace) -> tuple[int, int]:
    """``--size WxH`` in line spacings."""
    if not args.size:
        raise InputError("--size is required (e.g. --size 40x30, in line spacings)")
    shp = parse_shape(args.size, what="--size")
    while len(shp) > 2 and shp[-1] == 1:
        shp = shp[:-1]
    if len(shp) != 2:
        raise InputError(f"--size {args.size}: a continuous 2D model needs WxH")
    return shp[0], shp[1]


def boundary_label(args: argparse.Namespace, example: PolygonModel) -> int:
    """``--boundary``: the label outside the region (default 0, empty space)."""
    b = args.boundary
    if b is None or b in ("auto", "none", "0"):
        return 0
    try:
        label = int(b)
    except ValueError:
        raise InputError(
            f"--boundary {b}: a continuous model takes one label for outside the region "
            "(e.g. --boundary 0)"
        ) from None
    if label not in (0, *example.labels):
        raise InputError(f"--boundary {b}: label {label} does not occur in {example.name}")
    return label


def polygon_output(path: str | None, flag: str = "--out") -> Any:
    """The polygon format for an output path (checked before any work), or None."""
    if not path:
        return None
    from csplab.cli.common import check_output_path
    from csplab.io.registry import output_format

    fmt = output_format(path, gives="PolygonModel")
    check_output_path(path, flag)
    return fmt


def synthesize(args: argparse.Namespace, example: PolygonModel, opts: dict[str, Any]) -> int:
    """``csplab synthesize POLYGONS.json --size WxH``."""
    from csplab.continuous.synthesis import synthesize as run
    from csplab.solvers import solver_class

    if args.periodic:
        raise InputError("--periodic: continuous models are not periodic")
    if args.out_partial:
        raise InputError("--out-partial: a failed continuous run has no partial polygons")
    if args.spacing is not None and not args.spacing > 0:
        raise InputError(f"--spacing must be positive, not {args.spacing}")
    size = region(args)
    boundary = boundary_label(args, example)
    fmt = polygon_output(args.out)
    cls = solver_class(args.solver.partition(":")[0])
    restarts = 0 if cls.complete else args.restarts
    settings: dict[str, Any] = {}
    for key in ("order", "choice"):
        o = cls.option(key)
        if o is not None:
            settings[key] = (
                f"{opts[key]} (given)" if key in opts else f"{o.default} (the thesis defaults)"
            )
    settings["restarts"] = restarts
    settings["lines"] = args.lines
    s = run(
        example, size, solver=args.solver, rng=args.seed, spacing=args.spacing,
        snap=args.snap, boundary=boundary, lines=args.lines, restarts=restarts, **opts,
    )  # fmt: skip
    r, csp, P = s.result, s.csp, s.csp.problem
    wrote = None
    if fmt is not None and s.model is not None:
        fmt.write(s.model, args.out)
        wrote = args.out
    A = csp.arrangement
    spacing = float(csp.lattice.spacing)
    if args.json:
        d = r.to_dict()
        d.update(
            example=example.name, out=wrote, format="polygons", settings=settings,
            size=list(size), spacing=spacing, vertices=A.n_vertices, edges=A.n_edges,
            families=A.dirs.tolist(), violations=len(s.violations),
            polygons=len(s.model) if s.model is not None else None,
            times={k: round(v, 6) for k, v in s.times.items()},
        )  # fmt: skip
        print(json.dumps(d))
    else:
        fams = int((~A.boundary_only).sum())
        print(
            f"{r.status}: {example.name or args.model} {size[0]}x{size[1]} spacings of "
            f"{spacing:g} ({fams} edge directions, {A.n_vertices} vertices, {A.n_edges} "
            f"edges, K={P.K}) with {r.solver} in {r.time_s:.3f} s, seed {r.seed}"
        )
        print("  settings: " + ", ".join(f"{k}={v}" for k, v in settings.items()))
        keys = [k for k in r.stats if k not in ("order", "choice")]
        if keys:
            print("  " + ", ".join(f"{k}={r.stats[k]}" for k in keys))
        if s.model is not None:
            print(
                f"  {len(s.model)} polygons, labels {list(s.model.labels)}; "
                f"Eq. 4.1 violations={len(s.violations)} (checked on the polygons); "
                + ", ".join(f"{k} {v:.3f} s" for k, v in s.times.items())
            )
            if s.violations:
                print(s.violations.describe(5), file=sys.stderr)
        if wrote:
            print(f"  wrote {wrote}")
        elif args.out:
            print(f"  not written: {args.out} (no solution)", file=sys.stderr)
        if r.status == "failed" and not cls.complete and cls.name != "blocks":
            hint = (
                "  hint: --solver blocks modifies the model in parts (Fig. 4.23) and always "
                "returns a consistent model; an exact solver (sat) decides"
            )
            print(hint, file=sys.stderr)
    return 0 if s.ok else 1


def check(args: argparse.Namespace, example: PolygonModel) -> int:
    """``csplab check EXAMPLE.json OUT.json``: violations of Eq. 4.1."""
    from csplab.cli.common import load_model
    from csplab.continuous.check import violations

    out = load_model(args.grid)
    if not isinstance(out, PolygonModel):
        raise InputError(f"{args.grid} is not a polygon model (the example {args.model} is)")
    v = violations(example, out)
    if args.json:
        print(json.dumps({"violations": len(v), **v.counts(), "polygons": len(out)}))
    else:
        print(f"{len(v)} violations in {args.grid} ({len(out)} polygons, labels "
              f"{list(out.labels)}) against {example.name or args.model}")  # fmt: skip
        if len(v):
            print(v.describe(args.limit))
    return 0 if len(v) == 0 else 1
