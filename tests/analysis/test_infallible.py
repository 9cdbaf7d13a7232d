"""The corner condition, the region prover and exhaustive Alg. 3.6 (csplab.analysis.infallible).

Thesis statements of Sec. 3.3.7/3.3.8 (ledger rows I1-I9) and soundness checks against
brute force: whenever the prover says "infallible", no exhaustive run of Alg. 3.1 (or of
Alg. 3.6) on small outputs fails; whenever it gives a replayed witness, the witness
replays as a failing run.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from csplab import ExampleModel
from csplab.analysis import (
    alg31_exhaustive,
    alg36_failure,
    corner_condition,
    prove_infallible,
    region_catalog,
    replay,
)
from csplab.analysis.infallible import Rules, _scan_cells, _Walk, region_box
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.grids import from_example
from csplab.testing.strategies import analysis_examples

FIG = "scan:yx"


# ----------------------------------------------------------------------------- thesis (I1-I9)


@pytest.mark.parametrize("name", ["fig3_1a", "fig3_1b", "line"])
@pytest.mark.parametrize("order", [FIG, "scanline"])
def test_fig3_1abc_infallible_with_2x2(name, order):  # I1
    E = load_example(name)
    assert corner_condition(E, order).holds
    v = prove_infallible(E, "2x2", order=order)
    assert v.holds is True
    assert v.stats["states"] > 0 and len(v.witness["sha256"]) == 64


def test_fig3_13_line_regions():  # I2: consistent 2x2 regions with <= 3 labels (Fig. 3.13)
    E = load_example("line")
    v = prove_infallible(E, "2x2", order=FIG, history=0)
    # interior configuration: windows = labellings of the 3 assigned cells (+ catalog)
    walk = _Walk((2, 2), _scan_cells((2, 2), (1, 0)), (2, 2))
    rules = Rules.of(E)
    full = []
    for a in range(2):
        for b in range(2):
            for c in range(2):
                labels = [a, b, c]
                ok = all(walk.catalog(rules, i, labels) >> labels[i] & 1 for i in range(3))
                if ok:
                    full.append((a, b, c, walk.catalog(rules, 3, labels)))
    assert len(full) == 6  # consistent L-shapes; R' = [[1], [1 1]] is not among them
    assert (1, 1, 1) not in [t[:3] for t in full]
    assert all(t[3] for t in full)
    assert v.holds


def test_fig3_4a_not_provable_with_2x2_but_with_3x2():  # I3
    E = load_example("fig3_4a")
    v = prove_infallible(E, "2x2", order=FIG, refute=False)
    assert v.holds is None
    w = v.witness["alg36"]
    assert w["realized"]
    run = w["run"]
    # replay the Alg. 3.6 failure with the reference catalog (Propagator on the region)
    grid = np.full(run["shape"], -1)
    for c, b in run["choices"]:
        cat = region_catalog(E, grid, c, "2x2").tolist()
        if b is None:
            assert cat == []
            p = tuple(c)
        else:
            assert b in cat
            grid[tuple(c)] = b
    # the thesis' pair of regions: a 1 below p and a 1 left of p
    assert grid[p[0], p[1] - 1] == 1 and grid[p[0] - 1, p[1]] == 1
    assert prove_infallible(E, "3x2", order=FIG).holds is True


def test_fig3_5a_not_provable_and_fallible():  # I4 (prover side)
    v = prove_infallible(load_example("fig3_5a"), "2x2", order=FIG)
    assert v.holds is False
    assert replay(load_example("fig3_5a"), v.witness["alg31"]).holds


def test_fig3_15_infallible_with_2x2():  # I5
    E = load_example("fig3_15")
    assert corner_condition(E, FIG).holds
    assert prove_infallible(E, "2x2", order=FIG).holds is True


def test_fig3_16_infallible_with_4x2_regions():  # I6
    E = load_example("fig3_16")
    assert not corner_condition(E).holds
    v3 = prove_infallible(E, "3x2", order=FIG, refute=False)
    assert v3.holds is None and v3.witness["alg36"]["realized"]
    v4 = prove_infallible(E, "4x2", order=FIG)
    assert v4.holds is True
    assert v4.stats["windows"] > 100


def test_fig3_4a_scanline_order_differs():
    # the 3x2 proof is specific to the figure order: in csplab's scanline order (x
    # outermost, columns filled bottom to top) Alg. 3.6 really fails with 3x2 and even
    # 3x3 regions (a 1 is placed under a column whose top the region cannot see); regions
    # reaching two cells above p (2x4) prove it
    E = load_example("fig3_4a")
    for region in ("3x2", "2x3", "3x3"):
        v = prove_infallible(E, region, order="scanline", refute=False)
        assert v.holds is None and v.witness["alg36"]["realized"]
    assert prove_infallible(E, "2x4", order="scanline").holds is True


def test_pillar_corner_condition_3d():
    E = load_example("pillar")
    assert corner_condition(E).holds
    assert prove_infallible(E, 2).holds is True


def test_bad_arguments():
    E = load_example("line")
    with pytest.raises(InputError, match="region proof"):
        prove_infallible(E, 2, order="random")
    with pytest.raises(InputError, match="at least 2"):
        prove_infallible(E, (1, 2))
    with pytest.raises(InputError, match="axes"):
        prove_infallible(E, "2x2x2x2")


def test_budget_gives_undecided():
    v = prove_infallible(load_example("fig3_16"), "4x2", order=FIG, max_states=50)
    assert v.holds is None and "budget" in v.message


def test_proof_hash_is_reproducible():
    E = load_example("fig3_15")
    a = prove_infallible(E, "3x2", order=FIG)
    b = prove_infallible(E, "3x2", order=FIG)
    c = prove_infallible(E, "2x2", order=FIG)
    assert a.witness["sha256"] == b.witness["sha256"] != c.witness["sha256"]
    assert "--expect-hash" in a.witness["recheck"]


# ----------------------------------------------------------------------------- soundness


def small_shapes(ndim: int) -> list[tuple[int, ...]]:
    if ndim == 2:
        return [(1, 3), (3, 1), (2, 2), (2, 3), (3, 2), (3, 3), (4, 3), (3, 4)]
    return [(2, 2, 2), (3, 2, 2), (2, 3, 2), (2, 2, 3)]


@settings(max_examples=40)
@given(analysis_examples(max_side=3, max_labels=4), st.sampled_from([FIG, "scanline"]),
       st.sampled_from([(2, 2), (3, 2), (2, 3)]))  # fmt: skip
def test_prover_is_sound_against_exhaustive_runs(E, order, region):
    v = prove_infallible(E, region, order=order, refute=False, max_states=20_000)
    if v.holds is True:
        for shape in small_shapes(2):
            P = from_example(E, shape)
            ex = alg31_exhaustive(P, order, max_states=20_000)
            assert ex.holds is not False, (shape, ex.witness)
            assert alg36_failure(E, shape, region, order=order).holds is not False
    elif v.holds is None and v.witness is not None and v.witness["alg36"]["realized"]:
        run = v.witness["alg36"]["run"]
        grid = np.full(run["shape"], -1)
        for c, b in run["choices"]:
            cat = region_catalog(E, grid, c, region).tolist()
            if b is None:
                assert cat == []
            else:
                assert b in cat
                grid[tuple(c)] = b


@settings(max_examples=25)
@given(analysis_examples(ndim=3, max_side=2, max_labels=3))
def test_prover_is_sound_in_3d(E):
    v = prove_infallible(E, 2, refute=False, max_states=20_000)
    if v.holds is True:
        for shape in small_shapes(3):
            ex = alg31_exhaustive(from_example(E, shape), max_states=20_000)
            assert ex.holds is not False, (shape, ex.witness)


@settings(max_examples=40)
@given(analysis_examples(max_side=3, max_labels=4))
def test_refutations_replay(E):
    v = prove_infallible(E, (2, 2), order=FIG, max_states=20_000)
    if v.holds is False:
        assert replay(E, v.witness["alg31"]).holds


@settings(max_examples=40)
@given(st.one_of(analysis_examples(max_side=3, max_labels=4),
                 analysis_examples(ndim=3, max_side=2, max_labels=3)))  # fmt: skip
def test_corner_condition_is_the_2x2_region_proof(E):
    c = corner_condition(E)
    v = prove_infallible(E, 2, history=0, realize=False, refute=False)
    assert c.holds == (v.holds is True)


@settings(max_examples=40)
@given(analysis_examples(max_side=3, max_labels=4), st.data())
def test_region_catalog_kernel_matches_propagator(E, data):
    """The prover's bitset arc consistency on a region = Propagator on the sub-grid."""
    shape = data.draw(st.sampled_from([(3, 3), (4, 3), (2, 4)]))
    region = data.draw(st.sampled_from([(2, 2), (3, 2), (3, 3)]))
    order = data.draw(st.sampled_from([FIG, "scanline"]))
    axes = (1, 0) if order == FIG else (0, 1)
    cells = _scan_cells(shape, axes)
    t = data.draw(st.integers(0, len(cells) - 1))
    used = np.flatnonzero(E.counts() > 0)
    labels = [int(data.draw(st.sampled_from(used.tolist()))) for _ in range(t)]
    walk = _Walk(shape, cells[: t + 1], region)
    grid = np.full(shape, -1)
    for c, b in zip(cells, labels, strict=False):
        grid[c] = b
    ref = region_catalog(E, grid, cells[t], region).tolist()
    got = walk.catalog(Rules.of(E), t, labels)
    # the walk leaves out fixed cells that border no unassigned cell: equal when the fixed
    # cells are consistent among themselves (always so in a run), else only a superset
    assert set(ref) <= {b for b in range(E.K) if got >> b & 1}
    P = from_example(E, shape)
    g = grid.reshape(-1)
    s, d, r = P.arcs[:, 0], P.arcs[:, 1], P.arcs[:, 2]
    both = (g[s] >= 0) & (g[d] >= 0)
    if P.relations[r[both], g[s[both]], g[d[both]]].all():
        assert set(ref) == {b for b in range(E.K) if got >> b & 1}


def test_region_box_clips():
    assert region_box((0, 0), (3, 3), (2, 2)) == ((0, 0), (0, 0))
    assert region_box((2, 1), (3, 3), (3, 2)) == ((1, 0), (2, 1))


def test_examples_with_no_model_are_not_proven():
    E = ExampleModel([[0, 1, 2]])  # no label repeats: no model wider than the example
    v = prove_infallible(E, 2, order=FIG)
    assert v.holds is False
    assert v.witness["alg31"]["kind"] in ("failed", "unsat")


def test_fig3_13_twelve_regions_in_fill_order():
    """Fig. 3.13 lists R1..R12: a 2x2 region filled in the figure's order (bottom-left,
    bottom-right, top-left) holding 1, 2 or 3 labels with a non-empty catalog: 2 + 4 + 6."""
    from csplab.catalog import Propagator
    from csplab.grids import from_example

    P = from_example(load_example("line"), (2, 2))
    fill = [(0, 0), (1, 0), (0, 1)]
    counts = []
    for k in range(1, 4):
        ok = 0
        for labels in np.ndindex(*(2,) * k):
            eng = Propagator(P)
            if all(eng.assign(P.cell(c), int(b)) for c, b in zip(fill, labels, strict=False)):
                ok += 1
        counts.append(ok)
    assert counts == [2, 4, 6] and sum(counts) == 12
    eng = Propagator(P)  # R' = [[1], [1 1]]: its catalog is empty
    assert not all(eng.assign(P.cell(c), 1) for c in fill)
