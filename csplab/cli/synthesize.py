"""``csplab synthesize``: build a model from an example and write it.

Synthesize a model consistent with an example model (Alg. 3.1 or 3.4 or any registered
solver); for a polygon example (.json, .svg), continuous model synthesis in a WxH region of
line spacings, written as .json, .svg or .png. An incomplete solver (catalog, blocks) that
gives up after its ``--restarts`` is followed by an exact one (``--fallback``), so a
default run ends solved, or 'unsat' with the exact solver's proof, or 'not solved' when the
time ran out.

``--solver blocks`` on an example whose whole problem would need more than
:data:`csplab.solvers.blocks.STREAM_BYTES` streams the thesis' sweep slab by slab
(:func:`csplab.solvers.blocks.stream_blocks`, the same output for a seed): the settings line
says ``streamed=yes``.

Exit codes: 0 solved, 1 not solved or unsat (the message and ``--json`` say which), 2 bad
input.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from csplab.cli.common import (
    EXPLAINED_STATS,
    add_constraints_arg,
    add_memory_limit_arg,
    add_problem_args,
    check_output_path,
    explain,
    fallback_setting,
    input_files,
    is_continuous,
    key_values,
    model_from_args,
    not_written,
    order_setting,
    outcome,
    problem_from_args,
)
from csplab.errors import InputError
from csplab.grids import GridWindows, parse_shape
from csplab.problem import Problem

#: the output is written atomically and worker pools are closed before ``run`` returns: the
#: console script skips the interpreter's teardown (a large SAT solver's among it)
EXIT_AT_ONCE = True


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_problem_args(p)
    from csplab.solvers import option_values, solver_names, solvers_taking

    p.add_argument(
        "--solver",
        default="catalog",
        help=f"{' | '.join(solver_names())}, or NAME:BACKEND (`csplab info` lists the "
        "backends and every solver's options)",
    )
    p.add_argument(
        "--order",
        help=f"cell order: {', '.join(option_values('order'))} (scan:AXES e.g. scan:yx, x "
        f"fastest: the thesis' 2D figures; auto, catalog's default: scanline without global "
        f"constraints, min-entropy under them); for {', '.join(solvers_taking('order'))}",
    )
    p.add_argument(
        "--choice",
        choices=option_values("choice"),
        help=f"label choice; for {', '.join(solvers_taking('choice'))}",
    )
    p.add_argument(
        "--block",
        help=f"block size, e.g. 10 or 10x10x10; for {', '.join(solvers_taking('block'))}",
    )
    p.add_argument(
        "--retries", type=int, help=f"retries; for {', '.join(solvers_taking('retries'))}"
    )
    p.add_argument(
        "--restarts",
        type=int,
        default=10,
        help="run an incomplete solver again, with a fresh derived seed, up to N times while "
        "it fails (default 10, as WaveFunctionCollapse per output; Merrell's code retries "
        "20 times per block; 0: one run, as the thesis' experiments); then --fallback",
    )
    from csplab.solvers.chain import FALLBACKS

    p.add_argument(
        "--fallback",
        choices=FALLBACKS,
        default="auto",
        help="after an incomplete solver gave up on every restart, finish with an exact "
        "solver for the time left: auto (default: sat where python-sat is installed, else "
        "backtrack; modify in blocks with exact block completion for a model too large for "
        "SAT), sat, backtrack, or none (the incomplete solver's run alone, as the thesis)",
    )
    p.add_argument(
        "--spacing",
        type=float,
        help="continuous models: line spacing in the example's units (default: the largest "
        "that puts every example vertex on the lattice)",
    )
    p.add_argument(
        "--lines",
        choices=("auto", "lattice", "equal"),
        default="auto",
        help="continuous models: 'lattice' puts every family's lines (planes) through every "
        "lattice point (exact corners anywhere; sloped families are denser), 'equal' spaces "
        "every family's lines (planes) about one spacing apart (as the 2008 paper; in 3D "
        "through the example's faces); 'auto' (default): lattice in 2D, in 3D equal for a "
        "mesh in real coordinates (derived spacing), lattice for exact ones",
    )
    p.add_argument(
        "--snap",
        action="store_true",
        help="continuous models: round example vertices onto the --spacing lattice",
    )
    p.add_argument(
        "--ground",
        default="auto",
        help="faces (polyhedral models) or sides (polygon models: x-, x+, y-, y+) past which "
        "the example (its bounding box) and the output (the region) continue, an infinite "
        "ground: z- (y- in 2D; solids standing on the bottom go on below it, none floats), "
        "a list such as z-,x-,x+, window (every face but the top), none; default auto: the "
        "example's own (its meta's \"ground\"; the built-in polyhedral ones declare theirs)",
    )
    p.add_argument("--seed", type=int, help="random seed (default: fresh, printed)")
    add_memory_limit_arg(p)
    p.add_argument("--time-limit", type=float, help="seconds")
    p.add_argument(
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="extra solver option (repeatable; VALUE parsed as JSON when possible)",
    )
    from csplab.io.registry import formats, output_extensions

    kinds = ", ".join(f"{f.extensions[0]} ({f.name})" for f in formats(writable=True))
    p.add_argument(
        "--out",
        help=f"output file, format by extension: {kinds}",
    )
    p.add_argument(
        "--out-partial",
        action="store_true",
        help="also write a failed or timed-out run's partial grid (unassigned cells -1; "
        f"{', '.join(output_extensions(partial=True))})",
    )
    add_constraints_arg(p)
    p.add_argument("--json", action="store_true", help="print status, time and stats as JSON")


def solver_complete(spec: str) -> bool:
    """Whether the solver of ``spec`` (``name[:backend]``) is complete (needs no fallback)."""
    from csplab.solvers import solver_class

    return bool(solver_class(spec.partition(":")[0]).complete)


def _options(args: argparse.Namespace) -> dict[str, Any]:
    from csplab.solvers import solver_names, solvers_taking

    opts: dict[str, Any] = {}
    if args.order:
        opts["order"] = args.order
    if args.choice:
        opts["choice"] = args.choice
    if args.block:
        opts["block"] = parse_shape(args.block, what="--block")
    if args.retries is not None:
        opts["retries"] = args.retries
    if args.time_limit is not None:
        opts["time_limit"] = args.time_limit
    from csplab.solvers import solver_class

    name = args.solver.partition(":")[0]
    for flag in ("order", "choice", "block", "retries", "time_limit"):
        if flag in opts and name in solver_names() and solver_class(name).option(flag) is None:
            raise InputError(
                f"--{flag.replace('_', '-')} does not apply to --solver {name} "
                f"(it applies to {', '.join(solvers_taking(flag))})"
            )
    opts.update(key_values(args.option, "--option"))
    return opts


def _settings(
    args: argparse.Namespace, example: Any, opts: dict[str, Any], problem: Problem | None = None
) -> dict[str, Any]:
    """Fill the order and choice the model's format suits (when the user named none and
    the solver takes them); return the effective settings and where they came from (with
    ``problem``, the order ``auto`` stands for, :func:`csplab.engine.alg31.auto_order`)."""
    from csplab.io.registry import synthesis_defaults
    from csplab.solvers import solver_class

    cls = solver_class(args.solver.partition(":")[0])
    suggested, sources = synthesis_defaults(example)
    settings: dict[str, Any] = {}
    for key in ("order", "choice"):
        o = cls.option(key)
        if o is None:
            continue
        value = suggested.get(key)
        # sat's phases under global constraints: its auto (the Alg. 3.1 start) over the
        # format's suggested label weights, which as phases alone do not find the object
        constrained_auto = (
            key == "choice" and o.default == "auto" and problem is not None
            and bool(problem.constraints)
        )  # fmt: skip
        if key in opts:
            settings[key] = f"{opts[key]} (given)"
        elif constrained_auto:
            settings[key] = (
                "auto (solver default: global constraints, a short uniform attempt, then a "
                "seeded Alg. 3.1 solution)"
            )
        elif value is not None and (o.values is None or value in o.values):
            opts[key] = value
            settings[key] = f"{value} ({sources[key]})"
        elif o.default == "auto" and key == "choice" and problem is not None:
            settings[key] = "uniform (auto: no global constraints; solver default)"
        elif o.default == "auto":  # catalog's order: by the problem's constraints, below
            settings[key] = "auto (solver default)"
        else:
            origin = "solver default" if suggested else sources.get("*", "solver default")
            settings[key] = f"{o.default} ({origin})"
        if key == "order" and problem is not None:
            settings[key] = order_setting(settings[key], problem)
    settings["restarts"] = 0 if cls.complete else args.restarts
    if not cls.complete:
        settings["fallback"] = fallback_setting(args.fallback)
    if cls.option("progress") is not None:
        opts.setdefault("progress", True)  # a bar on stderr once a run takes over 2 s
    return settings


def _check_grid_memory(args: argparse.Namespace, example: Any) -> None:
    """Refuse, before building anything, a grid problem whose estimated peak
    (:func:`csplab.problem.memory_estimate`: domains, arcs, the propagator) is over
    ``--memory-limit`` (default :func:`csplab.limits.memory_budget`)."""
    import math

    from csplab.limits import check_memory, memory_budget
    from csplab.problem import memory_estimate

    shape = parse_shape(args.size, what="--size") if args.size else getattr(example, "shape", None)
    K = getattr(example, "K", None)
    if not shape or not K:
        return
    n = math.prod(int(s) for s in shape)
    need = memory_estimate(n, int(K), len(shape) * n)
    check_memory(
        need,
        f"{example.name or args.model} --size {'x'.join(map(str, shape))} (K={K})",
        "use a smaller --size",
        budget=memory_budget(args.memory_limit),
    )


def _windows(args: argparse.Namespace, example: Any, opts: dict[str, Any]) -> GridWindows | None:
    """The problem built window by window (:class:`csplab.grids.GridWindows`) when
    ``--solver blocks`` on an example at ``--size`` would hold a whole problem over
    :data:`csplab.solvers.blocks.STREAM_BYTES` and the sweep can be streamed
    (:func:`csplab.solvers.blocks.streams`: the same grid either way); else ``None``."""
    import math

    from csplab.example import ExampleModel
    from csplab.problem import memory_estimate
    from csplab.solvers.blocks import STREAM_BYTES, BlocksSolver, streams

    if (args.solver != "blocks" or not isinstance(example, ExampleModel) or not args.size
            or args.periodic or getattr(args, "constraints", None)
            or getattr(args, "topology", None)):  # fmt: skip
        return None
    shape = parse_shape(args.size, what="--size")
    n = math.prod(shape)
    if memory_estimate(n, example.K, len(shape) * n) <= STREAM_BYTES:
        return None
    from csplab.grids import parse_boundary

    try:
        windows = GridWindows(example, shape, boundary=parse_boundary(args.boundary) or "none")
    except InputError:
        return None  # not a square grid, a size that does not fit: the whole path says why
    filled = dict(opts)
    _settings(args, example, filled)  # the order and choice the model's format suits
    if streams(windows, **BlocksSolver.validate(filled)) is not None:
        return None
    return windows


def _check_stream_memory(args: argparse.Namespace, windows: GridWindows) -> None:
    """Refuse a streamed run whose output (int32 cells) and the rest (interpreter, kernels,
    slab problems, the check's and the file's slabs: 0.65-0.72 GB measured at 10^7 and
    10^8 cells of castle with check windows of 2**19 cells, 0.39 GB at 10^7 with 2**16)
    are over ``--memory-limit``."""
    from csplab.limits import check_memory, memory_budget

    need = 4 * windows.n + (768 << 20)
    check_memory(
        need,
        f"{windows.example.name or args.model} --size {'x'.join(map(str, windows.shape))} "
        f"(K={windows.K}) streamed",
        "use a smaller --size",
        budget=memory_budget(args.memory_limit),
    )


def run(args: argparse.Namespace) -> int:
    from csplab.io import write_labels
    from csplab.io.registry import output_format
    from csplab.solvers import solve

    if args.restarts < 0:
        raise InputError("--restarts must be >= 0")
    if args.seed is not None and args.seed < 0:
        raise InputError("--seed must be non-negative")
    example = model_from_args(args)
    if is_continuous(example):
        from csplab.cli import _continuous

        return _continuous.synthesize(args, example, _options(args))
    if args.spacing is not None or args.snap or args.lines != "auto":
        raise InputError("--spacing, --snap and --lines apply to continuous (polygon) models only")
    opts = _options(args)
    windows = _windows(args, example, opts)
    if windows is None:
        _check_grid_memory(args, example)
        problem: Problem | None = problem_from_args(args, example)
    else:
        problem = None
    settings = _settings(args, example, opts, problem)
    if args.out:  # an input, a folder, an unwritable place: refused before the work
        check_output_path(args.out, "--out", inputs=input_files(args))
    out_format = output_format(args.out) if args.out else None  # bad extension: fail early
    if out_format is not None and args.out_partial and not out_format.partial:
        raise InputError(f"--out-partial: {args.out} cannot hold unassigned cells")
    fallback = None if solver_complete(args.solver) or args.fallback == "none" else args.fallback
    from csplab import _jit
    from csplab.engine.sat import free_at_exit

    compiling = _jit.compile_seconds()
    free_at_exit()  # the command ends after this solve: the OS frees a large SAT solver
    try:
        if problem is not None:
            result = solve(problem, args.solver, rng=args.seed, restarts=settings["restarts"],
                           fallback=fallback, **opts)  # fmt: skip
        else:  # the same sweep and grid, the problem built slab by slab
            assert windows is not None
            _check_stream_memory(args, windows)
            settings["streamed"] = "yes (the problem built slab by slab)"
            from csplab.rng import make_rng
            from csplab.solvers.blocks import BlocksSolver

            gen, seed = make_rng(args.seed)
            result = BlocksSolver().stream(windows, rng=gen, seed=seed, **opts)
    finally:
        free_at_exit(False)
    if problem is not None:
        shape, K, meta = problem.shape, problem.K, problem.meta
    else:
        assert windows is not None
        shape, K, meta = windows.shape, windows.K, windows.miniature().meta
    compiling = _jit.compile_seconds() - compiling  # numba's one-time cost, not the solve's
    wrote = None
    if out_format is not None and (result.ok or args.out_partial):
        per = meta.get("periodic", False)
        topo = meta.get("topology")
        write_labels(
            result.grid, args.out, name=example.name, model=example, periodic=bool(all(per)),
            meta={"topology": topo} if topo else None,
        )  # fmt: skip
        wrote = args.out
    if args.json:
        d = result.to_dict()
        d["example"] = example.name
        d["out"] = wrote
        d["format"] = example.meta.get("format")
        d["settings"] = settings
        d["outcome"] = outcome(result.status)
        d["proof"] = result.stats.get("proof") if result.status == "unsat" else None
        print(json.dumps(d))
    else:
        size = "x".join(map(str, shape))
        took = f"{max(0.0, result.time_s - compiling):.3f} s"
        if compiling >= 0.05:
            took += f" (+ {compiling:.1f} s compiling csplab's kernels, once)"
        msg = (
            f"{outcome(result.status)}: {example.name or args.model} {size} (K={K}) "
            f"with {result.solver} in {took}, seed {result.seed}"
        )
        print(msg)
        print("  settings: " + ", ".join(f"{k}={v}" for k, v in settings.items()))
        for line in explain(result):
            print(line)
        if meta.get("boundary_rule"):
            print(f"  boundary {meta['boundary_rule']}")
        keys = [k for k in result.stats if k not in ("order", "choice", *EXPLAINED_STATS)]
        if keys:
            print("  " + ", ".join(f"{k}={result.stats[k]}" for k in keys))
        if (result.status == "failed" and problem is not None and problem.constraints
                and fallback is None):  # fmt: skip
            from csplab.solvers import solver_class

            if solver_class(result.solver.partition(":")[0]).constraints != "exact":
                print("  hint: with global constraints, --solver backtrack, sat or asp search "
                      "with them (catalog and blocks retry with --restarts)")  # fmt: skip
        if wrote:
            unset = int((result.grid < 0).sum())
            print(f"  wrote {wrote}" + (f" (partial: {unset} cells unassigned)" if unset else ""))
        elif args.out:
            print(not_written(args.out, result.status), file=sys.stderr)
    return 0 if result.ok else 1
