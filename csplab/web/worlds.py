"""An endless world as the page sees it: chunks of a :class:`csplab.World`, and the user's
edits, each re-synthesized locally (modify in blocks around the edit) and undoable.

An edit paints a brush on a rectangle of world cells: ``label`` (the cells must be label
``X``), ``empty`` (they must stay empty: the model's empty label) or ``reroll`` (a new
random completion of the rectangle). The server takes the rectangle widened by
``margin`` cells, keeps every cell around it (the arcs' reach) fixed to the labels the
world has there now, and completes the rectangle with the painted cells fixed: Alg. 3.1
with restarts, then SAT (:func:`csplab.solve` with ``fallback="auto"``). That is one block
of modify in blocks (thesis Sec. 3.3.6) on the world's current labels, so the world stays
consistent and every cell outside the rectangle keeps its bytes: the chunks that change are
exactly those the rectangle touches (and only those where a label changed). When no
completion exists, the edit is refused and the UNSAT core of the painted cells
(:func:`csplab.exact.explain_unsat`) names the cells that conflict.

Examples
--------
>>> s = WorldSession("fig3_4a", seed=1, chunk=(8, 8))
>>> before = s.chunk(0, 0)
>>> e = s.edit("reroll", (2, 6), (2, 6))
>>> e["status"], set(e["touched"]) == {(0, 0)}
('solved', True)
>>> bool((s.chunk(1, 0) == s.world.chunk(1, 0)).all())
True
>>> s.undo()
[(0, 0)]
>>> bool((s.chunk(0, 0) == before).all())
True
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError
from csplab.world import World

__all__ = ["BRUSHES", "Patch", "WorldSession"]

BRUSHES = ("label", "empty", "reroll")


@dataclass(frozen=True)
class Patch:
    """One accepted edit: the labels of rectangle ``xs x ys`` (and the painted cells)."""

    xs: tuple[int, int]
    ys: tuple[int, int]
    labels: NDArray[np.int32]
    brush: str
    label: int | None


class WorldSession:
    """A :class:`csplab.World` with the user's edits on top.

    Parameters
    ----------
    model : str or model
        What :class:`csplab.World` takes.
    margin : int
        Cells re-synthesized around the painted rectangle.
    **settings
        :class:`csplab.World`'s keyword settings (seed, chunk, order, choice ...).
    """

    def __init__(self, model: Any, *, margin: int = 2, **settings: Any) -> None:
        self.world = World(model, **settings)
        self.model = self.world.model
        self.margin = int(margin)
        self.patches: list[Patch] = []
        self.lock = threading.Lock()  # a World and its caches serve one request at a time
        self.editing = threading.Lock()  # edits (and undo) one at a time, on the latest state

    # -- reading ----------------------------------------------------------------------------
    def region(self, xs: tuple[int, int], ys: tuple[int, int]) -> NDArray[np.int32]:
        """The labels of ``[x0, x1) x [y0, y1)``: the world's, then every patch in order."""
        with self.lock:
            g = self.world.region(xs, ys)
        for p in self.patches:
            lo = (max(xs[0], p.xs[0]), max(ys[0], p.ys[0]))
            hi = (min(xs[1], p.xs[1]), min(ys[1], p.ys[1]))
            if lo[0] < hi[0] and lo[1] < hi[1]:
                g[lo[0] - xs[0] : hi[0] - xs[0], lo[1] - ys[0] : hi[1] - ys[0]] = p.labels[
                    lo[0] - p.xs[0] : hi[0] - p.xs[0], lo[1] - p.ys[0] : hi[1] - p.ys[0]
                ]
        return g

    def chunk(self, i: int, j: int) -> NDArray[np.int32]:
        """The labels of chunk ``(i, j)`` with the edits."""
        X, Y = self.world.B
        return self.region((i * X, (i + 1) * X), (j * Y, (j + 1) * Y))

    @property
    def empty(self) -> int:
        """The model's empty label (3D: the sky; 2D: label 0 unless the model names one)."""
        e = getattr(self.model, "empty", None)
        if e is None:
            e = self.model.meta.get("empty") if hasattr(self.model, "meta") else None
        if e is None and self.world.ndim == 3:
            from csplab.render import empty_label_guess

            e = empty_label_guess(self.world.chunk(0, 0))
        return int(e or 0)

    # -- editing ----------------------------------------------------------------------------
    def edit(
        self,
        brush: str,
        xs: tuple[int, int],
        ys: tuple[int, int],
        *,
        label: int | None = None,
        cells: list[tuple[int, int]] | None = None,
        limit: int = 48 * 48,
        time_limit: float = 30.0,
    ) -> dict[str, Any]:
        """Paint ``brush`` on ``cells`` (default: the whole rectangle) and re-synthesize the
        rectangle widened by :attr:`margin`.

        Parameters
        ----------
        brush : {"label", "empty", "reroll"}
            What the painted cells must hold.
        xs, ys : tuple of int
            The painted rectangle, half-open world cells.
        label : int, optional
            The label of the ``label`` brush.
        cells : list of (x, y), optional
            The painted cells (inside the rectangle); default: all of it.
        limit : int
            Largest re-synthesized rectangle, in cells.
        time_limit : float
            Seconds for the completion.

        Returns
        -------
        dict
            ``status`` (``solved``, ``unsat`` or ``failed``), ``rect`` (the re-synthesized
            rectangle), ``touched`` (its chunks), ``changed`` (the chunks where a label
            changed), ``core`` (``unsat``: the painted cells that conflict) and ``solver``.

        Raises
        ------
        InputError
            For an unknown brush, a label out of range, a 3D world or a rectangle over
            ``limit``.
        """
        with self.editing:
            return self._edit(brush, xs, ys, label, cells, limit, time_limit)

    def _edit(
        self,
        brush: str,
        xs: tuple[int, int],
        ys: tuple[int, int],
        label: int | None,
        cells: list[tuple[int, int]] | None,
        limit: int,
        time_limit: float,
    ) -> dict[str, Any]:
        from csplab.solvers import solve

        if brush not in BRUSHES:
            raise InputError(f"brush must be one of {', '.join(BRUSHES)}, not {brush!r}")
        if self.world.ndim != 2:
            raise InputError("editing works on 2D worlds (a 3D world is shown in the viewer)")
        K = self.world.K
        if brush == "label" and (label is None or not 0 <= int(label) < K):
            raise InputError(f"label must be 0..{K - 1}, not {label!r}")
        if xs[1] <= xs[0] or ys[1] <= ys[0]:
            raise InputError(f"empty rectangle {xs}, {ys}")
        m, r = self.margin, self.world.reach
        rx = (xs[0] - m, xs[1] + m)
        ry = (ys[0] - m, ys[1] + m)
        w, h = rx[1] - rx[0], ry[1] - ry[0]
        if w * h > limit:
            raise InputError(f"an edit re-synthesizes {w}x{h} cells, more than the limit {limit}")
        painted = [(x, y) for x in range(*xs) for y in range(*ys)] if cells is None else cells
        for x, y in painted:
            if not (xs[0] <= x < xs[1] and ys[0] <= y < ys[1]):
                raise InputError(f"painted cell {(x, y)} is outside the rectangle")
        want = {"label": label, "empty": self.empty}.get(brush)
        outer = self.region((rx[0] - r, rx[1] + r), (ry[0] - r, ry[1] + r))
        P = self.world.problem(outer.shape)
        inner = np.zeros(outer.shape, dtype=bool)
        inner[r:-r, r:-r] = True
        cells_idx = np.flatnonzero(inner.ravel())
        sub = P.subproblem(cells_idx, outer, shape=(w, h))
        if want is not None:
            allowed = np.zeros(K, dtype=bool)
            allowed[int(want)] = True
            from csplab.problem import Unary

            sub = sub.with_unary([
                Unary("fixed", (x, y), np.array([(x - rx[0]) * h + (y - ry[0])], dtype=np.int64),
                      allowed[None, :].copy())
                for x, y in painted
            ])  # fmt: skip
        key = [self.world.seed, len(self.patches) + 1, rx[0] & 0xFFFF, ry[0] & 0xFFFF]
        seed = int(np.random.SeedSequence(key).generate_state(1)[0])
        res = solve(sub, "catalog", rng=seed, restarts=10, fallback="auto",
                    order=self.world.order, choice=self.world.choice,
                    time_limit=time_limit)  # fmt: skip
        touched = sorted(self.world.chunks_in(rx, ry))
        out: dict[str, Any] = {"status": res.status, "rect": [list(rx), list(ry)],
                               "touched": touched, "solver": res.solver, "changed": [],
                               "core": []}  # fmt: skip
        if res.status != "solved":
            if res.status == "unsat" and want is not None:
                from csplab.exact import explain_unsat

                v = explain_unsat(sub, time_limit=time_limit)
                if v.holds:
                    out["core"] = sorted(sub.unary[i].key for i in v.witness["core"])
            return out
        new = np.asarray(res.grid, dtype=np.int32).reshape(w, h)
        old = outer[r:-r, r:-r]
        X, Y = self.world.B
        diff = np.argwhere(new != old)
        out["changed"] = sorted({((rx[0] + int(a)) // X, (ry[0] + int(b)) // Y) for a, b in diff})
        self.patches.append(Patch(rx, ry, new, brush, None if want is None else int(want)))
        return out

    def undo(self) -> list[tuple[int, int]]:
        """Take back the last edit; returns the chunks it touched (empty: nothing to undo)."""
        with self.editing:
            if not self.patches:
                return []
            p = self.patches.pop()
        return sorted(self.world.chunks_in(p.xs, p.ys))
