import numpy as np
import pytest
from hypothesis import given

from csplab import ExampleModel, load_example
from csplab.errors import FormatError
from csplab.io import detect_format, read_example, write_example
from csplab.io.gridtext import format_grid, parse_grid
from csplab.testing.strategies import label_grids


@given(label_grids(max_side=4, max_labels=12, max_ndim=4))
def test_roundtrip_any_dimension(lab):
    E = ExampleModel(lab, name="t")
    E2 = parse_grid(format_grid(E))
    assert E2.shape == E.shape and np.array_equal(E2.labels, E.labels)


def test_picture_orientation_and_names():
    text = "# a comment\nlabels: air wall\n0 0 0\nwall wall 0\n"
    E = parse_grid(text)
    assert E.shape == (3, 2)
    assert E.labels[:, 0].tolist() == [1, 1, 0]  # bottom line is y = 0
    assert E.labels[:, 1].tolist() == [0, 0, 0]
    assert E.names == ("air", "wall")


def test_3d_slices_and_shape_header():
    text = "shape: 2x1x3\n1 2\n\n3 4\n\n5 6\n"
    E = parse_grid(text)
    assert E.shape == (2, 1, 3) and E.labels[1, 0, 2] == 6


@pytest.mark.parametrize(
    ("text", "line"),
    [
        ("0 1\n0\n", 2),
        ("0 1\n0 q\n", 2),
        ("0 -1\n", 1),
        ("shape: 3x3\n0 1\n1 0\n", 1),
        ("0 1\nshape: 2x1\n", 2),
        ("labels: a a\n0\n", 1),
    ],
)
def test_malformed(tmp_path, text, line):
    p = tmp_path / "m.grid"
    p.write_text(text)
    with pytest.raises(FormatError) as ei:
        read_example(p)
    assert str(p) in str(ei.value) and f"line {line}" in str(ei.value)


def test_empty_file_and_npy(tmp_path):
    p = tmp_path / "e.grid"
    p.write_text("# nothing\n")
    with pytest.raises(FormatError, match="no grid data"):
        read_example(p)
    E = load_example("line")
    q = tmp_path / "line.npy"
    write_example(E, q)
    assert read_example(q) == ExampleModel(E.labels)
    bad = tmp_path / "f.npy"
    np.save(bad, np.array([0.5]))
    with pytest.raises(FormatError):
        read_example(bad)
    junk = tmp_path / "j.npy"
    junk.write_bytes(b"not numpy")
    with pytest.raises(FormatError):
        read_example(junk)


def test_detect_format():
    assert detect_format("a.npy") == "npy"
    assert detect_format("a.grid") == "grid"
    assert detect_format("a.txt", "x\ny\nz\n2 2 1\n0 0\n0 0\n") == "merrell"
    assert detect_format("a.txt", "0 1 2 3\n0 1 2 3\n0 1 2 3\n1 2 3 4\n") == "grid"
    assert detect_format("a.txt", "# csplab grid v1\n0\n") == "grid"
