"""Helpers shared by the CLI subcommands: loading a model, building a problem.

A model is an :class:`ExampleModel` (an example grid) or a
:class:`~csplab.io.ruleset.RuleSet` (a tileset's rules); both become a :class:`Problem`
through :func:`problem_from_args`.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.grids import parse_boundary, parse_shape
from csplab.io.registry import input_help, option_help
from csplab.io.ruleset import RuleSet
from csplab.problem import Problem

__all__ = [
    "Model",
    "add_problem_args",
    "load_grid",
    "load_model",
    "model_options",
    "problem_from_args",
]

Model = ExampleModel | RuleSet


def model_options(items: list[str] | None) -> dict[str, Any]:
    """``KEY=VALUE`` strings (values parsed as JSON when possible) as a dict."""
    import json

    opts: dict[str, Any] = {}
    for kv in items or []:
        key, sep, val = kv.partition("=")
        if not sep or not key:
            raise InputError(f"--model-option {kv!r} must be KEY=VALUE")
        try:
            opts[key] = json.loads(val)
        except json.JSONDecodeError:
            opts[key] = val
    return opts


def load_model(spec: str, options: dict[str, Any] | None = None) -> Model:
    """:func:`csplab.io.load_model`, printing the loader's warnings to stderr, one line
    each."""
    import sys
    import warnings

    from csplab.io import load_model as load

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = load(spec, options)
    for w in caught:  # one line each, no source location
        print(f"csplab: warning: {w.message}", file=sys.stderr)
    return model


def load_grid(path: str, ndim: int) -> NDArray[np.int32]:
    """Read a label grid with ``ndim`` axes from a file that keeps label ids (``.npy``,
    ``.txt``, ``.grid``: the registry's ``exact`` formats)."""
    from csplab.io import read_example
    from csplab.io.registry import detect

    fmt = detect(path, gives="ExampleModel", exact=True).name if Path(path).is_file() else None
    g = np.asarray(read_example(path, format=fmt).labels)
    while g.ndim > ndim and g.shape[-1] == 1:
        g = g[..., 0]
    if g.ndim != ndim:
        raise FormatError(f"grid has shape {g.shape}, expected {ndim} axes", path=path)
    return g.astype(np.int32)


def add_problem_args(p: argparse.ArgumentParser, *, size_required: bool = True) -> None:
    p.add_argument(
        "model",
        metavar="MODEL",
        help=f"built-in example name or model file ({input_help()}; see `csplab info`)",
    )
    p.add_argument(
        "--size",
        help="output size such as 40x40x10 (trailing axes of extent 1 may be omitted)"
        + ("; required unless the tileset file gives one" if size_required else ""),
    )
    p.add_argument(
        "--boundary",
        default=None,
        help="'auto' (examples: ground below, empty space around; tilesets: the file's "
        "boundary conditions), 'none', or face=label pairs such as 'z-=1,x-=0' "
        "(default: none for examples, the file's for tilesets)",
    )
    p.add_argument(
        "--periodic",
        action="store_true",
        default=None,
        help="wrap around on every axis (default: off, or the tileset file's setting)",
    )
    p.add_argument(
        "--model-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"option for the model file's loader (repeatable): {option_help()}",
    )
    p.set_defaults(_size_required=size_required)


def problem_from_args(
    args: argparse.Namespace, model: Model, shape: tuple[int, ...] | None = None
) -> Problem:
    """The problem for ``--size`` (or ``shape``), ``--boundary`` and ``--periodic``."""
    if shape is None and args.size:
        shape = parse_shape(args.size, what="--size")
    boundary = parse_boundary(args.boundary)
    if isinstance(model, RuleSet):
        if shape is None and model.shape is None:
            raise InputError(f"{model.name or args.model} gives no output size: use --size")
        # no --boundary: a tileset keeps the file's own boundary conditions
        return model.problem(shape, periodic=args.periodic, boundary=boundary or "auto")
    if shape is None:
        if getattr(args, "_size_required", False):
            raise InputError("--size is required for an example model (e.g. --size 40x40x10)")
        shape = model.shape
    return Problem.from_example(
        model, shape, periodic=bool(args.periodic), boundary=boundary or "none"
    )
