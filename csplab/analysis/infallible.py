"""Infallibility proofs: the corner condition (Eq. 3.11) and the region prover (Alg. 3.6/3.7).

An example model E is *infallible* (thesis Sec. 3.3.7) when Alg. 3.1, run in a given scan
order, can never fail on it, whatever the output size and whatever labels it draws.

Reading of Sec. 3.3.7 used here (the seed text lost subscripts; see
``papers/merrell-2009-thesis/infallibility_reading.md``)
---------------------------------------------------------------------------------------
*Scan orders.* A scan visits cells lexicographically with the axes in a fixed order
(outermost first): ``"scanline"`` is Alg. 3.1's loop (x outermost), ``"scan:yx"`` the
thesis' 2D figures (left to right, then bottom to top). Random and min-entropy orders have
no region proof (a later neighbour may already be assigned) and are rejected.

*Alg. 3.6/3.7.* Alg. 3.6 is Alg. 3.1 except that the label at the point ``p`` is drawn
from ``C_R(p)``: arc consistency (Alg. 3.2/3.3) computed on the region ``R`` only, with
the labels already assigned inside ``R``. With region size ``r`` per axis, ``R`` is the box
``p - 1 .. p + r - 2`` on every axis, clipped at the model border (``p`` sits one cell in
from the minimum corner). Alg. 3.7 prints the loop bound ``p + r - 1``, which would give
``r + 1`` cells; we read ``r`` as the region's size, as the text says ("R has a size of
r_x x r_y x r_z") and as the 2x2 discussion requires.

*Theorem 3.3.6, as proven here.* Let ``r_d >= 2``. (i) The box contains ``p - e_d`` for
every axis, and in a lexicographic scan ``p - e_d`` is assigned before ``p`` while
``p + e_d`` is not; a label drawn from ``C_R(p)`` agrees with every assigned neighbour, so a
complete run of Alg. 3.6 is a consistent model. (ii) Arc consistency is monotone: the full
catalog ``C_{M_t}`` restricted to ``R`` is arc consistent on the smaller problem ``R`` with
fewer assignments, so ``C_{M_t}(p) ⊆ C_R(p)`` (Eq. 3.10). Hence every prefix of a run of
Alg. 3.1 is a prefix of a run of Alg. 3.6. (iii) If Alg. 3.6 can never fail, every such
prefix ``M_t`` completes to a consistent model, so ``C*_{M_t}`` is not empty anywhere, and
by Theorem 3.3.2 neither is ``C_{M_t}``: Alg. 3.1 never fails, and at the point it is about
to assign, ``C(p) = C*(p)`` (each label of ``C(p)`` starts a run of Alg. 3.6 that
completes). This is Lemma 3.3.1 restricted to the point being assigned, which is all
that infallibility needs.

*Eq. 3.11, corrected.* With ``r = 2`` the region of ``p`` is the unit box with ``p`` at its
top corner and every other cell already assigned, so ``C_R(p)`` is the set of labels
agreeing with the backward neighbours of ``p``. Alg. 3.6 never fails iff every labelling
of the unit box minus its top corner that is consistent on the box's arcs has a
completion -- in 2D: for all ``a, b, c`` with ``T_y(a, b)`` and ``T_x(a, c)`` there is a
``d`` with ``T_x(b, d)`` and ``T_y(c, d)`` -- and the same holds on every face of the box
(clipped regions at the first row and column: every label has a successor along each
axis). Every such labelling is reachable at a corner of the output, so this is exact.
:func:`corner_condition` checks it in closed form.

*The prover.* For larger regions the reachable contents of ``R`` depend on the whole run.
:func:`prove_infallible` over-approximates them soundly. The position of ``p`` relative to
the output's edges matters only up to a bound, so finitely many *configurations* (distance
to each lower edge ``0..1+history``, to each upper edge ``0..r-2``, capped) cover every
point of every output size. For each configuration a *frame* of cells is enumerated: the
cells before ``p`` in the box ``p - 1 - history .. p + r - 2``. Frame cells are labelled in
scan order, each with every label of its own ``C_R`` computed from what the frame sees
(its region intersected with the frame box; cells outside the frame count as
unassigned). Fewer assignments and a smaller region only enlarge a catalog, so every real
run restricted to the frame is among the enumerated labellings; if ``C_R(p)`` is never
empty, Alg. 3.6 never fails and E is infallible. Pruning a labelling where an earlier
frame cell's catalog is empty is sound (such a run already failed there, which that
cell's own configuration detects). Memoisation keeps only the labels that still influence
a later catalog (a fixed cell matters only through arcs to unassigned cells of a later
region), so equal futures are explored once. A window in which ``C_R(p)`` is empty is
replayed on a concrete output by exhaustive Alg. 3.6 to show that the failure is real.

Examples
--------
>>> from csplab.examples import load_example
>>> corner_condition(load_example("line")).holds
True
>>> v = corner_condition(load_example("fig3_4a"))
>>> v.holds, v.witness["labels"]
(False, {'a': 0, 'b': 1, 'c': 1})
>>> prove_infallible(load_example("fig3_4a"), region=(3, 2), order="scan:yx").holds
True
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import grids
from csplab._interp import set_bits
from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.grids import from_example
from csplab.problem import AXIS_NAMES
from csplab.result import Verdict

if TYPE_CHECKING:
    from csplab.io.ruleset import RuleSet

__all__ = [
    "Rules",
    "alg36_failure",
    "corner_condition",
    "dead_at",
    "dead_labels",
    "face_rules_of",
    "label_classes",
    "proof_scope",
    "prove_infallible",
    "region_box",
    "region_catalog",
    "run_certificate",
    "scan_axes",
]

Coords = tuple[int, ...]


# ----------------------------------------------------------------------------- rules


class Rules:
    """Transition matrices of an example as Python-int bitsets (bit ``c`` = label ``c``).

    ``fwd[d][a]``: labels that may follow ``a`` along ``+d``; ``bwd[d][c]``: labels that
    may precede ``c``. ``used``: labels that occur in the example (the only labels a cell
    may take, as in :func:`~csplab.grids.from_example`).
    """

    def __init__(self, T: ArrayLike, used: ArrayLike | None = None) -> None:
        Tb = np.asarray(T, dtype=bool)
        if Tb.ndim != 3 or Tb.shape[1] != Tb.shape[2]:
            raise InputError(f"transitions must have shape (ndim, K, K), got {Tb.shape}")
        self.T = Tb
        self.ndim, self.K = int(Tb.shape[0]), int(Tb.shape[1])
        u = np.ones(self.K, dtype=bool) if used is None else np.asarray(used, dtype=bool)
        self.used_mask = u
        self.used = _to_bits(u)
        self.fwd = [[_to_bits(Tb[d, a] & u) for a in range(self.K)] for d in range(self.ndim)]
        self.bwd = [[_to_bits(Tb[d, :, c] & u) for c in range(self.K)] for d in range(self.ndim)]
        self._union: dict[tuple[int, bool, int], int] = {}

    @classmethod
    def of(cls, example: ExampleModel | RuleSet | Rules) -> Rules:
        """The rules of an example (its labels in use) or of a rule set (every label)."""
        if isinstance(example, Rules):
            return example
        if isinstance(example, ExampleModel):
            return cls(example.transitions(), example.counts() > 0)
        return cls(example.transitions())

    def union(self, d: int, forward: bool, dom: int) -> int:
        """Labels supported along axis ``d`` by some label of ``dom`` (forward: as successor)."""
        key = (d, forward, dom)
        hit = self._union.get(key)
        if hit is not None:
            return hit
        table = self.fwd[d] if forward else self.bwd[d]
        out = 0
        for b in set_bits(dom):
            out |= table[b]
        if len(self._union) < 2_000_000:
            self._union[key] = out
        return out


def _bools(bits: int, K: int) -> NDArray[np.bool_]:
    return np.array([bool(bits >> b & 1) for b in range(K)], dtype=bool)


def _to_bits(mask: ArrayLike) -> int:
    out = 0
    for b in np.flatnonzero(np.asarray(mask, dtype=bool)):
        out |= 1 << int(b)
    return out


def _graph_ac(
    rules: Rules, dom: list[int], arcs: list[list[tuple[int, int, bool]]]
) -> list[int] | None:
    """Arc consistency on a tiny graph (``arcs[u]`` = ``(v, axis, v is u + e_axis)``).
    Returns the domains, or ``None`` on a wipe-out."""
    queue = list(range(len(dom)))
    inq = [True] * len(dom)
    while queue:
        u = queue.pop()
        inq[u] = False
        du = dom[u]
        for v, d, fwd in arcs[u]:
            nv = dom[v] & rules.union(d, fwd, du)
            if nv != dom[v]:
                if nv == 0:
                    return None
                dom[v] = nv
                if not inq[v]:
                    inq[v] = True
                    queue.append(v)
    return dom


def label_classes(rules: Rules, axes: Sequence[int] | None = None) -> list[int]:
    """Each label's class: the least label that supports the same labels as it forward
    along every axis of ``axes`` (default: all; ``fwd[d][a]`` equal for these ``d``).

    A frame cell whose forward neighbour along an axis is labelled (or outside the frame)
    no longer acts along it, so the prover's memoisation key records its label by its
    class along the other axes only.

    Why the prover may record a frame label as its class: a labelled frame cell ``x``
    changes a later catalog only through arcs to unlabelled cells, and in a scan order
    those are its forward neighbours (``x - e_d`` comes before ``x``, so inside the frame
    it is labelled). Along a forward arc, ``x``'s label ``a`` narrows the neighbour to
    ``fwd[d][a]`` and keeps ``a`` iff the neighbour's domain meets ``fwd[d][a]``: both
    depend on ``a`` only through its class. Arcs between two labelled cells hold in every
    run (each label was drawn from a catalog of a region holding its backward
    neighbours), so leaving them out of arc consistency changes no catalog of a real run.

    Parameters
    ----------
    rules : Rules
    axes : sequence of int, optional
        The axes compared.

    Returns
    -------
    list of int
        ``K`` entries; unused labels are their own class.

    Examples
    --------
    >>> label_classes(Rules([[[1, 1, 0], [1, 1, 0], [0, 0, 1]]]))
    [0, 0, 2]
    >>> label_classes(Rules([[[1, 1, 0], [1, 1, 0], [0, 0, 1]]]), axes=[])
    [0, 0, 0]
    """
    first: dict[tuple[int, ...], int] = {}
    out = []
    for a in range(rules.K):
        if not rules.used >> a & 1:
            out.append(a)
            continue
        ax = range(rules.ndim) if axes is None else axes
        out.append(first.setdefault(tuple(rules.fwd[d][a] for d in ax), a))
    return out


# ----------------------------------------------------------------------------- orders, regions


def scan_axes(ndim: int, order: str) -> tuple[int, ...]:
    """Axes of a scan order, outermost first (``"scanline"`` or ``"scan:AXES"``).

    Examples
    --------
    >>> scan_axes(2, "scan:yx"), scan_axes(3, "scanline")
    ((1, 0), (0, 1, 2))
    """
    if order == "scanline":
        return tuple(range(ndim))
    if order.startswith("scan:"):
        axes = tuple(AXIS_NAMES.find(a) for a in order[5:])
        if sorted(axes) == list(range(ndim)):
            return axes
        raise InputError(
            f"order {order!r}: name each of the {ndim} axes ({AXIS_NAMES[:ndim]}) once, "
            "outermost first"
        )
    raise InputError(
        f"order {order!r} has no region proof: use 'scanline' or 'scan:AXES' (a scan order)"
    )


def parse_region(region: Sequence[int] | str | int, ndim: int) -> tuple[int, ...]:
    if isinstance(region, int):
        r = (region,) * ndim
    elif isinstance(region, str):
        try:
            r = tuple(int(t) for t in region.lower().replace("×", "x").split("x"))
        except ValueError:
            raise InputError(f"region {region!r} is not of the form 3x2 or 2x2x2") from None
    else:
        r = tuple(int(t) for t in region)
    if len(r) < ndim:
        r = r + (2,) * (ndim - len(r))
    if len(r) != ndim:
        raise InputError(f"region {region!r} has {len(r)} axes, the example has {ndim}")
    if any(t < 2 for t in r):
        raise InputError(f"region {region!r}: Theorem 3.3.6 needs at least 2 cells per axis")
    return r


def region_box(
    p: Sequence[int],
    shape: Sequence[int],
    region: Sequence[int],
    back: Sequence[int] | None = None,
) -> tuple[Coords, Coords]:
    """The region of Alg. 3.7 at ``p``: inclusive ``(lo, hi)`` corners, clipped to ``shape``.

    ``back`` (default 1 per axis, Alg. 3.7's ``p - 1``) is how far the region reaches
    before ``p``: a region reaching further back still holds every ``p - e_d``, so
    Theorem 3.3.6 holds for it too, and it sees more of what was assigned.

    Examples
    --------
    >>> region_box((0, 3), (5, 5), (3, 2))
    ((0, 2), (1, 3))
    >>> region_box((2, 3), (5, 5), (3, 2), back=(2, 1))
    ((0, 2), (3, 3))
    """
    bk = (1,) * len(p) if back is None else back
    lo = tuple(max(0, int(pd) - int(b)) for pd, b in zip(p, bk, strict=True))
    hi = tuple(
        min(int(n) - 1, int(pd) + int(rd) - 2) for pd, n, rd in zip(p, shape, region, strict=True)
    )
    return lo, hi


def region_catalog(
    example: ExampleModel,
    grid: ArrayLike,
    p: Sequence[int],
    region: Sequence[int] | str,
) -> NDArray[np.int64]:
    """``C_R(p)`` of Alg. 3.7: arc consistency on the region of ``p`` only, with the labels
    of ``grid`` (``-1`` = unassigned) inside the region. Uses :class:`Propagator` on the
    region's sub-grid (a literal reference for the prover's own bitset code).

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> g = np.full((3, 3), -1); g[0, 1] = 1; g[1, 0] = 1      # two 1s on a diagonal
    >>> region_catalog(load_example("fig3_4a"), g, (1, 1), "2x2").tolist()
    []
    """
    from csplab.catalog import Propagator

    G = np.asarray(grid)
    r = parse_region(region, G.ndim)
    lo, hi = region_box(p, G.shape, r)
    sl = tuple(slice(a, b + 1) for a, b in zip(lo, hi, strict=True))
    sub = G[sl]
    fixed = np.where(sub >= 0, sub, -1).astype(np.int64)
    P = grids.grid(sub.shape, example.transitions(), fixed=fixed, labels=example.counts() > 0)
    eng = Propagator(P)
    if not eng.ok:
        return np.zeros(0, dtype=np.int64)
    return eng.domain(P.cell(tuple(int(a) - b for a, b in zip(p, lo, strict=True))))


# ----------------------------------------------------------------------------- walks


class _Walk:
    """Cells visited in scan order inside a box ``ext``; each cell's region clipped to it.

    Cell ``i`` of ``cells`` is labelled from the catalog of its region in which the cells
    ``< i`` are assigned and every other cell of the box is unassigned. Precomputes, per
    step, the small arc-consistency graph (fixed cells that border no unassigned cell of
    the region are left out: they cannot change the catalog) and which earlier labels a
    later step still depends on (the memoisation key).
    """

    def __init__(
        self,
        ext: Coords,
        cells: list[Coords],
        region: Coords,
        base: Callable[[Coords], int] | None = None,
        back: Coords | None = None,
        reduce: Rules | None = None,
    ) -> None:
        self.ext, self.cells, self.region = ext, cells, region
        # with ``reduce``: labels are drawn as their class (:func:`label_classes`), the
        # memoisation key records each label by its class along the axes on which the
        # cell's forward neighbour is not yet labelled, and arcs between two labelled cells
        # are left out (see :func:`label_classes`)
        classes = None if reduce is None else label_classes(reduce)
        self.classes = classes
        index = {c: i for i, c in enumerate(cells)}
        ndim = len(ext)
        self.steps: list[tuple[list[int], list[list[tuple[int, int, bool]]], int]] = []
        # per step, the domain of each unassigned node before arc consistency (None: the
        # labels in use; else a cell's domain under the file's face rules)
        self.bases: list[list[int] | None] = []
        relfixed: list[list[int]] = []
        for i, c in enumerate(cells):
            lo, hi = region_box(c, ext, region, back)
            box = list(itertools.product(*[range(a, b + 1) for a, b in zip(lo, hi, strict=True)]))
            inbox = set(box)

            def fixed(x: Coords, i: int = i) -> bool:
                j = index.get(x)
                return j is not None and j < i

            keep: list[Coords] = []
            for x in box:
                if not fixed(x):
                    keep.append(x)
                    continue
                for d in range(ndim):
                    for s in (-1, 1):
                        y = (*x[:d], x[d] + s, *x[d + 1 :])
                        if y in inbox and not fixed(y):
                            break
                    else:
                        continue
                    keep.append(x)
                    break
            pos = {x: k for k, x in enumerate(keep)}
            arcs: list[list[tuple[int, int, bool]]] = [[] for _ in keep]
            for x, k in pos.items():
                for d in range(ndim):
                    y = (*x[:d], x[d] + 1, *x[d + 1 :])
                    m = pos.get(y)
                    if m is not None and (classes is None or not (fixed(x) and fixed(y))):
                        arcs[k].append((m, d, True))
                        arcs[m].append((k, d, False))
            src = [index[x] if fixed(x) else -1 for x in keep]
            self.steps.append((src, arcs, pos[c]))
            self.bases.append(None if base is None else [base(x) for x in keep])
            relfixed.append([j for j in src if j >= 0])
        n = len(cells)
        # labels of steps < i that some step >= i still depends on
        self.key_at: list[list[int]] = [[] for _ in range(n + 1)]
        need: set[int] = set()
        for i in range(n - 1, -1, -1):
            need |= set(relfixed[i])
            self.key_at[i] = sorted(j for j in need if j < i)
        # per step, per key cell: label -> the label recorded in the memoisation key
        self.proj: list[list[list[int]]] | None = None
        if reduce is not None:
            canon: dict[frozenset[int], list[int]] = {}

            def open_axes(j: int, i: int) -> frozenset[int]:
                x = cells[j]
                out = set()
                for d in range(ndim):
                    y = (*x[:d], x[d] + 1, *x[d + 1 :])
                    if y[d] < ext[d] and index.get(y, n) >= i:
                        out.add(d)
                return frozenset(out)

            self.proj = []
            for i in range(n + 1):
                row = []
                for j in self.key_at[i]:
                    ax = open_axes(j, i)
                    if ax not in canon:
                        canon[ax] = label_classes(reduce, sorted(ax))
                    row.append(canon[ax])
                self.proj.append(row)
        self._cache: dict[tuple[int, tuple[int, ...]], int] = {}

    def catalog(self, rules: Rules, i: int, labels: Sequence[int]) -> int:
        src, arcs, target = self.steps[i]
        key = (i, tuple(labels[j] for j in src if j >= 0))
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        bases = self.bases[i]
        if bases is None:
            dom = [rules.used if j < 0 else (1 << labels[j]) for j in src]
        else:
            dom = [
                b0 & rules.used if j < 0 else (1 << labels[j])
                for j, b0 in zip(src, bases, strict=True)
            ]
        out = _graph_ac(rules, dom, arcs)
        res = 0 if out is None else out[target]
        if len(self._cache) < 4_000_000:
            self._cache[key] = res
        return res


class _Budget(Exception):
    pass


def _scan_cells(ext: Coords, axes: tuple[int, ...]) -> list[Coords]:
    cells = list(itertools.product(*[range(e) for e in ext]))
    cells.sort(key=lambda c: tuple(c[a] for a in axes))
    return cells


# ----------------------------------------------------------------------------- the prover


Edges = tuple[tuple[bool, ...], tuple[bool, ...]]


def _configs(
    ndim: int, region: Coords, history: Coords, faces: bool = False, back: Coords | None = None
) -> Iterator[tuple[Coords, Coords, Edges]]:
    """Positions of a point: distances to the lower edges (the last value meaning "at
    least"), to the upper edges (likewise), and whether the frame's first / last cell on
    each axis is on the output's edge (always when the frame is clipped there; both ways
    otherwise, when the file has face rules)."""
    bk = (1,) * ndim if back is None else back
    lo_ranges = [range(1 + bk[d] + history[d]) for d in range(ndim)]
    hi_ranges = [range(region[d] - 1) for d in range(ndim)]
    for lo in itertools.product(*lo_ranges):
        for hi in itertools.product(*hi_ranges):
            opts_lo = [
                (True,) if lo[d] < bk[d] + history[d] else ((False, True) if faces else (False,))
                for d in range(ndim)
            ]
            opts_hi = [
                (True,) if hi[d] < region[d] - 2 else ((False, True) if faces else (False,))
                for d in range(ndim)
            ]
            for at_lo in itertools.product(*opts_lo):
                for at_hi in itertools.product(*opts_hi):
                    yield lo, hi, (at_lo, at_hi)


def _frame(
    lo: Coords,
    hi: Coords,
    axes: tuple[int, ...],
    region: Coords,
    edges: Edges | None = None,
    face_domain: Callable[[frozenset[str]], int] | None = None,
    back: Coords | None = None,
    reduce: Rules | None = None,
    dead_where: Mapping[Where, int] | None = None,
) -> tuple[_Walk, Coords, Coords]:
    ext = tuple(a + 1 + b for a, b in zip(lo, hi, strict=True))
    q = lo
    key_q = tuple(q[a] for a in axes)
    cells = [c for c in _scan_cells(ext, axes) if tuple(c[a] for a in axes) < key_q]
    cells.append(q)
    base = None
    if face_domain is not None and edges is not None:
        at_lo, at_hi = edges

        def base(x: Coords) -> int:
            on = {AXIS_NAMES[d] + "-" for d in range(len(x)) if at_lo[d] and x[d] == 0}
            on |= {AXIS_NAMES[d] + "+" for d in range(len(x)) if at_hi[d] and x[d] == ext[d] - 1}
            dom = face_domain(frozenset(on))
            if dead_where:  # the labels alive wherever the cell may be
                alive = 0
                for k in itertools.product(*_where_options(x, ext, at_lo, at_hi, DEAD_CAP)):
                    alive |= ~dead_where[k]
                dom &= alive
            return dom

    return _Walk(ext, cells, region, base, back, reduce), ext, q


def prove_infallible(
    example: ExampleModel | RuleSet,
    region: Sequence[int] | str | int = 2,
    *,
    order: str = "scanline",
    history: Sequence[int] | int = 1,
    max_states: int = 5_000_000,
    realize: bool = True,
    refute: bool = True,
    certificate: bool = False,
    boundary: Mapping[str, int] | str | None = None,
    time_limit: float | None = None,
    back: Sequence[int] | int = 1,
    classes: bool = False,
) -> Verdict:
    """Prove that Alg. 3.1 never fails on ``example`` (any output size) via Alg. 3.6.

    Parameters
    ----------
    example : ExampleModel or RuleSet
        An example (its labels in use) or a tileset's rules (every label). The proof is
        about open grids: not periodic, no boundary conditions (:func:`proof_scope` says
        why a rule set falls outside it).
    region : int, ``"3x2"`` or sequence
        Region size ``r`` per axis (at least 2; missing trailing axes are 2).
    order : str
        A scan order: ``"scanline"`` (x outermost, default) or ``"scan:AXES"``.
    history : int or sequence
        Extra cells before the region, per axis, that the frame remembers (more history =
        a tighter over-approximation and more states).
    max_states : int
        Give up (``holds=None``) after this many memoised states.
    realize : bool
        When a window with an empty ``C_R`` is found, search a concrete output on which
        Alg. 3.6 really fails there (exhaustive Alg. 3.6).
    refute : bool
        When the proof fails, look for a failing run of Alg. 3.1 on small outputs
        (:func:`csplab.analysis.witness.find_failure`, exhaustive) to refute infallibility.
    certificate : bool
        Put a certificate in ``witness["certificate"]`` (a dict, JSON-ready): when proved,
        the closed set of frame states of every configuration (checked by
        :mod:`csplab.certcheck` without this module's code); when refuted, the failing run.
    boundary : mapping face -> label, "auto", "none" or None
        An example's boundary labels, as in :func:`~csplab.grids.from_example` (``"auto"``:
        :func:`~csplab.grids.auto_boundary`, the ground and empty space, whatever the
        output size; ``synthesize`` falls back to Merrell's rule where that has no
        solution). A tileset's boundary is its file's own.
    time_limit : float, optional
        Seconds for the enumeration; past them the verdict is undecided, as when the
        state budget runs out.
    back : int or sequence
        How far each region reaches before its point, per axis (Alg. 3.7: 1). Larger
        values see more of the assigned cells (:func:`region_box`).
    classes : bool
        Record each frame label as its class (:func:`label_classes`: labels that support
        the same labels along every axis forward have equal futures in the frame), so
        equal futures are explored once; the certificate then lists the classes.

    Raises
    ------
    InputError
        A bad region, order or history, or a model outside the proof's scope.

    Returns
    -------
    Verdict
        ``holds=True``: Alg. 3.6 cannot fail, so E is infallible (Theorem 3.3.6);
        ``stats`` has the configuration and state counts and ``witness`` the proof hash and
        a re-check command. ``holds=False``: E is fallible (``witness["alg31"]`` is a
        failing run of Alg. 3.1). ``holds=None``: not proven with this region (the
        Alg. 3.6 failure, real or only possible, is in ``witness``) or the state budget ran
        out.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> v = prove_infallible(load_example("fig3_4a"), "2x2", order="scan:yx", refute=False)
    >>> v.holds, v.witness["alg36"]["realized"]
    (None, True)
    """
    t0 = time.perf_counter()
    why = proof_scope(example)
    if why is not None:
        raise InputError(f"{example.name or 'the model'}: {why}")
    rules = Rules.of(example)
    ndim = rules.ndim
    axes = scan_axes(ndim, order)
    r = parse_region(region, ndim)
    face_rules = face_rules_of(example, boundary)
    rules0 = rules  # the certificate's rules; ``rules`` without the labels dead everywhere
    # dead labels by where a cell is (with label classes only: their certificates are
    # checked with per-cell domains)
    dead: list[tuple[str, list[tuple[Where, list[int]]]]] = []
    dead_where: dict[Where, int] = {}
    if classes and face_rules:  # the same for every region the decision ladder tries
        key = (example.hash(), repr(face_rules))
        if key not in _DEAD_SEEN:
            if len(_DEAD_SEEN) > 32:
                _DEAD_SEEN.clear()
            stages = dead_labels(rules, face_rules)
            _DEAD_SEEN[key] = (stages, dead_at(rules, face_rules, stages=stages))
        dead, dead_where = _DEAD_SEEN[key]
    if dead:
        everywhere = functools.reduce(lambda a, b: a & b, dead_where.values())
        rules = Rules(rules.T, rules.used_mask & ~_bools(everywhere, rules.K))
    face_domain = _face_domain(face_rules, rules) if face_rules else None
    if face_rules:
        realize = False  # exhaustive Alg. 3.6 on a concrete output ignores the face rules
    hist = (int(history),) * ndim if isinstance(history, int) else tuple(int(h) for h in history)
    if len(hist) != ndim or any(h < 0 for h in hist):
        raise InputError(f"history needs {ndim} non-negative values, got {history!r}")
    bk = (int(back),) * ndim if isinstance(back, int) else tuple(int(b) for b in back)
    if len(bk) != ndim or any(b < 1 for b in bk):
        raise InputError(f"back needs {ndim} values of at least 1, got {back!r}")
    btxt = "" if set(bk) == {1} else "x".join(map(str, bk))
    rtxt = "x".join(map(str, r)) + (f" (back {btxt})" if btxt else "")
    stats: dict[str, Any] = {
        "region": list(r),
        "order": order,
        "history": list(hist),
        "back": list(bk),
        "configs": 0,
        "states": 0,
        "windows": 0,
        "K": int(rules.used_mask.sum()),
    }
    digest = hashlib.sha256()
    digest.update(repr((example.hash(), r, order, hist)).encode())
    if set(bk) != {1}:
        digest.update(repr(bk).encode())
    if face_rules:
        digest.update(repr(face_rules).encode())
    if dead:
        digest.update(repr(dead).encode())
        stats["dead"] = sum(len(b) for _, got in dead for _, b in got)
    cls = label_classes(rules) if classes else None
    if cls is not None:
        digest.update(repr(cls).encode())
        stats["classes"] = len(set(cls))
    failure: dict[str, Any] | None = None
    closed: list[dict[str, Any]] = []
    deadline = None if time_limit is None else t0 + float(time_limit)
    try:
        for lo, hi, edges in _configs(ndim, r, hist, bool(face_rules), bk):
            walk, ext, q = _frame(
                lo, hi, axes, r, edges, face_domain, bk, rules if classes else None, dead_where
            )
            stats["configs"] += 1
            seen: set[tuple[int, tuple[int, ...]]] | None = set() if certificate else None
            fail, nstates, windows = _enumerate(
                rules, walk, max_states - stats["states"], seen, deadline
            )
            if seen is not None:
                closed.append({
                    "lower": list(lo), "upper": list(hi),
                    "at_lower": list(edges[0]), "at_upper": list(edges[1]),
                    "keys": walk.key_at[: len(walk.cells)],
                    "states": sorted([i, list(k)] for i, k in seen),
                })  # fmt: skip
            stats["states"] += nstates
            stats["windows"] += len(windows)
            for w in sorted(windows):
                digest.update(repr((lo, hi, w) if not face_rules else (lo, hi, edges, w)).encode())
            if fail is not None:
                failure = {
                    "config": {"lower": list(lo), "upper": list(hi), "edges": edges},
                    "output": list(ext),
                    "p": list(q),
                    "frame": [[list(c), int(b)] for c, b in zip(walk.cells, fail, strict=False)],
                }
                break
    except _Budget:
        stats["time_s"] = time.perf_counter() - t0
        return Verdict(
            None,
            None,
            stats,
            (
                "undecided: time limit reached"
                if deadline is not None and time.perf_counter() > deadline
                else f"undecided: state budget {max_states} reached"
            )
            + f" with {rtxt} regions "
            f"({stats['states']} states, {stats['configs']} configurations)",
        )
    stats["time_s"] = time.perf_counter() - t0
    if failure is None:
        h = digest.hexdigest()
        name = (example.meta.get("source") if not isinstance(example, ExampleModel) else None) or (
            example.name or "MODEL"
        )
        if face_rules and isinstance(example, ExampleModel):
            bnd = _boundary_map(example, boundary) or {}
            name += " --boundary " + ",".join(f"{f}={b}" for f, b in bnd.items())
        hs = "x".join(map(str, hist))
        proof: dict[str, Any] = {
            "scope": _scope(face_rules),
            "sha256": h,
            "recheck": f"csplab prove {name} --region {'x'.join(map(str, r))} --order {order} "
            f"--history {hs} " + (f"--back {btxt} " if btxt else "") + f"--expect-hash {h}",
        }
        if certificate:
            proof["certificate"] = _certificate(
                example, rules0, face_rules, "infallible", stats,
                {"region": list(r), "order": order, "axes": list(axes), "history": list(hist),
                 "back": list(bk), "configs": closed}
                | ({} if cls is None else {"label_classes": True})
                | ({"dead": {"cap": DEAD_CAP, "stages": [
                    [f, [[[list(a) for a in k], b] for k, b in got]] for f, got in dead
                ]}} if dead else {}),
            )  # fmt: skip
        dtxt = f"({stats['dead']} labels dead near faces; " if dead else "("
        return Verdict(
            True,
            proof,
            stats,
            f"infallible: Alg. 3.6 with {rtxt} regions ({order}) cannot fail "
            + dtxt
            + f"{stats['windows']} windows, {stats['states']} states, "
            f"{stats['configs']} configurations, {stats['time_s']:.2f} s)",
        )
    # the window check failed: is the failure real?
    wit: dict[str, Any] = {"alg36": failure}
    failure["realized"] = False
    if realize:
        prefer = {tuple(c): b for c, b in failure["frame"]}
        real = _realize(rules, failure, r, axes, prefer, order, bk)
        if real is not None:
            failure["realized"] = True
            failure["run"] = real
    msg = (
        f"not proven: Alg. 3.6 with {rtxt} regions ({order}) "
        + ("fails (replayed on a " if failure["realized"] else "may fail (window only; ")
        + "x".join(map(str, failure["output"]))
        + (" output)" if failure["realized"] else " output not realised)")
    )
    if failure["realized"]:
        alg31 = _as_alg31_failure(example, failure["run"], order)
        if alg31 is not None:
            wit["alg31"] = alg31
            if certificate:
                stats["time_s"] = time.perf_counter() - t0
                wit["certificate"] = _certificate(
                    example, rules0, face_rules, "fallible", stats, {"run": alg31}
                )
            return Verdict(False, wit, stats, msg + "; the same run fails in Alg. 3.1: fallible")
    if refute:
        from csplab.analysis.witness import find_failure

        ff = find_failure(
            example, order=order, max_size=_refute_size(ndim), random_runs=0,
            max_states=50_000 if ndim <= 2 else 5_000, boundary=_boundary_map(example, boundary),
        )  # fmt: skip
        stats["refute_states"] = ff.stats.get("states", 0)
        if ff.holds is False:
            wit["alg31"] = ff.witness
            if certificate and ff.witness is not None:
                stats["time_s"] = time.perf_counter() - t0
                run = dict(ff.witness)
                if face_rules:  # the run's boundary is the certificate's face rules
                    run["boundary"] = "auto"
                wit["certificate"] = _certificate(
                    example, rules0, face_rules, "fallible", stats, {"run": run}
                )
            return Verdict(False, wit, stats, msg + "; Alg. 3.1 fails too: fallible")
        size = "x".join(map(str, _refute_size(ndim)))
        done = "exhaustive" if ff.holds is True else "incomplete search"
        msg += f"; no failure of Alg. 3.1 found on outputs up to {size} ({done})"
    return Verdict(None, wit, stats, msg)


def proof_scope(model: ExampleModel | RuleSet) -> str | None:
    """Why the region proof cannot decide ``model`` as the synthesizer builds it (one line),
    or ``None`` when it can.

    The proof is about Alg. 3.1 on square grids of every size: no wrap-around, no global
    constraint, one transition matrix per axis; domain rules are covered when each applies
    to a face of the output or to every cell (the file's boundary conditions). Examples
    always qualify (on open grids); a rule set when its file states nothing else.

    Parameters
    ----------
    model : ExampleModel or RuleSet

    Returns
    -------
    str or None

    Examples
    --------
    >>> from csplab.io.ruleset import RuleSet
    >>> proof_scope(RuleSet(np.ones((2, 2, 2), dtype=bool), periodic=True))
    'the file makes the grid periodic: the region proof covers open grids only'
    >>> proof_scope(RuleSet(np.ones((2, 2, 2), dtype=bool))) is None
    True
    """
    if isinstance(model, ExampleModel):
        return None
    if getattr(model, "topology", "square") != "square":
        return f"{model.topology} grids have no scan order with a region proof (square only)"
    if model.constraints:
        return "the file states global constraints, which the region proof does not cover"
    per = model.periodic
    if per if isinstance(per, bool | np.bool_) else any(per):
        return "the file makes the grid periodic: the region proof covers open grids only"
    boxes = [op for op in (*model.boundary_ops, *model.constraint_ops) if _op_face(op) is None]
    if boxes:
        return (
            f"the file restricts the domains of boxes of cells ({len(boxes)} rules such as "
            f"{boxes[0].key or boxes[0].op!r}), which the region proof does not model: only "
            "faces and the whole grid"
        )
    return None


def _op_face(op: Any) -> str | None:
    """Where a domain rule applies, if the region proof can say: ``"x-"`` ... a face,
    ``"!x-"`` every cell but that face, ``"*"`` every cell; else ``None``."""
    if op.face is not None:
        return str(op.face)
    if op.region is None:
        return "*"
    parts = []
    for d, (a, b) in enumerate(op.region):
        if a in (None, 0) and b is None:
            continue
        sign = {(0, 1): "-", (-1, None): "+", (1, None): "!-", (None, -1): "!+"}.get((a, b))
        if sign is None or d >= len(AXIS_NAMES):
            return None
        if d < len(op.flip) and op.flip[d]:
            sign = sign.replace("-", "?").replace("+", "-").replace("?", "+")
        neg = sign.startswith("!")
        parts.append(("!" if neg else "") + AXIS_NAMES[d] + sign[-1])
    if not parts:
        return "*"
    return parts[0] if len(parts) == 1 else None


def _scope(face_rules: Sequence[Any]) -> str:
    n = len(face_rules)
    return "grids of every size, not periodic, " + (
        f"with {n} boundary/domain rules on faces" if n else "no boundary conditions"
    )


def _boundary_map(
    model: ExampleModel | RuleSet, boundary: Mapping[str, int] | str | None
) -> dict[str, int] | None:
    """An example's boundary as a mapping face -> label (``None``: none)."""
    if boundary is None or boundary == "none":
        return None
    if not isinstance(model, ExampleModel):
        raise InputError(
            f"{model.name or 'a tileset'}: its boundary is its file's own (no --boundary)"
        )
    if isinstance(boundary, str):
        if boundary != "auto":
            return _boundary_map(model, grids.parse_boundary(boundary))
        return grids.auto_boundary(model, model.ndim)
    faces = [f"{AXIS_NAMES[d]}{s}" for d in range(model.ndim) for s in "-+"]
    bad = [f for f in boundary if f not in faces]
    if bad:
        raise InputError(f"unknown boundary face(s) {bad}; faces are {faces}")
    return {str(f): int(b) for f, b in boundary.items()}


def face_rules_of(
    model: ExampleModel | RuleSet, boundary: Mapping[str, int] | str | None = None
) -> list[tuple[str, str, list[int]]]:
    """The domain rules the region proof applies, in order: a rule set's own (boundary
    rules first, as :meth:`RuleSet.problem` applies them on open grids), or an example's
    ``boundary`` labels (each face forced, the bottom face last: it wins where faces meet,
    as in :func:`~csplab.grids.from_example`).

    Parameters
    ----------
    model : ExampleModel or RuleSet
        Within :func:`proof_scope`.
    boundary : mapping face -> label, "auto", "none" or None
        An example's boundary (a tileset's is its file's own).

    Returns
    -------
    list of (op, where, labels)
        ``op`` keep / remove / force / add; ``where`` a face (``"z-"``), every cell but a
        face (``"!z-"``) or every cell (``"*"``); the labels, sorted.

    Examples
    --------
    >>> from csplab.io.ruleset import DomainOp, RuleSet
    >>> rs = RuleSet(np.ones((2, 2, 2), dtype=bool),
    ...              boundary_ops=[DomainOp("force", np.array([False, True]), face="y-")])
    >>> face_rules_of(rs)
    [('force', 'y-', [1])]
    """
    if isinstance(model, ExampleModel):
        bnd = _boundary_map(model, boundary)
        if not bnd:
            return []
        bottom = f"{AXIS_NAMES[model.ndim - 1]}-"
        faces = [f"{AXIS_NAMES[d]}{s}" for d in range(model.ndim) for s in "-+"]
        order = [f for f in faces if f != bottom] + [bottom]
        return [("force", f, [bnd[f]]) for f in order if f in bnd]
    _boundary_map(model, boundary)  # refuses a boundary for a tileset
    out = []
    for op in (*model.boundary_ops, *model.constraint_ops):
        face = _op_face(op)
        assert face is not None  # proof_scope refused the others
        out.append((str(op.op), face, np.flatnonzero(op.labels).tolist()))
    return out


Where = tuple[tuple[int, ...], ...]
DEAD_CAP = 3
# dead labels per (model hash, face rules): the stages and the bit sets per place
_DEAD_SEEN: dict[tuple[str, str], tuple[list[Any], dict[Where, int]]] = {}


def dead_labels(
    rules: Rules, face_rules: Sequence[tuple[str, str, list[int]]], cap: int = DEAD_CAP
) -> list[tuple[str, list[tuple[Where, list[int]]]]]:
    """Labels that arc consistency removes before the first choice, by where the cell
    is: stages ``(face, [(where, labels), ...])`` in order.

    ``where`` is a cell's distance to the lower and upper face on each axis, capped at
    ``cap`` (``cap`` meaning "at least"). A label is dead at ``where`` when no cell there
    may take it (its faces' domain rules), or when a stage says so: for each neighbour
    one cell nearer ``face`` (each ``where`` it may have), every label that supports it
    from there is dead, earlier or in this stage. Then it is in no initial catalog ``C_0``
    (the greatest arc-consistent domains) of a cell there, of any output: by induction
    over the stages and then the distance to the face (a label of ``C_0`` has a support
    in ``C_0`` of each neighbour). Alg. 3.1's catalogs lie inside ``C_0``, so
    :func:`prove_infallible` takes the dead labels out of each frame cell's domain (out
    of use where dead everywhere). Only domain rules on faces kill labels.

    Parameters
    ----------
    rules : Rules
    face_rules : sequence of (op, where, labels)
        As :func:`face_rules_of` returns them.
    cap : int
        Distances from which on cells count as equally far.

    Returns
    -------
    list of (str, list of (tuple, list of int))

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> E = load_example("fig3_5a")    # its objects stand on the bottom edge: with empty
    >>> d = dead_at(Rules.of(E), face_rules_of(E, "auto"))   # space all round, none fits
    >>> sorted(set.intersection(*({b for b in range(9) if k >> b & 1} for k in d.values())))
    [1, 2, 3, 4, 5, 6, 7, 8]
    >>> dead_labels(Rules.of(E), [])
    []
    """
    if not face_rules:
        return []
    ndim = rules.ndim
    dead = _domain_dead(rules, face_rules, cap)
    stages = []
    grew = True
    while grew:
        grew = False
        for d in range(ndim):
            for s, face in ((-1, AXIS_NAMES[d] + "-"), (1, AXIS_NAMES[d] + "+")):
                table = rules.bwd[d] if s < 0 else rules.fwd[d]
                near = {k: _toward(k, d, s, cap) for k in dead if k[d][0 if s < 0 else 1] > 0}
                B = {k: rules.used & ~dead[k] for k in near}
                changed = True
                while changed:  # the greatest set whose supports toward the face are dead
                    changed = False
                    for k, ns in near.items():
                        keep = sum(
                            1 << b for b in set_bits(B[k])
                            if all(not table[b] & ~(dead[n] | B.get(n, 0)) for n in ns)
                        )  # fmt: skip
                        if keep != B[k]:
                            B[k], changed = keep, True
                got = [(k, list(set_bits(b))) for k, b in B.items() if b]
                if got:
                    stages.append((face, got))
                    for k, b in B.items():
                        dead[k] |= b
                    grew = True
    return stages


def dead_at(
    rules: Rules,
    face_rules: Sequence[tuple[str, str, list[int]]],
    cap: int = DEAD_CAP,
    stages: Sequence[tuple[str, list[tuple[Where, list[int]]]]] | None = None,
) -> dict[Where, int]:
    """The dead labels (a bit set) at each ``where`` (see :func:`dead_labels`; ``stages``:
    its result, if at hand)."""
    dead = _domain_dead(rules, face_rules, cap)
    if stages is None:
        stages = dead_labels(rules, face_rules, cap)
    for _, got in stages:
        for k, labels in got:
            for b in labels:
                dead[k] |= 1 << b
    return dead


def _domain_dead(
    rules: Rules, face_rules: Sequence[tuple[str, str, list[int]]], cap: int
) -> dict[Where, int]:
    """Per ``where``: the labels in use that the faces' domain rules exclude there."""
    domain = _face_domain(face_rules, rules)
    ndim = rules.ndim
    out = {}
    for k in itertools.product(itertools.product(range(cap + 1), repeat=2), repeat=ndim):
        on = {AXIS_NAMES[d] + "-" for d in range(ndim) if k[d][0] == 0}
        on |= {AXIS_NAMES[d] + "+" for d in range(ndim) if k[d][1] == 0}
        out[k] = rules.used & ~domain(frozenset(on))
    return out


def _toward(k: Where, d: int, s: int, cap: int) -> list[Where]:
    """Where the neighbour along ``s * e_d`` of a cell at ``k`` may be."""
    lo, hi = k[d]
    if s < 0:
        los, his = ([lo - 1] if lo < cap else [cap - 1, cap]), [min(hi + 1, cap)]
    else:
        los, his = [min(lo + 1, cap)], ([hi - 1] if hi < cap else [cap - 1, cap])
    return [(*k[:d], (a, b), *k[d + 1 :]) for a in los for b in his]


def _where_options(
    x: Coords, ext: Coords, at_lo: Sequence[bool], at_hi: Sequence[bool], cap: int
) -> list[list[tuple[int, int]]]:
    """Per axis, the capped distances to the faces a frame cell ``x`` may have (exact
    where the frame's first / last cell lies on the face, else one more at least)."""
    out = []
    for d in range(len(x)):
        up = ext[d] - 1 - x[d]
        los = [min(x[d], cap)] if at_lo[d] else list(range(min(x[d] + 1, cap), cap + 1))
        his = [min(up, cap)] if at_hi[d] else list(range(min(up + 1, cap), cap + 1))
        out.append([(a, b) for a in los for b in his])
    return out


def _face_domain(
    face_rules: Sequence[tuple[str, str, list[int]]], rules: Rules
) -> Callable[[frozenset[str]], int]:
    """The domain (bit set) of a cell on the given faces, under the rules in file order."""
    cache: dict[frozenset[str], int] = {}

    def domain(faces: frozenset[str]) -> int:
        hit = cache.get(faces)
        if hit is None:
            dom = rules.used
            for op, face, labels in face_rules:
                on = face == "*" or (face[1:] not in faces if face[0] == "!" else face in faces)
                if not on:
                    continue
                bits = sum(1 << b for b in labels)
                if op == "keep":
                    dom &= bits
                elif op == "remove":
                    dom &= ~bits
                elif op == "force":
                    dom = bits
                else:  # add
                    dom |= bits
            hit = cache[faces] = dom & rules.used
        return hit

    return domain


def _certificate(
    example: ExampleModel | RuleSet,
    rules: Rules,
    face_rules: Sequence[tuple[str, str, list[int]]],
    claim: str,
    stats: Mapping[str, Any],
    body: Mapping[str, Any],
) -> dict[str, Any]:
    """A certificate (format ``csplab-certificate`` version 1) for :mod:`csplab.certcheck`."""
    import json

    rel = {
        "labels": rules.K,
        "used": [int(b) for b in rules.used_mask],
        "pairs": [np.argwhere(rules.T[d]).tolist() for d in range(rules.ndim)],
        "faces": [[op, face, labels] for op, face, labels in face_rules],
    }
    canon = json.dumps(rel, sort_keys=True, separators=(",", ":")).encode()
    return {
        "format": "csplab-certificate",
        "version": 1,
        "claim": claim,
        "scope": "Alg. 3.1 in the given scan order, " + _scope(face_rules),
        "model": {"name": example.name, "hash": example.hash()},
        "rules": rel,
        "rules_sha256": hashlib.sha256(canon).hexdigest(),
        "prover": {k: stats[k] for k in ("time_s", "states", "configs") if k in stats},
        **body,
    }


def run_certificate(
    example: ExampleModel | RuleSet,
    run: Mapping[str, Any],
    stats: Mapping[str, Any],
    boundary: Mapping[str, int] | str | None = None,
) -> dict[str, Any]:
    """A "fallible" certificate of a failing run of Alg. 3.1 (a witness of
    :func:`~csplab.analysis.witness.find_failure`), for :mod:`csplab.certcheck`.

    Parameters
    ----------
    example : ExampleModel or RuleSet
    run : mapping
        ``shape``, ``order`` and ``choices`` of the run.
    stats : mapping
        The search's figures (``time_s`` is recorded as the prover's time).
    boundary : mapping, "auto", "none" or None
        An example's boundary, as given to the search (a tileset's is its own).

    Returns
    -------
    dict
    """
    face_rules = face_rules_of(example, boundary)
    body = dict(run)
    if face_rules:  # the run's boundary is the certificate's face rules
        body["boundary"] = "auto"
    return _certificate(example, Rules.of(example), face_rules, "fallible", stats, {"run": body})


def _refute_size(ndim: int) -> tuple[int, ...]:
    return {1: (8,), 2: (5, 4), 3: (3, 2, 2)}.get(ndim, (2,) * ndim)


_R = TypeVar("_R")


def _enumerate(
    rules: Rules,
    walk: _Walk,
    budget: int,
    seen: set[tuple[int, tuple[int, ...]]] | None = None,
    deadline: float | None = None,
) -> tuple[list[int] | None, int, set[tuple[int, ...]]]:
    """DFS over the frame's labellings; returns (failing labels or None, states, windows).
    ``seen`` (if given) receives the memoised states ``(step, key labels)``."""
    last = len(walk.cells) - 1
    windows: set[tuple[int, ...]] = set()
    src_q = [j for j in walk.steps[last][0] if j >= 0]

    def at_last(i: int, cat: int, labels: list[int]) -> list[int] | None:
        if i < last:
            return None
        windows.add((*(labels[j] for j in src_q), cat))
        return list(labels) if cat == 0 else None

    fail, states = _dfs(rules, walk, budget, at_last, seen=seen, deadline=deadline)
    return fail, states, windows


def _dfs(
    rules: Rules,
    walk: _Walk,
    budget: int,
    found: Callable[[int, int, list[int]], _R | None],
    first: Mapping[int, int] | None = None,
    seen: set[tuple[int, tuple[int, ...]]] | None = None,
    deadline: float | None = None,
) -> tuple[_R | None, int]:
    """Depth-first search over the labellings of ``walk``'s cells in order, memoised on the
    labels later steps still see (``walk.key_at``); raises :class:`_Budget` past ``budget``
    states.

    At step ``i``, with ``labels`` of the cells before it and ``cat`` the bit set of the
    labels cell ``i`` may take, ``found(i, cat, labels)`` is what the search returns, if
    not ``None``; the search ends at the last cell. Labels are tried in increasing order,
    ``first[i]`` (if possible) first. Returns what was found (or ``None``) and the number
    of states visited (``seen``, if given, collects them). Past ``deadline`` (a
    ``time.perf_counter()`` value) it raises :class:`_Budget` too."""
    if seen is None:
        seen = set()
    labels: list[int] = []
    last = len(walk.cells) - 1

    proj = walk.proj

    def rec(i: int) -> _R | None:
        if proj is None:
            key = (i, tuple(labels[j] for j in walk.key_at[i]))
        else:
            key = (i, tuple(m[labels[j]] for m, j in zip(proj[i], walk.key_at[i], strict=True)))
        if key in seen:
            return None
        seen.add(key)
        if len(seen) > budget:
            raise _Budget
        if deadline is not None and not len(seen) & 1023 and time.perf_counter() > deadline:
            raise _Budget
        cat = walk.catalog(rules, i, labels)
        res = found(i, cat, labels)
        if res is not None or i == last:
            return res
        cls = walk.classes
        opts = list(set_bits(cat)) if cls is None else sorted({cls[b] for b in set_bits(cat)})
        want = None if first is None else first.get(i)
        if want is not None and want in opts:
            opts.remove(want)
            opts.insert(0, want)
        for b in opts:
            labels.append(b)
            res = rec(i + 1)
            labels.pop()
            if res is not None:
                return res
        return None

    return (rec(0) if last >= 0 else None), len(seen)


# ----------------------------------------------------------------------------- Alg. 3.6 runs


def alg36_failure(
    example: ExampleModel,
    shape: Sequence[int] | str,
    region: Sequence[int] | str | int = 2,
    *,
    order: str = "scanline",
    max_states: int = 2_000_000,
) -> Verdict:
    """Exhaustive Alg. 3.6 on one output size: does some choice sequence fail?

    Every label of ``C_R`` is tried at every step (memoised on the labels later regions
    still see). ``holds=True``: Alg. 3.6 never fails on this size; ``False``: ``witness``
    is a choice sequence ``[[coords, label], ...]`` whose last point has an empty ``C_R``
    (label ``None``); ``None``: ``max_states`` reached.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> alg36_failure(load_example("fig3_4a"), (3, 3), "2x2", order="scan:yx").holds
    False
    """
    from csplab.grids import parse_shape

    rules = Rules.of(example)
    shp = parse_shape(shape) if isinstance(shape, str) else tuple(int(s) for s in shape)
    if len(shp) < rules.ndim:
        shp = shp + (1,) * (rules.ndim - len(shp))
    axes = scan_axes(len(shp), order)
    r = parse_region(region, len(shp))
    t0 = time.perf_counter()
    try:
        run, states = _alg36_search(rules, shp, r, axes, {}, None, max_states)
    except _Budget:
        return Verdict(None, None, {"states": max_states}, "undecided: state budget reached")
    stats = {"states": states, "time_s": time.perf_counter() - t0, "shape": list(shp)}
    if run is None:
        return Verdict(True, None, stats, f"Alg. 3.6 never fails on {shp}")
    return Verdict(False, run, stats, f"Alg. 3.6 fails on {shp} after {len(run) - 1} choices")


def _alg36_search(
    rules: Rules,
    shp: Coords,
    r: Coords,
    axes: tuple[int, ...],
    prefer: Mapping[Coords, int],
    stop: Coords | None,
    max_states: int,
    back: Coords | None = None,
) -> tuple[list[list[Any]] | None, int]:
    cells = _scan_cells(shp, axes)
    if stop is not None:
        cells = cells[: cells.index(stop) + 1]
    walk = _Walk(shp, cells, r, None, back)

    def dead_end(i: int, cat: int, labels: list[int]) -> list[list[Any]] | None:
        if cat:
            return None
        return [[list(c), b] for c, b in zip(cells, labels, strict=False)] + [
            [list(cells[i]), None]
        ]

    first = {i: prefer[c] for i, c in enumerate(cells) if c in prefer}
    return _dfs(rules, walk, max_states, dead_end, first)


def _realize(
    rules: Rules,
    failure: dict[str, Any],
    r: Coords,
    axes: tuple[int, ...],
    prefer: Mapping[Coords, int],
    order: str,
    back: Coords | None = None,
) -> dict[str, Any] | None:
    """A concrete run of Alg. 3.6 failing at the window's point (or earlier), if one exists
    on the window's output or one a little larger at the lower edges."""
    out = tuple(failure["output"])
    p = tuple(failure["p"])
    hi = tuple(failure["config"]["upper"])
    ndim = len(out)
    grow_axes = [d for d in range(ndim) if hi[d] == r[d] - 2]
    tries = [(0,) * ndim]
    for g in (1, 2):
        for d in range(ndim):
            tries.append(tuple(g if e == d else 0 for e in range(ndim)))
        for d in grow_axes:
            tries.append(tuple(-g if e == d else 0 for e in range(ndim)))
    for delta in tries:
        shift = tuple(max(0, t) for t in delta)
        shp = tuple(out[d] + abs(delta[d]) for d in range(ndim))
        pp = tuple(p[d] + shift[d] for d in range(ndim))
        pref = {tuple(c[d] + shift[d] for d in range(ndim)): b for c, b in prefer.items()}
        try:
            run, _ = _alg36_search(rules, shp, r, axes, pref, pp, 200_000, back)
        except _Budget:
            continue
        if run is not None:
            return {"shape": list(shp), "choices": run, "order": order}
    return None


def _as_alg31_failure(
    example: ExampleModel | RuleSet, run: dict[str, Any], order: str
) -> dict[str, Any] | None:
    """If a failing Alg. 3.6 run only used labels of Alg. 3.1's catalog, it is a failing
    run of Alg. 3.1 too (``C ⊆ C_R``): return it as a witness."""
    from csplab.catalog import Propagator

    shape = tuple(run["shape"])
    if isinstance(example, ExampleModel):
        P = from_example(example, shape)
    else:  # the open grid of the proof's scope (proof_scope: no restrictions to drop)
        P = example.problem(shape, periodic=False, boundary="none")
    eng = Propagator(P)
    choices: list[list[Any]] = []
    for c, b in run["choices"]:
        cell = P.cell(tuple(c))
        if b is None:
            if eng.domain(cell).size == 0 or not eng.ok:
                return {"shape": list(shape), "order": order, "choices": choices}
            return None
        if not eng.ok or b not in eng.domain(cell):
            return None
        choices.append([list(c), int(b)])
        if not eng.assign(cell, int(b)):
            return {"shape": list(shape), "order": order, "choices": choices}
    return None


# ----------------------------------------------------------------------------- Eq. 3.11


def corner_condition(example: ExampleModel | RuleSet, order: str = "scanline") -> Verdict:
    """The corner condition (Eq. 3.11, corrected), in 1D, 2D and 3D.

    For every face of the unit box (every non-empty set of axes): each labelling of the
    box minus its top corner that is consistent on the box's arcs has a label for the top
    corner. In 2D: every used label has a successor along x and along y, and for all
    ``a, b, c`` with ``T_y(a, b)`` and ``T_x(a, c)`` some ``d`` has ``T_x(b, d)`` and
    ``T_y(c, d)``. It holds iff Alg. 3.6 with 2x2(x2) regions cannot fail, which proves
    E infallible (Theorem 3.3.6). Every scan order visits the top corner of each unit box
    last, so the condition does not depend on ``order`` (checked to be a scan order).

    Returns a :class:`Verdict`; on failure ``witness`` names the face (``axes``) and the
    labels: ``{"a": ..}`` (1D), ``{"a", "b" (a + e_second), "c" (a + e_first)}`` (2D), or
    the three backward neighbours ``u`` of the top corner (3D).
    """
    t0 = time.perf_counter()
    why = proof_scope(example)
    if why is None and face_rules_of(example):
        why = (
            "the corner condition is about open grids; prove without --corner applies the "
            "file's face rules"
        )
    if why is not None:
        raise InputError(f"{example.name or 'the model'}: {why}")
    T = example.transitions()
    ndim = T.shape[0]
    scan_axes(ndim, order)
    if ndim > 3:
        v = prove_infallible(example, 2, order=order, history=0, realize=False, refute=False)
        return Verdict(v.holds is True, v.witness, v.stats, "corner condition (4D, by prover)")
    used = Rules.of(example).used_mask
    Tu = T & used[None, :, None] & used[None, None, :]
    checked = 0
    # 1D faces
    for d in range(ndim):
        bad = np.flatnonzero(used & ~Tu[d].any(axis=1))
        checked += int(used.sum())
        if bad.size:
            return _corner_fail(
                example, (d,), {"a": int(bad[0])}, checked, t0,
                f"label {example.label_name(int(bad[0]))} has no successor along "
                f"{AXIS_NAMES[d]}",
            )  # fmt: skip
    # 2D faces: a at the origin, b = a + e_j, c = a + e_i, d at the top
    for i, j in itertools.combinations(range(ndim), 2):
        Ti, Tj = Tu[i].astype(np.int64), Tu[j].astype(np.int64)
        # completions[b, c] = #d with T_i(b, d) and T_j(c, d)
        comp = Ti @ Tj.T
        reach = (Tj.T @ Ti) > 0  # reach[b, c]: some a with T_j(a, b), T_i(a, c)
        checked += int(reach.sum())
        bad2 = np.argwhere(reach & (comp == 0))
        if bad2.size:
            b, c = (int(t) for t in bad2[0])
            a = int(np.flatnonzero(Tu[j][:, b] & Tu[i][:, c])[0])
            return _corner_fail(
                example, (i, j), {"a": a, "b": b, "c": c}, checked, t0,
                f"T_{AXIS_NAMES[j]}({a}, {b}) and T_{AXIS_NAMES[i]}({a}, {c}) but no d with "
                f"T_{AXIS_NAMES[i]}({b}, d) and T_{AXIS_NAMES[j]}({c}, d)",
            )  # fmt: skip
    if ndim == 3:
        res = _corner3(Tu)
        checked += res[1]
        if res[0] is not None:
            u = res[0]
            return _corner_fail(
                example, (0, 1, 2), {"u": list(u)}, checked, t0,
                f"backward neighbours {u} of a unit cube's top corner admit no label",
            )  # fmt: skip
    return Verdict(
        True,
        None,
        {"checked": checked, "time_s": time.perf_counter() - t0},
        f"corner condition holds ({checked} corner labellings)",
    )


def _corner3(Tu: NDArray[np.bool_]) -> tuple[tuple[int, int, int] | None, int]:
    """3D cube: u_d at q - e_d, w_de at q - e_d - e_e, z at q - e_x - e_y - e_z."""
    K = Tu.shape[1]
    T = [Tu[d].astype(np.int64) for d in range(3)]

    def W(i: int, j: int) -> NDArray[np.int64]:
        # W[u_i, u_j, w]: w = q - e_i - e_j with T_j(w, u_i) and T_i(w, u_j)
        return np.asarray(Tu[j].T[:, None, :] & Tu[i].T[None, :, :], dtype=np.int64)

    def Z(i: int, j: int, k: int) -> NDArray[np.bool_]:
        # Z[u_i, u_j, z]: some w in W(i, j) with T_k(z, w)
        w = W(i, j)
        return np.asarray((w.reshape(K * K, K) @ T[k].T).reshape(K, K, K) > 0, dtype=bool)

    z01, z02, z12 = Z(0, 1, 2), Z(0, 2, 1), Z(1, 2, 0)
    # completion of the top: d with T_0(u_0, d), T_1(u_1, d), T_2(u_2, d)
    checked = 0
    for u0 in range(K):
        # candidates (u1, u2) with no completion
        top = T[1][None, :, :] * T[2][:, None, :]  # [u2, u1, d]
        comp = (top & T[0][u0][None, None, :]).any(axis=2).T  # [u1, u2]
        ex = (z01[u0][:, None, :] & z02[u0][None, :, :] & z12).any(axis=2)  # [u1, u2]
        checked += int(ex.sum())
        bad = np.argwhere(ex & ~comp)
        if bad.size:
            return (u0, int(bad[0][0]), int(bad[0][1])), checked
    return None, checked


def _corner_fail(
    example: ExampleModel | RuleSet,
    axes: tuple[int, ...],
    labels: dict[str, Any],
    checked: int,
    t0: float,
    why: str,
) -> Verdict:
    return Verdict(
        False,
        {"axes": [AXIS_NAMES[a] for a in axes], "labels": labels},
        {"checked": checked, "time_s": time.perf_counter() - t0},
        f"corner condition fails on the {''.join(AXIS_NAMES[a] for a in axes)} face: {why}",
    )
