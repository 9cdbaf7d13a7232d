"""The 2007 paper's resemblance-weighted choice (Sec. 3.3, Eq. 2-6) and soft constraints by
Metropolis acceptance (Sec. 4.2)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import csplab
from csplab import ExampleModel, load_example
from csplab.engine.resemblance import Resemblance
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.soft import Energy, HeightField, Histogram, Region


def literal_L(E: np.ndarray, model: np.ndarray, v: tuple[int, int], cands, w: int = 1):
    """Eq. 2-5 written out: windows as sets of (offset, label), d(P, Q) = |P| - |P & Q|."""

    def window(M, p, assigned_only):
        out = set()
        for q in itertools.product(range(-w, w + 1), repeat=2):
            x, y = p[0] + q[0], p[1] + q[1]
            if 0 <= x < M.shape[0] and 0 <= y < M.shape[1] and (M[x, y] >= 0 or not assigned_only):
                out.add((q, int(M[x, y])))
        return out

    d = {}
    for k in cands:
        M = model.copy()
        M[v] = k
        P = window(M, v, True)
        d[k] = [len(P) - len(P & window(E, vp, False)) for vp in np.ndindex(E.shape)]
    d0 = min(min(x) for x in d.values())
    return [sum(1 for x in d[k] if x <= d0) for k in cands]


def test_weights_follow_equations_4_to_6():
    rng = np.random.default_rng(0)
    for _ in range(30):
        E = rng.integers(0, 3, size=(4, 5))
        ex = ExampleModel(E)
        R = Resemblance(ex, 2, 1)
        model = rng.integers(-1, 3, size=(5, 5))
        v = (int(rng.integers(5)), int(rng.integers(5)))
        model[v] = -1
        cands = np.flatnonzero(rng.random(ex.K) < 0.8)
        if cands.size < 2:
            continue
        around = np.full(9, -1)
        for i, q in enumerate(R.offsets):
            x, y = v[0] + q[0], v[1] + q[1]
            if 0 <= x < 5 and 0 <= y < 5:
                around[i] = model[x, y]
        assert R.weights(around, cands).tolist() == literal_L(E, model, v, cands)


def test_resemblance_choice_is_consistent_and_closer_to_the_example():
    from csplab.experiments.measures import pattern_distance

    E = load_example("loops")
    P = from_example(E, (24, 24))
    dist = {}
    for choice in ("uniform", "resemblance"):
        ds = []
        for seed in range(4):
            r = csplab.solve(P, "catalog", rng=seed, choice=choice, order="scan:yx", restarts=20)
            assert r.ok and P.is_solution(r.grid)
            ds.append(pattern_distance(r.grid, E.labels))
        dist[choice] = np.mean(ds)
    assert dist["resemblance"] < dist["uniform"]
    r = csplab.solve(P, "blocks", rng=1, choice="resemblance", block=6)
    assert r.ok and r.stats["choice"] == "resemblance"
    # the same seed repeats
    a = csplab.solve(P, "catalog", rng=5, choice="resemblance").grid
    assert np.array_equal(a, csplab.solve(P, "catalog", rng=5, choice="resemblance").grid)


def test_resemblance_needs_an_example():
    P = csplab.grids.grid((4, 4), np.ones((2, 2, 2), dtype=bool))
    with pytest.raises(InputError, match="needs a problem built from an example"):
        csplab.solve(P, "catalog", choice="resemblance")
    Q = from_example(load_example("line"), (6, 6))
    with pytest.raises(InputError, match="scan orders and random"):
        csplab.solve(Q, "catalog", choice="resemblance", order="min-entropy")


def test_energy_terms():
    g = np.array([[0, 1], [1, 1]])
    assert Histogram({1: 0.5})(g) == 1.0  # 3 ones, 1 zero: one cell to change
    assert Histogram({1: 0.5}, others=False)(g) == 1.0
    assert Region(np.array([[True, False], [False, False]]), [1])(g) == 1.0
    assert Region(np.array([[True, False], [False, False]]), [1], outside=True)(g) == 4.0
    h = np.zeros((2, 2, 3), dtype=int)
    h[0, 0, :2] = 1
    assert HeightField(np.full((2, 2), 1.0))(h) == 1 + 1 + 1 + 1
    assert Energy([Histogram({1: 0.5}, weight=2.0)])(g) == 2.0
    with pytest.raises(InputError):
        Energy([Histogram({1: 0.5})])(np.array([[-1, 0]]))


def test_metropolis_lowers_the_energy_and_keeps_consistency():
    E = load_example("loops")
    P = from_example(E, (24, 24))
    yy, xx = np.mgrid[0:24, 0:24]
    disk = np.hypot(xx - 11.5, yy - 11.5) < 8
    paths = [b for b in range(E.K) if E.names[b] != "empty"]
    en = Energy([Region(disk, paths, outside=True)])
    plain = csplab.solve(P, "blocks", rng=2, block=6, sweeps=6)
    soft = csplab.solve(P, "blocks", rng=2, block=6, sweeps=6, energy=en, temperature=2.0,
                        cooling=0.7)  # fmt: skip
    assert plain.ok and soft.ok and P.is_solution(soft.grid)
    tr = soft.stats["energies"]
    assert len(tr) == 7 and tr[-1] == soft.stats["energy"] == en(soft.grid)
    assert tr[-1] < tr[0] and en(soft.grid) < en(plain.grid)
    assert soft.stats["metropolis_rejected"] > 0
    with pytest.raises(InputError, match=r"csplab\.soft\.Energy"):
        csplab.solve(P, "blocks", energy="ring")
    with pytest.raises(InputError, match="workers=0"):
        csplab.solve(P, "blocks", energy=en, workers=1)
