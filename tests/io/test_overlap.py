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


def test_ground_bottom():
    m = read_model(DATA / "sample.png", N=3, symmetry=2, ground="bottom")
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


SKY, BLOCK, EARTH = (120, 180, 250), (200, 50, 50), (90, 60, 30)


def skyline(path):
    """A small sample made for this test: towers on the ground (EARTH only on the bottom row)."""
    from PIL import Image

    rows = ["ssssssssss", "ssssssssss", "ssbsssssss", "sbbbssssbs", "sbbbssssbs", "sbbbsssbbb"]
    rows.append("gggggggggg")
    col = {"s": SKY, "b": BLOCK, "g": EARTH}
    img = np.array([[col[c] for c in r] for r in rows], dtype=np.uint8)
    Image.fromarray(img).save(path)
    return img


def wfc_ground_pattern(img, N, symmetry):
    """WaveFunctionCollapse's ground pattern, computed as WFC does on the picture (rows from
    the top, periodic input): the last new pattern, turned into csplab's [x, y] with y up."""
    H, W = img.shape[:2]
    seen, last = set(), None
    for y in range(H):
        for x in range(W):
            p = img[np.ix_([(y + d) % H for d in range(N)], [(x + d) % W for d in range(N)])]
            for q in [p, p[:, ::-1]][:symmetry]:
                key = q.tobytes()
                if key not in seen:
                    seen.add(key)
                    last = q
    return last.transpose(1, 0, 2)[:, ::-1]  # [row, col] -> [x, y up]


@pytest.mark.parametrize("symmetry", [1, 2])
def test_ground_is_wfcs_rule(tmp_path, symmetry):
    img = skyline(tmp_path / "skyline.png")
    m = read_model(tmp_path / "skyline.png", N=3, symmetry=symmetry, ground="true")
    g = m.meta["ground_pattern"]
    assert m.meta["ground"] == "wfc"
    want = wfc_ground_pattern(img, 3, symmetry)
    assert np.array_equal(m.sample_colors[m.patterns[g]], want)
    W, H = 16, 11
    for seed in range(2):
        r = csplab.solve(m.problem((W, H), periodic=True), "catalog", rng=seed)
        assert r.ok
        # the ground pattern fills one row of cells (the one that puts its ground row on
        # the picture's bottom row) and is nowhere else
        rows = {int(y) for y in np.nonzero(r.grid == g)[1]}
        assert rows == {H - 3 + 1} and (r.grid[:, H - 2] == g).all()
        pic = m.sample_colors[m.reconstruct(r.grid, periodic=True)]  # [x, y up, rgb]
        earth = (pic == EARTH).all(axis=-1)
        assert earth[:, 0].all() and not earth[:, 1:].any()  # one band, at the bottom


def test_ground_needs_periodic_output_for_wfcs_rule(tmp_path):
    skyline(tmp_path / "skyline.png")
    m = read_model(tmp_path / "skyline.png", N=3, symmetry=2, ground=True)
    with pytest.warns(UserWarning, match="periodic along y.*ground=bottom"):
        P = m.problem((12, 8))
    r = csplab.solve(P, "catalog", rng=0)
    assert r.ok
    earth = (m.sample_colors[m.reconstruct(r.grid, periodic=False)] == EARTH).all(axis=-1)
    assert earth[:, 0].all() and not earth[:, 1:].any()
    assert read_model(tmp_path / "skyline.png", ground="false").meta["ground"] is False
    with pytest.raises(InputError, match=r"option ground='maybe' of overlapping files") as e:
        read_model(tmp_path / "skyline.png", ground="maybe")
    assert "\n" not in str(e.value)
