import numpy as np

from csplab import solve
from csplab.grids import from_example
from csplab.testing.synthetic import box_town


def test_box_town_labels_supports_and_solvability():
    for m in (1, 2, 4):
        E = box_town(m, rng=m)
        assert E.ndim == 3 and E.K == 2 + 27 * m
        assert (E.counts() > 0).all()
        T = E.transitions()
        assert 1.2 < T.sum(axis=2).mean() < 2.0  # small supports, as in tiled models
    P = from_example(box_town(1, rng=0), (10, 10, 6), boundary="auto")
    r = solve(P, "catalog", rng=0)
    assert r.status in ("solved", "failed")
    assert np.array_equal(box_town(2, rng=5).labels, box_town(2, rng=5).labels)
