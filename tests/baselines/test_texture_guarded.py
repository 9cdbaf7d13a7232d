"""The texture baselines guarded (issue 32): Efros-Leung copies a best-matching position
(checked cell by cell against a brute-force search), its outputs break far fewer arcs than
random sampling with the same label histogram, pinned outputs for a seed, and graph-cut
seams of minimum cost (checked by enumerating every seam of a tiny case)."""

from __future__ import annotations

import hashlib
import itertools

import numpy as np
import pytest

from csplab.baselines.texture import _offsets, efros_leung, graphcut
from csplab.example import ExampleModel
from csplab.examples import load_example
from csplab.grids import from_example


def _el_distances(E: np.ndarray, out: np.ndarray, cell: tuple[int, ...], window: int):
    """Brute force: the Hamming distance of every example position's causal neighbourhood
    to the output's at ``cell`` (cells outside the example count as different), and
    whether any neighbour of ``cell`` was known."""
    off = [tuple(o) for o in _offsets(E.ndim, window).tolist()]
    known = {}
    for o in off:
        q = tuple(c + d for c, d in zip(cell, o, strict=True))
        if all(0 <= x < s for x, s in zip(q, out.shape, strict=True)):
            known[o] = int(out[q])
    dist = {}
    for p in itertools.product(*(range(s) for s in E.shape)):
        d = 0
        for o, lab in known.items():
            r = tuple(a + b for a, b in zip(p, o, strict=True))
            inside = all(0 <= x < s for x, s in zip(r, E.shape, strict=True))
            d += (not inside) or int(E[r]) != lab
        dist[p] = d
    return dist, bool(known)


@pytest.mark.parametrize(("window", "eps"), [(3, 0.0), (5, 0.0), (3, 0.5)])
def test_each_cell_copies_a_position_within_1_plus_eps_of_the_best(window, eps) -> None:
    """Efros & Leung: a cell takes the label of an example position whose neighbourhood is
    within ``(1 + eps)`` of the smallest distance (cells are written once, in scan order,
    so the final output shows what each cell saw)."""
    ex = load_example("fig3_10")
    E = np.asarray(ex.labels)
    for seed in range(2):
        out = efros_leung(ex, (9, 9), window=window, eps=eps, rng=seed)
        for cell in itertools.product(range(9), range(9)):
            dist, any_known = _el_distances(E, out, cell, window)
            if not any_known:
                continue  # the first cell: any position
            best = min(dist.values())
            ok = {int(E[p]) for p, d in dist.items() if d <= best * (1 + eps)}
            assert int(out[cell]) in ok, (seed, cell, best)


@pytest.mark.parametrize("window", [3, 5])
def test_breaks_far_fewer_arcs_than_random_sampling(window) -> None:
    """On a structured example, Efros-Leung's output breaks far fewer adjacency arcs than
    its own cells shuffled (random sampling with exactly the same label histogram)."""
    E = load_example("fig3_10")
    P = from_example(E, (24, 24))
    for seed in range(3):
        g = efros_leung(E, (24, 24), window=window, rng=seed)
        shuffled = np.random.default_rng(seed).permutation(g.reshape(-1)).reshape(g.shape)
        assert np.array_equal(np.bincount(g.ravel()), np.bincount(shuffled.ravel()))
        ours, rand = len(P.violations(g)), len(P.violations(shuffled))
        assert ours < 0.3 * rand, (seed, ours, rand)


def test_pinned_outputs_for_a_seed() -> None:
    """Same seed, same bytes (the digests of these outputs at the time of writing: a change
    of the sampling shows here first); another seed, other bytes."""
    E = load_example("fig3_10")
    el = efros_leung(E, (12, 12), window=3, rng=1)
    assert np.array_equal(el, efros_leung(E, (12, 12), window=3, rng=np.random.default_rng(1)))
    assert hashlib.sha256(el.tobytes()).hexdigest()[:16] == "12534482930927dd"
    assert not np.array_equal(el, efros_leung(E, (12, 12), window=3, rng=2))
    pytest.importorskip("maxflow")
    gc = graphcut(E, (14, 14), patch=4, overlap=2, rng=0)
    assert hashlib.sha256(gc.tobytes()).hexdigest()[:16] == "e16a8eb568fd7727"


def _seam_cost(mask: np.ndarray, diff: np.ndarray) -> float:
    """What the docstring says a seam costs: for neighbours ``s, t`` on different sides,
    ``[old(s) != new(s)] + [old(t) != new(t)]``."""
    c = 0.0
    for axis in range(mask.ndim):
        a = [slice(None)] * mask.ndim
        b = [slice(None)] * mask.ndim
        a[axis], b[axis] = slice(0, -1), slice(1, None)
        cut = mask[tuple(a)] != mask[tuple(b)]
        c += float(((diff[tuple(a)] + diff[tuple(b)]) * cut).sum())
    return c


@pytest.mark.parametrize("seed", range(4))
def test_graphcut_seam_is_a_minimum_cut_by_brute_force(seed) -> None:
    """Two patches of a random 8x8 example on a 4x10 output (patch 8, overlap 3): the second
    patch covers output columns 5-9; column 5 is written with written cells left of it (it
    keeps the old labels), columns 8-9 are unwritten (they take the new ones) and the seam
    runs through columns 6-7. Its cost is the least of all 2^8 seams there."""
    pytest.importorskip("maxflow")
    E = np.random.default_rng(seed).integers(0, 3, (8, 8))
    out = graphcut(ExampleModel(E), (4, 10), patch=8, overlap=3, rng=seed)
    # the example has one 8x8 block: the first patch is E[:4, :8], the second E[:4, :5]
    old = E[:4, 5:8]
    new = E[:4, :5]
    assert np.array_equal(out[:, :5], E[:4, :5])
    assert np.array_equal(out[:, 8:], new[:, 3:])
    assert np.array_equal(out[:, 5], old[:, 0])
    diff = np.zeros((4, 5))
    diff[:, :3] = old != new[:, :3]
    diff[:, 3:] = 1.0  # unwritten cells: old is "-1", never a label
    free = [(i, j) for i in range(4) for j in (1, 2)]

    def mask_of(bits: tuple[int, ...]) -> np.ndarray:
        m = np.zeros((4, 5), dtype=bool)
        m[:, 3:] = True
        for (i, j), b in zip(free, bits, strict=True):
            m[i, j] = bool(b)
        return m

    costs = {bits: _seam_cost(mask_of(bits), diff) for bits in itertools.product((0, 1), repeat=8)}
    best = min(costs.values())
    # seams that give the output (cells where old == new may be on either side)
    got = out[:, 6:8]
    fits = [
        c
        for bits, c in costs.items()
        if all(
            got[i, j - 1] == (new[i, j] if b else old[i, j])
            for (i, j), b in zip(free, bits, strict=True)
        )
    ]
    assert fits and min(fits) == pytest.approx(best)
