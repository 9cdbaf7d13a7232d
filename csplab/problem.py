"""`Problem`: a general binary extensional CSP, the model-synthesis problem of Sec. 3.1.

A problem has ``n`` cells (with a grid ``shape`` whose C-order flattening numbers them, so
cell order is the thesis' scan order: x outermost, z innermost), ``K`` labels, initial
domains ``bool (n, K)``, relations ``bool (R, K, K)`` and arcs ``(src, dst, relation)``:
an arc requires ``relations[r, label[src], label[dst]]``. Grid adjacency is one relation per
axis (the transition matrices ``T_d`` of Eq. 3.2); symmetry pairs, diagonals, wrap-around or
anything else are just more arcs. Fixed cells, boundary labels and masks (Sec. 3.3.6, 3.5.3)
are domain restrictions, remembered one by one in :attr:`Problem.unary` so that analysis
tools can explain which of them make a problem unsatisfiable.

:meth:`Problem.violations` is the one solver-independent checker used by every solver and
test. Problems on grids are built by :mod:`csplab.grids` (``from_example``, ``grid``,
``with_fixed``), which sits above this module: a problem knows nothing of examples or files.

Examples
--------
>>> import numpy as np
>>> from csplab.example import ExampleModel
>>> from csplab.grids import from_example
>>> E1 = ExampleModel([[0, 1], [1, 0]])                  # checkerboard
>>> P = from_example(E1, (3, 3))
>>> P.n, P.K, len(P.arcs)
(9, 2, 12)
>>> P.is_solution(np.array([[0, 1, 0], [1, 0, 1], [0, 1, 0]]))
True
>>> v = P.violations(np.zeros((3, 3), dtype=int))
>>> len(v.arcs), len(v.cells)
(12, 0)
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import InputError

if TYPE_CHECKING:
    from csplab.constraints import Constraint

__all__ = [
    "AXIS_NAMES",
    "Problem",
    "Unary",
    "Violations",
    "memory_estimate",
]

AXIS_NAMES = "xyzw"
UnaryKind = Literal["fixed", "boundary", "mask", "domain"]


@dataclass(frozen=True)
class Unary:
    """One remembered domain restriction: ``cells`` may only take ``allowed`` labels.

    ``kind`` is ``"fixed"`` (one cell, one label), ``"boundary"`` (one face),
    ``"mask"`` (one cell's mask) or ``"domain"`` (anything else); ``key`` names it
    (coordinates or a face such as ``"z-"``).
    """

    kind: UnaryKind
    key: Any
    cells: NDArray[np.int64]
    allowed: NDArray[np.bool_]  # (len(cells), K)

    def describe(self, problem: Problem, names: bool = True) -> str:
        labels = np.flatnonzero(self.allowed.any(axis=0) if len(self.cells) else [])
        if self.kind == "fixed":
            b = int(labels[0]) if labels.size else -1
            return f"fixed cell {self.key} = {problem.label_name(b) if names else b}"
        if self.kind == "boundary":
            one = int(labels[0]) if labels.size == 1 else None
            what = problem.label_name(one) if one is not None else f"{labels.size} labels"
            return f"boundary face {self.key} = {what} ({len(self.cells)} cells)"
        if self.kind == "mask":
            return f"mask at cell {self.key} allows {labels.size} of {problem.K} labels"
        return f"domain restriction {self.key} ({len(self.cells)} cells)"


@dataclass(frozen=True)
class Violations:
    """What :meth:`Problem.violations` found: violated arcs, out-of-domain cells and broken
    global constraints.

    ``arcs`` are indices into ``problem.arcs``; ``cells`` are flat cell indices whose label is
    unassigned (negative), out of range or not in the cell's domain; ``constraints`` holds
    one line per broken constraint of ``problem.constraints`` (checked on complete grids).
    ``len()`` is the total.

    Parameters
    ----------
    arcs : ndarray of int64
        Indices into ``problem.arcs`` of the violated arcs.
    cells : ndarray of int64
        Flat indices of the cells whose label is unassigned, out of range or outside their
        domain.
    problem : Problem
        The checked problem (for naming cells, labels and relations in :meth:`describe`).
    grid : ndarray of int64
        The checked labelling, flattened.
    constraints : tuple of str, optional
        One message per broken global constraint.
    """

    arcs: NDArray[np.int64]
    cells: NDArray[np.int64]
    problem: Problem = field(repr=False, compare=False)
    grid: NDArray[np.int64] = field(repr=False, compare=False)
    constraints: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.arcs.size + self.cells.size + len(self.constraints))

    def __bool__(self) -> bool:
        return len(self) > 0

    def describe(self, limit: int = 10) -> str:
        """Human-readable list of the first ``limit`` violations.

        Parameters
        ----------
        limit : int, optional
            At most this many out-of-domain cells and this many violated arcs are listed
            (after a one-line summary with the totals and every broken constraint).

        Returns
        -------
        str
            The summary line followed by one indented line per listed violation.
        """
        P, lab = self.problem, self.grid
        lines = [f"{self.arcs.size} violated arcs, {self.cells.size} cells outside their domain"]
        if self.constraints:
            lines[0] += f", {len(self.constraints)} broken constraints"
            lines += [f"  {c}" for c in self.constraints]
        for c in self.cells[:limit]:
            b = int(lab[c])
            why = "unassigned" if b < 0 else ("out of range" if b >= P.K else "not allowed")
            lines.append(f"  cell {P.coords(int(c))}: label {b} {why}")
        for i in self.arcs[:limit]:
            s, d, r = (int(t) for t in P.arcs[i])
            lines.append(
                f"  arc {P.coords(s)} -> {P.coords(d)} ({P.relation_name(r)}): "
                f"{int(lab[s])} then {int(lab[d])} never occurs"
            )
        return "\n".join(lines)


class Problem:
    """A binary extensional CSP over the cells of a grid.

    Parameters
    ----------
    shape : tuple of int
        Grid shape; cells are numbered in C order (``x`` outermost).
    domains : array_like of bool, shape ``(n, K)`` or ``(*shape, K)``
        Allowed labels per cell (after all unary restrictions).
    relations : array_like of bool, shape ``(R, K, K)``
        The allowed label pairs of each relation (``R[a, b]``: ``b`` may follow ``a``).
    arcs : array_like of int, shape ``(A, 3)``
        ``(src, dst, relation)``: ``relations[r, label[src], label[dst]]`` must hold.
    weights : array_like of float, optional
        Per-label weights for weighted label choice and entropy (default: all ones).
    value_weights : (array_like, array_like), optional
        Weights per weight class instead, for problems whose values mean different things
        in different cells (continuous synthesis: a value is a state of the cell's vertex
        or edge type): a ``(T, K)`` table and each cell's class, ``(n,)`` ints in
        ``0..T-1``. The weighted choice and entropy of a cell read its class's row
        (:meth:`weight_classes`); ``weights`` then stays the default.
    names : sequence of str, optional
        Label names.
    relation_names : sequence of str, optional
        A name for each relation (e.g. ``"T_x"``), used in messages.
    unary : sequence of Unary, optional
        The restrictions that produced ``domains`` from ``base_domains``.
    base_domains : array_like of bool, optional
        Domains before the ``unary`` restrictions (default: ``domains``).
    name : str
        A short name for reports.
    meta : mapping
        Free-form provenance (example name and hash, boundary labels, periodicity ...).
    positions : array_like of float, shape ``(n, d)``, optional
        Where each cell is, for problems whose cells are not a grid (continuous model
        synthesis: arrangement vertices and edges, in line spacings). ``blocks`` cuts such
        a problem into boxes of these coordinates; grid problems leave it ``None``.
    constraints : sequence of Constraint, optional
        Global constraints beside the arcs (:mod:`csplab.constraints`: count, connected,
        mirror/rotate, separation, max-run), checked by :meth:`violations`.

    Raises
    ------
    InputError
        When the shape has a non-positive extent, or ``relations``, ``domains``, ``arcs``,
        ``weights``, ``names``, ``relation_names`` or ``positions`` do not fit each other
        (wrong shape, arc endpoints outside the grid, unknown relation ids, negative or
        non-finite weights), or a global constraint does not fit the problem.

    Notes
    -----
    Self-arcs (a cell related to itself, as on a periodic axis of length 1) are kept in
    ``arcs`` for the checker and folded into the domains (``label`` must satisfy
    ``R[label, label]``).
    """

    def __init__(
        self,
        shape: Sequence[int],
        domains: ArrayLike,
        relations: ArrayLike,
        arcs: ArrayLike,
        *,
        weights: ArrayLike | None = None,
        value_weights: tuple[ArrayLike, ArrayLike] | None = None,
        names: Sequence[str] | None = None,
        relation_names: Sequence[str] | None = None,
        unary: Sequence[Unary] = (),
        base_domains: ArrayLike | None = None,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        positions: ArrayLike | None = None,
        constraints: Sequence[Constraint] = (),
    ) -> None:
        self.shape: tuple[int, ...] = tuple(int(s) for s in shape)
        if not self.shape or any(s < 1 for s in self.shape):
            raise InputError(f"shape {self.shape} must have positive extents")
        n = math.prod(self.shape)
        rel = np.array(relations, dtype=bool)
        if rel.ndim != 3 or rel.shape[1] != rel.shape[2]:
            raise InputError(f"relations must have shape (R, K, K), got {rel.shape}")
        K = int(rel.shape[1])
        if K < 1:
            raise InputError("a problem needs at least one label")
        dom = np.array(domains, dtype=bool)
        if dom.shape == (*self.shape, K):
            dom = dom.reshape(n, K)
        if dom.shape != (n, K):
            raise InputError(f"domains must have shape ({n}, {K}), got {dom.shape}")
        a = np.array(arcs, dtype=np.int64).reshape(-1, 3)
        if a.size:
            if a[:, :2].min() < 0 or a[:, :2].max() >= n:
                raise InputError(f"arc endpoints must be cells 0..{n - 1}")
            if a[:, 2].min() < 0 or a[:, 2].max() >= rel.shape[0]:
                raise InputError(f"arc relation ids must be 0..{rel.shape[0] - 1}")
        # without unary restrictions the base domains are the domains: one (read-only) array
        base = dom if base_domains is None else np.array(base_domains, dtype=bool)
        if base.shape == (*self.shape, K):
            base = base.reshape(n, K)
        # fold self-arcs into the domains
        selfarc = a[:, 0] == a[:, 1]
        if selfarc.any():
            for c, r in a[selfarc][:, [0, 2]]:
                diag = np.diagonal(rel[r]).copy()
                dom[c] &= diag
                if base is not dom:
                    base[c] &= diag
        w = np.ones(K) if weights is None else np.array(weights, dtype=np.float64).reshape(-1)
        if w.shape != (K,) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InputError(f"weights must be {K} finite non-negative numbers")
        vw: tuple[NDArray[np.float64], NDArray[np.int64]] | None = None
        if value_weights is not None:
            tab = np.array(value_weights[0], dtype=np.float64)
            cls = np.array(value_weights[1], dtype=np.int64).reshape(-1)
            if tab.ndim != 2 or tab.shape[1] != K or not len(tab):
                raise InputError(f"value_weights: the table must have shape (T, {K})")
            if not np.all(np.isfinite(tab)) or np.any(tab < 0):
                raise InputError("value_weights: weights must be finite non-negative numbers")
            if cls.shape != (n,) or (n and (cls.min() < 0 or cls.max() >= len(tab))):
                raise InputError(f"value_weights: one class in 0..{len(tab) - 1} per cell "
                                 f"({n}) is needed")  # fmt: skip
            tab.setflags(write=False)
            cls.setflags(write=False)
            vw = (tab, cls)
        if names is not None:
            names = tuple(str(s) for s in names)
            if len(names) != K:
                raise InputError(f"{len(names)} label names for K={K}")
        if relation_names is not None:
            relation_names = tuple(relation_names)
            if len(relation_names) != rel.shape[0]:
                raise InputError("one relation name per relation is needed")
        pos = None
        if positions is not None:
            pos = np.array(positions, dtype=np.float64)
            if pos.ndim != 2 or pos.shape[0] != n:
                raise InputError(f"positions must have shape ({n}, d), got {pos.shape}")
            pos.setflags(write=False)
        self.positions: NDArray[np.float64] | None = pos
        for arr in (dom, rel, a, w, base):
            arr.setflags(write=False)
        self.domains: NDArray[np.bool_] = dom
        self.relations: NDArray[np.bool_] = rel
        self.arcs: NDArray[np.int64] = a
        self.weights: NDArray[np.float64] = w
        self.value_weights: tuple[NDArray[np.float64], NDArray[np.int64]] | None = vw
        self.names: tuple[str, ...] | None = names
        self.relation_names: tuple[str, ...] | None = relation_names
        self.unary: tuple[Unary, ...] = tuple(unary)
        self.base_domains: NDArray[np.bool_] = base
        self.name = name
        self.meta: dict[str, Any] = dict(meta or {})
        self.constraints: tuple[Constraint, ...] = tuple(constraints)
        for c in self.constraints:
            c.validate(self)

    def weight_classes(self) -> tuple[NDArray[np.float64], NDArray[np.int64] | None]:
        """The weights the weighted choice reads: a ``(T, K)`` table and each cell's class
        (``value_weights``), or ``weights`` as a one-row table and ``None`` (every cell
        class 0).

        Returns
        -------
        table : float array ``(T, K)``
        classes : int array ``(n,)`` or None

        Examples
        --------
        >>> P = Problem((2,), [[1, 1], [1, 1]], [[[1, 1], [1, 1]]], [[0, 1, 0]],
        ...             value_weights=([[1, 0], [0, 1]], [0, 1]))
        >>> P.weight_classes()[0].tolist(), P.weight_classes()[1].tolist()
        ([[1.0, 0.0], [0.0, 1.0]], [0, 1])
        """
        if self.value_weights is None:
            return self.weights.reshape(1, -1), None
        return self.value_weights

    # ------------------------------------------------------------------ sizes
    @property
    def n(self) -> int:
        """Number of cells."""
        return int(self.domains.shape[0])

    @property
    def K(self) -> int:
        """Number of labels."""
        return int(self.relations.shape[1])

    @property
    def ndim(self) -> int:
        """Number of grid axes (``len(shape)``)."""
        return len(self.shape)

    @property
    def R(self) -> int:
        """Number of relations."""
        return int(self.relations.shape[0])

    def __repr__(self) -> str:
        nm = f"{self.name!r}, " if self.name else ""
        return (
            f"Problem({nm}shape={self.shape}, K={self.K}, relations={self.R}, "
            f"arcs={len(self.arcs)}, unary={len(self.unary)}"
            + (f", constraints={len(self.constraints)})" if self.constraints else ")")
        )

    # ------------------------------------------------------------------ naming helpers
    def coords(self, cell: int) -> tuple[int, ...]:
        """Grid coordinates of a flat cell index.

        Parameters
        ----------
        cell : int
            A flat cell index ``0..n-1`` (C order over ``shape``).

        Returns
        -------
        tuple of int
            The cell's coordinates, one per axis.
        """
        return tuple(int(i) for i in np.unravel_index(int(cell), self.shape))

    def cell(self, coords: Sequence[int]) -> int:
        """Flat index of grid coordinates.

        Parameters
        ----------
        coords : sequence of int
            One coordinate per axis.

        Returns
        -------
        int
            The flat cell index (C order over ``shape``).

        Raises
        ------
        InputError
            When ``coords`` lie outside the grid.
        """
        try:
            return int(np.ravel_multi_index(tuple(int(c) for c in coords), self.shape))
        except ValueError:
            raise InputError(f"cell {tuple(coords)} is outside the grid {self.shape}") from None

    def label_name(self, b: int | None) -> str:
        """Name of label ``b`` for messages.

        Parameters
        ----------
        b : int or None
            A label index; ``None`` stands for an unknown label.

        Returns
        -------
        str
            The label's name from ``names``, else its number; ``"?"`` for ``None``.
        """
        if b is None:
            return "?"
        if self.names is not None and 0 <= b < len(self.names):
            return self.names[b]
        return str(b)

    def relation_name(self, r: int) -> str:
        """Name of relation ``r`` for messages.

        Parameters
        ----------
        r : int
            A relation index ``0..R-1``.

        Returns
        -------
        str
            The name from ``relation_names``, else ``"R<r>"``.
        """
        if self.relation_names is not None:
            return self.relation_names[r]
        return f"R{r}"

    # ------------------------------------------------------------------ the checker
    def _flat_grid(self, grid: ArrayLike) -> NDArray[np.int64]:
        g = np.asarray(grid)
        if g.shape != self.shape and g.shape != (self.n,):
            raise InputError(f"grid has shape {g.shape}, the problem has shape {self.shape}")
        if not (np.issubdtype(g.dtype, np.integer) or g.size == 0):
            raise InputError(f"grid must hold integer labels, got dtype {g.dtype}")
        return g.reshape(-1).astype(np.int64)

    def violations(self, grid: ArrayLike) -> Violations:
        """Every violated arc and every cell whose label is not in its domain.

        Unassigned cells (negative labels) and labels outside ``0..K-1`` count as
        out-of-domain cells; arcs touching them count as violated. Global constraints are
        checked only when every label is in range.

        Parameters
        ----------
        grid : array_like of int
            A labelling of shape ``shape`` or ``(n,)``.

        Returns
        -------
        Violations
            The violated arcs, out-of-domain cells and broken constraints (empty, and false,
            for a solution).

        Raises
        ------
        InputError
            When ``grid`` has the wrong shape or does not hold integers.
        """
        lab = self._flat_grid(grid)
        K = self.K
        inr = (lab >= 0) & (lab < K)
        safe = np.where(inr, lab, 0)
        bad_cell = ~inr | ~self.domains[np.arange(self.n), safe]
        s, d, r = self.arcs[:, 0], self.arcs[:, 1], self.arcs[:, 2]
        ok = inr[s] & inr[d] & self.relations[r, safe[s], safe[d]]
        broken: list[str] = []
        if self.constraints and inr.all():
            broken = [m for c in self.constraints if (m := c.check(self, lab)) is not None]
        return Violations(
            arcs=np.flatnonzero(~ok).astype(np.int64),
            cells=np.flatnonzero(bad_cell).astype(np.int64),
            problem=self,
            grid=lab,
            constraints=tuple(broken),
        )

    def is_solution(self, grid: ArrayLike) -> bool:
        """Whether ``grid`` is a solution: complete, and violating nothing.

        Parameters
        ----------
        grid : array_like of int
            A labelling of shape ``shape`` or ``(n,)``.

        Returns
        -------
        bool
            ``True`` iff :meth:`violations` finds nothing.

        Raises
        ------
        InputError
            When ``grid`` has the wrong shape or does not hold integers.
        """
        return len(self.violations(grid)) == 0

    # ------------------------------------------------------------------ derived data
    @cached_property
    def fixed_grid(self) -> NDArray[np.int32]:
        """Labels of cells whose domain is a single label (else -1), shape ``shape``."""
        single = self.domains.sum(axis=1) == 1
        out = np.full(self.n, -1, dtype=np.int32)
        out[single] = self.domains[single].argmax(axis=1)
        out.setflags(write=False)
        return out.reshape(self.shape)

    def neighbours(self, cell: int) -> Iterator[tuple[int, int, bool]]:
        """Yield ``(other, relation, forward)`` for each arc touching ``cell``.

        Parameters
        ----------
        cell : int
            A flat cell index.

        Yields
        ------
        other : int
            The cell at the arc's other end.
        relation : int
            The arc's relation index.
        forward : bool
            ``True`` if ``cell`` is the arc's source, ``False`` if it is its destination.
        """
        a = self.arcs
        for i in np.flatnonzero(a[:, 0] == cell):
            yield int(a[i, 1]), int(a[i, 2]), True
        for i in np.flatnonzero(a[:, 1] == cell):
            yield int(a[i, 0]), int(a[i, 2]), False

    # ------------------------------------------------------------------ derived problems
    def restrict(
        self, allowed: ArrayLike, *, kind: UnaryKind = "domain", key: Any = None
    ) -> Problem:
        """A copy with domains intersected with ``allowed``, recorded as one unary restriction.

        Parameters
        ----------
        allowed : array_like of bool
            Allowed labels per cell, shape ``(n, K)`` or ``(*shape, K)`` or broadcastable
            to ``(*shape, K)``.
        kind : {"domain", "fixed", "boundary", "mask"}, optional
            The kind of the recorded :class:`Unary`.
        key : object, optional
            What names the restriction in explanations (coordinates, a face ...).

        Returns
        -------
        Problem
            The restricted copy; ``self`` is unchanged.
        """
        al = np.broadcast_to(np.asarray(allowed, dtype=bool), (*self.shape, self.K))
        al = al.reshape(self.n, self.K)
        cells = np.flatnonzero(~al.all(axis=1)).astype(np.int64)
        u = Unary(kind, key, cells, al[cells].copy())
        return self.with_unary([u])

    def _replace(self, **changes: Any) -> Problem:
        """A new problem with the given constructor arguments changed (the one way every
        derived problem is built; a finished problem is never mutated)."""
        args: dict[str, Any] = dict(
            shape=self.shape, domains=self.domains, relations=self.relations, arcs=self.arcs,
            weights=self.weights, value_weights=self.value_weights, names=self.names,
            relation_names=self.relation_names, unary=self.unary,
            base_domains=self.base_domains, name=self.name, meta=self.meta,
            positions=self.positions, constraints=self.constraints,
        )  # fmt: skip
        args.update(changes)
        return Problem(**args)

    def with_constraints(self, extra: Sequence[Constraint]) -> Problem:
        """A copy with more global constraints (:mod:`csplab.constraints`).

        Parameters
        ----------
        extra : sequence of Constraint
            Constraints added after the existing ones.

        Returns
        -------
        Problem
            The copy; ``self`` is unchanged.

        Raises
        ------
        InputError
            When a constraint does not fit the problem (its own validation).
        """
        return self._replace(constraints=(*self.constraints, *extra))

    def without_constraints(self) -> Problem:
        """A copy without global constraints (what the arcs and domains alone say).

        Returns
        -------
        Problem
            The copy; ``self`` is unchanged.
        """
        return self._replace(constraints=())

    def require_no_constraints(self, what: str) -> None:
        """Refuse global constraints: for solvers and tools that cannot handle them.

        Parameters
        ----------
        what : str
            The refusing tool, named in the message (e.g. ``"counting"``).

        Raises
        ------
        InputError
            One line naming ``what`` and the constraint kinds, when the problem has any
            global constraint.
        """
        if self.constraints:
            kinds = ", ".join(sorted({c.kind for c in self.constraints}))
            raise InputError(f"{what} does not handle global constraints ({kinds}); drop them")

    def with_unary(self, extra: Sequence[Unary]) -> Problem:
        """A copy with more unary restrictions (each remembered, for explanations).

        Parameters
        ----------
        extra : sequence of Unary
            The restrictions; each intersects the domains of its cells with its labels.

        Returns
        -------
        Problem
            The restricted copy; ``self`` is unchanged.
        """
        dom = self.domains.copy()
        for u in extra:
            dom[u.cells] &= u.allowed
        return self._replace(domains=dom, unary=(*self.unary, *extra))

    def with_mask(self, mask: ArrayLike) -> Problem:
        """A copy with per-cell allowed labels, recorded as one ``mask`` restriction (Sec. 3.5.3).

        Parameters
        ----------
        mask : array_like of bool
            Allowed labels per cell, shape ``(*shape, K)`` or broadcastable to it.

        Returns
        -------
        Problem
            The masked copy; ``self`` is unchanged.
        """
        return self.restrict(mask, kind="mask")

    def without_unary(self, keep: Sequence[int] = ()) -> Problem:
        """A copy with only the unary restrictions whose indices are in ``keep``.

        Parameters
        ----------
        keep : sequence of int, optional
            Indices into :attr:`unary` of the restrictions to keep (default: none, so the
            domains become ``base_domains``).

        Returns
        -------
        Problem
            The copy; ``self`` is unchanged.
        """
        kept = [self.unary[i] for i in keep]
        dom = self.base_domains.copy()
        for u in kept:
            dom[u.cells] &= u.allowed
        return self._replace(domains=dom, unary=kept)

    def add_arcs(
        self, relation: ArrayLike, src: ArrayLike, dst: ArrayLike, name: str | None = None
    ) -> Problem:
        """A copy with one more relation and arcs ``src[i] -> dst[i]`` carrying it.

        For symmetry pairs, diagonal or distance-2 neighbours, and anything else binary.

        Parameters
        ----------
        relation : array_like of bool, shape ``(K, K)``
            The allowed label pairs of the new relation.
        src, dst : array_like of int
            Flat cell indices of the new arcs' sources and destinations (same length).
        name : str, optional
            The new relation's name (default ``"R<index>"`` when any relation is named).

        Returns
        -------
        Problem
            The copy; ``self`` is unchanged.

        Raises
        ------
        InputError
            When ``relation`` is not ``(K, K)``, ``src`` and ``dst`` differ in length, or an
            endpoint is not a cell.
        """
        R = np.asarray(relation, dtype=bool)
        if R.shape != (self.K, self.K):
            raise InputError(f"relation must have shape ({self.K}, {self.K}), got {R.shape}")
        s = np.asarray(src, dtype=np.int64).ravel()
        d = np.asarray(dst, dtype=np.int64).ravel()
        if s.shape != d.shape:
            raise InputError("src and dst must have the same length")
        r = np.full_like(s, self.R)
        rn = None
        if self.relation_names is not None or name is not None:
            old = self.relation_names or tuple(f"R{i}" for i in range(self.R))
            rn = (*old, name or f"R{self.R}")
        return self._replace(
            relations=np.concatenate([self.relations, R[None]]),
            arcs=np.concatenate([self.arcs, np.stack([s, d, r], axis=1)]),
            relation_names=rn,
        )

    def subproblem(
        self,
        cells: ArrayLike,
        grid: ArrayLike,
        shape: Sequence[int] | None = None,
        arc_ids: ArrayLike | None = None,
    ) -> Problem:
        """The problem on ``cells`` with every other cell fixed to its label in ``grid``.

        Arcs inside ``cells`` are kept (renumbered in the given cell order); arcs from a
        labelled outside cell become domain restrictions on the inside cell (this is how a
        block of Alg. 3.4 sees the fixed labels around it); arcs to unlabelled (negative)
        outside cells are dropped. ``shape`` gives the sub-grid's shape (default: flat).
        ``arc_ids`` (sorted) may name a subset of the arcs that contains every arc touching
        ``cells`` (a speed-up for many small blocks; the result is the same).

        Parameters
        ----------
        cells : array_like of int
            Flat indices of the sub-problem's cells, in its cell order.
        grid : array_like of int
            Labels of the whole problem (shape ``shape`` or ``(n,)``); negative = unlabelled.
        shape : sequence of int, optional
            The sub-problem's grid shape (default ``(len(cells),)``).
        arc_ids : array_like of int, optional
            Sorted indices of a superset of the arcs touching ``cells``.

        Returns
        -------
        Problem
            The sub-problem, without unary records and global constraints; its ``meta``
            has ``"subproblem_of"`` set to this problem's shape.

        Raises
        ------
        InputError
            When ``grid`` has the wrong shape or does not hold integers.
        """
        idx = np.asarray(cells, dtype=np.int64).ravel()
        g = np.asarray(grid)
        if g.shape != self.shape and g.shape != (self.n,):
            raise InputError(f"grid has shape {g.shape}, the problem has shape {self.shape}")
        if not (np.issubdtype(g.dtype, np.integer) or g.size == 0):
            raise InputError(f"grid must hold integer labels, got dtype {g.dtype}")
        flat = g.reshape(-1)  # a view: nothing of the whole grid's size is built per block
        a = self.arcs if arc_ids is None else self.arcs[np.asarray(arc_ids, dtype=np.int64)]
        # the position in ``cells`` of each arc end, by search: nothing of the whole grid's
        # size is built, so many small blocks cost what their arcs cost
        o = np.argsort(idx, kind="stable")
        srt = idx[o]

        def where(x: NDArray[np.int64]) -> NDArray[np.int64]:
            if not srt.size:
                return np.full(x.size, -1, dtype=np.int64)
            p = np.minimum(np.searchsorted(srt, x), srt.size - 1)
            return np.where(srt[p] == x, o[p], -1)

        ls, ld = where(a[:, 0]), where(a[:, 1])
        lab_s = flat[a[:, 0]].astype(np.int64)
        lab_d = flat[a[:, 1]].astype(np.int64)
        inside = (ls >= 0) & (ld >= 0)
        dom = self.domains[idx].copy()
        # outside src (labelled) -> inside dst
        m = (ls < 0) & (ld >= 0) & (lab_s >= 0)
        if m.any():
            np.logical_and.at(dom, ld[m], self.relations[a[m, 2], lab_s[m], :])
        m = (ls >= 0) & (ld < 0) & (lab_d >= 0)
        if m.any():
            np.logical_and.at(dom, ls[m], self.relations[a[m, 2], :, lab_d[m]])
        arcs = np.stack([ls[inside], ld[inside], a[inside, 2]], axis=1)
        shp = (idx.size,) if shape is None else tuple(shape)
        return Problem(
            shp,
            dom,
            self.relations,
            arcs,
            weights=self.weights,
            value_weights=None if self.value_weights is None else (
                self.value_weights[0], self.value_weights[1][idx]),
            names=self.names,
            relation_names=self.relation_names,
            name=self.name,
            meta={**self.meta, "subproblem_of": self.shape},
            positions=None if self.positions is None else self.positions[idx],
        )


# ----------------------------------------------------------------------------- memory

def memory_estimate(
    n: int, K: int, arcs: int, *, problem: bool = True, propagator: bool = True
) -> int:
    """Estimated peak bytes of a problem with ``n`` cells, ``K`` labels and ``arcs`` arcs.

    With ``problem``: the problem keeps two ``(n, K)`` bool arrays (``domains``,
    ``base_domains``) and its ``(arcs, 3)`` int64 arcs, and builds them with about as much
    again. With
    ``propagator`` it adds what :class:`csplab.catalog.Propagator` allocates: two packed
    catalogs of ``W = ceil(K / 64)`` words per cell (``bits``, ``prev``), the CSR adjacency
    (``2 arcs`` neighbours and relation ids) and the larger of its transients (packing the
    domains: ``n`` rows of ``64 W`` bools and two ``n x W`` word copies; sorting the arcs).

    Examples
    --------
    >>> round(memory_estimate(2000 * 2000 * 10, 119, 3 * 2000 * 2000 * 10) / 2**30, 1)
    35.9
    >>> memory_estimate(4, 2, 4) < 2000
    True
    """
    W = max(1, (K + 63) // 64)
    total = 4 * n * K + 48 * arcs + 8 * n if problem else 0
    if propagator:
        keeps = 16 * n * W + 32 * arcs + 17 * n
        transient = max(64 * n * W + 16 * n * W, 64 * arcs)
        total += keeps + transient
    return total
