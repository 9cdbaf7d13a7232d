"""The region prover with boundary labels and face rules (issue 26): every proof is checked
against exhaustive runs of Alg. 3.1 on small outputs with the same boundary, and its
certificate against csplab.certcheck."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from csplab.analysis import alg31_exhaustive, prove_infallible
from csplab.analysis.infallible import face_rules_of
from csplab.certcheck import check_certificate
from csplab.examples import load_example
from csplab.grids import from_example
from csplab.testing.strategies import analysis_examples

SHAPES = [(1, 3), (3, 1), (2, 2), (2, 3), (3, 2), (3, 3), (4, 3), (3, 4)]


@st.composite
def with_boundary(draw):
    E = draw(analysis_examples(max_side=3, max_labels=3))
    used = np.flatnonzero(E.counts() > 0).tolist()
    faces = draw(st.lists(st.sampled_from(["x-", "x+", "y-", "y+"]), min_size=1, max_size=4,
                          unique=True))  # fmt: skip
    return E, {f: draw(st.sampled_from(used)) for f in faces}


@settings(max_examples=60, deadline=None)
@given(with_boundary(), st.sampled_from(["scanline", "scan:yx"]))
def test_boundary_proofs_are_sound_against_exhaustive_runs(case, order):
    E, bnd = case
    v = prove_infallible(E, 2, order=order, refute=False, max_states=20_000, certificate=True,
                         boundary=bnd)  # fmt: skip
    if v.holds is not True:
        return
    for shape in SHAPES:
        ex = alg31_exhaustive(from_example(E, shape, boundary=bnd), order, max_states=20_000)
        assert ex.holds is not False, (shape, ex.witness)
    assert check_certificate(json.loads(json.dumps(v.witness["certificate"])))[0]


@settings(max_examples=40, deadline=None)
@given(with_boundary())
def test_boundary_refutations_check(case):
    E, bnd = case
    v = prove_infallible(E, 2, certificate=True, boundary=bnd, max_states=20_000)
    if v.holds is False:
        cert = json.loads(json.dumps(v.witness["certificate"]))
        ok, msg = check_certificate(cert)
        assert ok, msg


def test_bottom_face_wins_where_faces_meet():
    E = load_example("line")
    rules = face_rules_of(E, {"y-": 1, "x-": 0})
    assert rules == [("force", "x-", [0]), ("force", "y-", [1])]
    assert face_rules_of(E, "none") == []


def test_line_with_auto_boundary_is_proved_and_checked():
    E = load_example("line")
    v = prove_infallible(E, 2, boundary="auto", certificate=True)
    assert v.holds is True and v.stats["configs"] == 64  # 9 positions x face variants
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert cert["rules"]["faces"] and check_certificate(cert)[0]
    for shape in SHAPES:
        P = from_example(E, shape, boundary="auto")
        assert alg31_exhaustive(P, max_states=20_000).holds is not False
