"""Helpers shared by the CLI subcommands: loading a model, building a problem."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.problem import Problem, parse_shape

__all__ = ["add_problem_args", "load_grid", "load_model", "problem_from_args"]


def load_model(spec: str) -> ExampleModel:
    """A built-in example name or a model file path."""
    from csplab.examples import ALIASES, EXAMPLES, load_example

    p = Path(spec)
    if p.exists():
        from csplab.io import read_example

        return read_example(p)
    if spec in EXAMPLES or spec in ALIASES:
        return load_example(spec)
    if p.suffix or "/" in spec or "\\" in spec:
        raise FormatError("no such file", path=spec)
    raise InputError(
        f"{spec!r} is neither a model file nor a built-in example "
        f"({', '.join(EXAMPLES)}); see `csplab info`"
    )


def load_grid(path: str, ndim: int) -> NDArray[np.int32]:
    """Read a label grid from ``.npy``, Merrell ``.txt`` or ``.grid`` with ``ndim`` axes."""
    from csplab.io import read_example

    g = np.asarray(read_example(path).labels)
    while g.ndim > ndim and g.shape[-1] == 1:
        g = g[..., 0]
    if g.ndim != ndim:
        raise FormatError(f"grid has shape {g.shape}, expected {ndim} axes", path=path)
    return g.astype(np.int32)


def add_problem_args(p: argparse.ArgumentParser, *, size_required: bool = True) -> None:
    p.add_argument("model", metavar="MODEL", help="built-in example name or model file")
    p.add_argument(
        "--size",
        required=size_required,
        help="output size such as 40x40x10 (trailing axes of extent 1 may be omitted)",
    )
    p.add_argument(
        "--boundary",
        default="none",
        help="'auto' (ground below, empty space around), 'none', or face=label pairs "
        "such as 'z-=1,x-=0'",
    )
    p.add_argument("--periodic", action="store_true", help="wrap around on every axis")


def parse_boundary(text: str) -> Any:
    if text in ("auto", "none"):
        return text
    out: dict[str, int] = {}
    for part in text.split(","):
        face, sep, lab = part.partition("=")
        if not sep:
            raise InputError(f"--boundary {text!r}: use auto, none or face=label,face=label")
        try:
            out[face.strip()] = int(lab)
        except ValueError:
            raise InputError(f"--boundary {text!r}: label {lab!r} is not an integer") from None
    return out


def problem_from_args(args: argparse.Namespace, example: ExampleModel) -> Problem:
    shape = parse_shape(args.size, what="--size") if args.size else example.shape
    return Problem.from_example(
        example, shape, periodic=bool(args.periodic), boundary=parse_boundary(args.boundary)
    )
