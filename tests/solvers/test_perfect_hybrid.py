import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, grids, solve
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.testing.brute import count
from csplab.testing.strategies import csp_problems

pytest.importorskip("pysat")

# a fallible example found by csplab.exact: Alg. 3.1 fails on it at 8x8 for every seed tried
FALLIBLE = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])


@given(csp_problems(), st.sampled_from(["perfect", "hybrid"]),
       st.sampled_from(["scanline", "random"]), st.integers(0, 2**31))  # fmt: skip
def test_never_fail_and_agree_with_brute_force(P, name, order, seed):
    r = solve(P, name, rng=seed, order=order)
    assert r.status in ("solved", "unsat")
    assert (r.status == "solved") == (count(P) > 0)


def test_succeed_where_alg31_fails():
    P = from_example(FALLIBLE, (8, 8))
    fails = sum(solve(P, "catalog", rng=s).status == "failed" for s in range(10))
    assert fails == 10
    for s in range(10):
        h = solve(P, "hybrid", rng=s)
        assert h.status == "solved" and h.stats["repairs"] >= 1 and h.stats["sat_calls"] >= 2
        p = solve(P, "perfect", rng=s, choice="weighted")
        assert p.status == "solved"
    # perfect met labels of C outside C* and rejected them
    assert sum(solve(P, "perfect", rng=s).stats["rejected"] for s in range(5)) > 0


def test_hybrid_uses_no_sat_when_alg31_succeeds():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (6, 6))
    r = solve(P, "hybrid", rng=0)
    assert r.status == "solved" and r.stats["sat_calls"] == 0 and "sat" not in r.stats


def test_unsat_proofs_and_options():
    odd = grids.grid((5,), [[[False, True], [True, False]]], periodic=True)
    for name in ("perfect", "hybrid", "perfect:glucose4", "hybrid:minisat22"):
        r = solve(odd, name, rng=0)
        assert r.status == "unsat" and r.stats["proof"].startswith("refutation by")
    P = from_example(FALLIBLE, (4, 4))
    with pytest.raises(InputError):
        solve(P, "perfect", rng=0, order="min-entropy")
    with pytest.raises(InputError):
        solve(P, "hybrid", rng=0, zz=1)
    assert solve(P, "hybrid", rng=0, order="min-entropy").status == "solved"
    big = from_example(FALLIBLE, (40, 40))
    r = solve(big, "perfect", rng=0, time_limit=0.3)
    assert r.status in ("timeout", "solved") and r.time_s < 1.3


def _perfect_distribution(P):
    """Exact output distribution of Alg. 3.1 drawing uniformly from C* (scanline)."""
    import numpy as np

    from csplab.testing.brute import solutions

    S = np.array([g.reshape(-1) for g in solutions(P)])
    probs = []
    for g in S:
        p, mask = 1.0, np.ones(len(S), dtype=bool)
        for t in range(P.n):
            p /= len(set(S[mask, t].tolist()))  # |C*(p_t)| given the prefix
            mask &= S[:, t] == g[t]
        probs.append(p)
    return S, np.array(probs)


def test_hybrid_samples_the_same_distribution_as_perfect():
    """A doomed draw of Alg. 3.1 is exactly what `perfect` rejects, so redrawing it from C*
    (hybrid) gives each step a uniform label of C*: both match the exact distribution."""
    import numpy as np

    P = from_example(FALLIBLE, (2, 2))  # 17 solutions; Alg. 3.1 fails 32% of runs
    S, probs = _perfect_distribution(P)
    assert len(S) == 17 and abs(probs.sum() - 1) < 1e-9
    N = 600
    for name in ("hybrid", "perfect"):
        counts = {g.astype(np.int32).tobytes(): 0 for g in S}
        for seed in range(N):
            counts[solve(P, name, rng=seed).grid.reshape(-1).tobytes()] += 1
        obs = np.array(list(counts.values()))
        chi2 = float(((obs - N * probs) ** 2 / (N * probs)).sum())
        assert chi2 < 39.25, (name, chi2)  # chi-square, 16 degrees of freedom, alpha = 0.001
