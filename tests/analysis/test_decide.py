"""The decision procedure of ``csplab prove`` (issue 26): regions of growing size and
backward reach, refined by Alg. 3.6's real failures, and a search for failing runs."""

from __future__ import annotations

import json

import pytest

from csplab.analysis import alg31_exhaustive, decide_infallibility, prove_infallible, replay
from csplab.analysis.decide import _same_back, _same_on, region_ladder
from csplab.certcheck import check_certificate
from csplab.examples import load_example
from csplab.grids import from_example


def test_fig3_4a_proved_with_the_thesis_region_and_checked():
    v = decide_infallibility(load_example("fig3_4a"), order="scan:yx", time_limit=60,
                             certificate=True)  # fmt: skip
    assert v.holds is True and v.stats["method"] == "region 3x2 history 0 (Alg. 3.6)"
    cert = json.loads(json.dumps(v.witness["certificate"]))
    ok, msg = check_certificate(cert)
    assert ok, msg
    assert cert["prover"]["method"] == v.stats["method"]  # the time of the whole decision


def test_fig3_5a_refuted_with_a_replayable_run():
    E = load_example("fig3_5a")
    v = decide_infallibility(E, order="scan:yx", time_limit=60, certificate=True)
    assert v.holds is False
    assert replay(E, v.witness["alg31"]).holds
    ok, msg = check_certificate(json.loads(json.dumps(v.witness["certificate"])))
    assert ok and "fallible" in msg


def test_regions_reaching_back_prove_what_alg37_regions_cannot():
    # fig3_6a in scanline order: every region of Alg. 3.7 (reaching 1 cell back) up to 6
    # per axis fails for real on a 2xN output, a region reaching 3 cells back along y proves it
    E = load_example("fig3_6a")
    assert prove_infallible(E, (3, 4), refute=False).holds is None
    v = prove_infallible(E, (3, 4), back=(1, 3), refute=False, certificate=True)
    assert v.holds is True
    # sound: no run of Alg. 3.1 fails on any output up to 4x4
    for shape in [(2, 2), (2, 4), (3, 3), (4, 4)]:
        assert alg31_exhaustive(from_example(E, shape), "scanline", 200_000).holds is True
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert check_certificate(cert)[0]
    cert["back"] = [1, 1]  # a planted defect: the regions the states were closed under
    ok, msg = check_certificate(cert)
    assert not ok and "configurations" in msg


def test_ladder_and_pruning():
    ladder = region_ladder(2, 3, 2)
    assert ladder[0] == ((2, 2), (1, 1)) and len(ladder) == 16
    assert len(set(ladder)) == len(ladder)
    # on a 2x3 output a region of 3 along x and one of 5 both cover x
    assert _same_on((3, 2), (5, 2), (2, 3)) and not _same_on((3, 2), (3, 3), (2, 3))
    assert _same_back((1, 2), (1, 4), (2, 3)) and not _same_back((1, 1), (1, 2), (2, 3))


def test_undecided_says_what_was_tried():
    v = decide_infallibility(load_example("city"), time_limit=4, max_region=2)
    assert v.holds in (None, False)
    if v.holds is None:
        assert v.stats["attempts"] and "no failure" in v.message


@pytest.mark.parametrize("bad", [0, float("nan"), -1])
def test_bad_time_limit(bad):
    from csplab.errors import InputError

    with pytest.raises(InputError, match="time limit"):
        decide_infallibility(load_example("line"), time_limit=bad)
