"""``csplab explain``: explain why a problem is unsatisfiable (minimal conflicting constraints).

A minimal conflicting set of its fixed cells, boundary faces and masks (an assumption core,
shrunk by deletion).

Fixed cells come from ``--fixed FILE``: a ``.npy`` integer array of the output size with -1
for free cells, or a text file with one cell per line, ``x y [z ...] label`` (``#``
comments; commas and ``=`` may separate the numbers). Masks from ``--mask FILE``: a ``.npy``
boolean array ``(*size, K)``. Exit codes as every csplab command: 0 the problem is
satisfiable (nothing to explain), 1 it is unsatisfiable (the explanation is printed), 2 bad
input, 3 time limit.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.cli.common import add_problem_args, model_from_args, problem_from_args
from csplab.errors import FormatError, InputError
from csplab.problem import Problem


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_problem_args(p, size_required=True)
    add_fixed_args(p)
    p.add_argument("--backend", help="pysat backend (default cadical195)")
    p.add_argument("--no-minimize", action="store_true", help="report the first core as is")
    p.add_argument("--time-limit", type=float, help="seconds")
    p.add_argument("--json", action="store_true")


def add_fixed_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--fixed", metavar="FILE", help="fixed cells: .npy (-1 = free) or text "
                   "lines 'x y [z] label'")  # fmt: skip
    p.add_argument("--mask", metavar="FILE", help="allowed labels per cell: .npy bool (*size, K)")


def load_fixed(path: str, shape: tuple[int, ...]) -> NDArray[np.int64]:
    """Read fixed cells (see the module docstring) as an int array of ``shape`` (-1 = free)."""
    p = Path(path)
    if not p.exists():
        raise FormatError("no such file", path=path)
    out = np.full(shape, -1, dtype=np.int64)
    if p.suffix.lower() == ".npy":
        try:
            arr = np.load(p, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise FormatError(f"not a numpy file ({e})", path=path) from None
        if not np.issubdtype(arr.dtype, np.integer):
            raise FormatError(f"fixed cells must be integers (-1 = free), got {arr.dtype}",
                              path=path)  # fmt: skip
        if arr.shape != shape and [d for d in arr.shape if d != 1] == [d for d in shape if d != 1]:
            arr = arr.reshape(shape)  # e.g. a 2D array for an nz = 1 model
        if arr.shape != shape:
            raise FormatError(f"array has shape {arr.shape}, the model {shape}", path=path)
        return np.asarray(arr, dtype=np.int64)
    for lineno, raw in enumerate(p.read_text(encoding="utf-8").splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = [t for t in re.split(r"[\s,=()]+", line) if t]
        try:
            nums = [int(t) for t in parts]
        except ValueError:
            raise FormatError(f"expected integers 'x y [z] label', got {raw.strip()!r}",
                              path=path, line=lineno) from None  # fmt: skip
        ncoord = len(nums) - 1
        if not 1 <= ncoord <= len(shape) or any(d != 1 for d in shape[max(ncoord, 1) :]):
            raise FormatError(f"expected {len(shape)} coordinates and a label, got "
                              f"{len(nums)} numbers", path=path, line=lineno)  # fmt: skip
        coords = tuple(nums[:-1]) + (0,) * (len(shape) - ncoord)
        if any(not 0 <= c < s for c, s in zip(coords, shape, strict=True)):
            raise FormatError(f"cell {coords} is outside the model {shape}", path=path,
                              line=lineno)  # fmt: skip
        out[coords] = nums[-1]
    return out


def problem_with_fixed(args: argparse.Namespace) -> tuple[Any, Problem]:
    """The model and the problem from ``MODEL --size --boundary --periodic --fixed --mask``.

    Fixed cells and mask cells become one unary restriction each (so an explanation can
    name them one by one).
    """
    from csplab.grids import build_unary

    model = model_from_args(args)
    problem = problem_from_args(args, model)
    extra = []
    if getattr(args, "fixed", None):
        fixed = load_fixed(args.fixed, problem.shape)
        extra += build_unary(problem.shape, problem.K, fixed=fixed)
    if getattr(args, "mask", None):
        try:
            mask = np.load(args.mask, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise FormatError(f"not a numpy file ({e})", path=args.mask) from None
        extra += build_unary(problem.shape, problem.K, mask=mask)
    if extra:
        problem = problem.with_unary(extra)
    return model, problem


def run(args: argparse.Namespace) -> int:
    from csplab.exact import explain_unsat

    if args.time_limit is not None and args.time_limit < 0:
        raise InputError("--time-limit must be >= 0")
    model, problem = problem_with_fixed(args)
    v = explain_unsat(problem, backend=args.backend, minimize=not args.no_minimize,
                      time_limit=args.time_limit)  # fmt: skip
    size = "x".join(map(str, problem.shape))
    if args.json:
        d = v.to_dict()
        if v.holds is False:
            d["witness"] = "a solution exists"
        d.update(model=model.name or args.model, size=size)
        print(json.dumps(d))
    else:
        head = f"{model.name or args.model} {size} (K={problem.K}, {len(problem.unary)} "
        head += "fixed/boundary/mask restrictions)"
        if v.holds is None:
            print(f"undecided: {head}: {v.message}")
        elif v.holds is False:
            print(f"satisfiable: {head}; nothing to explain")
        else:
            print(f"unsat: {head}: {v.message}")
            for line in v.witness["unary"]:
                print(f"  {line}")
            print(f"  ({v.stats['sat_calls']} SAT calls, {v.stats['time_s']:.3f} s)")
    return 3 if v.holds is None else (1 if v.holds else 0)  # 1: unsat, as every command
