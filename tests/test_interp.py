"""The interpreted engine (:mod:`csplab._interp`) against the compiled kernels, and the lazy
``@njit`` of :mod:`csplab._jit`."""

import importlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from csplab import ExampleModel, Problem, _interp, _jit, catalog, load_example
from csplab.catalog import Propagator, unpack
from csplab.engine.alg31 import run_alg31
from csplab.grids import from_example

ORDERS = ["scanline", "random", "min-entropy", "min-domain", "scan:yx"]
CHOICES = ["uniform", "weighted"]


@pytest.fixture
def engine(monkeypatch):
    def use(name):
        monkeypatch.setattr(_interp, "ENGINE", name)

    return use


def _both(engine, build, seed, **kw):
    """The same run with the kernels and interpreted, each on a freshly built problem."""
    out = []
    for name in ("kernels", "interp"):
        engine(name)
        out.append(run_alg31(build(), np.random.default_rng(seed), **kw))
    return out


def _same(a, b):
    assert a.status == b.status
    assert np.array_equal(a.grid, b.grid)
    assert np.array_equal(a.trace, b.trace)
    assert a.stats == b.stats  # queue pops, removals, fail cell: pop for pop


def _random_example(rng, K, shape):
    return ExampleModel(rng.integers(0, K, size=shape).astype(np.int32))


@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("choice", CHOICES)
def test_alg31_same_as_kernels_on_random_examples(engine, order, choice):
    rng = np.random.default_rng(7)
    statuses = set()
    for trial in range(6):
        E = _random_example(rng, int(rng.integers(3, 9)), (5, 4))
        w = rng.random(E.K) + 0.05
        shape = (int(rng.integers(4, 14)), int(rng.integers(4, 14)))

        def build(E=E, w=w, shape=shape):
            P = from_example(E, shape)
            return Problem(P.shape, P.domains, P.relations, P.arcs, weights=w)

        a, b = _both(engine, build, trial, order=order, choice=choice)
        _same(a, b)
        statuses.add(a.status)
    assert statuses & {"solved", "failed"}


@pytest.mark.parametrize("order", ["scanline", "min-entropy"])
def test_alg31_same_with_and_without_the_nibble_table(engine, monkeypatch, order):
    """The kernels' revision by slice table (K <= NIBBLE_MAX_K: 8-label slices while the
    table fits in BYTE_TABLE_MAX, else 4-label ones) and label by label (larger K) give the
    interpreted twin's run: grid, trace, pops and removals."""
    rng = np.random.default_rng(11)
    cases = [(load_example("city"), (6, 6, 4), {"boundary": "auto"})]  # K = 119: two words
    for _ in range(4):
        cases.append((_random_example(rng, int(rng.integers(3, 12)), (6, 5)), (11, 9), {}))
    settings = [(catalog.NIBBLE_MAX_K, catalog.BYTE_TABLE_MAX, 256),
                (catalog.NIBBLE_MAX_K, 0, 16), (0, catalog.BYTE_TABLE_MAX, 0)]  # fmt: skip
    for E, shape, kw in cases:
        for seed in range(2):
            runs = []
            for limit, table, rows in settings:
                monkeypatch.setattr(catalog, "NIBBLE_MAX_K", limit)
                monkeypatch.setattr(catalog, "BYTE_TABLE_MAX", table)
                P = from_example(E, shape, **kw)
                nib = Propagator(P).c.nib
                assert (nib.shape[0] > 0) == (limit > 0) and (rows == 0 or nib.shape[1] == rows)
                runs.append(_both(engine, lambda P=P: P, seed, order=order, choice="weighted"))
            for a, b in runs:
                _same(a, b)
                _same(a, runs[0][0])


def test_propagate_stops_at_a_wipe_out_of_cell_0(engine):
    """A wipe-out ends the propagation at once, also when the wiped cell is cell 0 and more
    cells wait in the queue: the twins pop the same cells (a chain 0 - 1 - 2 of equal
    labels; cell 1 changed to label 1 empties cell 0, fixed to label 0, before cell 2 is
    looked at)."""
    EQ = np.eye(2, dtype=bool)[None]
    dom = np.array([[True, False], [False, True], [True, True]])
    P = Problem((3,), dom, EQ, [[0, 1, 0], [1, 2, 0]])
    got = []
    for name in ("kernels", "interp"):
        engine(name)
        eng = Propagator(P, domains=dom, propagate_initial=False)
        ok = eng.propagate(np.array([1, 2]))
        got.append((ok, eng.wiped, eng.stats.copy()))
    (ok1, w1, s1), (ok2, w2, s2) = got
    assert not ok1 and not ok2 and w1 == w2 == 0
    assert np.array_equal(s1, s2)


@pytest.mark.parametrize("order", ["min-entropy", "scanline"])
def test_alg31_same_as_kernels_with_labels_of_weight_0(engine, order):
    """Weights may be 0 or tiny: a cell whose labels left weigh (almost) nothing is keyed by
    the entropy of its domain computed afresh, or by its label count when they weigh 0 (the
    weighted entropy's fallbacks), the same in both twins, draw for draw."""
    rng = np.random.default_rng(11)
    for trial in range(16):
        E = _random_example(rng, int(rng.integers(3, 7)), (5, 4))
        w = rng.random(E.K) * (rng.random(E.K) < (0.5 if trial < 8 else 0.2))
        w[int(rng.integers(E.K))] = 0.0
        w[int(rng.integers(E.K))] = 1e-13  # below the memo's 1e-12: entropy from the domain
        shape = (int(rng.integers(4, 10)), int(rng.integers(4, 10)))

        def build(E=E, w=w, shape=shape):
            P = from_example(E, shape)
            return Problem(P.shape, P.domains, P.relations, P.arcs, weights=w)

        a, b = _both(engine, build, trial, order=order, choice="weighted")
        _same(a, b)


@pytest.mark.parametrize(
    "name,shape,kw",
    [
        ("city", (6, 6, 4), {"boundary": "auto"}),  # K = 119: two words per domain
        ("castle", (5, 7, 4), {}),
        ("fig3_10", (12, 12), {"periodic": True}),
        ("loops", (30, 30), {}),
    ],
)
def test_alg31_same_as_kernels_on_builtins(engine, name, shape, kw):
    E = load_example(name)
    for order in ("scanline", "min-entropy"):
        for seed in range(3):
            a, b = _both(engine, lambda: from_example(E, shape, **kw), seed,
                         order=order, choice="weighted")  # fmt: skip
            _same(a, b)


@pytest.mark.parametrize(
    "name,shape,kw",
    [("fig3_10", (9, 11), {}),  # one word per domain: the kernels' _propagate_w1
     ("city", (6, 6, 4), {"boundary": "auto"})],  # K = 119, two words: _propagate's loops
)  # fmt: skip
def test_propagate_same_as_kernels_on_random_catalogs(engine, name, shape, kw):
    rng = np.random.default_rng(3)
    E = load_example(name)
    P = from_example(E, shape, **kw)
    wipes = 0
    C0 = Propagator(P).catalog()
    for _ in range(40):
        changed = rng.choice(P.n, size=int(rng.integers(1, 12)), replace=False)
        C = C0.copy()
        C[changed] &= rng.random((changed.size, P.K)) < rng.uniform(0.05, 0.9)
        got = []
        for name in ("kernels", "interp"):
            engine(name)
            eng = Propagator(P, domains=C, propagate_initial=False)
            ok = eng.propagate(changed)
            got.append((ok, eng.catalog(), eng.stats.copy(), eng.prev.copy()))
        (ok1, C1, s1, p1), (ok2, C2, s2, p2) = got
        assert ok1 == ok2 and np.array_equal(s1, s2) and np.array_equal(p1, p2)
        wipes += not ok1
        if ok1:
            assert np.array_equal(C1, C2)
    assert 0 < wipes < 40


def test_int_bitsets_round_trip():
    rng = np.random.default_rng(0)
    C = rng.random((7, 130)) < 0.5
    from csplab.catalog import pack

    bits = pack(C)
    ints = _interp._ints(bits)
    assert all(i == sum(1 << int(b) for b in np.flatnonzero(C[r])) for r, i in enumerate(ints))
    out = np.zeros_like(bits)
    _interp._store(ints, out)
    assert np.array_equal(unpack(out, 130), C)


def test_auto_rule(monkeypatch):
    monkeypatch.setattr(_interp, "ENGINE", "auto")
    monkeypatch.setattr(_interp, "_SPENT", [0.0])
    monkeypatch.setattr(_jit, "compiled", lambda module: False)
    loads = []
    monkeypatch.setattr(_jit, "load", loads.append)
    assert _interp.use_interp(100, 10) and not _interp.use_interp(10_000, 10)
    assert loads == []
    _interp._SPENT[0] = _interp.BUDGET + 0.1  # much interpreted work: load the kernels
    assert not _interp.use_interp(100, 10) and loads == ["csplab._kernels"]
    monkeypatch.setattr(_jit, "compiled", lambda module: True)
    assert not _interp.use_interp(100, 10)  # numba is loaded: the kernels are faster


def test_interpreted_work_is_counted(monkeypatch):
    monkeypatch.setattr(_interp, "ENGINE", "interp")
    monkeypatch.setattr(_interp, "_SPENT", [0.0])
    P = from_example(load_example("fig3_10"), (16, 16))
    run_alg31(P, np.random.default_rng(0))
    assert _interp._SPENT[0] > 0


def test_lazy_njit_materializes_a_module_at_first_call(tmp_path, monkeypatch):
    src = textwrap.dedent(
        """
        import numpy as np
        from csplab._jit import njit, prange

        @njit(cache=False)
        def inner(x):
            return x + 1

        @njit(cache=False)
        def outer(a):
            s = 0
            for i in prange(a.shape[0]):
                s += inner(a[i])
            return s
        """
    )
    (tmp_path / "lazymod.py").write_text(src)
    monkeypatch.syspath_prepend(str(tmp_path))
    mod = importlib.import_module("lazymod")
    assert isinstance(mod.outer, _jit.Kernel) and not _jit.compiled("lazymod")
    assert mod.outer.py_func is not None and mod.inner.py_func(1) == 2
    seen = []
    _jit.on_load(seen.append)
    assert mod.outer(np.arange(4)) == 10  # compiles both: outer calls inner as a dispatcher
    assert _jit.compiled("lazymod") and seen[-1] == "lazymod"
    assert not isinstance(mod.outer, _jit.Kernel) and not isinstance(mod.inner, _jit.Kernel)
    import numba

    assert mod.prange is numba.prange


def test_import_and_small_solve_do_not_load_numba():
    code = (
        "import sys, numpy as np, csplab\n"
        "P = csplab.from_example(csplab.load_example('fig3_10'), (20, 20))\n"
        "r = csplab.solve(P, 'catalog', rng=1)\n"
        "print(r.status, 'numba' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.split() == ["solved", "False"], out.stderr
