import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel
from csplab.catalog import (
    Propagator,
    assign,
    initial_catalog,
    nibble_supports,
    pack,
    propagate,
    propagate_reference,
    unpack,
)
from csplab.grids import from_example
from csplab.testing.brute import exact_catalog
from csplab.testing.strategies import example_models, problems, random_problems


@given(st.integers(1, 200), st.integers(1, 10), st.integers(0, 2**31))
def test_pack_roundtrip(K, n, seed):
    C = np.random.default_rng(seed).random((n, K)) < 0.5
    assert np.array_equal(unpack(pack(C), K), C)


def _random_catalog(P, seed, p=0.8):
    rng = np.random.default_rng(seed)
    return P.domains & (rng.random((P.n, P.K)) < p)


@given(random_problems(max_side=4, max_labels=6), st.integers(0, 2**31))
def test_kernel_reaches_reference_fixpoint(P, seed):
    C0 = _random_catalog(P, seed)
    a, oka = propagate(P, C0)
    b, okb = propagate_reference(P, C0)
    assert oka == okb
    if oka:
        assert np.array_equal(a, b)


@given(problems(max_side=3, max_labels=4), st.integers(0, 2**31))
def test_kernel_reference_on_example_problems(P, seed):
    C0 = _random_catalog(P, seed, 0.9)
    a, oka = propagate(P, C0)
    b, okb = propagate_reference(P, C0)
    assert oka == okb and (not oka or np.array_equal(a, b))


def test_propagate_does_not_mutate_and_changed_subset_matches_full():
    E = ExampleModel([[0, 0, 0, 0], [0, 1, 2, 0], [0, 3, 4, 0], [0, 0, 0, 0]])
    P = from_example(E, (6, 6))
    C, ok = propagate(P, initial_catalog(P))
    assert ok
    before = C.copy()
    C2, ok2 = assign(P, C, P.cell((2, 2)), 1)
    assert np.array_equal(C, before) and ok2
    C3 = C.copy()
    C3[P.cell((2, 2))] = False
    C3[P.cell((2, 2)), 1] = True
    full, _ = propagate(P, C3)
    assert np.array_equal(C2, full)


@given(problems(max_side=3, max_labels=3, fixed=True, masks=True), st.integers(0, 2**31))
def test_theorem_3_3_2_never_removes_a_label_of_some_solution(P, seed):
    """C(x, b) = 0  =>  C*(x, b) = 0, for a random partial assignment (brute force)."""
    if P.n > 9:
        return
    rng = np.random.default_rng(seed)
    partial = np.full(P.n, -1)
    for c in rng.choice(P.n, size=min(2, P.n), replace=False):
        allowed = np.flatnonzero(P.domains[c])
        if allowed.size:
            partial[c] = rng.choice(allowed)
    C0 = P.domains.copy()
    for c in np.flatnonzero(partial >= 0):
        C0[c] = False
        C0[c, partial[c]] = True
    C, ok = propagate(P, C0)
    Cstar = exact_catalog(P, partial)
    if not ok:
        assert not Cstar.any()
    else:
        assert not np.any(Cstar & ~C)


@given(example_models(ndim=1, max_side=6, max_labels=5), st.integers(2, 7), st.integers(0, 2**31))
def test_1d_catalog_equals_exact_catalog(E, n, seed):
    """Thesis remark after Theorem 3.3.5: in 1D, C = C*."""
    P = from_example(E, (n,))
    rng = np.random.default_rng(seed)
    partial = np.full(n, -1)
    eng = Propagator(P)
    for c in rng.permutation(n)[: rng.integers(0, n)]:
        dom = eng.domain(int(c))
        if dom.size == 0:
            break
        b = int(rng.choice(dom))
        if not eng.assign(int(c), b):
            break
        partial[c] = b
    else:
        C = eng.catalog() if eng.ok else np.zeros((P.n, P.K), dtype=bool)
        Cstar = exact_catalog(P, partial)
        if eng.ok and Cstar.any():
            assert np.array_equal(C, Cstar)
        else:
            assert not Cstar.any()


def test_propagator_save_load_copy():
    E = ExampleModel([[0, 1], [1, 0]])
    P = from_example(E, (3, 3))
    eng = Propagator(P)
    st_ = eng.save()
    assert eng.assign(0, 0)
    assert eng.sizes().tolist() == [1] * 9
    eng.load(st_)
    assert eng.sizes().tolist() == [2] * 9
    other = eng.copy()
    assert other.sizes().tolist() == [2] * 9  # the copy starts in the same state
    # the checkerboard (0 and 1 alternate on both axes) has exactly two 3x3 models, so
    # fixing one cell forces all nine: label (x + y) % 2 for a 0 at the origin
    assert other.assign(0, 0) and other.ok
    want = [[False, True] if (x + y) % 2 else [True, False] for x in range(3) for y in range(3)]
    assert other.catalog().tolist() == want
    assert eng.sizes().tolist() == [2] * 9  # ... and the original did not move
    third = eng.copy()
    assert eng.assign(0, 1) and eng.sizes().tolist() == [1] * 9
    assert third.sizes().tolist() == [2] * 9 and other.catalog().tolist() == want
    fourth = eng.copy()  # a copy of an engine with assignments keeps them
    eng.load(st_)
    assert eng.sizes().tolist() == [2] * 9
    assert fourth.catalog().tolist() == [w[::-1] for w in want]
    assert eng.restrict(4, [False, True])
    assert eng.catalog()[0].tolist() == [False, True]
    assert not eng.assign(0, 0) and not eng.ok


@given(random_problems(max_side=4, max_labels=9, density=(0.3, 0.95)), st.integers(0, 2**31))
def test_incremental_restrictions_match_reference(P, seed):
    """Random restriction sequences on one engine (delta revisions) = fresh reference runs."""
    rng = np.random.default_rng(seed)
    eng = Propagator(P)
    C = P.domains.copy()
    C, ok = propagate_reference(P, C)
    assert ok == eng.ok
    for _ in range(6):
        if not ok:
            break
        cell = int(rng.integers(P.n))
        allowed = rng.random(P.K) < 0.7
        ok_fast = eng.restrict(cell, allowed)
        C[cell] &= allowed
        C, ok = propagate_reference(P, C, [cell]) if C[cell].any() else (C, False)
        assert ok_fast == ok
        if ok:
            assert np.array_equal(eng.catalog(), C)
        if ok:  # a trial assignment (it may wipe out) and back
            state = eng.save()
            eng.assign(cell, int(eng.domain(cell)[0]))
            eng.load(state)
            assert eng.ok and np.array_equal(eng.catalog(), C)


@pytest.mark.parametrize(
    "name,shape,kw",
    [("fig3_10", (37, 23), {"periodic": True}), ("city", (9, 7, 5), {}),
     ("line", (1, 5), {"periodic": True})],  # the last one has self-arcs
)  # fmt: skip
def test_arc_rows_by_counting_sort_equal_the_numpy_rows(monkeypatch, name, shape, kw):
    """``_kernels.arc_csr`` (large problems) builds the rows the stable sort builds."""
    from csplab import _interp
    from csplab.catalog import _Compiled
    from csplab.examples import load_example

    P = from_example(load_example(name), shape, **kw)
    got = []
    for engine in ("interp", "kernels"):
        monkeypatch.setattr(_interp, "ENGINE", engine)
        c = _Compiled(P)
        got.append((c.ptr, c.nbr, c.sidx))
    for x, y in zip(*got, strict=True):
        assert x.dtype == y.dtype == np.int64 and np.array_equal(x, y)


@pytest.mark.parametrize("b", [4, 8])
@pytest.mark.parametrize("K", [1, 3, 4, 5, 64, 69, 130])
def test_nibble_table_ors_to_the_union_of_the_supports_of_a_domain(K, b):
    """OR of the table's rows for the b-label slices of D = the labels some label of D
    supports (computed on the unpacked relation), in every direction."""
    rng = np.random.default_rng(K)
    S = 4
    rel = rng.random((S, K, K)) < 0.08  # rel[s, a, b]: b supported by a across direction s
    W = (K + 63) // 64
    sup = pack(rel.reshape(S * K, K)).reshape(S, K, W)
    nib = nibble_supports(sup, b)
    assert nib.shape == ((K + b - 1) // b, 1 << b, S * W)
    per = 64 // b  # slices per word
    for _ in range(20):
        D = rng.random(K) < rng.uniform(0.0, 1.0)
        bits = pack(D.reshape(1, K))[0]
        got = np.zeros(S * W, dtype=np.uint64)
        for j in range(nib.shape[0]):
            got |= nib[j, (int(bits[j // per]) >> (b * (j % per))) & ((1 << b) - 1)]
        for s in range(S):
            want = rel[s][D].any(axis=0)
            assert np.array_equal(unpack(got[s * W : (s + 1) * W].reshape(1, W), K)[0], want)
