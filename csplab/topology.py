"""Grid variants of thesis Sec. 3.5.1: hexagonal and triangular grids, and the affine and
cylindrical grids, as first-class topologies.

A topology says which cells of a grid of ``shape`` are neighbours and through which
relation: a square grid has one relation per axis (the transition matrices ``T_d`` of Eq.
3.2); a hexagonal grid three (``E``, ``NE``, ``NW`` for rows offset, ``N``, ``NE``,
``SE`` for columns offset: each cell has six neighbours, the other three directions use
the transposed relations); a triangular grid three (a triangle pointing up and its right
neighbour, a triangle pointing down and its right neighbour, and the pair across a
horizontal edge). Hexagonal and triangular grids may have a third axis ``z`` (prisms). An
example on a topology gives its relations by :meth:`Topology.learn` (the pairs it shows);
the synthesis problem uses the same arcs on the output's shape, so every solver runs on it
unchanged.

==============  ============================================================================
name            cells and neighbours (``y`` points up)
==============  ============================================================================
``square``      axis neighbours (the default)
``hex:odd-r``   pointy-top hexagons in rows, odd rows shifted right by half a cell
``hex:even-r``  the same with even rows shifted
``hex:odd-q``   flat-top hexagons in columns, odd columns shifted up by half a cell
``hex:even-q``  the same with even columns shifted
``tri``         triangles, ``(x, y)`` pointing up when ``x + y`` is even
``cylinder``    the square grid with ``(r, theta[, z])`` axes, ``theta`` periodic; drawn as
                an annulus (pieces rotate with theta)
``affine:A,B,C,D``  the square grid drawn through the matrix ``[[A, B], [C, D]]``
                (parallelogram pieces)
==============  ============================================================================

Examples
--------
>>> import numpy as np
>>> T = Topology.parse("hex:odd-r")
>>> T.relation_names(2)
('E', 'NE', 'NW')
>>> sorted(T.neighbours((3, 3), (1, 1)))            # an odd row: shifted right
[(0, 1), (1, 0), (1, 2), (2, 0), (2, 1), (2, 2)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import InputError

__all__ = ["TOPOLOGIES", "Topology"]

TOPOLOGIES = ("square", "hex:odd-r", "hex:even-r", "hex:odd-q", "hex:even-q", "tri",
              "cylinder", "affine:A,B,C,D")  # fmt: skip


@dataclass(frozen=True)
class Topology:
    """One grid topology (see the module docstring); build it with :meth:`parse`."""

    kind: str = "square"  #: square, hex, tri
    variant: str = ""  #: hex: odd-r, even-r, odd-q, even-q; square: cylinder or affine
    matrix: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 1.0)  #: affine drawing

    @classmethod
    def parse(cls, text: str | Topology | None) -> Topology:
        """A topology from its name (``None``: square)."""
        if isinstance(text, Topology):
            return text
        t = (text or "square").strip().lower()
        if t == "square":
            return cls()
        if t in ("hex:odd-r", "hex:even-r", "hex:odd-q", "hex:even-q"):
            return cls("hex", t[4:])
        if t in ("hex", "hexagonal"):
            return cls("hex", "odd-r")
        if t in ("tri", "triangular"):
            return cls("tri")
        if t in ("cylinder", "cylindrical"):
            return cls("square", "cylinder")
        if t.startswith("affine:"):
            try:
                m = tuple(float(v) for v in t[7:].split(","))
            except ValueError:
                m = ()
            if len(m) != 4 or not all(math.isfinite(v) for v in m) or m[0] * m[3] == m[1] * m[2]:
                raise InputError(f"grid {text!r}: affine needs 4 numbers A,B,C,D with AD != BC")
            return cls("square", "affine", (m[0], m[1], m[2], m[3]))
        raise InputError(f"unknown grid {text!r}; grids: {', '.join(TOPOLOGIES)}")

    @property
    def name(self) -> str:
        if self.kind == "hex":
            return f"hex:{self.variant}"
        if self.variant == "affine":
            return "affine:" + ",".join(f"{v:g}" for v in self.matrix)
        return self.variant or self.kind

    @property
    def square(self) -> bool:
        """Axis neighbours (square, cylinder, affine): the arcs of :func:`csplab.grids.grid`."""
        return self.kind == "square"

    def relation_names(self, ndim: int) -> tuple[str, ...]:
        """One name per relation of a grid with ``ndim`` axes."""
        if self.kind == "square":
            return tuple(f"T_{'xyzw'[d]}" for d in range(ndim))
        if ndim not in (2, 3):
            raise InputError(f"a {self.name} grid has 2 or 3 axes, not {ndim}")
        base = ("E", "NE", "NW") if self.variant in ("odd-r", "even-r") else ("N", "NE", "SE")
        if self.kind == "tri":
            base = ("right_of_up", "right_of_down", "across")
        return base + (("T_z",) if ndim == 3 else ())

    # ------------------------------------------------------------------ arcs
    def _steps(self, x: NDArray[np.int64], y: NDArray[np.int64]) -> list[tuple[Any, Any, Any]]:
        """Per relation: ``(mask, dx, dy)`` arrays for the cells at ``(x, y)`` (the arc goes
        from the cell to the cell at ``+ (dx, dy)`` where ``mask``)."""
        one = np.ones_like(x, dtype=bool)
        if self.kind == "tri":
            up = (x + y) % 2 == 0
            return [(up, 1, 0), (~up, 1, 0), (~up, 0, 1)]
        v = self.variant
        if v in ("odd-r", "even-r"):
            shifted = (y % 2 == 1) if v == "odd-r" else (y % 2 == 0)
            return [(one, 1, 0), (one, shifted.astype(np.int64), 1),
                    (one, shifted.astype(np.int64) - 1, 1)]  # fmt: skip
        shifted = (x % 2 == 1) if v == "odd-q" else (x % 2 == 0)
        return [(one, 0, 1), (one, 1, shifted.astype(np.int64)),
                (one, 1, shifted.astype(np.int64) - 1)]  # fmt: skip

    def arcs(self, shape: tuple[int, ...]) -> NDArray[np.int64]:
        """``(src, dst, relation)`` of a hexagonal or triangular grid of ``shape`` (2D, or
        3D prisms with a ``T_z`` relation along ``z``)."""
        if self.square:
            raise InputError("square grids take their arcs from csplab.grids.grid")
        if len(shape) not in (2, 3):
            raise InputError(f"a {self.name} grid has 2 or 3 axes, got shape {shape}")
        nx, ny = shape[0], shape[1]
        nz = shape[2] if len(shape) == 3 else 1
        idx = np.arange(nx * ny * nz, dtype=np.int64).reshape(nx, ny, nz)
        x, y = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
        parts = []
        for r, (mask, dx, dy) in enumerate(self._steps(x, y)):
            x2, y2 = x + dx, y + dy
            ok = mask & (x2 >= 0) & (x2 < nx) & (y2 >= 0) & (y2 < ny)
            src = idx[x[ok], y[ok]].reshape(-1)
            dst = idx[x2[ok], y2[ok]].reshape(-1)
            parts.append(np.stack([src, dst, np.full_like(src, r)], axis=1))
        if nz > 1:
            src, dst = idx[:, :, :-1].reshape(-1), idx[:, :, 1:].reshape(-1)
            parts.append(np.stack([src, dst, np.full_like(src, 3)], axis=1))
        return np.concatenate(parts)

    def neighbours(self, shape: tuple[int, ...], cell: tuple[int, ...]) -> set[tuple[int, ...]]:
        """The neighbours of one cell (coordinates), for checks and pictures."""
        a = self.arcs(shape)
        i = int(np.ravel_multi_index(cell, shape))
        out = set(a[a[:, 0] == i, 1].tolist()) | set(a[a[:, 1] == i, 0].tolist())
        return {tuple(int(c) for c in np.unravel_index(j, shape)) for j in out}

    def learn(self, labels: ArrayLike, K: int) -> NDArray[np.bool_]:
        """The relations an example on this topology shows: ``T[r, a, b]`` when some arc of
        relation ``r`` joins a cell labelled ``a`` to one labelled ``b``."""
        g = np.asarray(labels, dtype=np.int64)
        a = self.arcs(tuple(g.shape))
        flat = g.reshape(-1)
        T = np.zeros((len(self.relation_names(g.ndim)), K, K), dtype=bool)
        T[a[:, 2], flat[a[:, 0]], flat[a[:, 1]]] = True
        return T

    # ------------------------------------------------------------------ pictures
    def polygons(self, shape: tuple[int, int]) -> list[NDArray[np.float64]]:
        """The outline of every cell of a 2D grid (C order), in drawing units, ``y`` up."""
        nx, ny = shape
        out: list[NDArray[np.float64]] = []
        s3 = math.sqrt(3.0)
        for x in range(nx):
            for y in range(ny):
                if self.kind == "hex" and self.variant in ("odd-r", "even-r"):
                    shift = (y % 2 == 1) if self.variant == "odd-r" else (y % 2 == 0)
                    cx, cy = s3 * (x + 0.5 * shift), 1.5 * y
                    ang = np.radians(np.arange(6) * 60 + 30)
                    out.append(np.stack([cx + np.cos(ang), cy + np.sin(ang)], axis=1))
                elif self.kind == "hex":
                    shift = (x % 2 == 1) if self.variant == "odd-q" else (x % 2 == 0)
                    cx, cy = 1.5 * x, s3 * (y + 0.5 * shift)
                    ang = np.radians(np.arange(6) * 60)
                    out.append(np.stack([cx + np.cos(ang), cy + np.sin(ang)], axis=1))
                elif self.kind == "tri":
                    h = s3 / 2
                    if (x + y) % 2 == 0:  # pointing up
                        pts = [(x / 2, y * h), (x / 2 + 1, y * h), (x / 2 + 0.5, (y + 1) * h)]
                    else:
                        pts = [(x / 2, (y + 1) * h), (x / 2 + 1, (y + 1) * h),
                               (x / 2 + 0.5, y * h)]  # fmt: skip
                    out.append(np.array(pts, dtype=np.float64))
                elif self.variant == "cylinder":
                    r0, r1 = nx * 0.6 + x, nx * 0.6 + x + 1  # r grows with x, theta with y
                    t = np.linspace(2 * np.pi * y / ny, 2 * np.pi * (y + 1) / ny, 6)
                    inner = np.stack([r0 * np.cos(t), r0 * np.sin(t)], axis=1)
                    outer = np.stack([r1 * np.cos(t[::-1]), r1 * np.sin(t[::-1])], axis=1)
                    out.append(np.concatenate([inner, outer]))
                else:
                    A, B, C, D = self.matrix
                    sq = np.array([(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)], float)
                    out.append(sq @ np.array([[A, C], [B, D]]))
        return out
