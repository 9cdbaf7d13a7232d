"""The example model E: an integer label grid of 1 to 4 dimensions (thesis Sec. 3.1).

Labels are indexed ``E[x, y, z]`` as in the thesis; the label count is
``K = max label + 1`` (ids that never occur get no support). Sparse ids (``max label`` at
least :data:`COMPACT_ABOVE` and more than twice the number of labels in use) are
compacted to ``0..k-1``; ``meta["label_ids"]`` maps them back, and the writers of
:mod:`csplab.io` write the file's ids. :meth:`ExampleModel.transitions`
computes the transition matrices of Eq. 3.2.

Examples
--------
>>> import numpy as np
>>> E = ExampleModel(np.array([[0, 1], [1, 0]]))   # the checkerboard E1 (Fig. 3.1b)
>>> E.K, E.ndim
(2, 2)
>>> T = E.transitions()
>>> T.shape
(2, 2, 2)
>>> T[0].astype(int).tolist()      # T_x[b, c]: c may follow b along +x
[[0, 1], [1, 0]]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import InputError

__all__ = ["COMPACT_ABOVE", "ExampleModel", "file_labels", "pair_transitions"]

MAX_NDIM = 4


def pair_transitions(grid: NDArray[np.integer[Any]], K: int) -> NDArray[np.bool_]:
    """Transition matrices of a fully labelled grid: ``T[d, b, c]`` (Eq. 3.2).

    ``T[d, b, c]`` is true iff some cell has label ``b`` and its ``+1`` neighbour along axis
    ``d`` has label ``c``. Cells with negative labels (unassigned) are skipped.

    Examples
    --------
    >>> import numpy as np
    >>> pair_transitions(np.array([0, 1, 1]), 2)[0].tolist()
    [[False, True], [False, True]]
    """
    g = np.asarray(grid)
    T = np.zeros((g.ndim, K, K), dtype=bool)
    for d in range(g.ndim):
        if g.shape[d] < 2:
            continue
        a = np.moveaxis(g, d, 0)
        b, c = a[:-1].ravel(), a[1:].ravel()
        ok = (b >= 0) & (c >= 0)
        T[d, b[ok], c[ok]] = True
    return T


#: label ids are compacted when ``max label + 1`` exceeds this and twice the labels in use
COMPACT_ABOVE = 256


def _compact(
    raw: NDArray[Any], weights: ArrayLike | None, meta: dict[str, Any]
) -> tuple[NDArray[Any], ArrayLike | None]:
    """Sparse label ids (``{0, 100000}``) -> ``0..k-1`` with ``meta["label_ids"]`` mapping
    back (an example with ``K = max + 1`` would allocate memory for every unused id)."""
    ids = meta.get("label_ids")
    if ids is not None:  # already compact (a model rebuilt from a compacted one)
        if int(raw.max()) >= len(ids):
            raise InputError(f"label {int(raw.max())} has no entry in meta['label_ids']")
        return raw, weights
    top = int(raw.max())
    if top > np.iinfo(np.int64).max:
        raise InputError(f"label {top} does not fit in 64 bits")
    if top < COMPACT_ABOVE:
        return raw, weights
    used = np.unique(raw)
    if top + 1 <= 2 * used.size:
        return raw, weights
    meta["label_ids"] = tuple(int(v) for v in used)
    if weights is not None:
        w = np.asarray(weights, dtype=np.float64).reshape(-1)
        if w.size == top + 1:
            weights = w[used]
    return np.searchsorted(used, raw).astype(np.int32), weights


def file_labels(grid: ArrayLike, meta: Mapping[str, Any]) -> NDArray[np.int64]:
    """A label grid with the ids of the file it came from (``meta["label_ids"]`` of a
    compacted :class:`ExampleModel`; the grid itself when there is none). ``-1`` (an
    unassigned cell) stays ``-1``.

    Examples
    --------
    >>> file_labels([[0, 1], [-1, 1]], {"label_ids": (0, 100000)}).tolist()
    [[0, 100000], [-1, 100000]]
    """
    g = np.asarray(grid, dtype=np.int64)
    ids = meta.get("label_ids")
    if ids is None:
        return g
    table = np.array([*ids, -1], dtype=np.int64)  # index -1 -> -1
    return table[np.where(g >= 0, g, len(ids))]


@dataclass(frozen=True, eq=False)
class ExampleModel:
    """An example model ``E``: labels indexed ``[x, y, z]`` plus optional names and weights.

    Parameters
    ----------
    labels : array_like of int
        Label grid with 1 to 4 dimensions; non-negative integers. Copied and made read-only.
    names : sequence of str, optional
        One name per label id (length ``K``).
    weights : array_like of float, optional
        One non-negative weight per label (default: the label frequencies in ``labels``).
    name : str
        A short name used in reports.
    meta : mapping
        Free-form data carried along (for example the header and trailing table of a
        Merrell-format file, so it can be written back).
    num_labels : int, optional
        Force ``K`` larger than ``max label + 1`` (labels that never occur).

    Raises
    ------
    InputError
        When the labels are not integers, negative, too large, empty, or not 1 to 4
        dimensional, or ``names``, ``weights`` or ``num_labels`` do not fit ``K``.
    """

    labels: NDArray[np.int32]
    names: tuple[str, ...] | None = None
    weights: NDArray[np.float64] | None = None
    name: str = ""
    meta: Mapping[str, Any] = field(default_factory=dict)
    num_labels: int | None = None

    def __init__(
        self,
        labels: ArrayLike,
        names: Sequence[str] | None = None,
        weights: ArrayLike | None = None,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        num_labels: int | None = None,
    ) -> None:
        raw = np.asarray(labels)
        if raw.dtype == object and raw.size and all(isinstance(v, int) for v in raw.flat):
            big = max(raw.flat, key=abs)
            raise InputError(f"label {big} does not fit in 64 bits")
        if raw.dtype == bool or not (np.issubdtype(raw.dtype, np.integer) or raw.size == 0):
            if np.issubdtype(raw.dtype, np.floating) and np.all(np.mod(raw, 1) == 0):
                raw = raw.astype(np.int64)
            else:
                raise InputError(f"example labels must be integers, got dtype {raw.dtype}")
        if not 1 <= raw.ndim <= MAX_NDIM:
            raise InputError(
                f"example model must have 1 to {MAX_NDIM} dimensions, got shape {raw.shape}"
            )
        if raw.size == 0:
            raise InputError(f"example model is empty (shape {raw.shape})")
        if raw.min() < 0:
            bad = tuple(int(i) for i in np.argwhere(raw < 0)[0])
            raise InputError(f"negative label {int(raw[bad])} at {bad} in example model")
        meta = dict(meta or {})
        if names is None and num_labels is None:
            raw, weights = _compact(raw, weights, meta)
        if raw.max() > np.iinfo(np.int32).max // 2:
            raise InputError(f"label {int(raw.max())} is too large")
        arr = np.ascontiguousarray(raw, dtype=np.int32)
        arr.setflags(write=False)
        K = int(arr.max()) + 1
        if num_labels is not None:
            if num_labels < K:
                raise InputError(f"num_labels={num_labels} is less than max label + 1 = {K}")
            K = int(num_labels)
        if names is not None:
            names = tuple(str(n) for n in names)
            if len(names) < K:
                raise InputError(f"{len(names)} label names given for K={K} labels")
            K = len(names)
        w: NDArray[np.float64] | None = None
        if weights is not None:
            w = np.array(weights, dtype=np.float64).reshape(-1)
            if w.shape != (K,) or not np.all(np.isfinite(w)) or np.any(w < 0):
                raise InputError(f"weights must be {K} finite non-negative numbers")
            w.setflags(write=False)
        object.__setattr__(self, "labels", arr)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "weights", w)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "meta", meta)
        object.__setattr__(self, "num_labels", K)

    # ------------------------------------------------------------------ basic properties
    @property
    def K(self) -> int:
        """Number of labels ``k`` (``max label + 1`` unless forced larger)."""
        assert self.num_labels is not None
        return self.num_labels

    @property
    def ndim(self) -> int:
        """Number of dimensions of the label grid (1 to 4)."""
        return int(self.labels.ndim)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the label grid."""
        return tuple(int(s) for s in self.labels.shape)

    def counts(self) -> NDArray[np.int64]:
        """How often each label occurs in the example.

        Returns
        -------
        ndarray of int64, shape ``(K,)``
            The number of cells with each label.
        """
        return np.bincount(self.labels.ravel(), minlength=self.K).astype(np.int64)

    def label_weights(self) -> NDArray[np.float64]:
        """Per-label weights: the given ``weights`` or else the label frequencies.

        Returns
        -------
        ndarray of float64, shape ``(K,)``
            A fresh array of the weights.
        """
        if self.weights is not None:
            return np.array(self.weights, dtype=np.float64)
        return self.counts().astype(np.float64)

    @property
    def topology(self) -> str:
        """The grid the example lives on (:mod:`csplab.topology`; ``meta["topology"]``,
        default ``"square"``)."""
        return str(self.meta.get("topology", "square"))

    def transitions(self) -> NDArray[np.bool_]:
        """Transition matrices ``T[d, b, c]`` of Eq. 3.2.

        Only for examples on square grids (and cylinders, affine grids): a hexagonal or
        triangular example has other relations (:meth:`csplab.topology.Topology.learn`),
        and a tool that reads axis transitions refuses it with one line.

        Returns
        -------
        ndarray of bool, shape ``(ndim, K, K)``
            ``T[d, b, c]``: some cell labelled ``b`` has a ``+1`` neighbour along axis ``d``
            labelled ``c``.

        Raises
        ------
        InputError
            When the example is on a hexagonal or triangular grid.
        """
        if self.topology.startswith(("hex", "tri")):
            raise InputError(
                f"{self.name or 'the example'} is on a {self.topology} grid: this tool works "
                "on square grids (synthesis takes it: csplab.from_example, csplab synthesize)"
            )
        return pair_transitions(self.labels, self.K)

    def file_labels(self, grid: ArrayLike | None = None) -> NDArray[np.int64]:
        """A label grid with the file's label ids: the inverse of the compaction of sparse ids.

        Parameters
        ----------
        grid : array_like of int, optional
            Labels in this model's ids (default: the example's own labels); ``-1`` stays
            ``-1``.

        Returns
        -------
        ndarray of int64
            ``grid`` mapped through ``meta["label_ids"]``, or ``grid`` itself when the
            example was not compacted.
        """
        g = self.labels if grid is None else grid
        return file_labels(g, self.meta)

    def label_name(self, b: int) -> str:
        """Name of label ``b``.

        Parameters
        ----------
        b : int
            A label index.

        Returns
        -------
        str
            The label's name, or its number when the example has no name for it.
        """
        if self.names is not None and 0 <= b < len(self.names):
            return self.names[b]
        return str(b)

    def hash(self) -> str:
        """A stable content hash (labels, K, names, weights) for result stores.

        Returns
        -------
        str
            The first 16 hex digits of a SHA-256 over shape, ``K``, labels, names, weights
            and the file's label ids.
        """
        import hashlib

        h = hashlib.sha256()
        h.update(str((self.shape, self.K)).encode())
        h.update(self.labels.tobytes())
        if self.names is not None:
            h.update("\0".join(self.names).encode())
        if self.weights is not None:
            h.update(self.weights.tobytes())
        if self.meta.get("label_ids") is not None:
            h.update(str(tuple(self.meta["label_ids"])).encode())
        return h.hexdigest()[:16]

    def __repr__(self) -> str:
        nm = f"{self.name!r}, " if self.name else ""
        return f"ExampleModel({nm}shape={self.shape}, K={self.K})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ExampleModel):
            return NotImplemented
        return (
            self.shape == other.shape
            and self.K == other.K
            and bool(np.array_equal(self.labels, other.labels))
            and self.names == other.names
        )

    __hash__ = None  # type: ignore[assignment]

    def _repr_png_(self) -> bytes:
        from csplab.render import render_png_bytes

        return render_png_bytes(self.labels, names=self.names, model=self)
