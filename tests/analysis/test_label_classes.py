"""Frame labels recorded by class (issue 26): the region prover explores equal futures
once, its certificates are re-verified by the independent checker, and planted defects
and fallible models are still caught."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from csplab.analysis import alg31_exhaustive, decide_infallibility, prove_infallible
from csplab.analysis.infallible import Rules, label_classes
from csplab.certcheck import check_certificate, rules_hash
from csplab.examples import load_example, load_model
from csplab.grids import from_example

DATA = Path(__file__).resolve().parents[1] / "io" / "data"


@pytest.fixture(scope="module")
def pipes3d_cert() -> dict:
    M = load_model(str(DATA / "pipes3d.xml"))
    v = prove_infallible(M, "2x2x3", history=0, classes=True, certificate=True, refute=False)
    assert v.holds is True, v.message
    return json.loads(json.dumps(v.witness["certificate"]))


def test_classes_are_forward_supports():
    # pipes: a tile's class along x is its +x connection; unused labels stay apart
    R = Rules.of(load_model(str(DATA / "pipes3d.xml")))
    cls = label_classes(R)
    for a in range(R.K):
        assert all(R.fwd[d][a] == R.fwd[d][cls[a]] for d in range(3))
    assert len(set(label_classes(R, [0]))) == 2 and len(set(cls)) < R.K


def test_pipes3d_proved_and_checked(pipes3d_cert):
    ok, msg = check_certificate(pipes3d_cert)
    assert ok, msg
    assert "labels by class" in msg


def test_checker_rejects_planted_defects(pipes3d_cert):
    # a state removed: the set is no longer closed
    cert = copy.deepcopy(pipes3d_cert)
    conf = max(cert["configs"], key=lambda c: len(c["states"]))
    conf["states"] = [s for s in conf["states"] if s[0] != len(conf["keys"]) - 1]
    ok, msg = check_certificate(cert)
    assert not ok and "not closed" in msg
    # the same states read as plain labels: not closed under the real labels
    cert = copy.deepcopy(pipes3d_cert)
    del cert["label_classes"]
    assert not check_certificate(cert)[0]
    # classes coarser than the checker's: every label of a state replaced by the first one
    cert = copy.deepcopy(pipes3d_cert)
    for c in cert["configs"]:
        c["states"] = sorted({(i, tuple(0 for _ in labs)) for i, labs in c["states"]})
    assert not check_certificate(cert)[0]
    # a rule removed (the hash updated): the states no longer cover the runs
    cert = copy.deepcopy(pipes3d_cert)
    cert["rules"]["pairs"][2] = cert["rules"]["pairs"][2][1:]
    cert["rules_sha256"] = rules_hash(cert["rules"])
    assert not check_certificate(cert)[0]


@pytest.mark.parametrize(("name", "order"), [("fig3_5a", "scan:yx"), ("fig3_1d", "scanline"),
                                             ("fig3_6a", "scan:yx")])  # fmt: skip
def test_fallible_models_are_not_proved(name, order):
    # each fails on a small output (the table's witnesses); classes must not hide that
    E = load_example(name)
    for region in ("2x2", "3x2", "2x3", "3x3", "4x2"):
        for history in (0, 1):
            v = prove_infallible(E, region, order=order, history=history, classes=True,
                                 refute=False)  # fmt: skip
            assert v.holds is not True, (region, history)
    assert decide_infallibility(E, order=order, time_limit=30).holds is False


def test_classes_agree_with_plain_labels_on_small_models():
    # classes change what is memoised, not a catalog: the same verdict with and without
    # them (same region and history); proofs agree with exhaustive runs of Alg. 3.1
    for name, order in [("fig3_4a", "scan:yx"), ("fig3_15", "scanline"), ("line", "scan:yx")]:
        E = load_example(name)
        for region in ("2x2", "3x2", "2x3"):
            for history in (0, 1):
                a, b = (
                    prove_infallible(E, region, order=order, refute=False, realize=False,
                                     history=history, classes=c)
                    for c in (False, True)
                )  # fmt: skip
                assert a.holds == b.holds, (name, region, history)
                assert b.stats["states"] <= a.stats["states"]
                if b.holds is True:
                    for shape in [(3, 3), (4, 3)]:
                        P = from_example(E, shape)
                        assert alg31_exhaustive(P, order, 200_000).holds is True


# ----------------------------------------------------------------------------- dead labels


def _where(c, shape, cap):
    return tuple((min(x, cap), min(n - 1 - x, cap)) for x, n in zip(c, shape, strict=True))


@pytest.mark.parametrize("name", ["fig3_5a", "loops", "fig3_16", "pillar"])
def test_dead_labels_are_in_no_initial_catalog(name):
    # Alg. 3.1's own arc consistency, on outputs thin and wide, never keeps a label
    # where it is dead
    import itertools

    from csplab.analysis.infallible import DEAD_CAP, dead_at, dead_labels, face_rules_of
    from csplab.analysis.witness import model_problem
    from csplab.catalog import Propagator

    E = load_example(name)
    dead = dead_at(Rules.of(E), face_rules_of(E, "auto"))
    shapes = [(1, 5), (2, 2), (2, 7), (3, 3), (3, 8), (4, 6), (6, 4), (9, 9)]
    if E.ndim == 3:
        shapes = [(1, 1, 4), (2, 2, 2), (3, 2, 5), (4, 4, 4), (5, 3, 6)]
    killed = 0
    for shape in shapes:
        P = model_problem(E, shape, "auto")
        eng = Propagator(P)
        if not eng.ok:
            continue
        for c in itertools.product(*map(range, shape)):
            gone = dead[_where(c, shape, DEAD_CAP)]
            assert not any(gone >> b & 1 for b in eng.domain(P.cell(c)).tolist()), (shape, c)
            killed += bin(gone).count("1")
    assert killed
    assert dead_labels(Rules.of(E), face_rules_of(E, None)) == []  # open edges kill nothing


@pytest.mark.parametrize(("name", "region"), [("castle", "2x2x2"), ("canal", "2x2x2")])
def test_fallible_models_with_a_boundary_are_not_proved(name, region):
    # castle and canal fail with empty space all round (the table's witnesses)
    v = prove_infallible(load_example(name), region, boundary="auto", classes=True, history=0,
                         refute=False, time_limit=20)  # fmt: skip
    assert v.holds is not True


def test_dead_labels_prove_loops_with_its_boundary_and_checker_verifies():
    E = load_example("loops")
    v = decide_infallibility(E, boundary="auto", time_limit=60, certificate=True)
    assert v.holds is True, v.message
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert cert["dead"]["stages"] and check_certificate(cert)[0]
    # planted defects: a live label (0, the empty space) claimed dead in a stage; the
    # stages reversed; the stages gone (the states then miss runs); no label classes
    bad = copy.deepcopy(cert)
    bad["dead"]["stages"][0][1][0][1] = [0, *bad["dead"]["stages"][0][1][0][1]]
    assert not check_certificate(bad)[0]
    bad = copy.deepcopy(cert)
    bad["dead"]["stages"] = bad["dead"]["stages"][::-1]
    assert not check_certificate(bad)[0]
    bad = copy.deepcopy(cert)
    del bad["dead"]
    assert not check_certificate(bad)[0]
    bad = copy.deepcopy(cert)
    del bad["label_classes"]
    ok, msg = check_certificate(bad)
    assert not ok and "label classes" in msg


def test_dead_labels_prove_fig3_5a_with_its_boundary():
    # every object of fig3_5a stands on the bottom edge: with empty space all round only
    # the empty label is left, in both orders
    for order in ("scanline", "scan:yx"):
        v = prove_infallible(load_example("fig3_5a"), "2x2", order=order, boundary="auto",
                             classes=True, history=0, certificate=True)  # fmt: skip
        assert v.holds is True
        cert = json.loads(json.dumps(v.witness["certificate"]))
        assert cert["rules"]["used"] == [1] * 9 and check_certificate(cert)[0]


def test_class_states_checked_with_row_codes_as_with_polynomial_codes(pipes3d_cert, monkeypatch):
    # states too wide for one polynomial code are ranked row by row: the classes of the
    # next states must be taken there too, and a missing state still found
    import csplab.certcheck as cc

    monkeypatch.setattr(cc, "_CODE_LIMIT", 0)
    ok, msg = check_certificate(pipes3d_cert)
    assert ok, msg
    cert = copy.deepcopy(pipes3d_cert)
    conf = max(cert["configs"], key=lambda c: len(c["states"]))
    conf["states"] = [s for s in conf["states"] if s[0] != len(conf["keys"]) - 1]
    ok, msg = check_certificate(cert)
    assert not ok and "not closed" in msg
