import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from csplab.io.symmetry import (
    Orientations,
    closure_violations,
    cube_group,
    expand_rules,
    square_group,
)
from csplab.io.wfc import _ORDER, CARDINALITY, stabilizer_words


def test_group_orders_and_subgroups():
    assert len(square_group()) == 8
    C = cube_group()
    assert len(C) == 48
    assert len(C.all_subgroups()) == 98  # the cube group has 98 subgroups
    assert len(square_group().all_subgroups()) == 10


def test_generators_move_directions_as_documented():
    S, C = square_group(), cube_group()
    assert S.apply(S.index("a"), (0, 1)) == (1, 1)
    assert S.apply(S.index("b"), (0, 1)) == (0, -1)
    assert C.apply(C.index("x"), (1, 1)) == (2, 1)
    assert C.apply(C.index("y"), (0, 1)) == (2, 1)
    assert C.apply(C.index("z"), (0, 1)) == (1, 1)
    # words apply right to left: "zy" = first y (+x -> +z), then z (fixes z)
    assert C.apply(C.index("zy"), (0, 1)) == (2, 1)


def test_wfc_action_tables_are_reproduced():
    """The cosets reproduce WaveFunctionCollapse's hand-written action tables."""
    tables = {
        "X": (lambda i: i, lambda i: i),
        "I": (lambda i: 1 - i, lambda i: i),
        "\\": (lambda i: 1 - i, lambda i: 1 - i),
        "T": (lambda i: (i + 1) % 4, lambda i: i if i % 2 == 0 else 4 - i),
        "L": (lambda i: (i + 1) % 4, lambda i: i + 1 if i % 2 == 0 else i - 1),
        "F": (
            lambda i: (i + 1) % 4 if i < 4 else 4 + (i - 1) % 4,
            lambda i: i + 4 if i < 4 else i - 4,
        ),
    }
    G = square_group()
    a, b = G.index("a"), G.index("b")
    for sym, (fa, fb) in tables.items():
        card = CARDINALITY[sym]
        O = Orientations(
            G, [G.subgroup(stabilizer_words(sym))], [[G.index(w) for w in _ORDER[:card]]]
        )
        assert O.K == card
        assert [int(O.perm[a, t]) for t in range(card)] == [fa(t) for t in range(card)], sym
        assert [int(O.perm[b, t]) for t in range(card)] == [fb(t) for t in range(card)], sym


@given(st.data())
def test_expanded_rules_are_closed(data):
    G = data.draw(st.sampled_from([square_group(), cube_group()]))
    subs = G.all_subgroups()
    n = data.draw(st.integers(1, 3))
    stabs = [data.draw(st.sampled_from(subs)) for _ in range(n)]
    O = Orientations(G, stabs)
    rules = data.draw(
        st.lists(
            st.tuples(st.integers(0, O.K - 1), st.integers(0, O.K - 1),
                      st.tuples(st.integers(0, G.ndim - 1), st.sampled_from([1, -1]))),
            max_size=4,
        )
    )  # fmt: skip
    T = expand_rules(O, rules)
    assert closure_violations(G, O.perm, T) == []
    for a, b, (ax, s) in rules:
        assert T[ax, a, b] if s > 0 else T[ax, b, a]


def test_closure_violations_finds_a_missing_image():
    G = square_group()
    O = Orientations(G, [G.subgroup([])])  # 8 orientations of an asymmetric tile
    T = np.zeros((2, 8, 8), dtype=bool)
    T[0, 0, 1] = True
    bad = closure_violations(G, O.perm, T)
    assert bad and all(v[1] == 0 and v[2] == 1 for v in bad[:1])
