"""Resemblance figures of polyhedral outputs (csplab.continuous.resemblance), planted."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("trimesh")
pytest.importorskip("manifold3d")

from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.resemblance import floating_solids, resemblance
from csplab.io import read_model
from csplab.testing import cad
from tests._meshes import box


def _model(*solids):
    return PolyhedralModel(list(solids))


def _read(tmp_path, name):
    return read_model(cad.export(cad.build(name), tmp_path / f"{name}.stl"))


@pytest.mark.parametrize("name", ["engraved", "holes", "chamfered", "slanted", "lathe"])
def test_a_model_resembles_itself_fully(tmp_path, name):
    m = _read(tmp_path, name)
    r = resemblance(m, m)
    assert (r.edge_kinds, r.face_orientations, r.median_volume_ratio) == (1.0, 1.0, 1.0)
    assert r.solids == r.example_solids == 1 and r.floating == r.example_floating == 0
    assert r.example_edge_kinds > 0 and r.example_face_orientations > 0


def test_a_floating_box_counts_one_and_stacked_boxes_none():
    ex = _model(box(1, [0, 0, 0], [2, 2, 1]))
    stack = _model(box(1, [0, 0, 0], [4, 4, 1]), box(1, [1, 1, 1], [2, 2, 3]),
                   box(1, [1, 1, 3], [2, 2, 4]))  # fmt: skip
    assert floating_solids(stack) == []
    one = _model(*[box(1, lo, hi) for lo, hi in [([0, 0, 0], [4, 4, 1]), ([1, 1, 2], [2, 2, 3])]])
    assert floating_solids(one) == [1]
    r = resemblance(ex, one)
    assert (r.floating, r.example_floating) == (1, 0)


def test_a_box_on_a_slope_rests_on_it(tmp_path):
    # a tetrahedron's slanted face holds the lowest vertex of a small tetrahedron on it
    v = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], float)
    big = {"label": 1, "vertices": v, "faces": [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]}
    p = np.array([1.0, 1.0, 2.0])  # on the face x + y + z = 4
    up = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]], float)
    small = {"label": 2, "vertices": p + up,
             "faces": [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]}  # fmt: skip
    m = PolyhedralModel([big, small])
    assert floating_solids(m) == []


def test_touching_boxes_make_no_edges_and_tiny_boxes_a_small_volume_ratio():
    ex = _model(box(1, [0, 0, 0], [4, 2, 2]))
    # two 2x2x2 cubes side by side: their union is the example
    cubes = _model(*[box(1, [x, 0, 0], [x + 2, 2, 2]) for x in (0, 2)])
    r = resemblance(ex, cubes)
    assert (r.edge_kinds, r.face_orientations, r.solids) == (1.0, 1.0, 2)
    assert r.median_volume_ratio == pytest.approx(0.5)
    tiny = _model(*[box(1, [x, 0, 0], [x + 1, 1, 1]) for x in range(0, 8, 2)])
    assert resemblance(ex, tiny).median_volume_ratio == pytest.approx(1 / 16)


def test_a_turned_copy_shares_only_the_horizontal_orientations(tmp_path):
    import trimesh

    m = cad.build("bevelled")
    turned = m.copy()
    turned.apply_transform(trimesh.transformations.rotation_matrix(0.3, [0, 0, 1]))
    a = read_model(cad.export(m, tmp_path / "a.stl"))
    b = read_model(cad.export(turned, tmp_path / "b.stl"))
    r = resemblance(a, b)
    # up and down survive a turn about z; the 4 sides and 4 bevels do not
    assert r.example_face_orientations == 10
    assert r.face_orientations == pytest.approx(2 / 10)
    assert r.edge_kinds == 0.0
