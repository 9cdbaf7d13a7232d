"""Blocks with a fixed ring: when can Alg. 3.1 not fail on them (modify in blocks, worlds)?

Modify in blocks (Alg. 3.4/3.5, :class:`csplab.World`) solves a block with the labels
around it (a *ring* of the arcs' reach) fixed. The region prover
(:func:`~csplab.analysis.infallible.prove_infallible`, Theorem 3.3.6) is about another
situation: an *open* grid that Alg. 3.1 fills from nothing in scan order, with constant
labels forced on whole faces at most. What it covers for a block:

* a block whose ring is one label ``e`` on every side (the isolated blocks of a world
  whose start model is that label), arcs reaching one cell: the block and its ring form an
  open grid with its faces forced to ``e``, so a proof with that boundary covers it, for
  every block size;
* with a proof of 2x2 regions (the corner condition) and the forward faces forced to
  ``e``, a ring with any consistent labels on the *backward* sides (``x-``, ``y-``: with
  every scan prefix they form a down-set, and the corner condition extends a consistent
  down-set cell by cell) and ``e`` on the forward ones;
* not a ring with arbitrary labels on a *forward* side: an open-grid run never has cells
  after the one it assigns fixed beforehand, so its proof says nothing about them.
  Every modify in blocks that leaves none of the start model behind has such blocks
  (a block of the last sub-pass has every neighbour fixed), and open-grid infallibility
  does not imply anything there: the pipes tileset is proved with 2x2 regions, yet a cell
  whose ring holds one pipe end pointing at it and no other has no label (it has no dead
  end).

What does cover them, whatever the block's shape and the ring's labels:
:func:`ring_completion`, the closed-form condition "every cell has a label whatever labels
its neighbours hold" (a cell's neighbours are the cells its arcs join; each takes any
label of its domain). Then any consistent partial labelling extends one cell at a time,
so the exact catalog ``C*`` is never empty and neither is Alg. 3.1's catalog, which
contains it (Theorem 3.3.2): Alg. 3.1 in any order never fails on any block with any
consistent ring, and no block needs a retry, an exact completion or to keep its labels.

Examples
--------
>>> import numpy as np
>>> from csplab.grids import grid
>>> P = grid((5, 5), np.ones((2, 3, 3), dtype=bool))   # anything next to anything
>>> ring_completion(P, [P.cell((2, 2))]).holds
True
>>> T = np.stack([np.eye(2, dtype=bool)] * 2)           # a neighbour copies its label
>>> v = ring_completion(grid((5, 5), T), [12])
>>> v.holds, v.witness["cell"]
(False, 12)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from csplab.problem import Problem
from csplab.result import Verdict

__all__ = ["ring_completion"]


def ring_completion(P: Problem, cells: Sequence[int], *, max_sets: int = 200_000) -> Verdict:
    """Whether each cell of ``cells`` has a label whatever labels its neighbours hold.

    For a cell ``p``, every assignment of a label of its domain to each cell an arc joins
    to ``p`` leaves ``p`` a label of its domain that every such arc allows. Checked by
    folding the neighbours in one at a time over the family of label sets ``p`` may still
    take (bit sets, duplicates merged): the condition fails exactly when the empty set
    appears.

    Parameters
    ----------
    P : Problem
        A problem whose ``cells`` stand for every cell of the blocks in question (for a
        world: the centre column of its block template, whose neighbours all lie inside).
    cells : sequence of int
        Flat indices of the cells to check.
    max_sets : int
        Give up (``holds=None``) when the family of label sets grows past this.

    Returns
    -------
    Verdict
        ``holds`` True (every such block with any consistent ring completes, in any
        order), False (``witness``: the cell and one neighbour labelling that leaves it no
        label) or None (the family grew too large).

    Examples
    --------
    >>> import numpy as np
    >>> from csplab.grids import grid
    >>> v = ring_completion(grid((3, 3), np.ones((2, 2, 2), dtype=bool)), [4])
    >>> v.holds, v.stats
    (True, {'cells': 1, 'neighbours': 4})
    """
    rel, dom = P.relations, P.domains
    s, d, r = P.arcs[:, 0], P.arcs[:, 1], P.arcs[:, 2]
    most = 0
    for p in (int(c) for c in cells):
        # per neighbour q: for each label l of q, the labels of p that every arc to q allows
        nb: dict[int, dict[int, int]] = {}
        for i in np.flatnonzero((s == p) | (d == p)):
            q = int(d[i]) if int(s[i]) == p else int(s[i])
            m = rel[int(r[i])] if int(s[i]) == p else rel[int(r[i])].T  # [label p, label q]
            sets = nb.setdefault(q, {})
            for k in (int(x) for x in np.flatnonzero(dom[q])):
                bits = _bits(m[:, k] & dom[p])
                sets[k] = sets.get(k, bits) & bits
        most = max(most, len(nb))
        family: dict[int, tuple[tuple[int, int], ...]] = {_bits(dom[p]): ()}
        for q in sorted(nb):
            nxt: dict[int, tuple[tuple[int, int], ...]] = {}
            for a, why in family.items():
                for lq, bits in nb[q].items():
                    b = a & bits
                    if not b:
                        labels = dict((*why, (q, lq)))
                        at = {_at(P, c): v for c, v in labels.items()}
                        return Verdict(False, {"cell": p, "neighbours": labels}, {},
                                       f"cell {_at(P, p)} has no label when its neighbours "
                                       f"hold the labels {at}")  # fmt: skip
                    nxt.setdefault(b, (*why, (q, lq)))
            if len(nxt) > max_sets:
                msg = f"undecided: more than {max_sets} label sets at cell {_at(P, p)}"
                return Verdict(None, None, {"sets": len(nxt)}, msg)
            family = nxt
        if not family or not any(family):
            return Verdict(False, {"cell": p, "neighbours": {}}, {},
                           f"cell {_at(P, p)} has no label")  # fmt: skip
    return Verdict(True, None, {"cells": len(cells), "neighbours": most},
                   f"every cell has a label whatever its neighbours hold (checked at "
                   f"{len(cells)} cell(s), at most {most} neighbours each)")  # fmt: skip


def _at(P: Problem, c: int) -> tuple[int, ...]:
    return tuple(int(x) for x in np.unravel_index(c, P.shape))


def _bits(mask: NDArray[np.bool_]) -> int:
    """A bool mask over labels as a Python-int bit set (bit ``c`` = label ``c``)."""
    return sum(1 << int(c) for c in np.flatnonzero(mask))
