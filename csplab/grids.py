"""Grid builders: the model-synthesis problem of an example model on a grid (Sec. 3.1).

:func:`from_example` (also ``csplab.from_example``) turns an example model E and an output
size into a :class:`~csplab.problem.Problem`: one variable per cell, one relation per axis
(E's transition matrices, Eq. 3.2), wrap-around arcs for periodic axes, and the unary
restrictions (fixed cells, boundary labels, masks); :func:`grid` does the same from
transition matrices; :func:`with_fixed` pre-assigns cells of a problem that has been built
(a derived problem, as in :mod:`csplab.problem`). :func:`auto_boundary` finds E's ground
and empty-space labels (Fig. 3.11); :func:`parse_shape` and :func:`parse_boundary` read
``40x40x10`` and ``z-=1,x-=0``.

Examples
--------
>>> from csplab.example import ExampleModel
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), "3x3", periodic=True)
>>> P.n, len(P.arcs)
(9, 18)
>>> parse_boundary("z-=1,x-=0")
{'z-': 1, 'x-': 0}
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import InputError
from csplab.limits import check_memory
from csplab.problem import AXIS_NAMES, Problem, Unary, memory_estimate

if TYPE_CHECKING:
    from csplab.example import ExampleModel

__all__ = [
    "GridWindows",
    "arc_reach",
    "auto_boundary",
    "build_unary",
    "from_example",
    "grid",
    "merrell_boundary",
    "parse_boundary",
    "parse_shape",
    "with_fixed",
]


def parse_shape(text: str | Sequence[int], *, what: str = "size") -> tuple[int, ...]:
    """Parse ``"40x40x10"`` (or a sequence) into a shape tuple of positive ints.

    Examples
    --------
    >>> parse_shape("40x40x10")
    (40, 40, 10)
    >>> parse_shape([5, 6])
    (5, 6)
    """
    if isinstance(text, str):
        parts = text.lower().replace("×", "x").replace(",", "x").split("x")
        try:
            shape = tuple(int(p) for p in parts)
        except ValueError:
            raise InputError(
                f"{what} {text!r} is not of the form NxM or NxMxL (positive integers)"
            ) from None
    else:
        try:
            shape = tuple(int(p) for p in text)
        except (TypeError, ValueError):
            raise InputError(f"{what} {text!r} is not a sequence of integers") from None
    if not 1 <= len(shape) <= 4 or any(s < 1 for s in shape):
        raise InputError(f"{what} {text!r} must have 1 to 4 positive extents")
    if math.prod(shape) > 200_000_000:
        raise InputError(f"{what} {text!r} has too many cells")
    return shape


def parse_boundary(text: str | None) -> Literal["auto", "none"] | dict[str, int] | None:
    """``"auto"``, ``"none"`` or ``None`` as they are; ``"z-=1,x-=0"`` as a mapping."""
    if text is None:
        return None
    if text == "auto":
        return "auto"
    if text == "none":
        return "none"
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


def _face_list(ndim: int) -> list[str]:
    return [f"{AXIS_NAMES[d]}{s}" for d in range(ndim) for s in "-+"]


def _as_flag_tuple(value: bool | Sequence[bool], ndim: int, what: str) -> tuple[bool, ...]:
    if isinstance(value, bool | np.bool_):
        return (bool(value),) * ndim
    flags = tuple(bool(v) for v in value)
    if len(flags) != ndim:
        raise InputError(f"{what} needs {ndim} flags (one per axis), got {len(flags)}")
    return flags


def grid(
    shape: Sequence[int] | str,
    transitions: ArrayLike,
    *,
    periodic: bool | Sequence[bool] = False,
    fixed: ArrayLike | Mapping[Sequence[int], int] | None = None,
    boundary: Mapping[str, int] | None = None,
    mask: ArrayLike | None = None,
    weights: ArrayLike | None = None,
    names: Sequence[str] | None = None,
    name: str = "",
    meta: Mapping[str, Any] | None = None,
    labels: ArrayLike | None = None,
    topology: str | None = None,
) -> Problem:
    """A grid problem from per-axis transition matrices ``T[d, b, c]``.

    ``T[d]`` constrains each cell and its ``+1`` neighbour along axis ``d``; with
    ``periodic`` (all axes or one flag per axis) the last cell also wraps to the first.
    ``fixed``, ``boundary`` and ``mask`` restrict domains as in
    :func:`from_example` (which supplies ``T`` from an example model). ``labels`` (bool
    ``(K,)``) limits the base domains of every cell to the labels in use. ``topology``
    (:mod:`csplab.topology`: ``hex:odd-r``, ``tri``, ``cylinder`` ...) changes the
    neighbours: ``T`` then has one matrix per relation of the topology; a cylinder's
    ``theta`` axis (``y``) is periodic.
    """
    from csplab.topology import Topology

    topo = Topology.parse(topology)
    shp = parse_shape(shape) if isinstance(shape, str) else tuple(int(s) for s in shape)
    T = np.asarray(transitions, dtype=bool)
    ndim = len(shp)
    R = len(topo.relation_names(ndim))
    if T.ndim != 3 or T.shape[0] != R or T.shape[1] != T.shape[2]:
        raise InputError(
            f"transitions must have shape ({R}, K, K) for a {ndim}-D {topo.name} grid, "
            f"got {T.shape}"
        )
    K = T.shape[1]
    per = _as_flag_tuple(periodic, ndim, "periodic")
    if topo.variant == "cylinder":
        if ndim < 2:
            raise InputError("a cylinder grid needs the axes r and theta")
        per = (per[0], True, *per[2:])
    if not topo.square and any(per):
        raise InputError(f"a {topo.name} grid cannot be periodic")
    n = math.prod(shp)
    size = "x".join(map(str, shp))  # one line with the estimate before allocating
    check_memory(memory_estimate(n, K, ndim * n), f"{size} with K={K}",
                 "a smaller --size, or fewer labels", available=True)  # fmt: skip
    idx = np.arange(n, dtype=np.int64).reshape(shp)
    parts = [] if topo.square else [topo.arcs(shp)]
    for d in range(ndim if topo.square else 0):
        a = np.moveaxis(idx, d, 0)
        if shp[d] > 1:
            src, dst = a[:-1].ravel(), a[1:].ravel()
            parts.append(np.stack([src, dst, np.full_like(src, d)], axis=1))
        if per[d]:
            src, dst = a[-1].ravel(), a[0].ravel()
            parts.append(np.stack([src, dst, np.full_like(src, d)], axis=1))
    arcs = np.concatenate(parts) if parts else np.zeros((0, 3), dtype=np.int64)
    base = np.ones((n, K), dtype=bool)
    if labels is not None:
        lab = np.asarray(labels, dtype=bool).reshape(-1)
        if lab.shape != (K,):
            raise InputError(f"labels must be {K} booleans, got shape {lab.shape}")
        base &= lab
    unary = build_unary(shp, K, fixed=fixed, boundary=boundary, mask=mask)
    dom = base.copy()
    for u in unary:
        dom[u.cells] &= u.allowed
    m = dict(meta or {})
    m.setdefault("periodic", per)
    if topo.name != "square":
        m["topology"] = topo.name
    if boundary is not None:
        m.setdefault("boundary", dict(boundary))
    return Problem(
        shp,
        dom,
        T,
        arcs,
        weights=weights,
        names=names,
        relation_names=topo.relation_names(ndim),
        unary=unary,
        base_domains=base,
        name=name,
        meta=m,
    )


def from_example(
    example: ExampleModel,
    shape: Sequence[int] | str,
    *,
    periodic: bool | Sequence[bool] = False,
    fixed: ArrayLike | Mapping[Sequence[int], int] | None = None,
    boundary: Mapping[str, int] | Literal["auto", "none"] | None = None,
    mask: ArrayLike | None = None,
    topology: str | None = None,
) -> Problem:
    """The model-synthesis problem for example ``E`` and output size ``shape``.

    ``topology`` (:mod:`csplab.topology`) reads the example and builds the output on that
    grid (default: the example's own, ``example.meta["topology"]``, else square).

    Labels that never occur in the example are excluded from every cell (a model
    consistent with E only uses pieces of E, even in a cell without neighbours).

    Parameters
    ----------
    example : ExampleModel
        The example model ``E`` whose adjacent label pairs define the relations.
    shape : sequence of int or str
        Output size, e.g. ``(40, 40, 10)`` or ``"40x40x10"``. It may omit trailing axes
        along which the example has extent 1 (a 2D size for an ``nz = 1`` model).
    periodic : bool or sequence of bool
        Wrap around on all axes or on the flagged ones (toroidal output).
    fixed : int array with -1 for free cells, or mapping ``{coords: label}``
        Pre-assigned cells.
    boundary : mapping ``{face: label}``, ``"auto"`` or ``None``/``"none"``
        Label the outer layer of the model (Sec. 3.3.6, Fig. 3.11). Faces are ``"x-"``,
        ``"x+"``, ``"y-"``, ... . Where faces meet, the bottom face (the ``-`` face of the
        last axis) wins, then faces later in the order ``x-, x+, y-, y+, ...``.
        ``"auto"`` puts on the bottom face the example's most frequent bottom-layer
        label that tiles itself along the other axes (the ground), and on every other
        face the example's empty-space label: the label that tiles itself along every
        axis and is most frequent on the example's outer layer (bottom excluded); for an
        example whose empty space is one layer thin, a top-layer label that tiles itself
        along the horizontal axes.
        On a 3D example whose output has no solution under that rule (decided on a small
        probe of the output's height: arc consistency, then a search with a node budget),
        ``"auto"`` uses Merrell's rule instead: the bottom layer gets the example's label
        at ``(0, 0, 0)``, the top layer the label at the top of the example's column
        ``(0, 0)``, and the sides stay free (if that has no solution either: the bottom
        layer alone, else no boundary). ``problem.meta["boundary_rule"]`` says which rule
        was used.
    mask : bool array ``(*shape, K)`` (or broadcastable)
        Per-cell allowed labels (large-scale constraints, Sec. 3.5.3).
    topology : str, optional
        The grid to read the example on and build the output on: ``"square"``,
        ``"hex:odd-r"`` (and the other hexagonal layouts), ``"tri"``, ``"cylinder"`` or
        ``"affine:A,B,C,D"`` (default: the example's ``meta["topology"]``, else square).
        An explicit square topology reads any example along its axes.

    Returns
    -------
    Problem
        The problem: one relation per axis (or per topology direction) with its arcs, the
        restricted domains (each ``fixed``/``boundary``/``mask`` restriction recorded in
        ``problem.unary``), the example's label weights and names, and ``meta`` with the
        example, its hash and (for ``boundary="auto"``) ``"boundary_rule"``.

    Raises
    ------
    InputError
        When ``shape`` cannot be parsed or does not fit the example's dimensions,
        ``boundary`` is an unknown string, ``topology`` is unknown, a hexagonal or
        triangular example gets a size of other dimensions, a hexagonal or triangular
        output is periodic, or ``fixed``, ``boundary`` or ``mask`` do not fit the output.
    MemoryLimitError
        When the problem would not fit in the available memory (one line with the
        estimate, before anything large is allocated).
    """
    shp = parse_shape(shape) if isinstance(shape, str) else tuple(int(s) for s in shape)
    shp = _match_ndim(shp, example.shape)
    rule: str | None = None
    if isinstance(boundary, str):
        if boundary == "auto":
            boundary, rule = _auto_or_merrell(example, shp, periodic)
        elif boundary == "none":
            boundary = None
        else:
            raise InputError(f"boundary must be 'auto', 'none' or a mapping, not {boundary!r}")
    from csplab.example import pair_transitions
    from csplab.topology import Topology

    topo = Topology.parse(topology or example.meta.get("topology"))
    if topo.square:
        # an explicit square topology reads any example along its axes
        T = pair_transitions(example.labels, example.K) if topology else example.transitions()
        if T.shape[0] < len(shp):
            pad = np.zeros((len(shp) - T.shape[0], example.K, example.K), dtype=bool)
            T = np.concatenate([T, pad])
    else:
        if example.ndim != len(shp):
            raise InputError(
                f"a {example.ndim}-D {topo.name} example needs a {example.ndim}-D size"
            )
        T = topo.learn(example.labels, example.K)
    meta: dict[str, Any] = {"example": example.name, "example_hash": example.hash(),
                            "model": example}  # fmt: skip
    if rule is not None:
        meta["boundary_rule"] = rule
    return grid(
        shp,
        T,
        periodic=periodic,
        fixed=fixed,
        boundary=boundary,
        mask=mask,
        weights=example.label_weights(),
        names=example.names,
        name=example.name,
        meta=meta,
        labels=example.counts() > 0,
        topology=topo.name,
    )


_PROBE_SIDE = 6
_PROBE_NODES = 20_000


def merrell_boundary(example: ExampleModel, ndim: int | None = None) -> dict[str, int]:
    """Merrell's boundary rule: the bottom face gets the example's label at the origin and
    the top face the label at the top of the example's first column; the sides stay free.

    Examples
    --------
    >>> from csplab.example import ExampleModel
    >>> E = ExampleModel([[[2, 1, 0]], [[2, 1, 0]]])   # 2x1x3: 2 at the bottom, 0 on top
    >>> merrell_boundary(E)
    {'z-': 2, 'z+': 0}
    """
    ndim = example.ndim if ndim is None else ndim
    lab = example.labels
    axis = AXIS_NAMES[ndim - 1]
    column = lab[(0,) * (example.ndim - 1)]
    return {f"{axis}-": int(column[0]), f"{axis}+": int(column[-1])}


def _probe(
    example: ExampleModel,
    shape: tuple[int, ...],
    periodic: bool | Sequence[bool],
    boundary: Mapping[str, int],
) -> bool | None:
    """Whether the problem on a small probe of ``shape`` (sides at most 6 cells, the full
    height) has a solution: ``False`` when arc consistency wipes out or the search is
    exhausted, ``None`` when the node budget runs out."""
    from csplab._kernels import Code, Search
    from csplab.catalog import Propagator

    small = (*(min(s, _PROBE_SIDE) for s in shape[:-1]), shape[-1])
    P = from_example(example, small, periodic=periodic, boundary=boundary)
    eng = Propagator(P)
    if not eng.ok:
        return False
    search = Search.new(P.n, eng.c.W, seed=0)
    while search.nodes < _PROBE_NODES:
        code = eng.mac_search(
            search, scan=True, weighted=False, max_nodes=_PROBE_NODES - search.nodes
        )
        if code is Code.SOLVED:
            return True
        if code is Code.EXHAUSTED:
            return False
        if code is Code.GROW:
            search = search.grown()
        elif code is Code.RESTART:  # pragma: no cover - no restarts were asked for
            eng.mac_restart(search)
    return None


def _auto_or_merrell(
    example: ExampleModel, shape: tuple[int, ...], periodic: bool | Sequence[bool]
) -> tuple[dict[str, int], str]:
    """The ``boundary="auto"`` labelling for ``shape`` and a line naming the rule used."""
    ndim = len(shape)
    bottom, top = f"{AXIS_NAMES[ndim - 1]}-", f"{AXIS_NAMES[ndim - 1]}+"
    try:
        auto: dict[str, int] | None = auto_boundary(example, ndim)
    except InputError:
        if ndim != 3 or example.ndim != 3:
            raise
        auto = None
    if auto is not None:
        others = sorted({b for f, b in auto.items() if f != bottom})
        rule = (
            f"auto: ground {bottom}={auto[bottom]}, empty space "
            f"{'/'.join(map(str, others))} on every other face"
            if bottom in auto
            else f"auto: empty space {'/'.join(map(str, others))} on every face"
        )
        if ndim != 3 or example.ndim != 3 or _probe(example, shape, periodic, auto):
            return auto, rule
    merrell = merrell_boundary(example, ndim)
    why = f"the auto rule has {'no solution' if auto is not None else 'no empty-space label'}"
    if _probe(example, shape, periodic, merrell) is not False:
        return merrell, (
            f"merrell: {bottom}={merrell[bottom]}, {top}={merrell[top]}, sides free ({why})"
        )
    # never unsatisfiable because of the default: the ground alone, else no boundary
    ground = {bottom: merrell[bottom]}
    if _probe(example, shape, periodic, ground) is not False:
        return ground, (
            f"merrell, bottom only: {bottom}={merrell[bottom]} ({why}, Merrell's rule too)"
        )
    return {}, f"none ({why}, Merrell's rule and its bottom layer alone too)"


def _match_ndim(shape: tuple[int, ...], ex_shape: tuple[int, ...]) -> tuple[int, ...]:
    if len(shape) == len(ex_shape):
        return shape
    if len(shape) < len(ex_shape):
        if all(s == 1 for s in ex_shape[len(shape) :]):
            return shape + (1,) * (len(ex_shape) - len(shape))
        raise InputError(
            f"size {'x'.join(map(str, shape))} has {len(shape)} axes but the example has "
            f"shape {'x'.join(map(str, ex_shape))}"
        )
    raise InputError(
        f"size {'x'.join(map(str, shape))} has more axes than the example "
        f"({'x'.join(map(str, ex_shape))})"
    )


def build_unary(
    shape: tuple[int, ...],
    K: int,
    *,
    fixed: ArrayLike | Mapping[Sequence[int], int] | None = None,
    boundary: Mapping[str, int] | None = None,
    mask: ArrayLike | None = None,
) -> list[Unary]:
    n = math.prod(shape)
    ndim = len(shape)
    out: list[Unary] = []
    if boundary is not None:
        faces = _face_list(ndim)
        bottom = f"{AXIS_NAMES[ndim - 1]}-"
        unknown = [f for f in boundary if f not in faces]
        if unknown:
            raise InputError(f"unknown boundary face(s) {unknown}; faces are {faces}")
        order = [f for f in faces if f != bottom] + [bottom]
        owner = np.full(shape, -1, dtype=np.int64)  # index into order
        for j, f in enumerate(order):
            if f in boundary:
                d, side = AXIS_NAMES.index(f[0]), f[1]
                sl: list[slice | int] = [slice(None)] * ndim
                sl[d] = 0 if side == "-" else shape[d] - 1
                owner[tuple(sl)] = j
        flat_owner = owner.ravel()
        for j, f in enumerate(order):
            if f not in boundary:
                continue
            b = _check_label(boundary[f], K, f"boundary[{f!r}]")
            cells = np.flatnonzero(flat_owner == j).astype(np.int64)
            allowed = np.zeros((cells.size, K), dtype=bool)
            allowed[:, b] = True
            out.append(Unary("boundary", f, cells, allowed))
    if fixed is not None:
        if isinstance(fixed, Mapping):
            items: list[tuple[int, tuple[int, ...], Any]] = []
            for coords, b in fixed.items():
                c = tuple(int(i) for i in (coords if isinstance(coords, Sequence) else (coords,)))
                if len(c) != ndim or any(not 0 <= ci < si for ci, si in zip(c, shape, strict=True)):
                    raise InputError(f"fixed cell {c} is outside the grid {shape}")
                items.append((int(np.ravel_multi_index(c, shape)), c, b))
        else:
            arr = np.asarray(fixed)
            if arr.shape != shape:
                raise InputError(f"fixed array has shape {arr.shape}, expected {shape}")
            if not np.issubdtype(arr.dtype, np.integer):
                raise InputError(f"fixed array must hold integers (-1 = free), got {arr.dtype}")
            flat = arr.reshape(-1)
            if np.any(flat < -1):
                raise InputError("fixed array may only hold labels and -1 for free cells")
            items = [
                (int(c), tuple(int(i) for i in np.unravel_index(int(c), shape)), int(flat[c]))
                for c in np.flatnonzero(flat >= 0)
            ]
        for cell, where, label in items:
            lb = _check_label(label, K, f"fixed label at {where}")
            allowed = np.zeros((1, K), dtype=bool)
            allowed[0, lb] = True
            out.append(Unary("fixed", where, np.array([cell], dtype=np.int64), allowed))
    if mask is not None:
        m = np.asarray(mask)
        if m.dtype != bool:
            raise InputError(f"mask must be boolean, got dtype {m.dtype}")
        try:
            m = np.broadcast_to(m, (*shape, K)).reshape(n, K)
        except ValueError:
            raise InputError(
                f"mask of shape {np.shape(mask)} does not fit ({shape}, K={K})"
            ) from None
        for mc in np.flatnonzero(~m.all(axis=1)):
            mcoords = tuple(int(i) for i in np.unravel_index(int(mc), shape))
            out.append(
                Unary("mask", mcoords, np.array([mc], dtype=np.int64), m[mc : mc + 1].copy())
            )
    return out


def with_fixed(problem: Problem, fixed: ArrayLike | Mapping[Sequence[int], int]) -> Problem:
    """A copy of ``problem`` with some cells pre-assigned, recorded as unary restrictions.

    Parameters
    ----------
    problem : Problem
    fixed : int array with -1 for free cells, or mapping ``{coords: label}``
        The same forms as ``fixed`` of :func:`from_example`.

    Returns
    -------
    Problem
        ``problem`` with its domains intersected (``problem.with_unary``).

    Examples
    --------
    >>> from csplab.example import ExampleModel
    >>> P = with_fixed(from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3)), {(0, 0): 1})
    >>> P.fixed_grid[0].tolist()
    [1, -1, -1]
    """
    return problem.with_unary(build_unary(problem.shape, problem.K, fixed=fixed))


def _check_label(b: Any, K: int, what: str) -> int:
    try:
        lb = int(b)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a label id, got {b!r}") from None
    if not 0 <= lb < K:
        raise InputError(f"{what} = {lb} is outside the label range 0..{K - 1}")
    return lb


def auto_boundary(example: ExampleModel, ndim: int | None = None) -> dict[str, int]:
    """The ``boundary="auto"`` labelling for an example (see :func:`~csplab.grids.from_example`).

    Returns a mapping face -> label. Raises :class:`~csplab.errors.InputError` when the
    example has no empty-space label (one that tiles itself along every axis) or, for 2D and
    higher, no ground label (a bottom-layer label that tiles itself along the other axes).

    Examples
    --------
    >>> from csplab.example import ExampleModel
    >>> E = ExampleModel([[1, 0, 0], [1, 0, 0], [1, 0, 0]])   # ground 1 at y = 0
    >>> auto_boundary(E)
    {'x-': 0, 'x+': 0, 'y+': 0, 'y-': 1}
    """
    ndim = example.ndim if ndim is None else ndim
    T = example.transitions()
    lab = example.labels
    K = example.K
    diag = np.stack([np.diagonal(T[d]) for d in range(example.ndim)])  # (ndim, K)
    self_tiling = diag.all(axis=0)
    # outer layer minus the bottom face
    outer = np.zeros(lab.shape, dtype=bool)
    for d in range(example.ndim):
        sl: list[slice | int] = [slice(None)] * example.ndim
        if d != example.ndim - 1 or example.ndim == 1:
            sl[d] = 0
            outer[tuple(sl)] = True
        sl[d] = lab.shape[d] - 1
        outer[tuple(sl)] = True
    counts_outer = np.bincount(lab[outer], minlength=K)
    counts_all = np.bincount(lab.ravel(), minlength=K)
    cand = np.flatnonzero(self_tiling & (counts_all > 0))
    if cand.size == 0 and example.ndim >= 2:
        # a thin example (empty space only one layer deep): fall back to labels on the top
        # layer that tile themselves along the horizontal axes
        top = np.take(lab, lab.shape[-1] - 1, axis=example.ndim - 1)
        on_top = np.bincount(top.ravel(), minlength=K) > 0
        cand = np.flatnonzero(diag[:-1].all(axis=0) & on_top)
    if cand.size == 0:
        raise InputError(
            f"boundary='auto': example {example.name or ''} has no empty-space label "
            "(no label is adjacent to itself along every axis); give boundary labels explicitly"
        )
    empty = int(cand[np.lexsort((-counts_all[cand], -counts_outer[cand]))[0]])
    faces = _face_list(ndim)
    result = {f: empty for f in faces}
    if ndim >= 2 and example.ndim >= 2:
        last = example.ndim - 1
        bottom_layer = np.take(lab, 0, axis=last)
        cb = np.bincount(bottom_layer.ravel(), minlength=K)
        tiles_sideways = diag[:last].all(axis=0)
        gcand = np.flatnonzero(tiles_sideways & (cb > 0))
        if gcand.size == 0:
            raise InputError(
                "boundary='auto': no label on the example's bottom layer tiles itself along "
                "the horizontal axes, so there is no ground label; give boundary labels "
                "explicitly"
            )
        ground = int(gcand[np.argmax(cb[gcand])])
        bottom = f"{AXIS_NAMES[ndim - 1]}-"
        del result[bottom]
        result[bottom] = ground
    return result


def arc_reach(problem: Problem, axes: Sequence[int] | None = None) -> int:
    """The largest offset, along ``axes`` (default: every axis), between the two cells of
    an arc of a grid problem (at least 1).

    Examples
    --------
    >>> from csplab.example import ExampleModel
    >>> arc_reach(from_example(ExampleModel([[0, 1], [1, 0]]), (4, 3)))
    1
    """
    if not len(problem.arcs):
        return 1
    ax = list(range(problem.ndim)) if axes is None else list(axes)
    c = np.stack(np.unravel_index(problem.arcs[:, :2].reshape(-1), problem.shape), axis=1)
    c = c.reshape(len(problem.arcs), 2, problem.ndim)[:, :, ax]
    return max(1, int(np.abs(c[:, 0] - c[:, 1]).max()))


#: cells of one window of :meth:`GridWindows.violations` (its slabs along ``x``); small
#: windows stay in the caches: a castle 1000x1000x10 output is checked in 0.52 s of CPU
#: with 2**16, 0.68 s with 2**17, 1.1 s with 2**18 and 1.5 s with 2**19
CHECK_CELLS = 1 << 16


class GridWindows:
    """A grid problem too large to build, built window by window (thesis Sec. 3.3.6).

    The problem of ``example`` at ``shape`` (square grid, no periodic axis) restricted to a
    box of cells is the model's problem on the box's shape with the faces of the whole
    that the box touches: its domains (the boundary labels of those faces, the labels in
    use) and arcs (one relation per axis between neighbours) are those of the whole
    problem, renumbered. :meth:`window` builds it (:func:`from_example`) and keeps one
    per box shape and touched faces, so a sweep over a large output builds a handful;
    nothing of the size of the whole model is held. ``boundary="auto"`` is decided once,
    on the whole size (its small probe), as :func:`from_example` does.

    Parameters
    ----------
    example : ExampleModel
        The example model.
    shape : sequence of int or str
        The size of the whole output.
    boundary : mapping ``{face: label}``, ``"auto"``, ``"none"`` or None
        As :func:`from_example`'s.

    Raises
    ------
    InputError
        When the shape does not fit the example, the example is not on a square grid or
        the boundary is not understood.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> W = GridWindows(load_example("fig3_4a"), (30, 20), boundary="auto")
    >>> P = W.window((10, 0), (16, 20))
    >>> whole = from_example(load_example("fig3_4a"), (30, 20), boundary="auto")
    >>> bool((P.domains == whole.domains.reshape(30, 20, -1)[10:16].reshape(-1, P.K)).all())
    True
    """

    def __init__(
        self,
        example: ExampleModel,
        shape: Sequence[int] | str,
        *,
        boundary: Mapping[str, int] | Literal["auto", "none"] | None = None,
    ) -> None:
        from csplab.topology import Topology

        shp = parse_shape(shape) if isinstance(shape, str) else tuple(int(s) for s in shape)
        self.shape = _match_ndim(shp, example.shape)
        if not Topology.parse(example.meta.get("topology")).square:
            raise InputError(f"{example.name or 'the example'} is not on a square grid: "
                             "its problem cannot be built in windows")  # fmt: skip
        self.example = example
        self.rule: str | None = None
        if boundary == "auto":
            faces, self.rule = _auto_or_merrell(example, self.shape, False)
        elif boundary in (None, "none"):
            faces = {}
        elif isinstance(boundary, Mapping):
            faces = {str(f): int(b) for f, b in boundary.items()}
        else:
            raise InputError(f"boundary must be 'auto', 'none' or a mapping, not {boundary!r}")
        #: the faces of the whole output and their labels
        self.boundary: dict[str, int] = faces
        #: the window problems built so far, by shape and faces touched
        self.built: dict[tuple[Any, ...], Problem] = {}
        small = self.miniature()
        self.K = small.K
        #: the arcs' reach (a window's ring of fixed cells is this wide)
        self.reach = arc_reach(small)

    @property
    def n(self) -> int:
        """The cells of the whole output."""
        return math.prod(self.shape)

    @property
    def ndim(self) -> int:
        """Its axes."""
        return len(self.shape)

    def _build(self, shape: tuple[int, ...], faces: dict[str, int]) -> Problem:
        key = (shape, tuple(sorted(faces.items())))
        P = self.built.get(key)
        if P is None:
            P = from_example(self.example, shape, boundary=faces or "none")
            if self.rule is not None:
                P.meta["boundary_rule"] = self.rule
            self.built[key] = P
        return P

    def window(self, lo: Sequence[int], hi: Sequence[int]) -> Problem:
        """The whole problem restricted to the cells ``lo <= (x, y, ...) < hi``.

        Parameters
        ----------
        lo, hi : sequence of int
            The box's corners, one per axis (``hi`` excluded).

        Returns
        -------
        Problem
            The box's problem (cell ``(x, y, ...)`` of the whole is its cell ``(x, y, ...)
            - lo``); the same object for every box of the same shape touching the same
            faces.

        Raises
        ------
        InputError
            When the box is empty or leaves the output.
        """
        lo_, hi_ = tuple(int(v) for v in lo), tuple(int(v) for v in hi)
        if len(lo_) != self.ndim or len(hi_) != self.ndim or any(
            not 0 <= a < b <= s for a, b, s in zip(lo_, hi_, self.shape, strict=True)
        ):
            raise InputError(f"window {lo_}..{hi_} is not a box of the output {self.shape}")
        faces = {}
        for f, b in self.boundary.items():
            d = AXIS_NAMES.index(f[0])
            if (f[1] == "-" and lo_[d] == 0) or (f[1] == "+" and hi_[d] == self.shape[d]):
                faces[f] = b
        return self._build(tuple(b - a for a, b in zip(lo_, hi_, strict=True)), faces)

    def miniature(self, keep: int | None = None) -> Problem:
        """The model with every face of the whole but at most ``2 * reach + 1`` cells per
        axis (all of axis ``keep``): every kind of cell of the whole (which faces it is
        on), every relation between neighbours and, along ``keep``, every layer.

        Parameters
        ----------
        keep : int, optional
            An axis kept at its full length.

        Returns
        -------
        Problem
            The small problem.
        """
        side = 2 * getattr(self, "reach", 1) + 1
        shp = tuple(s if a == keep else min(s, side) for a, s in enumerate(self.shape))
        return self._build(shp, dict(self.boundary))

    def violations(self, grid: NDArray[np.integer[Any]], *, cells: int = CHECK_CELLS) -> int:
        """The number of violations of ``grid`` (the whole output's labels, e.g. a memory
        map) counted by :meth:`Problem.violations` of windows: slabs of the output along
        ``x`` of about ``cells`` cells, each widened by the reach so that every arc lies
        inside one; an arc is counted in the slab of its lower ``x`` end, a cell in its own.

        Parameters
        ----------
        grid : int array of the output's shape
            The labels.
        cells : int
            About the cells per window.

        Returns
        -------
        int
            Violated arcs plus cells whose label is not in their domain (0 for a solution).

        Raises
        ------
        InputError
            When ``grid`` does not have the output's shape.
        """
        if tuple(grid.shape) != self.shape:
            raise InputError(f"grid has shape {grid.shape}, the output {self.shape}")
        nx, rest = self.shape[0], math.prod(self.shape[1:])
        width = max(1, min(nx, cells // max(1, rest)))
        total = 0
        for a in range(0, nx, width):
            own = min(nx, a + width)
            hi = min(nx, own + self.reach)
            P = self.window((a, *(0,) * (self.ndim - 1)), (hi, *self.shape[1:]))
            v = P.violations(np.asarray(grid[a:hi]))
            ends = P.arcs[v.arcs, :2]
            low = np.minimum(ends[:, 0], ends[:, 1]) // rest  # the arc's lower x, local
            total += int((low < own - a).sum()) + int((v.cells // rest < own - a).sum())
        return total
