"""3D previews: faces shaded by orientation, labels coloured by object, a legend."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from csplab.example import ExampleModel
from csplab.render import label_objects, model_objects, object_colors, palette, render

S = 20  # pixels per cell


def _px(
    img: Image.Image, shape: tuple[int, int, int], x: float, y: float, z: float
) -> tuple[int, ...]:
    """The pixel at the projection of the point (x, y, z) (as ``_render_3d`` projects)."""
    _, ny, nz = shape
    a, b, c = S * 0.866, S * 0.5, S * 1.0
    u, v = ny * a + 2 + (x - y) * a, nz * c + 2 + (x + y) * b - z * c
    px = img.getpixel((int(u), int(v)))
    assert isinstance(px, tuple)
    return px


def _voxels(labels: dict[tuple[int, int, int], int], shape: tuple[int, int, int]) -> np.ndarray:
    g = np.zeros(shape, dtype=np.int64)
    for k, v in labels.items():
        g[k] = v
    return g


def test_faces_of_a_voxel_get_three_brightnesses_top_brightest() -> None:
    shape = (1, 1, 2)
    img = render(_voxels({(0, 0, 0): 1}, shape), scale=S, empty=0)
    top = _px(img, shape, 0.5, 0.5, 1)
    side_x = _px(img, shape, 1, 0.5, 0.5)
    side_y = _px(img, shape, 0.5, 1, 0.5)
    assert top == tuple(int(v) for v in palette(2)[1])
    bright = [sum(top), sum(side_x), sum(side_y)]
    assert bright[0] > bright[1] > bright[2]


def test_labels_of_one_object_share_a_colour() -> None:
    shape = (3, 1, 2)
    g = _voxels({(0, 0, 0): 1, (1, 0, 0): 2, (2, 0, 0): 3}, shape)
    objects = ["air", "wall", "wall", "roof"]
    img = render(g, scale=S, empty=0, objects=objects)
    tops = [_px(img, shape, x + 0.5, 0.5, 1) for x in range(3)]
    assert tops[0] == tops[1] != tops[2]
    # without objects every label has its own colour
    plain = render(g, scale=S, empty=0)
    assert len({_px(plain, shape, x + 0.5, 0.5, 1) for x in range(3)}) == 3


def test_object_names_from_merrell_table_and_tile_names() -> None:
    trailer = "<Objects>\n0 empty\n1 objs/wall.obj\n2 wall.obj 90\n3 door.obj\n"
    assert label_objects(4, trailer=trailer) == ["empty", "wall", "wall", "door"]
    E = ExampleModel(np.array([[[1, 0]], [[2, 0]], [[3, 0]]]), meta={"merrell_trailer": trailer})
    cols = object_colors(model_objects(E) or [])
    assert (cols[1] == cols[2]).all() and not (cols[1] == cols[3]).all()
    assert label_objects(3, names=["corner 0", "corner 3", "line 1"]) == [
        "corner",
        "corner",
        "line",
    ]
    assert label_objects(2, names=["air", "brick_edge_n"]) == ["air", "brick"]
    assert model_objects(ExampleModel([[0, 1]])) is None


def test_all_distinct_objects_keep_the_palette_so_2d_pictures_are_unchanged() -> None:
    g = np.array([[0, 1, 2], [2, 1, 0]])
    a = np.asarray(render(g, scale=3))
    b = np.asarray(render(g, scale=3, objects=["a", "b", "c"]))
    assert (a == b).all()
    assert (object_colors(["a", "b", "c"]) == palette(3)).all()


def test_legend_shows_each_drawn_object_once() -> None:
    shape = (3, 1, 2)
    g = _voxels({(0, 0, 0): 1, (1, 0, 0): 2, (2, 0, 0): 3}, shape)
    objects = ["air", "wall", "wall", "roof"]
    plain = render(g, scale=S, empty=0, objects=objects)
    img = render(g, scale=S, empty=0, objects=objects, legend=True)
    assert img.width > plain.width
    panel = np.asarray(img)[:, plain.width :]
    cols = object_colors(objects)
    for b in (1, 3):  # the swatches of wall and roof
        assert (panel == cols[b]).all(axis=2).sum() >= 50
    # only what is drawn: no roof in the grid, no roof in the legend
    g[2, 0, 0] = 0
    panel = np.asarray(render(g, scale=S, empty=0, objects=objects, legend=True))[:, plain.width :]
    assert (panel == cols[1]).all(axis=2).sum() >= 50
    assert (panel == cols[3]).all(axis=2).sum() == 0


def test_tileset_orientations_share_a_colour() -> None:
    from csplab.examples import load_model
    from csplab.io.ruleset import RuleSet

    R = load_model(Path(__file__).parent / "io" / "data" / "pipes.xml", {"images": False})
    assert isinstance(R, RuleSet) and R.images is None and R.colors is None
    c = R.label_colors()
    i, j, k = R.names.index("corner 0"), R.names.index("corner 3"), R.names.index("line 0")
    assert (c[i] == c[j]).all() and not (c[i] == c[k]).all()


def test_notebook_picture_of_a_merrell_model_uses_its_object_table() -> None:
    import io

    trailer = "0 empty\n1 wall.obj\n2 wall.obj\n3 door.obj\n"
    lab = np.zeros((3, 1, 2), dtype=np.int64)
    lab[:, 0, 0] = [1, 2, 3]
    E = ExampleModel(lab, meta={"merrell_trailer": trailer})
    png = E._repr_png_()
    with Image.open(io.BytesIO(png)) as img:
        got = np.asarray(img.convert("RGB"))
    want = np.asarray(render(lab, objects=label_objects(4, trailer=trailer)))
    assert got.shape == want.shape and (got == want).all()
