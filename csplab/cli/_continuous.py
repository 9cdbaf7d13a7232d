"""The continuous-model branch of ``synthesize``, ``check`` and ``show`` (polygon models)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from csplab.cli.common import explain, fallback_setting, not_written, outcome
from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.user3d import UserConstraints3
from csplab.errors import InputError
from csplab.grids import parse_shape


def region(args: argparse.Namespace, dim: int = 2) -> tuple[int, ...]:
    """``--size WxH`` in line spacings (``AxBxC`` plane spacings in 3D)."""
    form = "40x30, in line spacings" if dim == 2 else "20x20x8, in plane spacings"
    if not args.size:
        raise InputError(f"--size is required (e.g. --size {form})")
    shp = parse_shape(args.size, what="--size")
    while len(shp) > dim and shp[-1] == 1:
        shp = shp[:-1]
    if len(shp) != dim:
        need = "WxH" if dim == 2 else "AxBxC"
        raise InputError(f"--size {args.size}: a continuous {dim}D model needs {need}")
    return tuple(shp)


_UNITS = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


def parse_memory(text: str | None) -> int | None:
    """``--max-memory``: bytes, or a number with K, M, G or T (powers of 1024; ``B``,
    ``B`` and ``iB`` suffixes allowed), or ``None`` when not given.

    >>> parse_memory("1.5G"), parse_memory("500MiB"), parse_memory(None)
    (1610612736, 524288000, None)
    """
    if text is None:
        return None
    t = text.strip().upper().removesuffix("B").removesuffix("I")
    unit = t[-1:] if t[-1:] in _UNITS and t[-1:] else ""
    try:
        v = float(t[: len(t) - len(unit)]) * _UNITS[unit]
    except ValueError:
        v = -1.0
    if not (v > 0 and v < 2**60):
        raise InputError(f"--max-memory {text}: give bytes such as 2G, 500M or 1000000000")
    return int(v)


def boundary_label(
    args: argparse.Namespace, example: PolygonModel | PolyhedralModel
) -> int | dict[str, int]:
    """``--boundary``: the label outside the region (default 0, empty space); for a
    polyhedral example also per face, e.g. ``z-=1`` (a ground below)."""
    b = args.boundary
    if b is None or b in ("auto", "none", "0"):
        return 0
    if "=" in b and getattr(example, "ndim", 2) == 3:
        from csplab.grids import parse_boundary

        faces = parse_boundary(b)
        assert isinstance(faces, dict)
        for lab in faces.values():
            if lab not in (0, *example.labels):
                raise InputError(f"--boundary {b}: label {lab} does not occur in {example.name}")
        return faces
    try:
        label = int(b)
    except ValueError:
        raise InputError(
            f"--boundary {b}: a continuous model takes one label for outside the region "
            "(e.g. --boundary 0; polyhedral models also face=label pairs such as z-=1)"
        ) from None
    if label not in (0, *example.labels):
        raise InputError(f"--boundary {b}: label {label} does not occur in {example.name}")
    return label


def polygon_output(path: str | None, flag: str = "--out", gives: Any = "PolygonModel") -> Any:
    """The polygon (or polyhedral) format for an output path (checked before any work),
    or None."""
    if not path:
        return None
    from csplab.cli.common import (
        check_output_path,
    )
    from csplab.io.registry import output_format

    fmt = output_format(path, gives=gives)
    check_output_path(path, flag)
    return fmt


def synthesize(
    args: argparse.Namespace, example: PolygonModel | PolyhedralModel, opts: dict[str, Any]
) -> int:
    """``csplab synthesize POLYGONS.json --size WxH`` (or a polyhedral ``MESH.obj --size
    AxBxC``)."""
    from csplab.continuous.lattice import DIVISIONS, PlaneArrangement
    from csplab.continuous.synthesis import synthesize as run
    from csplab.solvers import solver_class

    dim = example.ndim

    if args.periodic:
        raise InputError("--periodic: continuous models are not periodic")
    if args.out_partial:
        raise InputError("--out-partial: a failed continuous run has no partial polygons")
    if args.spacing is not None and not args.spacing > 0:
        raise InputError(f"--spacing must be positive, not {args.spacing}")
    if dim == 3 and args.lines != "lattice":
        raise InputError("--lines applies to 2D polygon models (3D planes: lattice only)")
    size = region(args, dim)
    boundary = boundary_label(args, example)
    fmt = polygon_output(args.out, gives=type(example).__name__)
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
    if not cls.complete:
        settings["fallback"] = fallback_setting(args.fallback)
    fallback = None if cls.complete or args.fallback == "none" else args.fallback
    max_memory = parse_memory(getattr(args, "max_memory", None))
    if max_memory is not None and dim == 2:
        raise InputError("--max-memory applies to polyhedral (3D) models")
    common = dict(solver=args.solver, rng=args.seed, spacing=args.spacing, snap=args.snap,
                  boundary=boundary, restarts=restarts, fallback=fallback)  # fmt: skip
    if dim == 3:
        common["max_memory"] = max_memory
    cons = user_constraints(args, example)
    if cons is not None and dim == 2:
        raise InputError("--constraints: polygon models (2D) take no user constraints yet")
    if cons is not None:
        settings["constraints"] = ", ".join(cons_summary(cons))
    if dim == 2:
        settings["lines"] = args.lines
    s = run(example, size, lines=args.lines, constraints=cons, **common, **opts)
    r, csp, P = s.result, s.csp, s.csp.problem
    wrote = None
    if fmt is not None and s.model is not None:
        fmt.write(s.model, args.out)
        wrote = args.out
    A: PlaneArrangement = csp.arrangement
    spacing = float(csp.lattice.spacing)
    if dim == 3:
        from csplab.continuous.space import estimate3

        v, e, b = estimate3(csp.lattice, size)
        settings["estimate"] = f"~{v} vertices, ~{e} edges, ~{b / 2**20:.0f} MiB"
    lat = csp.lattice
    if lat.derived:
        settings["spacing"] = (
            f"{spacing:g} (derived: the example's thinnest side / {DIVISIONS}, rounded down "
            "to 1, 2 or 5 x 10^k)"
        )
    if lat.snapped:
        settings["snap"] = (
            f"largest vertex move {lat.snapped * spacing:.3g} ({lat.snapped:.2f} spacings)"
            + (f", largest normal change {lat.normal_change:.2f} deg" if dim == 3 else "")
        )
    fams = int((~A.boundary_only).sum())
    out = s.model
    polys = None if out is None else out.n_polygons
    n_solids = len(out) if out is not None and out.ndim == 3 else None
    if args.json:
        d = r.to_dict()
        d.update(
            example=example.name, out=wrote, format="polygons" if dim == 2 else "polyhedra",
            settings=settings, size=list(size), spacing=spacing, vertices=A.n_vertices,
            edges=A.n_edges, families=A.family_vectors.tolist(),
            violations=len(s.violations), polygons=polys,
            solids=n_solids,
            times={k: round(v, 6) for k, v in s.times.items()},
            outcome=outcome(r.status) if s.ok or r.status != "solved" else "not solved",
            proof=r.stats.get("proof") if r.status == "unsat" else None,
        )  # fmt: skip
        if isinstance(example, PolyhedralModel) and isinstance(s.model, PolyhedralModel):
            from csplab.continuous.resemblance import resemblance3  # from the geometry alone

            d["resemblance"] = resemblance3(example, s.model).to_dict()
        print(json.dumps(d))
    else:
        what = "edge directions" if dim == 2 else "face orientations"
        unit = "spacings" if dim == 2 else "plane spacings"
        said = outcome(r.status) if s.ok or r.status != "solved" else "not solved"
        print(
            f"{said}: {example.name or args.model} {'x'.join(map(str, size))} {unit} of "
            f"{spacing:g} ({fams} {what}, {A.n_vertices} vertices, {A.n_edges} "
            f"edges, K={P.K}) with {r.solver} in {r.time_s:.3f} s, seed {r.seed}"
        )
        print("  settings: " + ", ".join(f"{k}={v}" for k, v in settings.items()))
        for line in explain(r):
            print(line)
        keys = [k for k in r.stats if k not in ("order", "choice", "proof", "fallback_from",
                                                "gave_up_s", "reason")]  # fmt: skip
        if keys:
            print("  " + ", ".join(f"{k}={r.stats[k]}" for k in keys))
        if s.model is not None:
            made = f"{polys} polygons" if n_solids is None else (
                f"{n_solids} solids of {polys} polygons")  # fmt: skip
            on = "polygons" if dim == 2 else "solids"
            print(
                f"  {made}, labels {list(s.model.labels)}; "
                f"Eq. 4.1 violations={len(s.violations)} (checked on the {on}); "
                + ", ".join(f"{k} {v:.3f} s" for k, v in s.times.items())
            )
            if s.violations:
                print(s.violations.describe(5), file=sys.stderr)
        if wrote:
            print(f"  wrote {wrote}")
        elif args.out:
            print(not_written(args.out, r.status).replace(
                "; --out-partial writes the partial grid", ""), file=sys.stderr)  # fmt: skip
        if r.status == "failed" and fallback is None and not cls.complete and cls.name != "blocks":
            hint = (
                "  hint: --solver blocks modifies the model in parts (Fig. 4.23) and always "
                "returns a consistent model; an exact solver (sat) decides"
            )
            print(hint, file=sys.stderr)
    return 0 if s.ok else 1


def check(args: argparse.Namespace, example: PolygonModel | PolyhedralModel) -> int:
    """``csplab check EXAMPLE.json OUT.json`` (or ``EXAMPLE.obj OUT.obj``): violations of
    Eq. 4.1 (and of the user constraints of thesis Sec. 4.6 on solids)."""
    from csplab.cli.common import load_model
    from csplab.continuous.check import violations
    from csplab.continuous.check3d import user_violations3
    from csplab.continuous.defects import Violations
    from csplab.continuous.lattice import Lattice

    out = load_model(args.grid)
    if not isinstance(out, PolygonModel | PolyhedralModel) or out.ndim != example.ndim:
        raise InputError(f"{args.grid} is not a {example.kind} model (the example {args.model} is)")
    v = violations(example, out)
    if isinstance(out, PolyhedralModel):  # the user constraints of Sec. 4.6, on the solids
        cons = user_constraints(args, example)
        if cons is not None:
            lat = Lattice.of_model(example)
            origin = [float(x) for x in lat.origin]
            extra = user_violations3(out, cons, origin=origin, spacing=float(lat.spacing))
            v = Violations([*v, *extra])
    if args.json:
        print(json.dumps({"violations": len(v), **v.counts(), out.parts: len(out)}))
    else:
        print(f"{len(v)} violations in {args.grid} ({len(out)} {out.parts}, labels "
              f"{list(out.labels)}) against {example.name or args.model}")  # fmt: skip
        if len(v):
            print(v.describe(args.limit))
    return 0 if len(v) == 0 else 1


def user_constraints(
    args: argparse.Namespace, example: PolygonModel | PolyhedralModel
) -> UserConstraints3 | None:
    """The ``--constraints`` files merged (:mod:`csplab.continuous.user3d`), or ``None``."""
    if not getattr(args, "constraints", None):
        return None
    from csplab.continuous.user3d import read_user_constraints

    names = {str(v): int(k) for k, v in (example.meta.get("label_names") or {}).items()}
    out = None
    for path in args.constraints:
        c = read_user_constraints(path, names)
        out = c if out is None else out.merged(c)
    return out


def cons_summary(c: UserConstraints3) -> list[str]:
    """One phrase per kind of user constraint."""
    out = []
    if c.dimensional:
        out.append("dimensional " + " ".join(f"{b}:{list(n)}" for b, n in c.dimensional))
    if c.allowed:
        out.append(f"large-scale {len(c.allowed)} label(s) in voxels {list(c.voxel or ())}")
    if c.connected:
        out.append(f"connected {list(c.connected)}")
    return out
