"""Resemblance figures of polygon outputs (csplab.continuous.resemblance.resemblance),
planted by hand, and printed by ``synthesize --json`` for 2D as for 3D."""

from __future__ import annotations

import json

import pytest

from csplab.continuous.model import PolygonModel
from csplab.continuous.resemblance import floating_polygons, resemblance


def _model(*rings, label=1):
    return PolygonModel.from_json({"polygons": [{"label": label, "points": r} for r in rings]})


NOTCHED = [[0, 0], [4, 0], [4, 4], [3, 4], [2, 2], [1, 4], [0, 4]]  # a V notch on top


def test_a_notched_square_resembles_itself_and_a_square_lacks_the_notch():
    ex = _model(NOTCHED)
    r = resemblance(ex, ex)
    assert (r.edge_kinds, r.face_orientations, r.median_volume_ratio) == (1.0, 1.0, 1.0)
    # directions: down, right, up, left and the notch's two; corners: the square's four,
    # up/notch twice (convex) and the notch's bottom (reflex)
    assert (r.example_face_orientations, r.example_edge_kinds) == (6, 7)
    sq = resemblance(ex, _model([[0, 0], [2, 0], [2, 2], [0, 2]]))
    assert sq.face_orientations == pytest.approx(4 / 6) and sq.edge_kinds == pytest.approx(4 / 7)
    assert sq.median_volume_ratio == pytest.approx(4 / 14)


def test_a_reflex_corner_is_not_a_convex_one():
    ex = _model([[0, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4]])  # an L: one reflex corner
    mirror = _model([[0, 0], [2, 0], [2, 2], [4, 2], [4, 4], [0, 4]])  # reflex facing down-right
    r = resemblance(ex, mirror)
    # the L's corners: down/left, down/right, up/left convex, right/up convex (twice) and
    # reflex; the mirror has the four convex ones and a reflex down/right instead
    assert r.face_orientations == 1.0 and r.example_edge_kinds == 5
    assert r.edge_kinds == pytest.approx(4 / 5)


def test_polygons_on_the_ground_on_posts_and_on_slopes_rest_and_others_float():
    posts = _model([[0, 0], [10, 0], [10, 5], [0, 5]], [[1, 5], [4, 5], [4, 7], [1, 7]],
                   [[6, 5], [9, 5], [9, 7], [6, 7]], [[0, 7], [10, 7], [10, 12], [0, 12]])
    assert floating_polygons(posts) == []  # the top slab overhangs its posts: it rests
    slope = _model([[0, 0], [4, 0], [0, 4]], [[1, 3], [2, 3], [1.5, 4]])  # tip on x + y = 4
    assert floating_polygons(slope) == []
    air = _model([[0, 0], [4, 0], [4, 1], [0, 1]], [[5, 2], [6, 2], [6, 3], [5, 3]])
    assert floating_polygons(air) == [1]
    assert floating_polygons(air, ground=2.0) == [0]  # a ground at y = 2 holds the other
    r = resemblance(posts, air)
    assert (r.floating, r.example_floating, r.solids, r.example_solids) == (1, 0, 2, 4)


def test_synthesize_json_prints_the_2d_figures_of_its_output(tmp_path, capsys):
    from csplab.cli import main
    from csplab.examples import load_model
    from csplab.io import read_model

    out = tmp_path / "out.json"
    assert main(["synthesize", "two_objects", "--size", "12x12", "--seed", "1", "--json",
                 "--out", str(out)]) == 0  # fmt: skip
    d = json.loads(capsys.readouterr().out)
    r = d["resemblance"]
    assert set(r) == {"solids", "example_solids", "median_volume_ratio", "edge_kinds",
                      "example_edge_kinds", "face_orientations", "example_face_orientations",
                      "floating", "example_floating"}  # fmt: skip
    assert r["solids"] == d["polygons"] and r["example_solids"] == 2
    assert r == resemblance(load_model("two_objects"), read_model(out)).to_dict()


def test_models_of_two_dimensions_are_refused():
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.errors import InputError

    square = PolygonModel.from_json({"polygons": [
        {"label": 1, "points": [[0, 0], [1, 0], [1, 1], [0, 1]]}]})  # fmt: skip
    tet = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                            "faces": [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]}])  # fmt: skip
    with pytest.raises(InputError, match="PolygonModel with a PolyhedralModel"):
        resemblance(square, tet)
