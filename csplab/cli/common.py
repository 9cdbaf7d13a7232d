"""Helpers shared by the CLI subcommands: loading a model, building a problem.

A model is an :class:`ExampleModel` (an example grid) or a
:class:`~csplab.io.ruleset.RuleSet` (a tileset's rules); both become a :class:`Problem`
through :func:`problem_from_args`.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias, TypeGuard, cast

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.grids import from_example, parse_boundary, parse_shape
from csplab.io.registry import input_help, option_help
from csplab.io.ruleset import RuleSet
from csplab.problem import Problem

if TYPE_CHECKING:
    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel

__all__ = [
    "COMPILING",
    "Model",
    "add_constraints_arg",
    "add_memory_limit_arg",
    "add_model_args",
    "add_model_option",
    "add_problem_args",
    "check_output_dir",
    "check_output_path",
    "check_time_limit",
    "input_files",
    "is_continuous",
    "load_grid",
    "load_model",
    "model_options",
    "problem_from_args",
]

#: The line the CLI prints on stderr before numba compiles csplab's kernels for the first time
#: (a fresh clone's first `synthesize city --size 40x40x10`: 22.6 s of compiling, 25.4 s of CPU).
COMPILING = "compiling csplab's kernels once (about 25 s; cached afterwards)"

Model: TypeAlias = "ExampleModel | RuleSet | PolygonModel | PolyhedralModel"


def is_continuous(model: object) -> TypeGuard[PolygonModel | PolyhedralModel]:
    """Whether ``model`` is a continuous model (polygons or polyhedra).

    :mod:`csplab.continuous` (shapely, scipy; about 0.07 s of CPU) is imported by the
    loaders that make such models, not by the CLI: a grid command does not pay for it.

    Examples
    --------
    >>> is_continuous(ExampleModel([[0, 1]]))
    False
    """
    for module, name in (("csplab.continuous.model", "PolygonModel"),
                         ("csplab.continuous.polyhedra", "PolyhedralModel")):  # fmt: skip
        mod = sys.modules.get(module)
        if mod is not None and isinstance(model, getattr(mod, name)):
            return True
    return False


def key_values(items: list[str] | None, flag: str, form: str = "KEY=VALUE") -> dict[str, Any]:
    """``KEY=VALUE`` strings of a repeatable ``flag`` as a dict (values parsed as JSON when
    possible, else kept as strings); a malformed item is one line naming the flag."""
    import json

    opts: dict[str, Any] = {}
    for kv in items or []:
        key, sep, val = kv.partition("=")
        if not sep or not key:
            raise InputError(f"{flag} {kv!r} must be {form}")
        try:
            opts[key] = json.loads(val)
        except json.JSONDecodeError:
            opts[key] = val
    return opts


def model_options(items: list[str] | None) -> dict[str, Any]:
    """The ``--model-option KEY=VALUE`` items as a dict."""
    return key_values(items, "--model-option")


def load_model(spec: str, options: dict[str, Any] | None = None) -> Model:
    """:func:`csplab.examples.load_model`, printing the loader's warnings to stderr, one line
    each.

    A model file that takes longer than :data:`csplab.progress.DELAY_S` to read (a tileset
    of many megabytes) gets one line on stderr, ``csplab: reading FILE (N MB) ...``, once
    that time has passed; the XML and picture readers parse in one call, so there is no
    bar. Quick reads print nothing.
    """
    import sys
    import threading
    import warnings

    from csplab import progress
    from csplab.examples import load_model as load

    def notice() -> None:
        try:
            mb = os.path.getsize(spec) / 1e6
        except OSError:
            mb = 0.0
        size = f" ({mb:.0f} MB)" if mb >= 1 else ""
        print(f"csplab: reading {spec}{size} ...", file=sys.stderr, flush=True)

    timer = None
    if os.path.isfile(spec):  # a file, not a built-in example
        timer = threading.Timer(progress.DELAY_S, notice)
        timer.daemon = True
        timer.start()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = load(spec, options)
    finally:
        if timer is not None:
            timer.cancel()
    for w in caught:  # one line each, no source location
        print(f"csplab: warning: {readable(str(w.message))}", file=sys.stderr)
    return model


def model_from_args(args: argparse.Namespace) -> Model:
    """The model of a command's ``MODEL`` argument, read with its ``--model-option`` values
    (:func:`load_model`, :func:`model_options`).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``model`` and ``model_option``.

    Returns
    -------
    Model
        The example model, rule set or continuous model.
    """
    return load_model(args.model, model_options(args.model_option))


def input_files(args: argparse.Namespace) -> list[tuple[str, Path]]:
    """The files a command reads, as ``(role, path)`` pairs: the model (when it is a file,
    not a built-in name), every ``--constraints`` file, the grid ``check`` reads and a
    blocks ``--option init=FILE``; an output must be none of them."""
    found: list[tuple[str, Path]] = []
    model = getattr(args, "model", None)
    if isinstance(model, str) and os.path.isfile(model):
        found.append(("the model", Path(model)))
    for c in getattr(args, "constraints", None) or []:
        found.append(("a --constraints file", Path(c)))
    grid = getattr(args, "grid", None)
    if isinstance(grid, str) and os.path.isfile(grid):
        found.append(("the grid to check", Path(grid)))
    for kv in getattr(args, "option", None) or []:
        key, _, val = str(kv).partition("=")
        if key == "init" and os.path.isfile(val):
            found.append(("the --option init grid", Path(val)))
    return found


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def _companions(p: Path) -> list[Path]:
    """The files written beside ``p``: an OBJ mesh's material library (same stem)."""
    return [p.with_suffix(".mtl")] if p.suffix.lower() == ".obj" else []


def check_output_path(
    path: str | Path,
    what: str,
    *,
    force: bool = True,
    inputs: Sequence[tuple[str, Path]] = (),
) -> Path:
    """``path`` as a file the command can write, checked before the work: its folder exists
    and is writable, ``path`` is not a folder, it is none of the ``inputs`` (never
    overwrite what was read), and (``force=False``) no file is there yet. An ``.obj``
    path checks its ``.mtl`` companion the same way.

    Parameters
    ----------
    path : str or Path
        The output file.
    what : str
        The argument that named it (``"--out"``), for the message.
    force : bool
        Whether an existing file may be overwritten.
    inputs : sequence of (str, Path)
        The files the command reads (:func:`input_files`), with their roles.

    Raises
    ------
    InputError
        One line naming ``what`` and the path.

    Examples
    --------
    >>> check_output_path("/no/such/folder/a.png", "--out")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: --out /no/such/folder/a.png: the folder /no/such/folder does \
not exist
    """
    p = Path(path)
    if str(path) == "" or p.name in ("", ".", ".."):
        raise InputError(f"{what} {str(path)!r} is not a file name")
    for q in (p, *_companions(p)):
        for role, src in inputs:
            if _same_file(q, src) or q.resolve() == src.resolve():
                raise InputError(
                    f"{what} {p}: {q} is {role} this command reads; write the output elsewhere"
                )
    for q in _companions(p):
        if q.is_dir():
            raise InputError(f"{what} {p}: its material file {q} is a folder")
        if q.exists() and not os.access(q, os.W_OK):
            raise InputError(f"{what} {p}: its material file {q} is not writable")
    folder = p.parent
    if not folder.exists():
        raise InputError(f"{what} {p}: the folder {folder} does not exist")
    if not folder.is_dir():
        raise InputError(f"{what} {p}: {folder} is not a folder")
    if p.is_dir():
        raise InputError(f"{what} {p} is a folder, not a file")
    if p.exists():
        if not force:
            raise InputError(f"{what} {p} exists; use --force to overwrite it")
        if not os.access(p, os.W_OK):
            raise InputError(f"{what} {p}: the file is not writable")
    elif not _writable(folder):
        raise InputError(f"{what} {p}: the folder {folder} is not writable")
    return p


def check_output_dir(path: str | Path, what: str) -> Path:
    """``path`` as a folder the command can write into (created later with its parents):
    not a file, and the nearest existing folder on the way is writable; one
    :class:`InputError` line naming ``what`` otherwise.

    Examples
    --------
    >>> check_output_dir("/dev/null/report", "--out")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: --out /dev/null/report: /dev/null is a file, not a folder
    """
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(f"{what} {p} is a file, not a folder")
    base = p
    while not base.exists():
        if base.parent == base:
            break
        base = base.parent
    if not base.is_dir():
        raise InputError(f"{what} {p}: {base} is a file, not a folder")
    if not _writable(base):
        raise InputError(f"{what} {p}: the folder {base} is not writable")
    return p


def _writable(folder: Path) -> bool:
    """Whether a file can be created in ``folder`` (a real probe: permissions alone do not
    tell for root, read-only mounts or ``/proc``)."""
    import tempfile

    if not os.access(folder, os.W_OK | os.X_OK):
        return False
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".csplab-probe-"):
            return True
    except OSError:
        return False


def check_time_limit(value: float | None, what: str = "--time-limit") -> float | None:
    """``value`` when it is ``None`` or a positive finite number of seconds; otherwise one
    :class:`InputError` line naming ``what``.

    Examples
    --------
    >>> check_time_limit(2.5), check_time_limit(None)
    (2.5, None)
    >>> check_time_limit(float("nan"))
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: --time-limit must be a positive number of seconds, not nan
    """
    if value is None:
        return None
    if not math.isfinite(value) or value < sys.float_info.min:  # subnormal: no usable time
        raise InputError(f"{what} must be a positive number of seconds, not {value:g}")
    return float(value)


def load_grid(path: str, ndim: int | None, model: Model | None = None) -> NDArray[np.int32]:
    """Read a label grid with ``ndim`` axes (``None``: as stored) from a file csplab
    writes: the formats that keep label ids (``.npy``, ``.txt``, ``.grid``: the registry's
    ``exact`` formats; ``.npy`` may hold ``-1`` for cells a failed or timed-out run left
    unassigned) and ``.vox`` (colour ``b + 1`` is label ``b``, colour 0 the ``model``'s
    empty label, as the writer stores them)."""
    from csplab.io import read_example
    from csplab.io.common import check_file
    from csplab.io.registry import detect

    p = check_file(path)
    if p.suffix.lower() == ".vox":
        g = _vox_labels(p, model)
    else:
        fmt = detect(p, gives="ExampleModel", exact=True).name
        if fmt == "npy":
            g = _npy_labels(p)
        else:
            g = np.asarray(read_example(p, format=fmt).labels)
    while ndim is not None and g.ndim > ndim and g.shape[-1] == 1:
        g = g[..., 0]
    if ndim is not None and g.ndim != ndim:
        raise FormatError(f"grid has shape {g.shape}, expected {ndim} axes", path=path)
    return g.astype(np.int32)


def _npy_labels(p: Path) -> NDArray[np.int64]:
    """An ``.npy`` result grid: labels ``>= 0`` and ``-1`` for unassigned cells."""
    from csplab.io.npy import load_int_array

    arr = load_int_array(p)
    if arr.size and (int(arr.min()) < -1 or int(arr.max()) > np.iinfo(np.int32).max):
        bad = int(arr.min()) if int(arr.min()) < -1 else int(arr.max())
        raise FormatError(f"label {bad} is not a label id (0, 1, ... or -1 unassigned)", path=p)
    return np.asarray(arr, dtype=np.int64)


def _vox_labels(p: Path, model: Model | None) -> NDArray[np.int64]:
    """A ``.vox`` result as labels: colour ``c > 0`` is label ``c - 1``, colour 0 the empty
    label (the model's, else the guess the writer made on the example)."""
    from csplab.io.vox import read_vox
    from csplab.render import empty_label_guess

    vox = read_vox(p)
    g = vox.grid.astype(np.int64) - 1
    empty: int | None = None
    if isinstance(model, RuleSet):
        empty = model.empty
    elif model is not None:
        empty = model.meta.get("empty")
        if empty is None:
            empty = int(empty_label_guess(np.asarray(model.labels)))
    if empty is not None and empty >= 0:
        g[g < 0] = empty
    return g


def add_memory_limit_arg(p: argparse.ArgumentParser) -> None:
    """``--memory-limit GB``: the budget a command's up-front memory estimate must fit
    (:func:`csplab.limits.memory_budget`)."""
    from csplab.limits import MEMORY_SHARE

    p.add_argument(
        "--memory-limit",
        type=float,
        metavar="GB",
        # "%%": argparse %-formats help texts (a lone "%" made every --help a traceback)
        help="refuse, before the work, a run whose estimated peak memory is larger (default: "
        f"{MEMORY_SHARE:.0%}% of the machine's RAM, or the memory available when less)",
    )


def add_constraints_arg(p: argparse.ArgumentParser) -> None:
    """``--constraints FILE`` (repeatable), for the commands that take constraints."""
    p.add_argument(
        "--constraints",
        action="append",
        metavar="FILE",
        help='a constraints file {"constraints": [...]} (repeatable); grid models take count, '
        "connected, mirror, rotate, separation and max-run (csplab.constraints); polyhedral "
        "models take dimensional, large-scale and connected (thesis Sec. 4.6)",
    )


def add_model_args(p: argparse.ArgumentParser, help: str | None = None) -> None:
    """The positional ``MODEL`` (described by ``help``, by default every input format) and
    ``--model-option`` (:func:`add_model_option`)."""
    p.add_argument(
        "model",
        metavar="MODEL",
        help=help or f"built-in example name or model file ({input_help()}; see `csplab info`)",
    )
    add_model_option(p)


def add_problem_args(p: argparse.ArgumentParser, *, size_required: bool = True) -> None:
    add_model_args(p)
    p.add_argument(
        "--size",
        help="output size such as 40x40x10 (trailing axes of extent 1 may be omitted)"
        + ("; required unless the tileset file gives one" if size_required else ""),
    )
    p.add_argument(
        "--boundary",
        default=None,
        help="'auto' (examples: ground below, empty space around, on 3D examples Merrell's rule "
        "when that has no solution; tilesets: the file's "
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
        "--grid",
        dest="topology",
        metavar="TOPOLOGY",
        help="the grid of an example model (thesis Sec. 3.5.1): square, hex:odd-r, "
        "hex:even-r, hex:odd-q, hex:even-q, tri, cylinder (theta = y, periodic) or "
        "affine:A,B,C,D (default: the example's own, else square)",
    )
    p.set_defaults(_size_required=size_required)


def add_model_option(p: argparse.ArgumentParser, of: str = "the model file") -> None:
    """``--model-option KEY=VALUE`` (repeatable): an option for the loader ``of`` a file
    (read by :func:`model_options`)."""
    p.add_argument(
        "--model-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"option for the loader of {of} (repeatable): {option_help()}",
    )


def problem_from_args(
    args: argparse.Namespace, given: Model, shape: tuple[int, ...] | None = None
) -> Problem:
    """The problem for ``--size`` (or ``shape``), ``--boundary`` and ``--periodic``."""
    if is_continuous(given):
        raise InputError(
            f"{given.name or args.model} is a {given.kind} model (continuous model synthesis): "
            "`csplab synthesize`, `check` and `show` take it; this command takes grid "
            "examples and tilesets"
        )
    model = cast("ExampleModel | RuleSet", given)
    if shape is None and args.size:
        shape = parse_shape(args.size, what="--size")
    boundary = parse_boundary(args.boundary)
    if isinstance(model, RuleSet):
        if getattr(args, "topology", None):
            raise InputError("--grid applies to example models; a tileset states its own grid")
        if shape is None and model.shape is None:
            raise InputError(f"{model.name or args.model} gives no output size: use --size")
        # no --boundary: a tileset keeps the file's own boundary conditions
        P = model.problem(shape, periodic=args.periodic, boundary=boundary or "auto")
    else:
        if shape is None:
            if getattr(args, "_size_required", False):
                raise InputError("--size is required for an example model (e.g. --size 40x40x10)")
            shape = model.shape
        topology = getattr(args, "topology", None)
        if topology:
            from csplab.topology import Topology

            topology = Topology.parse(topology).name  # one line for a bad name
        P = from_example(
            model, shape, periodic=bool(args.periodic), boundary=boundary or "none",
            topology=topology,
        )  # fmt: skip
    return with_constraint_files(P, getattr(args, "constraints", None))


def with_constraint_files(problem: Problem, paths: Sequence[str] | None) -> Problem:
    """``problem`` with the constraints of every ``--constraints FILE``
    (:func:`csplab.io.constraints.read_constraints`)."""
    if not paths:
        return problem
    from csplab.io.constraints import read_constraints
    from csplab.progress import notice_after

    extra = []
    for p in paths:
        with notice_after(f"reading the constraints of {p}"):  # a large file: one line
            extra += read_constraints(p, problem)
    return problem.with_constraints(extra)


#: stats the lines of :func:`explain` say in words
EXPLAINED_STATS = ("proof", "fallback_from", "gave_up_s", "reason")


def order_setting(setting: str, problem: Problem) -> str:
    """The ``settings:`` entry of an order: ``"auto (ORIGIN)"`` names the order ``auto``
    stands for on ``problem`` (:func:`csplab.engine.alg31.auto_order`) and why; any other
    entry is returned as it is.

    Examples
    --------
    >>> from csplab import from_example, load_example
    >>> order_setting("auto (given)", from_example(load_example("line"), (4, 3)))
    'scanline (auto: no global constraints; given)'
    """
    if not setting.startswith("auto ("):
        return setting
    from csplab.engine.alg31 import auto_order

    why = "global constraints" if problem.constraints else "no global constraints"
    return f"{auto_order(problem)} (auto: {why}; {setting.removeprefix('auto (')}"


def fallback_setting(fallback: str) -> str:
    """The settings line's ``fallback`` entry: the solver ``--fallback`` names, and where
    it came from."""
    if fallback != "auto":
        return f"{fallback} (given)"
    from csplab.deps import available

    return f"{'sat' if available('pysat') else 'backtrack'} (auto)"


def outcome(status: str) -> str:
    """What the user is told: ``solved``, ``unsat`` (an exact solver's proof) or ``not
    solved`` (every solver gave up, or the time ran out)."""
    return status if status in ("solved", "unsat") else "not solved"


def explain(result: Any) -> list[str]:
    """The lines after the first that say how the result came about: which solver gave up
    before the fallback, the proof of an ``unsat``, why a run is ``not solved``."""
    st = result.stats
    lines = []
    if "fallback_from" in st:
        n = st.get("attempts", 1)
        lines.append(
            f"  {st['fallback_from']} gave up after {n} attempt{'s' * (n != 1)} "
            f"({st.get('gave_up_s', 0.0):.3f} s"
            + (f": {st['reason']}" if result.status != "failed" and st.get("reason") else "")
            + f"); {result.solver} took over"
            + (" (too large for SAT: modify in blocks, exact block completion)"
               if result.solver == "blocks" and st["fallback_from"] != "blocks" else "")
        )  # fmt: skip
    if result.status == "unsat":
        lines.append(f"  proof: {st.get('proof', 'refuted by ' + result.solver)}")
    elif result.status == "timeout":
        lines.append("  not solved: the time limit ran out (--time-limit); satisfiability "
                     "is not decided")  # fmt: skip
    elif result.status == "failed":
        why = st.get("reason") or "the incomplete solver gave up"
        lines.append(f"  not solved: {why}; this says nothing about satisfiability "
                     "(--fallback sat or backtrack decides)")  # fmt: skip
    return lines


def not_written(out: str, status: str) -> str:
    """The stderr line when ``--out`` is not written."""
    if status == "unsat":
        return f"  not written: {out} (no solution exists: unsat, proof above)"
    return f"  not written: {out} (not solved; --out-partial writes the partial grid)"


_NP_SCALAR = re.compile(r"np\.(?:float|int|uint|complex|bool|str)_?\d*\(([^()]*)\)")
_NP_BOOL = re.compile(r"np\.(True|False)_")
_NP_ARRAY = re.compile(r"array\((\[[^()]*?\])(?:, dtype=\w+)?\)")
_ERRNO = re.compile(r"\(?\((\d+), '([^']*)'\)\)?")


def readable(message: str) -> str:
    """``message`` without Python's reprs: numpy scalars and arrays as plain numbers and
    lists, an ``OSError``-style ``(errno, 'text')`` pair as its text.

    Examples
    --------
    >>> readable("spacing np.float64(3.0) at array([1, 2], dtype=int64): np.True_")
    'spacing 3.0 at [1, 2]: True'
    >>> readable("cannot: ((34, 'Numerical result out of range'))")
    'cannot: (Numerical result out of range)'
    """
    message = _NP_SCALAR.sub(r"\1", message)
    message = _NP_BOOL.sub(r"\1", message)
    message = _NP_ARRAY.sub(lambda m: " ".join(m.group(1).split()), message)
    return _ERRNO.sub(r"(\2)", message)
