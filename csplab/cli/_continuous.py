"""The continuous-model branch of ``synthesize``, ``check`` and ``show`` (polygon models)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np

from csplab.cli.common import (
    EXPLAINED_STATS,
    explain,
    fallback_setting,
    not_written,
    order_setting,
    outcome,
)
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


def polygon_output(
    path: str | None,
    flag: str = "--out",
    gives: Any = "PolygonModel",
    args: argparse.Namespace | None = None,
) -> Any:
    """The polygon (or polyhedral) format for an output path (checked before any work:
    the format, the folder, and that it is none of the files ``args`` names as inputs),
    or None."""
    if not path:
        return None
    from csplab.cli.common import check_output_path, input_files
    from csplab.io.registry import output_format

    check_output_path(path, flag, inputs=input_files(args) if args is not None else ())
    return output_format(path, gives=gives)


#: What a continuous synthesis needs per vertex and edge of the arrangement, in bytes:
#: ``BYTES_PER_ELEMENT + BYTES_PER_ELEMENT_LABEL * K`` (measured peaks: triangle 200x200,
#: K=8, 1.56 M vertices and edges, 712 MB; houses 40x40x20, K=40, 0.33 M, 445 MB), on top of
#: :data:`BASE_BYTES` (the interpreter, numpy, numba).
BYTES_PER_ELEMENT = 300
BYTES_PER_ELEMENT_LABEL = 9
BASE_BYTES = 250e6


def estimate_peak(
    example: Any,
    size: tuple[int, ...],
    *,
    spacing: float | None = None,
    snap: bool = False,
    lines: str = "lattice",
) -> float:
    """The peak memory (bytes) of a continuous synthesis of ``example`` in a region of
    ``size`` spacings, estimated before building it: the arrangement of a small probe
    region (at most 12x12, or 6x6x4 in 3D; a fraction of a second) scaled to ``size`` by
    area (volume), times the bytes per vertex and edge (:data:`BYTES_PER_ELEMENT`).
    Scaling a probe overestimates a little (its border is a larger share). A region no
    larger than the probe is not built twice: its estimate is :data:`BASE_BYTES`, the
    process's own, as every estimate includes (so ``--memory-limit`` bounds small runs
    too)."""
    import math

    dim = len(size)
    probe = tuple(min(s, p) for s, p in zip(size, (12, 12) if dim == 2 else (6, 6, 4), strict=True))
    ratio = math.prod(size) / math.prod(probe)
    if ratio <= 1:
        return BASE_BYTES
    if dim == 2:
        from csplab.continuous.csp import ContinuousCSP

        csp: Any = ContinuousCSP(example, probe, spacing=spacing, snap=snap, lines=lines)
    else:
        from csplab.continuous.csp3d import ContinuousCSP3

        csp = ContinuousCSP3(example, probe, spacing=spacing, snap=snap)
    A = csp.arrangement
    elements = float(A.n_vertices + A.n_edges) * ratio
    per = BYTES_PER_ELEMENT + BYTES_PER_ELEMENT_LABEL * int(csp.problem.K)
    return BASE_BYTES + elements * per


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
    if getattr(args, "topology", None):
        raise InputError(
            f"--grid {args.topology}: {example.name or args.model} is a "
            f"{'polygon' if dim == 2 else 'polyhedral'} model; --grid applies to grid examples"
        )
    if args.out_partial:
        raise InputError("--out-partial: a failed continuous run has no partial polygons")
    if args.spacing is not None and not args.spacing > 0:
        raise InputError(f"--spacing must be positive, not {args.spacing}")
    ground = getattr(args, "ground", "auto")
    lines = "lattice" if dim == 2 and args.lines == "auto" else args.lines
    size = region(args, dim)
    boundary = boundary_label(args, example)
    fmt = polygon_output(args.out, gives=type(example).__name__, args=args)
    cls = solver_class(args.solver.partition(":")[0])
    from csplab.limits import check_memory, fmt_bytes, memory_budget

    budget = memory_budget(getattr(args, "memory_limit", None))
    if dim == 2:  # a probe arrangement scaled up; 3D: estimate3 before any arrangement
        need = estimate_peak(example, size, spacing=args.spacing, snap=args.snap,
                             lines=lines)  # fmt: skip
        check_memory(
            need,
            f"{example.name or args.model} --size {'x'.join(map(str, size))}",
            "use a smaller --size or a larger --spacing" if budget >= BASE_BYTES else
            f"no --size fits in it (the interpreter, numpy and numba alone take about "
            f"{fmt_bytes(BASE_BYTES)})",
            budget=budget,
        )
    restarts = 0 if cls.complete else args.restarts
    settings: dict[str, Any] = {}
    for key in ("order", "choice"):
        o = cls.option(key)
        if o is not None:
            settings[key] = (
                f"{opts[key]} (given)" if key in opts
                else "auto (solver default)" if o.default == "auto"
                else f"{o.default} (the thesis defaults)"
            )
    if "choice" not in opts and cls.option("choice") is not None:
        o = cls.option("choice")
        if o is not None and (o.values is None or "weighted" in o.values):
            settings["choice"] = ("weighted (continuous default: by how much of the example "
                                  "each state covers; --choice uniform: the thesis')")
    settings["restarts"] = restarts
    if not cls.complete:
        settings["fallback"] = fallback_setting(args.fallback)
    fallback = None if cls.complete or args.fallback == "none" else args.fallback
    from csplab.rng import make_rng

    _, seed = make_rng(args.seed)  # the seed the header prints: it reproduces every attempt
    common = dict(solver=args.solver, rng=seed, spacing=args.spacing, snap=args.snap,
                  boundary=boundary, restarts=restarts, fallback=fallback,
                  ground=ground)  # fmt: skip
    if dim == 3:  # the arrangement's estimate (Sec. 4.5.7) is refused over the budget
        common["max_memory"] = int(budget)
    cons = user_constraints(args, example)
    if cls.option("progress") is not None:
        opts.setdefault("progress", True)  # a bar on stderr once a run takes over 2 s
    if cons is not None and dim == 2:
        raise InputError("--constraints: polygon models (2D) take no user constraints yet")
    if cons is not None:
        settings["constraints"] = ", ".join(cons_summary(cons))
    if dim == 2:
        settings["lines"] = lines
    try:
        s = run(example, size, lines=lines, constraints=cons, notices=True, **common,
                **opts)  # fmt: skip
    except InputError as e:  # the library names its arguments; the user typed flags
        raise InputError(as_flags(str(e))) from None
    r, csp, P = s.result, s.csp, s.csp.problem
    if "order" in settings:  # catalog's auto: by the CSP's global constraints
        settings["order"] = order_setting(settings["order"], P)
    wrote = None
    if fmt is not None and s.model is not None and s.ok:  # a failed run writes nothing
        # what check needs to compare the example as it was synthesized (kept by .obj and
        # .glb outputs)
        recorded = recorded_settings(args, example)
        if recorded:  # defaults record nothing (check derives the same)
            s.model.meta["synthesis"] = recorded
        fmt.write(s.model, args.out)
        wrote = args.out
        if recorded and not args.out.lower().endswith(KEEPS_SETTINGS):
            flags = " ".join(f"--{k}" if v is True else f"--{k} {v:g}" if k == "spacing"
                             else f"--{k} {v}" for k, v in recorded.items())  # fmt: skip
            print(f"csplab: note: {args.out} does not keep the settings it was made with; "
                  f"check it with {flags}", file=sys.stderr)  # fmt: skip
    A: PlaneArrangement = csp.arrangement
    spacing = float(csp.lattice.spacing)
    opened: tuple[str, ...] = csp.ground
    if dim == 3 or opened:
        open_faces = ",".join(opened) or "none"
        settings["ground"] = open_faces + (" (the example's)" if ground == "auto" else "")
    if dim == 3:
        from csplab.continuous.space import estimate3

        nv, ne, nb = estimate3(csp.lattice, size)
        settings["planes"] = csp.lattice.planes + (" (auto)" if args.lines == "auto" else "")
        settings["estimate"] = f"~{nv} vertices, ~{ne} edges, ~{nb / 2**20:.0f} MiB"
    lat = csp.lattice
    if s.bounded is not None and args.spacing is None:  # the proxy's lattice: derived too
        settings["spacing"] = (
            f"{spacing:g} (derived from the example before its bounding volumes: its "
            f"thinnest side / {DIVISIONS}, rounded down to 1, 2 or 5 x 10^k)"
        )
    elif lat.derived:
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
        snapped = csp.example  # (as synthesized: its vertices on the lattice)
        if isinstance(snapped, PolyhedralModel) and isinstance(s.model, PolyhedralModel):
            from csplab.continuous.resemblance import resemblance  # from the geometry alone

            floor = csp.region()[2] if "z-" in opened else None  # the ground's height
            # through bounding volumes: the original example against the output with its
            # curved geometry back (the proxy is what was synthesized, not what it resembles)
            like = s.bounded.example if s.bounded is not None else snapped
            d["resemblance"] = resemblance(like, s.model, ground=floor).to_dict()
        elif isinstance(snapped, PolygonModel) and isinstance(s.model, PolygonModel):
            from csplab.continuous.resemblance import resemblance

            floor = csp.region()[1] if "y-" in opened else None  # the ground's height
            d["resemblance"] = resemblance(snapped, s.model, ground=floor).to_dict()
        if s.bounded is not None:
            d["bounding_volumes"] = s.bounded.describe()
        print(json.dumps(d))
    else:
        what = "edge directions" if dim == 2 else "face orientations"
        unit = "spacings" if dim == 2 else "plane spacings"
        said = outcome(r.status) if s.ok or r.status != "solved" else "not solved"
        print(
            f"{said}: {example.name or args.model} {'x'.join(map(str, size))} {unit} of "
            f"{spacing:g} ({fams} {what}, {A.n_vertices} vertices, {A.n_edges} "
            f"edges, K={P.K}) with {r.solver} in {s.times['solve']:.3f} s, seed {seed}"
        )
        print("  settings: " + ", ".join(f"{k}={v}" for k, v in settings.items()))
        if s.bounded is not None:  # Sec. 4.6.4: which parts became bounding volumes
            print("  " + s.bounded.describe())
        for line in explain(r):
            print(line)
        # the solver's own count ("violations" of the CSP) is not the output's: the Eq. 4.1
        # line below is the one count of defects
        keys = [k for k in r.stats if k not in ("order", "choice", "violations",
                                                *EXPLAINED_STATS)]  # fmt: skip
        if keys:
            print("  " + ", ".join(f"{k}={r.stats[k]}" for k in keys))
        if s.model is not None:
            made = f"{polys} polygons" if n_solids is None else (
                f"{n_solids} solids of {polys} polygons")  # fmt: skip
            on = "polygons" if dim == 2 else "solids"
            user = sum(1 for d in s.violations if d.kind in USER_KINDS)
            counts = f"Eq. 4.1 violations={len(s.violations) - user}"
            if cons is not None:
                counts += f", constraint violations={user}"
            print(
                f"  {made}, labels {list(s.model.labels)}; "
                f"{counts} (checked on the {on}); "
                + ", ".join(f"{k} {v:.3f} s" for k, v in s.times.items())
            )
            if s.violations:
                print(s.violations.describe(5), file=sys.stderr)
        if wrote:
            print(f"  wrote {wrote}")
        elif args.out:
            print(not_written(args.out, r.status).replace(
                "; --out-partial writes the partial grid", ""), file=sys.stderr)  # fmt: skip
        hint = None
        if r.status == "failed" and "broken" in r.stats:  # a user constraint, not Eq. 4.1
            hint = (
                "  hint: a user constraint still breaks after the restarts; --solver sat "
                "searches with it (exact), or more --restarts"
            )
        elif (
            r.status == "failed" and fallback is None and not cls.complete
            and cls.name != "blocks"
        ):  # fmt: skip
            hint = (
                "  hint: --solver blocks modifies the model in parts (Fig. 4.23) and always "
                "returns a consistent model; an exact solver (sat) decides"
            )
        if hint:
            print(hint, file=sys.stderr)
    return 0 if s.ok else 1


#: The kinds of defect that are user constraints (Sec. 4.6), not Eq. 4.1
USER_KINDS = frozenset({"connected", "dimensional", "large-scale"})

#: The library's names of its arguments -> the flags a user typed
_FLAGS = (
    ("snap=true", "--snap"),
    ("pass a spacing", "pass --spacing"),
    ("a larger spacing", "a larger --spacing"),
    ("a coarser spacing", "a coarser --spacing"),
    ("another spacing", "another --spacing"),
)


def as_flags(message: str) -> str:
    """``message`` with the library's argument names (``snap=true``) as the command-line
    flags (``--snap``).

    Examples
    --------
    >>> as_flags("choose another spacing or snap=true")
    'choose another --spacing or --snap'
    """
    for lib, flag in _FLAGS:
        message = message.replace(lib, flag)
    return message


#: output formats that store float32 coordinates (binary STL, glTF positions)
FLOAT32_SUFFIXES = (".stl", ".glb")


def onto_planes(model: PolyhedralModel, lat: Any) -> tuple[PolyhedralModel, int]:
    """``model`` (read from a float32 format) with every vertex that lies within float32's
    rounding of a point where three of ``lat``'s planes meet put exactly there (a
    synthesis output's vertices are such points: rationals of denominator
    :func:`~csplab.continuous.lattice.denominator` in lattice units); other vertices (the
    curved geometry of bounding volumes) stay as read. Returns the model and how many
    vertices moved."""
    from csplab.continuous.lattice import denominator

    D = denominator(lat.normals)
    solids, moved = [], 0
    for sol in model.solids:
        v = np.asarray(sol.vertices, dtype=np.float64)
        u = lat.to_lattice(v) * D
        r = np.rint(u)
        near = (np.abs(u - r) <= 1e-4 * D).all(axis=1) & (np.abs(u - r) > 0).any(axis=1)
        v[near] = lat.to_world(r[near] / D)
        moved += int(near.sum())
        solids.append({"label": int(sol.label), "vertices": v.tolist(),
                       "faces": [list(f) for f in sol.faces]})  # fmt: skip
    if not moved:
        return model, 0
    return PolyhedralModel(solids, name=model.name, meta=model.meta, source=model.source), moved


#: the output formats that keep the recorded settings (an OBJ comment, glTF scene extras)
KEEPS_SETTINGS = (".obj", ".glb")
#: the options of synthesize an output records (with their defaults, which record nothing):
#: how the example was snapped for the output. Not ``--ground``: the example's own ground is
#: part of what it means, so check judges an output against it unless told otherwise
RECORDED: dict[str, Any] = {"spacing": None, "snap": False, "lines": "auto"}


def recorded_settings(
    args: argparse.Namespace, example: PolygonModel | PolyhedralModel
) -> dict[str, Any]:
    """The settings of ``csplab synthesize`` that ``csplab check`` needs and that differ
    from the defaults (which check derives as synthesize does), as given."""
    d: dict[str, Any] = {}
    if example.ndim == 3:
        d.update(spacing=args.spacing, snap=bool(args.snap), lines=args.lines)
    return {k: v for k, v in d.items() if v != RECORDED[k]}


def _valid_recorded(key: str, value: Any) -> bool:
    if key == "spacing":
        return type(value) in (int, float) and value > 0
    if key == "snap":
        return type(value) is bool
    return value in ("auto", "lattice", "equal")


def apply_recorded(args: argparse.Namespace, out: PolygonModel | PolyhedralModel) -> str:
    """Take the output's recorded synthesis settings for the options the user did not
    give (``None``; given options win), then the defaults for the rest; a note saying
    which were read, or ``""``."""
    rec = out.meta.get("synthesis")
    rec = rec if isinstance(rec, dict) else {}
    taken, differ = [], []
    for key, default in RECORDED.items():
        given = getattr(args, key, None)
        if key not in rec:
            setattr(args, key, default if given is None else given)
            continue
        value = rec[key]
        if not _valid_recorded(key, value):
            raise InputError(f"{args.grid}: the recorded {key} {value!r} is not valid")
        if given is not None:
            if given != value:
                differ.append(f"--{key} {given} given, synthesize used {value}")
            continue
        if key == "spacing":
            value = float(value)
            taken.append(f"--spacing {value:g}")
        else:
            taken.append(f"--{key}" if value is True else "--no-snap" if value is False
                         else f"--{key} {value}")  # fmt: skip
        setattr(args, key, value)
    note = f" (settings of synthesize read from {args.grid}: {' '.join(taken)})" if taken else ""
    return note + (f" ({'; '.join(differ)})" if differ else "")


def check(args: argparse.Namespace, example: PolygonModel | PolyhedralModel) -> int:
    """``csplab check EXAMPLE.json OUT.json`` (or ``EXAMPLE.obj OUT.obj``): violations of
    Eq. 4.1 (and of the user constraints of thesis Sec. 4.6 on solids)."""
    from csplab.cli.common import load_model
    from csplab.continuous.check import violations
    from csplab.continuous.check3d import user_violations3
    from csplab.continuous.defects import Violations
    from csplab.continuous.lattice import Lattice

    if getattr(args, "topology", None):
        raise InputError(
            f"--grid {args.topology}: {example.name or args.model} is a continuous model; "
            "--grid applies to grid examples"
        )
    out = load_model(args.grid)
    if not isinstance(out, PolygonModel | PolyhedralModel) or out.ndim != example.ndim:
        raise InputError(f"{args.grid} is not a {example.kind} model (the example {args.model} is)")
    recorded = apply_recorded(args, out)
    bounded = None
    if isinstance(example, PolyhedralModel) and isinstance(out, PolyhedralModel):
        from csplab.continuous.bounding import bounding_volumes

        # curved parts: checked through the proxy (on its own lattice, not snapped again)
        bounded = bounding_volumes(example, args.spacing)
    snapped = ""
    if isinstance(example, PolyhedralModel) and bounded is None:  # as synthesis uses it
        from csplab.continuous.csp3d import as_synthesized

        lat, example = as_synthesized(example, args.spacing, snap=args.snap, planes=args.lines)
        if lat.snapped:
            snapped = (f" (snapped onto its planes of spacing {float(lat.spacing):g}, as "
                       "synthesize does with these settings)")  # fmt: skip
    elif not isinstance(example, PolyhedralModel) and (
        args.spacing is not None or args.snap or args.lines != "auto"
    ):
        raise InputError("--spacing, --snap and --lines of check apply to polyhedral models")
    if isinstance(out, PolyhedralModel) and args.grid.lower().endswith(FLOAT32_SUFFIXES):
        # float32 coordinates: the output's plane vertices put back where synthesis made them
        plat = Lattice.of_model(bounded.proxy, bounded.spacing) if bounded is not None else lat
        out, moved = onto_planes(out, plat)
        if moved:
            snapped += f" ({moved} float32 vertices of the output put back on its planes)"
    ground = getattr(args, "ground", "auto")
    if ground == "auto":
        ground = example.meta.get("ground")
    from csplab.continuous.csp import ground_sides
    from csplab.continuous.csp3d import ground_faces

    faces = ground_faces(ground) if isinstance(out, PolyhedralModel) else ground_sides(ground)
    if bounded is not None and isinstance(out, PolyhedralModel):
        from csplab.continuous.boundcheck import bounded_violations

        region = out.bounds if faces and len(out) else None
        v = bounded_violations(bounded, out, region=region, ground=faces,
                               float32=args.grid.lower().endswith(FLOAT32_SUFFIXES))  # fmt: skip
    elif faces and len(out):  # the output's box stands for its region (solids reach its faces)
        v = violations(example, out, region=out.bounds, ground=faces)
    else:
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
              f"{list(out.labels)}) against {example.name or args.model}{snapped}"
              f"{recorded}")  # fmt: skip
        if bounded is not None:
            print(f"  {bounded.describe()}; checked: curved parts are moved and scaled "
                  "originals, each box holds the mapped original, Eq. 4.1 on the proxy")
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
    have = set(example.labels)
    out = None
    from csplab.progress import notice_after

    for path in args.constraints:
        with notice_after(f"reading the constraints of {path}"):  # a large file: one line
            c = read_user_constraints(path, names)
        for kind, labels in (
            ("connected", c.connected),
            ("dimensional", [b for b, _ in c.dimensional]),
            ("large-scale", [b for b, _ in c.allowed]),
        ):
            missing = [int(b) for b in labels if b not in have]
            if missing:  # as grid constraints: refused before any work
                raise InputError(
                    f"{path}: {kind}: label {missing[0]} does not occur in "
                    f"{example.name or args.model} (its labels: {sorted(have)})"
                )
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
