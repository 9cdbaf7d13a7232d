"""CNF encodings of a :class:`~csplab.problem.Problem`, built with numpy and numba.

The clause loops are the compiled :func:`csplab._kernels.support_clauses` and
:func:`csplab._kernels.direct_clauses` (kept in :mod:`csplab._kernels` with the helpers they
inline: see its kernel cache rule).

One Boolean variable ``x[v, b]`` means "cell ``v`` has label ``b``". Variables exist only
for pairs in the arc-consistent catalog C of the problem (Alg. 3.2; pruning is sound by
Theorem 3.3.2), and only for cells with more than one label left: a cell with a single
label is a constant. If arc consistency wipes out a domain, the encoding is the empty
clause (``Encoding.ok`` is ``False``): the wipe-out is itself a proof of unsatisfiability,
and it is exactly what unit propagation on the support encoding would find.

Encodings
---------
``support`` (default)
    For every arc direction ``v -> u`` and label ``b`` of ``v``, the clause
    ``-x[v, b] | OR{x[u, c] : c in D(u), T[b, c]}`` (Kasif 1990; Gent 2002). Unit
    propagation on it achieves exactly arc consistency. A clause whose support covers all of
    ``D(u)`` is implied by ``D(u)``'s at-least-one clause and is left out.
    ``supports="forward"`` keeps only the ``src -> dst`` direction of every arc: still
    correct together with at-most-one, half the clauses, weaker propagation.
``direct``
    A binary clause ``-x[v, b] | -x[u, c]`` for every forbidden pair (only forward
    checking; grows with ``K**2`` per arc, for small problems).

Every cell gets an at-least-one clause. At-most-one (``amo``):

``"lazy"`` (default)
    No clauses up front. With the support encoding a model whose cells each hold one true
    label is a solution; a cell with several true labels gets an at-most-one constraint
    added and the solver runs again (counterexample-guided refinement, done by
    :class:`csplab.engine.sat.SatOracle`). With the direct encoding any true label of each
    cell gives a solution, so no refinement is ever needed.
a :class:`pysat.card.EncType` name (``"seqcounter"``, ``"ladder"``, ``"bitwise"``, ...)
    Built once per domain size as a template from :mod:`pysat.card` and instantiated for
    every cell with numpy.

Clauses are stored flat: ``lits`` (int32) and ``starts`` (int64, one more than the number
of clauses); clause ``i`` is ``lits[starts[i]:starts[i + 1]]``.

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (2, 2))           # checkerboard
>>> enc = encode(P)
>>> enc.nvars, enc.nclauses
(8, 20)
>>> enc.clause(0).tolist()          # (0,0)=0 needs its +x neighbour (1,0) to be 1
[-1, 6]
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import _kernels as kern
from csplab.catalog import Propagator
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["AMO_ENCODINGS", "MAX_LITERALS", "DeadlineExceeded", "Encoding", "amo_clauses", "encode"]

MAX_LITERALS = 60_000_000  # ~240 MB of int32: refuse larger formulas with a clear message


class DeadlineExceeded(Exception):
    """Raised by :func:`encode` when its ``deadline`` passes (callers report a timeout)."""


EncodingName = Literal["support", "direct"]
AMO_ENCODINGS = (
    "lazy",
    "pairwise",
    "seqcounter",
    "ladder",
    "bitwise",
    "totalizer",
    "mtotalizer",
    "kmtotalizer",
    "sortnetwrk",
    "cardnetwrk",
)


# ----------------------------------------------------------------------------- encoding


@dataclass
class Encoding:
    """A CNF for a problem plus the map between variables and ``(cell, label)`` pairs.

    Attributes
    ----------
    problem : Problem
    catalog : bool array ``(n, K)``
        The arc-consistent catalog the variables come from (all ``False`` if ``not ok``).
    var : int32 array ``(n, K)``
        Variable of ``(cell, label)``; 0 where there is none (pruned, or a constant cell).
    const : int32 array ``(n,)``
        The label of cells whose catalog holds one label (no variables), else -1.
    nvars : int
        Largest variable id in use (``x`` variables first, then auxiliary ones).
    lits, starts : int32 and int64 arrays
        The clauses, flat (see the module docstring).
    ok : bool
        ``False`` when arc consistency wiped out a domain (``wiped`` is that cell).
    stats : dict
        Clause counts per kind and the build time.
    """

    problem: Problem
    catalog: NDArray[np.bool_]
    var: NDArray[np.int32]
    const: NDArray[np.int32]
    nvars: int
    lits: NDArray[np.int32]
    starts: NDArray[np.int64]
    ok: bool
    encoding: str
    amo: str
    wiped: int = -1
    nx: int = 0
    stats: dict[str, Any] = field(default_factory=dict)

    @property
    def nclauses(self) -> int:
        return int(self.starts.size - 1)

    def clause(self, i: int) -> NDArray[np.int32]:
        """Clause ``i`` as an int32 array."""
        return self.lits[self.starts[i] : self.starts[i + 1]]

    def clauses(self) -> list[list[int]]:
        """Every clause as a Python list (for small formulas, tests and pysat's API)."""
        return _split_lists(self.lits, self.starts)

    def literal(self, cell: int, label: int) -> int | bool:
        """The literal of ``cell = label``: a variable, or ``True``/``False`` if constant."""
        v = int(self.var[cell, label])
        if v:
            return v
        if self.const[cell] >= 0:
            return bool(self.const[cell] == label)
        return False

    def cell_vars(self, cell: int) -> NDArray[np.int32]:
        """Variables of one cell (empty for a constant cell)."""
        row = self.var[cell]
        return np.asarray(row[row > 0], dtype=np.int32)

    def decode(self, truth: NDArray[np.bool_]) -> tuple[NDArray[np.int32], NDArray[np.int64]]:
        """Grid from a model, plus the cells with several true labels.

        ``truth[v]`` is the value of variable ``v`` (index 0 unused). A cell with no true
        label is impossible in a model (at-least-one); a cell with several gets its lowest
        label and is reported.
        """
        X = np.zeros(self.var.shape, dtype=bool)
        has = self.var > 0
        X[has] = truth[self.var[has]]
        cnt = X.sum(axis=1)
        grid = np.where(self.const >= 0, self.const, X.argmax(axis=1)).astype(np.int32)
        multi = np.flatnonzero((cnt > 1) & (self.const < 0)).astype(np.int64)
        if self.encoding == "direct":
            multi = np.zeros(0, dtype=np.int64)  # any true label is compatible
        return grid.reshape(self.problem.shape), multi


def encode(
    problem: Problem,
    *,
    encoding: EncodingName = "support",
    supports: Literal["both", "forward"] = "both",
    amo: str = "lazy",
    domains: ArrayLike | None = None,
    prune: bool = True,
    deadline: float | None = None,
) -> Encoding:
    """Build the CNF of ``problem`` (see the module docstring).

    Parameters
    ----------
    problem : Problem
    encoding : {"support", "direct"}
    supports : {"both", "forward"}
        Support clauses for both directions of every arc (unit propagation = arc
        consistency) or only ``src -> dst``.
    amo : str
        ``"lazy"`` or a :mod:`pysat.card` encoding name (:data:`AMO_ENCODINGS`).
    domains : bool array ``(n, K)``, optional
        Encode these domains instead of the problem's (e.g. ``problem.base_domains`` to put
        the unary restrictions back as assumptions).
    prune : bool
        Make the domains arc consistent first (default). Without pruning every domain
        label gets a variable (no constants).
    deadline : float, optional
        A ``time.perf_counter()`` value; :class:`DeadlineExceeded` is raised when it has
        passed between the stages (arc consistency, counting, filling).

    Raises
    ------
    InputError
        If the formula would have more than :data:`MAX_LITERALS` literals (the direct
        encoding grows with ``K**2`` per arc).
    """
    if encoding not in ("support", "direct"):
        raise InputError(f"encoding must be 'support' or 'direct', not {encoding!r}")
    if supports not in ("both", "forward"):
        raise InputError(f"supports must be 'both' or 'forward', not {supports!r}")
    if amo not in AMO_ENCODINGS:
        raise InputError(f"amo must be one of {', '.join(AMO_ENCODINGS)}, not {amo!r}")
    t0 = time.perf_counter()
    eng = Propagator(problem, domains=domains, propagate_initial=prune)
    n, K = problem.n, problem.K
    if not eng.ok:
        return Encoding(
            problem, np.zeros((n, K), dtype=bool), np.zeros((n, K), dtype=np.int32),
            np.full(n, -1, dtype=np.int32), 0, np.zeros(0, dtype=np.int32),
            np.zeros(2, dtype=np.int64), False, encoding, amo, wiped=eng.wiped,
            stats={"encode_s": time.perf_counter() - t0, "clauses": 1, "empty_clause": 1},
        )  # fmt: skip
    C = eng.catalog()
    size = C.sum(axis=1)
    # a cell with one label is a constant only when arc consistency vouches for it
    single = (size == 1) if prune else np.zeros(n, dtype=bool)
    const = np.where(single, C.argmax(axis=1), -1).astype(np.int32)
    has = C & ~single[:, None]
    var = np.zeros((n, K), dtype=np.int32)
    nx = int(has.sum())
    if nx >= 2**31 - 1:
        raise InputError("problem too large for a SAT encoding (more than 2**31 variables)")
    var[has] = np.arange(1, nx + 1, dtype=np.int32)
    c = eng.c
    t1 = time.perf_counter()
    _check_deadline(deadline)
    stats: dict[str, Any] = {"ac_s": t1 - t0, "x_vars": nx}
    dummy_l = np.zeros(1, dtype=np.int32)
    dummy_s = np.zeros(1, dtype=np.int64)
    # one count pass, then every part is written in place into arrays of the final size
    # (16M literals at 40x40x10 castle: no concatenation and no length round trip)
    multi = ~single
    alo_c, alo_l = int(multi.sum()), nx
    if encoding == "support":
        fwd = supports == "forward"
        nc, nl = kern.support_clauses(eng.bits, c.arcs, single, var, fwd, False, dummy_l, dummy_s)
        _check_size(nl, encoding)
    else:
        nc = kern.direct_clauses(eng.bits, c.arcs, single, var, False, dummy_l)
        nl = 2 * nc
        _check_size(nl, encoding)
    _check_deadline(deadline)
    amo_l = np.zeros(0, dtype=np.int32)
    amo_n = np.zeros(0, dtype=np.int64)
    top = nx
    if amo != "lazy":
        amo_l, amo_n, top = amo_clauses(var, has, amo, top)
    all_l = np.empty(nl + alo_l + amo_l.size, dtype=np.int32)
    all_s = np.empty(nc + alo_c + amo_n.size + 1, dtype=np.int64)
    if encoding == "support":
        kern.support_clauses(eng.bits, c.arcs, single, var, fwd, True, all_l, all_s)
    else:
        kern.direct_clauses(eng.bits, c.arcs, single, var, True, all_l)
        np.multiply(np.arange(nc + 1, dtype=np.int64), 2, out=all_s[: nc + 1])
    stats["support_clauses" if encoding == "support" else "conflict_clauses"] = nc
    # at least one label per non-constant cell (var is numbered cell-major)
    all_l[nl : nl + alo_l] = var[has]
    np.cumsum(size[multi], out=all_s[nc + 1 : nc + alo_c + 1])
    all_s[nc + 1 : nc + alo_c + 1] += nl
    stats["alo_clauses"] = alo_c
    if amo != "lazy":
        stats["amo_clauses"] = int(amo_n.size)
    if amo_n.size:
        all_l[nl + alo_l :] = amo_l
        np.cumsum(amo_n, out=all_s[nc + alo_c + 1 :])
        all_s[nc + alo_c + 1 :] += nl + alo_l
    stats["clauses"] = int(all_s.size - 1)
    stats["literals"] = int(all_l.size)
    stats["aux_vars"] = top - nx
    stats["encode_s"] = time.perf_counter() - t0
    return Encoding(problem, C, var, const, top, all_l, all_s, True, encoding, amo, nx=nx,
                    stats=stats)  # fmt: skip


def _check_deadline(deadline: float | None) -> None:
    if deadline is not None and time.perf_counter() > deadline:
        raise DeadlineExceeded


def _check_size(nlits: int, encoding: str) -> None:
    if nlits > MAX_LITERALS:
        hint = "; the support encoding is much smaller" if encoding == "direct" else ""
        raise InputError(
            f"the {encoding} encoding of this problem needs {nlits:,} literals, more than "
            f"csplab's limit of {MAX_LITERALS:,}{hint}"
        )


def amo_clauses(
    var: NDArray[np.int32], has: NDArray[np.bool_], amo: str, top: int,
    cells: NDArray[np.int64] | None = None,
) -> tuple[NDArray[np.int32], NDArray[np.int64], int]:  # fmt: skip
    """At-most-one clauses for ``cells`` (default: all cells with >= 2 variables).

    One :mod:`pysat.card` template per domain size is instantiated with numpy; auxiliary
    variables are numbered from ``top + 1``. Returns ``(lits, lengths, new_top)``.
    """
    from pysat.card import CardEnc, EncType

    size = has.sum(axis=1)
    cand = np.flatnonzero(size >= 2) if cells is None else np.asarray(cells, dtype=np.int64)
    cand = cand[size[cand] >= 2]
    out_l: list[NDArray[np.int32]] = []
    out_n: list[NDArray[np.int64]] = []
    for d in np.unique(size[cand]):
        d = int(d)
        grp = cand[size[cand] == d]
        tmpl = CardEnc.atmost(lits=list(range(1, d + 1)), bound=1, top_id=d,
                              encoding=getattr(EncType, amo))  # fmt: skip
        aux = max(int(tmpl.nv) - d, 0)
        tl = np.concatenate([np.asarray(cl, dtype=np.int64) for cl in tmpl.clauses])
        tn = np.array([len(cl) for cl in tmpl.clauses], dtype=np.int64)
        # table: column j < d -> the cell's j-th variable; j >= d -> fresh auxiliaries
        vars_ = var[grp][has[grp]].reshape(grp.size, d).astype(np.int64)
        auxv = top + 1 + np.arange(grp.size * aux, dtype=np.int64).reshape(grp.size, aux)
        table = np.concatenate([np.zeros((grp.size, 1), dtype=np.int64), vars_, auxv], axis=1)
        inst = table[:, np.abs(tl)] * np.sign(tl)  # (cells, template literals)
        out_l.append(inst.reshape(-1).astype(np.int32))
        out_n.append(np.tile(tn, grp.size))
        top += grp.size * aux
    if not out_l:
        return np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int64), top
    return np.concatenate(out_l), np.concatenate(out_n), top


def _split_lists(lits: NDArray[np.int32], starts: NDArray[np.int64]) -> list[list[int]]:
    flat = lits.tolist()
    st = starts.tolist()
    return [flat[a:b] for a, b in itertools.pairwise(st)]
