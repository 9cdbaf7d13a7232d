import networkx as nx
import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from csplab.experiments.measures import (
    components,
    label_counts,
    objects,
    pack_hashes,
    pattern_counts,
    pattern_hashes,
    unpack_hashes,
)


@st.composite
def masks(draw):
    shape = tuple(draw(st.integers(1, 7)) for _ in range(draw(st.integers(1, 3))))
    bits = draw(st.lists(st.booleans(), min_size=int(np.prod(shape)), max_size=int(np.prod(shape))))
    return np.array(bits, dtype=bool).reshape(shape)


@given(masks())
def test_components_match_networkx(m):
    roots = components(m)
    G = nx.grid_graph(dim=list(reversed(m.shape)))  # nodes are coordinate tuples (ints in 1D)
    G = G.subgraph([c for c in G.nodes if m[c]])
    tup = (lambda c: c) if m.ndim > 1 else (lambda c: (c,))
    want = sorted(sorted(tup(c) for c in comp) for comp in nx.connected_components(G))
    got: dict[int, list] = {}
    for c in zip(*np.nonzero(m), strict=True):
        got.setdefault(int(roots[c]), []).append(tuple(int(i) for i in c))
    assert sorted(sorted(v) for v in got.values()) == want
    assert np.all((roots >= 0) == m)


def test_components_follow_a_long_snake():
    m = np.zeros((41, 41), dtype=bool)
    m[::2, :] = True
    m[1::4, -1] = True
    m[3::4, 0] = True
    assert len(set(components(m)[m].tolist())) == 1


def test_objects_on_a_rectangle():
    g = np.zeros((10, 8), dtype=int)
    g[2:7, 3:5] = 3
    g[9, 0] = 1
    o = objects(g, [0])
    assert o == {"objects": 2, "largest_object": 10, "largest_extent": [5, 2],
                 "nonempty_fraction": 11 / 80}  # fmt: skip
    assert objects(np.zeros((3, 3), int), [0])["largest_object"] == 0


@given(st.integers(0, 2**32), st.integers(2, 4), st.sampled_from([(5, 6), (4, 4, 3), (7,)]))
def test_pattern_hashes_count_distinct_windows(seed, K, shape):
    g = np.random.default_rng(seed).integers(0, K, size=shape)
    h = pattern_hashes(g, 3)
    from numpy.lib.stride_tricks import sliding_window_view

    w = tuple(min(3, s) for s in shape)
    rows = np.unique(sliding_window_view(g, w).reshape(-1, int(np.prod(w))), axis=0)
    assert h.size == rows.shape[0]
    assert np.array_equal(unpack_hashes(pack_hashes(h)), h)
    assert np.array_equal(pattern_hashes(g.copy(), 3), h)


def test_pattern_and_label_counts():
    g = np.array([[0, 1, 0], [1, 0, 1]])
    c = pattern_counts(g, 2, K=2)
    assert c.sum() == 2 and c[0b0110] == 1 and c[0b1001] == 1
    assert label_counts(np.array([[0, -1], [2, 2]]), 3).tolist() == [1, 0, 2]
