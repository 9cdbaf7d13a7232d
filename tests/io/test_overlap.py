import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import csplab
from csplab.errors import FormatError, InputError
from csplab.io import model_format, read_model
from csplab.io.overlap import OverlapModel
from csplab.testing.strategies import label_grids

from ._helpers import DATA, installed_solvers


def windows(img, N, periodic):
    """Every N-wide window of a label grid [x, y, ...]."""
    out = set()
    shp = img.shape
    anchors = [range(s if periodic else s - N + 1) for s in shp]
    for a in np.ndindex(*[len(r) for r in anchors]):
        idx = np.ix_(*[[(ai + k) % s for k in range(N)] for ai, s in zip(a, shp, strict=True)])
        out.add(img[idx].tobytes())
    return out


def test_sample_png_patterns():
    m = read_model(DATA / "sample.png", N=3, symmetry=2)
    assert model_format(DATA / "sample.png") == "overlapping"
    assert isinstance(m, OverlapModel) and m.meta["N"] == 3
    assert int(m.weights.sum()) == 12 * 8 * 2  # every anchor of the periodic sample, twice
    assert m.sample_colors.shape == (4, 3)
    assert tuple(m.sample_colors[0]) == (120, 180, 250)  # sky: the first colour, top-left


@pytest.mark.parametrize("solver", installed_solvers())
@pytest.mark.parametrize("periodic", [True, False])
def test_outputs_consist_of_sample_patterns(solver, periodic):
    m = read_model(DATA / "sample.png", N=3, symmetry=2)
    P = m.problem((14, 10), periodic=periodic)
    r = csplab.solve(P, solver, rng=4)
    if not r.ok:
        pytest.skip(f"{solver} gave up ({r.status}) on this seed")
    img = m.reconstruct(r.grid, periodic=periodic)
    assert img.shape == ((14, 10) if periodic else (16, 12))
    pats = {p.tobytes() for p in m.patterns}
    assert windows(img, 3, periodic) <= pats
    pic = m.render(r.grid, periodic=periodic, scale=1)
    assert pic.size == img.shape


def test_ground():
    m = read_model(DATA / "sample.png", N=3, symmetry=2, ground=True)
    r = csplab.solve(m.problem((20, 9)), "catalog", rng=0, order="min-entropy")
    assert r.ok
    img = m.reconstruct(r.grid, periodic=False)
    ground = 3  # brown: the fourth colour in scan order (sky, petal, stem, ground)
    assert tuple(m.sample_colors[ground]) == (120, 80, 40)
    assert (img[:, 0] == ground).all() and (img[:, 1:] != ground).all()
    with pytest.raises(InputError, match="ground"):
        OverlapModel.from_grid(np.zeros((4, 4), int), ground=True, symmetry=8)


@settings(max_examples=25, deadline=None)
@given(label_grids(ndim=2, max_side=5, max_labels=3), st.integers(1, 3), st.integers(1, 8))
def test_adjacency_is_overlap_agreement(sample, N, sym):
    m = OverlapModel.from_grid(sample, N=N, symmetry=sym)
    P = m.patterns
    for d in range(2):
        for a in range(m.K):
            for b in range(m.K):
                agree = np.array_equal(
                    np.take(P[a], range(1, N), axis=d), np.take(P[b], range(N - 1), axis=d)
                )
                assert m.relations[d, a, b] == agree


def test_3d_sample():
    s = np.zeros((4, 4, 3), int)
    s[:, :, 0] = 1
    s[1, 1, 1] = 2
    m = OverlapModel.from_grid(s, N=2, symmetry=4)
    assert m.ndim == 3
    r = csplab.solve(m.problem((5, 5, 3), periodic=True), "catalog", rng=0)
    assert r.ok
    img = m.reconstruct(r.grid, periodic=True)
    assert windows(img, 2, True) <= {p.tobytes() for p in m.patterns}


def test_bad_samples(tmp_path):
    (tmp_path / "x.png").write_bytes(b"\x89PNG\r\n\x1a\nnot really")
    with pytest.raises(FormatError, match="cannot read image"):
        read_model(tmp_path / "x.png")
    with pytest.raises(InputError):
        OverlapModel.from_grid(np.zeros((2, 2), int), N=3, periodic_input=False)
