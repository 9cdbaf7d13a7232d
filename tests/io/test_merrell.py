import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel
from csplab.errors import CsplabError, FormatError
from csplab.io import read_example, write_example
from csplab.io.merrell import format_merrell, parse_merrell
from csplab.testing.strategies import label_grids


@given(label_grids(ndim=3, max_side=5, max_labels=12), st.text(max_size=40))
def test_roundtrip_preserves_labels_and_trailer(lab, trailer_word):
    trailer = "".join(ch for ch in trailer_word if ch.isprintable()) + "\n"
    E = ExampleModel(lab, meta={"merrell_trailer": "objects:\n" + trailer})
    text = format_merrell(E)
    E2 = parse_merrell(text)
    assert np.array_equal(E2.labels, E.labels)
    assert E2.meta["merrell_trailer"] == "objects:\n" + trailer
    assert format_merrell(E2) == text


def test_order_is_z_then_x_then_y():
    text = "h1\nh2\nh3\n2 3 2\n1 2 3\n4 5 6\n\n7 8 9\n10 11 12\n"
    E = parse_merrell(text)
    assert E.shape == (2, 3, 2)
    assert E.labels[:, :, 0].tolist() == [[1, 2, 3], [4, 5, 6]]
    assert E.labels[1, 2, 1] == 12


def test_tolerates_whitespace_and_keeps_header(tmp_path):
    text = (
        "Castle wall  \n  by hand\n\n  2   2 1   extra words \n 0   1  \n\t1 0   \n"
        "\n0 empty\n1 wall.obj\n"
    )
    p = tmp_path / "castle.txt"
    p.write_text(text)
    E = read_example(p)
    assert E.labels[:, :, 0].tolist() == [[0, 1], [1, 0]]
    assert E.meta["merrell_header"][0] == "Castle wall  "
    assert E.meta["merrell_trailer"] == "\n0 empty\n1 wall.obj\n"
    out = tmp_path / "again.txt"
    write_example(E, out)
    assert read_example(out) == E
    assert out.read_text().endswith("0 empty\n1 wall.obj\n")


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        ("a\nb\nc\n2 2 1\n0 1\n1\n", 6, "ends after 3"),
        ("a\nb\nc\n2 2 1\n0 1\n1 x\n", 6, "not an integer"),
        ("a\nb\nc\n2 2 1\n0 1\n1 -3\n", 6, "negative"),
        ("a\nb\nc\nx y z\n0\n", 4, "size line"),
        ("a\nb\n", 2, "header"),
        ("a\nb\nc\n2 0 1\n", 4, "positive"),
        ("a\nb\nc\n1 2 1\n0 1 5\n", 5, "extra value"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, text, line, what):
    p = tmp_path / "bad.txt"
    p.write_text(text)
    with pytest.raises(FormatError) as ei:
        read_example(p)
    msg = str(ei.value)
    assert str(p) in msg and f"line {line}" in msg and what in msg
    assert isinstance(ei.value, CsplabError) and isinstance(ei.value, ValueError)


def test_missing_file_and_too_many_dims(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        read_example(tmp_path / "nope.txt")
    with pytest.raises(FormatError):
        format_merrell(ExampleModel(np.zeros((2, 2, 2, 2), dtype=int)))
