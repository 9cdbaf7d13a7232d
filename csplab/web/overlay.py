"""The global constraints of a run, shown on its picture: which cells are in a connected set
or are counted, how many, and whether each constraint holds (``Problem.violations``'s own
``check``).

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> from csplab.constraints import Count
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 4))
>>> P = P.with_constraints([Count(labels=[1], min=8, max=8)])
>>> g = np.indices((4, 4)).sum(axis=0) % 2
>>> [(c["kind"], c["cells"], c["holds"]) for c in constraint_rows(P, g)]
[('count', 8, True)]
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from csplab.problem import Problem

__all__ = ["constraint_rows", "highlight"]


def _members(problem: Problem, c: Any, grid: NDArray[np.int64]) -> NDArray[np.bool_]:
    """The cells a constraint is about: its labels' cells (a count: inside its region)."""
    labels = getattr(c, "labels", None)
    if labels is None:
        return np.zeros(grid.shape, dtype=bool)
    inset = np.isin(grid, np.asarray(list(labels), dtype=np.int64))
    cells = getattr(c, "cells", None)
    if callable(cells):  # a count's region
        keep = np.zeros(grid.size, dtype=bool)
        keep[cells(problem)] = True
        inset &= keep.reshape(grid.shape)
    return inset


def constraint_rows(problem: Problem, grid: NDArray[np.integer[Any]]) -> list[dict[str, Any]]:
    """One row per global constraint of ``problem`` on ``grid``.

    Parameters
    ----------
    problem : Problem
        The run's problem, with its constraints.
    grid : int array
        The run's labels.

    Returns
    -------
    list of dict
        ``kind``, ``text`` (the constraint's one line), ``cells`` (how many cells hold its
        labels: the connected set's size, the counted cells), ``holds`` and ``breach`` (the
        checker's message, or ``None``).
    """
    g = np.asarray(grid, dtype=np.int64)
    rows = []
    for c in problem.constraints:
        breach = c.check(problem, g.reshape(-1))
        rows.append({
            "kind": c.kind, "text": c.describe(problem),
            "cells": int(_members(problem, c, g).sum()), "holds": breach is None,
            "breach": breach,
        })  # fmt: skip
    return rows


def highlight(png: bytes, problem: Problem, grid: NDArray[np.integer[Any]]) -> bytes:
    """The picture ``png`` of a 2D ``grid`` with every cell that no constraint is about
    faded: the connected sets and the counted labels stand out.

    Parameters
    ----------
    png : bytes
        The run's picture (cells ``[x, y]`` drawn with ``y`` up, equal size).
    problem : Problem
        The run's problem.
    grid : int array
        The run's labels (2D).

    Returns
    -------
    bytes
        The PNG with the faded cells.
    """
    g = np.asarray(grid, dtype=np.int64)
    keep = np.zeros(g.shape, dtype=bool)
    for c in problem.constraints:
        keep |= _members(problem, c, g)
    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.float64)
    nx, ny = g.shape
    sy, sx = img.shape[0] // ny, img.shape[1] // nx
    fade = np.repeat(np.repeat((~keep).T[::-1], sy, axis=0), sx, axis=1)
    out = img.copy()
    h, w = fade.shape
    region = out[:h, :w]
    region[fade] = region[fade] * 0.25 + 255 * 0.75
    buf = io.BytesIO()
    Image.fromarray(out.astype(np.uint8), "RGB").save(buf, format="PNG")
    return buf.getvalue()
