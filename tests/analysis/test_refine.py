"""Refinement to infallible models, Sec. 3.3.8 (csplab.analysis.refine): thesis rows I8, I9."""

from __future__ import annotations

import numpy as np
import pytest

from csplab import ExampleModel
from csplab.analysis import lift_check, prove_infallible, refine_labels, to_infallible
from csplab.analysis.refine import closed_boundary
from csplab.errors import InputError
from csplab.examples import load_example

FIG = "scan:yx"


def test_rediscovers_fig3_15_from_fig3_5a():  # I8
    EF = load_example("fig3_5a")
    v = to_infallible(EF, order=FIG)
    assert v.holds is True
    EI = v.witness["example"]
    assert np.array_equal(EI.labels, load_example("fig3_15").labels)  # the same three 9s
    f = np.arange(EI.K)
    for b, a in v.witness["map"].items():
        f[int(b)] = a
    assert np.array_equal(f[EI.labels], EF.labels)
    assert prove_infallible(EI, "2x2", order=FIG).holds is True
    assert "holds" in v.witness["lift_closed"]["message"]
    # open outputs: a structure cut open by the output's edge does not lift (documented)
    assert v.witness["lift"]["holds"] is False


def test_rediscovers_fig3_16_from_fig3_6a():  # I9
    EF = load_example("fig3_6a")
    v = to_infallible(EF, order=FIG)
    assert v.holds is True and len(v.witness["splits"]) == 2
    EI = v.witness["example"]
    f = np.arange(EI.K)
    for b, a in v.witness["map"].items():
        f[int(b)] = a
    assert np.array_equal(f[EI.labels], EF.labels)
    # the same partition of cells as the thesis' Fig. 3.16 design (up to naming the posts)
    D = load_example("fig3_16").labels
    assert np.array_equal(EI.labels == EI.labels[2, 0], D == 10)
    posts = EI.labels == v.witness["splits"][0]["new_label"]
    assert np.array_equal(posts | (D == 12), EF.labels == 2)
    for shape in [(3, 3), (4, 3), (3, 4)]:
        assert lift_check(EI, f, EF, [shape]).holds  # Eq. 3.13 on outputs >= 3 rows
    assert lift_check(EI, f, EF, [(4, 2)]).holds is False  # as for the designed twin


def test_lift_check_closed_and_open():
    EI, EF = load_example("fig3_15"), load_example("fig3_5a")
    f = [0, 1, 2, 3, 4, 5, 6, 7, 8, 0]
    assert lift_check(EI, f, EF, [(6, 3)], boundary=closed_boundary(EF)).holds
    v = lift_check(EI, f, EF, [(3, 3)])
    assert v.holds is False
    assert EF.labels.size and np.asarray(v.witness["model"]).shape == (3, 3)
    assert lift_check(EI, [0] * 10, EF).holds is False  # f(E_I) != E_F


def test_refine_labels_errors():
    E = ExampleModel([[0, 1], [1, 0]])
    with pytest.raises(InputError):
        refine_labels(E, [(0, 0), (0, 1)])
    with pytest.raises(InputError):
        refine_labels(E, [])


def test_already_infallible_is_returned_unchanged():
    v = to_infallible(load_example("line"), order=FIG)
    assert v.holds is True and v.witness["splits"] == []
