"""Theorem 3.3.4 (Fig. 3.7): the planar 3-SAT reduction, verified on random formulas.

Fast form of the experiment in experiments/reduction_planar3sat.py: 32 formulas, half of
them unsatisfiable. For each: satisfiable (pysat on the CNF) <=> M_t completable (SAT on the
grid); a completion decodes to a satisfying assignment; every satisfying assignment encodes
to a completion with zero violations.
"""

import numpy as np
import pytest

from csplab.complexity import gadgets as G
from csplab.complexity.planar3sat import random_planar3sat
from csplab.complexity.reduction import reduce_planar3sat, verify_instance

CASES = [("unsat", 6 + i % 3, [8, 10, 12][i % 3], 100 + i) for i in range(16)]
CASES += [("near", 6 + i % 3, [8, 10, 12][i % 3], 200 + i) for i in range(8)]
CASES += [("random", 3 + i % 6, 1 + i % 8, 300 + i) for i in range(8)]


def _formula(mode, n, m, seed):
    return random_planar3sat(n, min(m, 2 * (n - 2)), rng=seed, signs=mode)


@pytest.mark.parametrize("mode,n,m,seed", CASES)
def test_reduction_verified(mode, n, m, seed):
    f = _formula(mode, n, m, seed)
    out = verify_instance(f, rng=seed, alg31=False)
    assert out["planar"]
    assert out["completable"] == out["sat"]
    assert out["sat"] == (mode != "unsat")
    assert out["decoded_ok"] is (True if out["sat"] else None)
    assert out["encoded_ok"] == out["models"]
    assert out["agree"]


def test_about_half_of_the_fast_set_is_unsatisfiable():
    assert sum(mode == "unsat" for mode, *_ in CASES) == len(CASES) // 2 and len(CASES) >= 30


def test_gadget_matrices():
    T = G.transitions()
    for d in range(2):  # TRUE and FALSE never touch, fill tiles itself
        assert not T[d, G.TRUE, G.FALSE] and not T[d, G.FALSE, G.TRUE]
        assert T[d, G.TRUE, G.TRUE] and T[d, G.FALSE, G.FALSE]
    # a cell next to an enclosure face can only hold TRUE, FALSE or a gate arrow
    arrows = {G.NOT_DN, G.NOT_UP, *G.ARROW_TOP, *G.ARROW_BOT}
    for side, (d, fwd) in {
        "L": (0, True),
        "R": (0, False),
        "D": (1, True),
        "U": (1, False),
    }.items():
        col = T[d, :, G.enclosure(side)] if fwd else T[d, G.enclosure(side), :]
        assert set(np.flatnonzero(col).tolist()) <= {G.TRUE, G.FALSE} | arrows
    # NOT swaps: TRUE below and FALSE above NOT-dn, the reverse for NOT-up
    assert T[1, G.TRUE, G.NOT_DN] and not T[1, G.FALSE, G.NOT_DN]
    assert T[1, G.NOT_DN, G.FALSE] and not T[1, G.NOT_DN, G.TRUE]
    assert T[1, G.FALSE, G.NOT_UP] and T[1, G.NOT_UP, G.TRUE] and not T[1, G.TRUE, G.NOT_UP]
    # OR arrows demand TRUE in their direction and accept either value elsewhere
    left, down, right = G.ARROW_TOP
    assert T[0, G.TRUE, left] and not T[0, G.FALSE, left]
    assert T[0, G.FALSE, down] and T[0, G.TRUE, down] and T[0, down, G.FALSE]
    assert T[1, G.TRUE, down] and not T[1, G.FALSE, down]
    assert T[0, right, G.TRUE] and not T[0, right, G.FALSE]
    assert np.flatnonzero(T[1, :, G.OR_TOP]).tolist() == list(G.ARROW_TOP)
    assert np.flatnonzero(T[1, G.OR_BOT, :]).tolist() == list(G.ARROW_BOT)


def test_free_cells_only_take_fill_or_arrows():
    from csplab.catalog import Propagator

    f = random_planar3sat(6, 8, rng=4, signs="near")
    red = reduce_planar3sat(f)
    C = Propagator(red.problem()).catalog().reshape(*red.shape, G.K)
    free = red.fixed < 0
    allowed = {G.TRUE, G.FALSE, G.NOT_DN, G.NOT_UP, *G.ARROW_TOP, *G.ARROW_BOT}
    used = set(np.flatnonzero(C[free].any(axis=0)).tolist())
    assert used <= allowed
    assert red.stats()["area"] == red.shape[0] * red.shape[1]


def test_encode_rejects_falsifying_assignments_and_checks_length():
    f = random_planar3sat(6, 8, rng=2, signs="unsat")
    red = reduce_planar3sat(f)
    assert red.encode(np.zeros(6, dtype=bool)) is None
    with pytest.raises(ValueError):
        red.encode([True, False])


def test_catalog_stays_nonempty_on_unsat_and_alg31_runs():
    f = random_planar3sat(7, 10, rng=9, signs="unsat")
    out = verify_instance(f, rng=9)
    assert out["catalog_nonempty"] is True  # arc consistency cannot see the contradiction
    assert out["alg31"] in ("failed", "unsat")


def test_pictures(tmp_path):
    from csplab.complexity.draw import label_sheet, save_reduction_png

    f = random_planar3sat(5, 6, rng=1)
    red = reduce_planar3sat(f)
    save_reduction_png(red.fixed, tmp_path / "m.png", scale=4)
    img = label_sheet(scale=12)
    assert (tmp_path / "m.png").stat().st_size > 0 and img.size[0] > 0


@pytest.mark.slow
def test_full_experiment_plan():
    """The 300 formulas of experiments/reduction_planar3sat.py (run with -m slow)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "experiments" / "reduction_planar3sat.py"
    spec = importlib.util.spec_from_file_location("reduction_planar3sat", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cases = mod.plan(300)
    assert sum(c[0] == "unsat" for c in cases) == 150
    for mode, n, m, seed in cases:
        out = verify_instance(random_planar3sat(n, m, rng=seed, signs=mode), rng=seed)
        assert out["agree"], (mode, n, m, seed)
