"""Pictures for notebooks: ``_repr_png_`` on ExampleModel, RuleSet and Result."""

import io
import warnings

import numpy as np
from PIL import Image

import csplab
from csplab.io import read_model

from .io._helpers import DATA


def png(obj):
    data = obj._repr_png_()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return Image.open(io.BytesIO(data))


def test_example_and_result_pictures():
    E = csplab.load_example("line")
    assert png(E).size[0] > 0
    r = csplab.solve(csplab.from_example(E, (10, 6)), "catalog", rng=1)
    assert png(r).size[0] > 0


def test_tileset_result_shows_tile_pictures():
    rs = read_model(DATA / "pipes.xml")
    sheet = png(rs)
    assert sheet.size[0] >= 8 * 48
    r = csplab.solve(rs.problem((6, 4)), "catalog", rng=0)
    img = np.asarray(png(r).convert("RGB"))
    assert np.array_equal(img, np.asarray(rs.render(r.grid)))  # the tile composite


def test_overlap_result_shows_the_reconstruction():
    m = read_model(DATA / "sample.png", N=3, symmetry=2)
    r = csplab.solve(m.problem((10, 8), periodic=True), "catalog", rng=0)
    assert r.ok
    img = png(r)
    assert img.size[0] % 10 == 0 and img.size[0] // 10 == img.size[1] // 8  # periodic: 10x8 px


def test_3d_result_picture():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rs = read_model(DATA / "pipes3d.xml")
    r = csplab.solve(rs.problem((4, 4, 3)), "catalog", rng=0)
    assert png(r).size[1] > 0
