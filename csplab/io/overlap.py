"""The overlapping model (WaveFunctionCollapse): patterns of a sample become the labels.

From a sample (a small picture, or any 2D/3D label grid) every ``N``-wide pattern is
extracted: with ``periodic_input`` the sample wraps around, and ``symmetry`` (1 to 8) adds
the first ``symmetry`` of the pattern's 8 images under the square's symmetries in
WaveFunctionCollapse's order (identity, mirror, quarter turn, its mirror, ...; in 3D they act
on ``x, y``). A pattern's weight is how often it occurs. Pattern ``q`` may be the ``+1``
neighbour of ``p`` along an axis iff they agree on their overlap (``p`` shifted by one).

Cell ``[x, y]`` of a result holds the pattern whose corner is pixel ``[x, y]``: the
picture of a periodic result has the grid's size; a non-periodic result of shape ``S`` shows
every pattern whole, ``S + N - 1`` pixels.

``ground`` (2D, symmetry 1 or 2) makes the output stand on the sample's ground:

* ``ground=True`` (or ``"wfc"``) is WaveFunctionCollapse's rule: the ground pattern is the
  last new pattern of WFC's scan of the sample (picture rows from the top, then columns),
  which holds the sample's bottom row with the sample's top wrapped below it; it fills the
  row of cells that puts its ground row on the picture's bottom row and is banned in every
  other cell, so the picture has exactly one ground band, at the bottom. The pattern wraps
  around, so the rule needs an output periodic along ``y`` (as in WFC's samples); a
  non-periodic output gets the ``"bottom"`` rule, with a warning.
* ``ground="bottom"``: the bottom row of cells may only hold patterns found on the sample's
  bottom row, and the other rows only patterns found elsewhere.

In csplab's cells (a pattern's corner is its bottom-left pixel) WFC's ground row of cells
is row ``height - N + 1`` (row 0 when ``N = 1``); the pictures are WFC's.

Examples
--------
>>> import numpy as np
>>> sample = np.array([[0, 0, 1], [0, 0, 1], [1, 1, 1]])    # [x, y]: wall on the right and top
>>> m = OverlapModel.from_grid(sample, N=2, symmetry=1)
>>> m.K, int(m.weights.sum())                      # 9 anchors, all different (periodic input)
(9, 9)
>>> import csplab
>>> r = csplab.solve(m.problem((6, 6), periodic=True), "catalog", rng=0)
>>> r.status, m.reconstruct(r.grid, periodic=True).shape
('solved', (6, 6))
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import FormatError, InputError
from csplab.io.common import NO, SURE, load_image
from csplab.io.ruleset import DomainOp, RuleSet
from csplab.problem import Problem

__all__ = ["OverlapModel", "sniff"]

_MAGIC = (b"\x89PNG", b"GIF87a", b"GIF89a")


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for a PNG or GIF picture (a sample)."""
    return SURE if head.startswith(_MAGIC) else NO


MAX_PATTERNS = 4000

Ground = Literal["wfc", "bottom"]
_GROUND = {"true": "wfc", "wfc": "wfc", "yes": "wfc", "1": "wfc", "bottom": "bottom"}
_NO_GROUND = ("false", "no", "0", "none", "")


def ground_rule(value: bool | str | None) -> Ground | None:
    """The ground rule an option value names: ``"wfc"`` (``True``, ``"true"``), ``"bottom"``
    or ``None`` (``False``, ``"false"``).

    Examples
    --------
    >>> ground_rule(True), ground_rule("bottom"), ground_rule("false")
    ('wfc', 'bottom', None)
    """
    if value is None or value is False:
        return None
    if value is True:
        return "wfc"
    v = str(value).strip().lower()
    if v in _NO_GROUND:
        return None
    if v not in _GROUND:
        raise InputError(
            f"option ground={value!r} of overlapping files must be true (WFC's rule), "
            "bottom or false"
        )
    return "wfc" if _GROUND[v] == "wfc" else "bottom"


def _wfc_last_pattern(
    s: NDArray[np.int64], N: int, symmetry: int, periodic_input: bool, index: dict[bytes, int]
) -> int:
    """The pattern WaveFunctionCollapse finds last: it scans the picture's rows from the
    top (csplab's ``y`` points up) and, in each, the columns, each window ``N`` pixels
    right and down from its anchor, then its first ``symmetry`` images."""
    SX, SY = s.shape
    xmax, ymax = (SX, SY) if periodic_input else (SX - N + 1, SY - N + 1)
    seen: set[int] = set()
    last = 0
    for r in range(ymax):  # picture row r from the top; the window's bottom is r + N - 1
        c = (SY - N - r) % SY  # its bottom-left corner in y-up coordinates
        for x in range(xmax):
            idx = np.ix_([(x + i) % SX for i in range(N)], [(c + j) % SY for j in range(N)])
            for q in _sym_images(s[idx])[:symmetry]:
                j = index[np.ascontiguousarray(q).tobytes()]
                if j not in seen:
                    seen.add(j)
                    last = j
    return last


def _sym_images(p: NDArray[np.int64]) -> list[NDArray[np.int64]]:
    """The 8 images of a pattern ``[x, y, ...]`` in WFC's order (rotation maps +x to +y)."""

    def rot(a: NDArray[np.int64]) -> NDArray[np.int64]:
        return np.rot90(a, 1, axes=(0, 1))  # [x, y]: quarter turn +x -> +y

    def refl(a: NDArray[np.int64]) -> NDArray[np.int64]:
        return a[::-1]

    out = [p]
    out.append(refl(p))
    r = rot(p)
    out += [r, refl(r)]
    r2 = rot(r)
    out += [r2, refl(r2)]
    r3 = rot(r2)
    out += [r3, refl(r3)]
    return out


class OverlapModel(RuleSet):
    """A :class:`RuleSet` whose labels are the ``N``-wide patterns of a sample.

    Build it with :meth:`from_png` or :meth:`from_grid`. ``patterns[k]`` is pattern ``k``
    (sample labels, indexed ``[x, y, ...]``), ``colors`` the RGB colour of each sample
    label; :meth:`reconstruct` turns a result into sample labels and :meth:`render` into a
    picture.
    """

    patterns: NDArray[np.int64]
    N: int
    sample_colors: NDArray[np.uint8] | None
    _bottom_ops: tuple[DomainOp, ...] = ()

    @classmethod
    def from_grid(
        cls,
        sample: ArrayLike,
        *,
        N: int = 3,
        symmetry: int = 8,
        periodic_input: bool = True,
        ground: bool | str = False,
        colors: ArrayLike | None = None,
        name: str = "sample",
        meta: dict[str, Any] | None = None,
    ) -> OverlapModel:
        """The overlapping model of a 2D or 3D label grid ``sample[x, y, ...]`` (``ground``:
        see the module docstring).

        Examples
        --------
        >>> sample = np.array([[1, 2, 0, 0], [1, 0, 0, 0], [1, 0, 2, 0]])  # [x, y]: 1 = ground
        >>> m = OverlapModel.from_grid(sample, N=2, symmetry=1, ground=True)
        >>> m.patterns[m.meta["ground_pattern"]].tolist()  # [x, y]: the sky wrapped below it
        [[0, 1], [0, 1]]
        >>> import csplab
        >>> r = csplab.solve(m.problem((6, 5), periodic=True), "catalog", rng=0)
        >>> m.reconstruct(r.grid, periodic=True)[:, 0].tolist()   # the bottom pixel row
        [1, 1, 1, 1, 1, 1]
        """
        rule = ground_rule(ground)
        s = np.asarray(sample)
        if s.ndim not in (2, 3) or s.size == 0:
            raise InputError(f"the sample must be a 2D or 3D grid, got shape {s.shape}")
        if not np.issubdtype(s.dtype, np.integer) or s.min() < 0:
            raise InputError("the sample must hold non-negative integer labels")
        s = s.astype(np.int64)
        if not 1 <= N <= 8:
            raise InputError(f"N must be 1..8, got {N}")
        if not 1 <= symmetry <= 8:
            raise InputError(f"symmetry must be 1..8, got {symmetry}")
        if rule and (s.ndim != 2 or symmetry > 2):
            raise InputError("ground needs a 2D sample and symmetry 1 or 2 (turns would move it)")
        if not periodic_input and any(n < N for n in s.shape):
            raise InputError(f"a {N}-wide pattern does not fit the sample {s.shape}")
        nd = s.ndim
        anchors = [range(n if periodic_input else n - N + 1) for n in s.shape]
        index: dict[bytes, int] = {}
        pats: list[NDArray[np.int64]] = []
        counts: list[int] = []
        bottom: set[int] = set()
        above: set[int] = set()
        grids = np.meshgrid(*[np.arange(N)] * nd, indexing="ij")
        for anchor in np.ndindex(*[len(a) for a in anchors]):
            idx = tuple((g + a) % n for g, a, n in zip(grids, anchor, s.shape, strict=True))
            p = s[idx]
            for q in _sym_images(p)[:symmetry]:
                key = q.tobytes()
                j = index.get(key)
                if j is None:
                    j = index[key] = len(pats)
                    pats.append(np.ascontiguousarray(q))
                    counts.append(0)
                    if len(pats) > MAX_PATTERNS:
                        raise InputError(f"the sample has more than {MAX_PATTERNS} patterns")
                counts[j] += 1
                if rule:
                    (bottom if anchor[1] == 0 else above).add(j)
        P = np.stack(pats)  # (K, N, N[, N])
        K = len(pats)
        T = np.zeros((nd, K, K), dtype=bool)
        for d in range(nd):
            a = np.take(P, np.arange(1, N), axis=d + 1).reshape(K, -1)  # p shifted by one
            b = np.take(P, np.arange(0, N - 1), axis=d + 1).reshape(K, -1)
            if N == 1:
                T[d] = True
                continue
            # group patterns by their overlap halves: equal keys agree
            _, ia = np.unique(a, axis=0, return_inverse=True)
            keys_b = {r.tobytes(): i for i, r in enumerate(np.unique(a, axis=0))}
            ib = np.array([keys_b.get(r.tobytes(), -1) for r in b])
            T[d] = ia.reshape(-1)[:, None] == ib[None, :]
        bottom_ops: list[DomainOp] = []
        ops: list[DomainOp] = []
        ground_pattern = None
        if rule:
            g_lab = np.zeros(K, dtype=bool)
            g_lab[sorted(bottom)] = True
            a_lab = np.zeros(K, dtype=bool)
            a_lab[sorted(above)] = True
            bottom_ops = [
                DomainOp("keep", g_lab, face="y-", kind="domain", key="ground (bottom row)"),
                DomainOp("keep", a_lab, region=[(None, None), (1, None)], key="above ground"),
            ]
            ops = bottom_ops
        if rule == "wfc":
            ground_pattern = _wfc_last_pattern(s, N, symmetry, periodic_input, index)
            only = np.zeros(K, dtype=bool)
            only[ground_pattern] = True
            lo = 1 - N  # the row of cells whose patterns' top row is the picture's row 0
            row = (lo, lo + 1 if lo + 1 < 0 else None) if N > 1 else (0, 1)
            ops = [
                DomainOp("remove", only, key="ground pattern (WFC): not above the ground"),
                DomainOp("force", only, region=[(None, None), row], key="ground (WFC)"),
            ]
        cols = None if colors is None else np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
        corner = P.reshape(K, -1)[:, 0]
        label_cols = None
        if cols is not None:
            if int(s.max()) >= len(cols):
                raise InputError("fewer colours than sample labels")
            label_cols = cols[corner]
        m = cls(
            T,
            names=[f"p{k}" for k in range(K)],
            weights=np.array(counts, dtype=np.float64),
            name=name,
            colors=label_cols,
            constraint_ops=ops,
            meta={
                "format": "overlapping",
                "N": N,
                "symmetry": symmetry,
                "periodic_input": periodic_input,
                "ground": rule or False,
                "ground_pattern": ground_pattern,
                "sample_shape": list(s.shape),
                **(meta or {}),
            },
        )
        m.patterns = P
        m.N = N
        m.sample_colors = cols
        m._bottom_ops = tuple(bottom_ops)
        return m

    @classmethod
    def from_png(
        cls,
        path: str | Path,
        *,
        N: int = 3,
        symmetry: int = 8,
        periodic_input: bool = True,
        ground: bool | str = "false",
    ) -> OverlapModel:
        """The overlapping model of a picture (WaveFunctionCollapse's overlapping model).

        Colours are numbered in order of first appearance (rows from the top); the
        picture's ``y`` axis is turned to point up.

        Parameters
        ----------
        path : str or Path
            The sample picture (PNG), at most 256x256 pixels.
        N : int, optional
            The pattern width, 1 to 8.
        symmetry : int, optional
            1 to 8: how many of a pattern's 8 images (turns, mirrors) are added.
        periodic_input : bool, optional
            Whether the sample wraps around (patterns across its edges are read too).
        ground : bool or str, optional
            2D, symmetry 1 or 2: ``True``/``"true"`` is WaveFunctionCollapse's rule (its
            ground pattern fills the bottom and nowhere else; periodic outputs),
            ``"bottom"`` keeps the bottom row of cells to patterns of the sample's bottom
            row, ``False``/``"false"`` adds no rule (see the module docstring).

        Returns
        -------
        OverlapModel
            One label per distinct pattern, with the patterns, their counts as weights, the
            colours and the overlap relations; named after the file's stem.

        Raises
        ------
        InputError
            When ``ground`` is not one of the values above.
        FormatError
            Naming the file when it cannot be read as a picture, is larger than 256x256, or
            the options do not fit it (``N`` or ``symmetry`` out of range, a pattern wider
            than a non-periodic sample, ``ground`` with a 3D sample or symmetry above 2).
        """
        p = Path(path)
        ground_rule(ground)  # a bad value is the option's error, not the file's
        img = load_image(p)
        if img.shape[0] * img.shape[1] > 256 * 256:
            raise FormatError(
                f"sample {img.shape[1]}x{img.shape[0]} is too large (max 256x256)", path=p
            )
        flat = img.reshape(-1, 4)
        _, first, inv = np.unique(flat, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first)
        rank = np.empty_like(order)
        rank[order] = np.arange(order.size)
        lab = rank[inv.reshape(-1)].reshape(img.shape[:2])  # [row, col]
        colors = flat[first[order], :3]
        sample = lab.T[:, ::-1]  # [x, y] with y up
        try:
            return cls.from_grid(
                sample,
                N=N,
                symmetry=symmetry,
                periodic_input=periodic_input,
                ground=ground,
                colors=colors,
                name=p.stem,
                meta={"source": str(p)},
            )
        except InputError as e:
            raise FormatError(str(e), path=p) from None

    def problem(
        self,
        shape: Sequence[int] | str | None = None,
        *,
        periodic: bool | Sequence[bool] | None = None,
        **options: Any,
    ) -> Problem:
        """As :meth:`RuleSet.problem`; WFC's ground rule on an output that is not periodic
        along ``y`` becomes the ``"bottom"`` rule, with a warning (WFC's ground pattern
        wraps around)."""
        if self.meta.get("ground") == "wfc":
            per = self.periodic if periodic is None else periodic
            per_y = bool(per) if isinstance(per, bool | np.bool_) else bool(list(per)[1])
            if not per_y:
                warnings.warn(
                    f"{self.name}: ground=true is WaveFunctionCollapse's rule for outputs "
                    "periodic along y; this output stands on the sample's bottom row instead "
                    "(ground=bottom)",
                    UserWarning,
                    stacklevel=2,
                )
                other = copy.copy(self)
                other.constraint_ops = self._bottom_ops
                return RuleSet.problem(other, shape, periodic=periodic, **options)
        return super().problem(shape, periodic=periodic, **options)

    # ------------------------------------------------------------------ results
    def reconstruct(self, grid: ArrayLike, periodic: bool | None = None) -> NDArray[np.int64]:
        """Sample labels of a result: cell ``[x, y]`` gives pixel ``[x, y]`` (its pattern's
        corner); a non-periodic result also gets the far rows of its last patterns.
        Unassigned cells give ``-1``."""
        g = np.asarray(grid, dtype=np.int64)
        if g.ndim != self.ndim:
            raise InputError(f"grid has {g.ndim} axes, the model {self.ndim}")
        per = bool(self.periodic) if periodic is None else periodic
        N = self.N
        shape = g.shape if per else tuple(s + N - 1 for s in g.shape)
        coords = np.meshgrid(*[np.arange(s) for s in shape], indexing="ij")
        cell = [np.minimum(c, s - 1) for c, s in zip(coords, g.shape, strict=True)]
        off = [c - k for c, k in zip(coords, cell, strict=True)]
        lab = g[tuple(cell)]
        ok = (lab >= 0) & (lab < self.K)
        flat_p = self.patterns.reshape(self.K, -1)
        strides = [N ** (self.ndim - 1 - d) for d in range(self.ndim)]
        pos = sum(o * st for o, st in zip(off, strides, strict=True))
        out = flat_p[np.where(ok, lab, 0), pos]
        return np.where(ok, out, -1)

    def render(
        self, grid: ArrayLike, *, scale: int | None = None, periodic: bool | None = None
    ) -> Any:
        """The picture of a result (sample colours, ``y`` up); ``periodic`` says whether the
        result wraps around (default: the model's setting)."""
        from csplab.render import render

        g = np.asarray(grid)
        img = self.reconstruct(g, periodic=periodic)
        K = int(self.patterns.max()) + 1
        return render(img, K=K, colors=self.sample_colors, scale=scale)
