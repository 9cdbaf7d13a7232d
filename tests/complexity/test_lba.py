"""Theorem 5.2.4: the LBA construction agrees with a direct simulation (fast form).

The full check (every word up to length 7 for both automata) is
experiments/lba_theorem_5_2_4.py; here: the simulators against the languages up to length
7, the construction against the simulator up to length 5, and SAT cross-checks.
"""

import numpy as np
import pytest

from csplab.complexity import complete_model as complete
from csplab.complexity.lba import (
    BUILTIN,
    LANGUAGES,
    all_words,
    build_construction,
    lba_consistent,
    lba_problem,
    load_lba,
    parse_lba,
)
from csplab.errors import FormatError, InputError


@pytest.mark.parametrize("name", list(BUILTIN))
def test_simulator_decides_the_language_up_to_length_7(name):
    M = load_lba(name)
    for w in all_words(M.input_alphabet, 7):
        assert M.accepts(w) == LANGUAGES[name](w), w


@pytest.mark.parametrize("name,max_len", [("anbncn", 4), ("ww", 5)])
def test_model_consistent_iff_lba_accepts(name, max_len):
    M = load_lba(name)
    for w in all_words(M.input_alphabet, max_len):
        v = lba_consistent(M, w)
        assert v.holds == M.accepts(w), w
        if v.holds:  # the unique completion replays the computation row by row
            con = build_construction(M)
            run = M.run(w)
            heads = [con.decode_row(v.witness[:, y]) for y in range(v.witness.shape[1] - 1, -1, -1)]
            states = [h[0] for h in heads if h[0] is not None]
            assert states[: len(run["configurations"])] == [c[0] for c in run["configurations"]]


@pytest.mark.parametrize("w", ["aabbcc", "aaabbbccc", "abc", "aabbbcc", "abcabc", "cba"])
def test_sat_agrees_with_arc_consistency(w):
    M = load_lba("anbncn")
    P, _ = lba_problem(M, w)
    assert (complete(P).status == "solved") == M.accepts(w)


def test_rows_too_few_hide_the_rejection():
    M = load_lba("anbncn")
    rows = M.run("abcc")["rows"]
    assert not lba_consistent(M, "abcc").holds
    first_bad = next(h for h in range(1, rows + 2) if not lba_consistent(M, "abcc", rows=h).holds)
    assert 1 < first_bad <= rows  # a model that ends before the rejection is consistent
    assert all(lba_consistent(M, "abcc", rows=h).holds for h in range(1, first_bad))


def test_reject_state_has_nothing_below_and_accept_repeats():
    M = load_lba("ww")
    con = build_construction(M)
    Ty = con.T[1]
    for s in M.symbols:
        assert not Ty[:, con.head(s, M.reject)].any()
        acc = con.head(s, M.accept)
        assert np.flatnonzero(Ty[:, acc]).tolist() == [acc]


def test_spec_errors():
    with pytest.raises(FormatError, match="line 2"):
        parse_lba("input: a\nq0 a -> q1 a\n")
    with pytest.raises(FormatError, match="end markers"):
        parse_lba("input: a\ntape: a\nstart: q\naccept: y\nreject: n\nq < -> q a R\n")
    with pytest.raises(FormatError, match="pass an end marker"):
        parse_lba("input: a\ntape: a\nstart: q\naccept: y\nreject: n\nq > -> q > R\n")
    with pytest.raises(FormatError, match="deterministic"):
        parse_lba("input: a\ntape: a\nstart: q\naccept: y\nreject: n\nq a -> q a R\nq a -> y a S\n")
    with pytest.raises(InputError, match="alphabet"):
        load_lba("anbncn").run("abd")
    with pytest.raises(InputError, match="neither"):
        load_lba("nope")
    loop = parse_lba(
        "input: a\ntape: a\nstart: q\naccept: y\nreject: n\nmax_steps: 5\nq a -> q a S\n"
    )
    with pytest.raises(InputError, match="did not halt"):
        loop.run("a")
