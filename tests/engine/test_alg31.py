"""Alg. 3.1 orders."""


def test_min_domain_is_mrv_whatever_the_choice():
    """``min-domain`` (WFC's MRV) keys cells by their label count: with a uniform choice it
    is exactly ``min-entropy``; with a weighted choice it still ignores the weights."""
    import numpy as np

    from csplab import solve
    from csplab.examples import load_example
    from csplab.grids import from_example

    P = from_example(load_example("castle"), (10, 10, 6), boundary="auto")
    for seed in range(3):
        a = solve(P, "catalog", rng=seed, order="min-domain")
        b = solve(P, "catalog", rng=seed, order="min-entropy")
        assert a.status == b.status and np.array_equal(a.grid, b.grid)
    W = P._replace(weights=np.linspace(1, 50, P.K))
    r = solve(W, "catalog", rng=0, order="min-domain", choice="weighted")
    assert r.stats["order"] == "min-domain" and (r.status != "solved" or W.is_solution(r.grid))
