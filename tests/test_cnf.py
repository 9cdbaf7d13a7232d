import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel
from csplab.catalog import propagate
from csplab.cnf import AMO_ENCODINGS, amo_clauses, encode
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.testing.strategies import csp_problems

pysat = pytest.importorskip("pysat")
from pysat.solvers import Solver  # noqa: E402


def _catalog_after_up(enc, C0):
    """Unit propagation on the encoding with the pairs removed from C0 assumed false."""
    var = enc.var
    removed = (var > 0) & ~C0
    assumptions = (-var[removed]).tolist()
    # pysat's propagate() does not report what level-0 units imply: assume units instead
    clauses = [c for c in enc.clauses() if len(c) != 1]
    assumptions += [c[0] for c in enc.clauses() if len(c) == 1]
    ok, lits = True, []
    if enc.nvars:  # (pysat reports a conflict for an empty formula)
        with Solver(name="cadical195", bootstrap_with=clauses) as S:
            ok, lits = S.propagate(assumptions=assumptions)
    if not ok:
        return None
    neg = np.zeros(enc.nvars + 1, dtype=bool)
    lits = np.asarray(lits, dtype=np.int64)
    neg[-lits[lits < 0]] = True
    C = np.zeros(var.shape, dtype=bool)
    has = var > 0
    C[has] = ~neg[var[has]]
    C[enc.const >= 0, enc.const[enc.const >= 0]] = True
    return C


@given(csp_problems(max_side=3), st.integers(0, 2**31))
def test_unit_propagation_on_support_encoding_is_arc_consistency(P, seed):
    """Kasif 1990 / Gent 2002: UP on the support encoding = arc consistency, incl. wipe-outs."""
    enc = encode(P, prune=False)
    if not enc.ok:
        return
    rng = np.random.default_rng(seed)
    C0 = P.domains & (rng.random((P.n, P.K)) < 0.8)
    C0[enc.const >= 0] = P.domains[enc.const >= 0]  # constants cannot be removed
    C_ac, ok = propagate(P, C0)
    C_up = _catalog_after_up(enc, C0)
    assert (C_up is not None) == ok
    if ok:
        assert np.array_equal(C_up, C_ac)


@given(csp_problems(max_side=3))
def test_variables_only_for_the_arc_consistent_catalog(P):
    enc = encode(P)
    C, ok = propagate(P, P.domains)
    assert enc.ok == ok
    if ok:
        assert np.array_equal(enc.catalog, C)
        single = C.sum(axis=1) == 1
        assert np.array_equal(enc.var > 0, C & ~single[:, None])
        assert np.array_equal(enc.const >= 0, single)
        ids = enc.var[enc.var > 0]
        assert sorted(ids.tolist()) == list(range(1, enc.nx + 1))


@pytest.mark.parametrize("amo", [a for a in AMO_ENCODINGS if a != "lazy"])
def test_amo_templates_allow_exactly_the_single_labels(amo):
    # one cell with 5 labels: models of ALO + AMO are exactly the 5 one-hot assignments
    var = np.array([[1, 2, 3, 4, 5]], dtype=np.int32)
    lits, lens, top = amo_clauses(var, var > 0, amo, 5)
    starts = np.concatenate([[0], np.cumsum(lens)])
    clauses = [lits[a:b].tolist() for a, b in itertools.pairwise(starts)]
    with Solver(name="cadical195", bootstrap_with=[[1, 2, 3, 4, 5], *clauses]) as S:
        seen = set()
        while S.solve():
            m = S.get_model()
            xs = tuple(v for v in m[:5] if v > 0)
            seen.add(xs)
            S.add_clause([-v for v in m[:5] if v > 0] + [v for v in range(1, 6) if v not in xs])
    assert seen == {(i,) for i in range(1, 6)}
    assert top >= 5


def test_clause_layout_and_literals():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (2, 2))
    enc = encode(P)
    assert enc.nclauses == enc.starts.size - 1 == len(enc.clauses())
    assert enc.stats["support_clauses"] == 16 and enc.stats["alo_clauses"] == 4
    assert enc.literal(0, 0) == 1
    fwd = encode(P, supports="forward")
    assert fwd.stats["support_clauses"] == 8
    d = encode(P, encoding="direct")
    assert all(len(c) == 2 for c in d.clauses()[: d.stats["conflict_clauses"]])
    Q = from_example(ExampleModel([[0, 1], [1, 0]]), (2, 2), fixed={(0, 0): 1})
    e = encode(Q)
    assert e.nx == 0 and e.literal(0, 1) is True and e.literal(0, 0) is False


def test_wipe_out_gives_the_empty_clause():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 0, (0, 1): 0})
    enc = encode(P)
    assert not enc.ok and enc.wiped >= 0


def test_bad_arguments():
    P = from_example(ExampleModel([0, 1]), (3,))
    for kw in ({"encoding": "log"}, {"supports": "sideways"}, {"amo": "magic"}):
        with pytest.raises(InputError):
            encode(P, **kw)


def test_fixed_cell_that_forces_the_board_leaves_no_variables():
    from csplab import ExampleModel
    from csplab.grids import from_example

    P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 1})
    enc = encode(P, amo="pairwise")
    assert enc.ok and enc.nx == 0 and enc.nclauses == 0  # one label forces the checkerboard
    assert P.is_solution(enc.const.reshape(P.shape))


def _independent_clauses(P, enc, supports, amo):
    """The clauses of the support encoding, built cell by cell in plain Python from the
    problem's relations and the encoding's variable map (shares no code with encode)."""
    var, C = enc.var, enc.catalog
    single = C.sum(axis=1) == 1
    out = []
    for a, b, r in P.arcs.tolist():
        if a == b:
            continue  # a loop restricts the cell's own labels: arc consistency did that
        dirs = [(a, b, P.relations[r])]
        if supports == "both":
            dirs.append((b, a, P.relations[r].T))
        for v, u, T in dirs:
            if single[v]:
                continue
            for lab in np.flatnonzero(C[v]).tolist():
                sup = [c for c in np.flatnonzero(C[u]).tolist() if T[lab, c]]
                if len(sup) == int(C[u].sum()):
                    continue  # covered by u's at-least-one clause (or u is a constant)
                out.append((-int(var[v, lab]), *sorted(int(var[u, c]) for c in sup)))
    alo = [tuple(int(x) for x in var[v][var[v] > 0]) for v in range(P.n) if not single[v]]
    return out, alo


@given(csp_problems(max_side=3), st.sampled_from(["both", "forward"]),
       st.sampled_from(["lazy", "seqcounter", "pairwise"]))  # fmt: skip
def test_flat_layout_holds_supports_then_alo_then_amo(P, supports, amo):
    """The flat arrays written in place: support clauses (as a multiset, equal to an
    independent construction), then one at-least-one clause per open cell in cell order,
    then the at-most-one clauses of ``amo_clauses``, with ``starts`` matching."""
    enc = encode(P, supports=supports, amo=amo)
    if not enc.ok:
        return
    assert enc.starts[0] == 0 and enc.starts[-1] == enc.lits.size
    assert np.all(np.diff(enc.starts) >= 1)
    cls = [tuple(c) for c in enc.clauses()]
    ns, na = enc.stats["support_clauses"], enc.stats["alo_clauses"]
    sup, alo = _independent_clauses(P, enc, supports, amo)
    got = sorted((c[0], *sorted(c[1:])) for c in cls[:ns])
    assert got == sorted(sup)
    assert cls[ns : ns + na] == alo
    rest = cls[ns + na :]
    if amo == "lazy":
        assert rest == [] and enc.nvars == enc.nx
    else:
        lits, lens, top = amo_clauses(enc.var, enc.var > 0, amo, enc.nx)
        st_ = np.concatenate([[0], np.cumsum(lens)])
        assert rest == [tuple(lits[a:b].tolist()) for a, b in itertools.pairwise(st_)]
        assert enc.nvars == top
