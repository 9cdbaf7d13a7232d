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


# a small example of Merrell's layout with an object table after the labels (made for these
# tests: a wall of labels 1 on the ground 0, air 2 above)
_WITH_TABLE = (
    "wall\nmade for csplab's tests\n\n3 3 2\n0 0 0\n0 1 0\n0 0 0\n2 2 2\n2 1 2\n2 2 2\n"
    "<Objects>\n0 ground.obj 0\n1 wall.obj 0\n2 EMPTY\n</Objects>\n"
)


def test_results_carry_the_object_table(tmp_path):
    import csplab
    from csplab.io import write_labels

    src = tmp_path / "wall.txt"
    src.write_text(_WITH_TABLE)
    E = read_example(src)
    trailer = E.meta["merrell_trailer"]
    assert trailer.startswith("<Objects>\n0 ground.obj")
    r = csplab.solve(csplab.from_example(E, (5, 4, 2)), "catalog", rng=1)
    assert r.ok
    out = tmp_path / "out.txt"
    write_labels(r.grid, out, name=E.name, model=E)
    again = read_example(out)
    assert np.array_equal(again.labels, r.grid)
    assert again.meta["merrell_trailer"] == trailer
    assert out.read_text().endswith(trailer)
    # a model without a table writes none; meta given by the caller wins
    write_labels(r.grid, out, model=ExampleModel(E.labels))
    assert read_example(out).meta["merrell_trailer"] == ""
    write_labels(r.grid, out, model=E, meta={"merrell_trailer": "<Objects>\nmine\n"})
    assert read_example(out).meta["merrell_trailer"] == "<Objects>\nmine\n"


def test_cli_output_carries_the_object_table(tmp_path, capsys):
    from csplab.cli import main

    src = tmp_path / "wall.txt"
    src.write_text(_WITH_TABLE)
    out = tmp_path / "out.txt"
    code = main(["synthesize", str(src), "--size", "4x4x2", "--seed", "2", "--out", str(out)])
    capsys.readouterr()
    assert code == 0
    assert out.read_text().endswith(
        "<Objects>\n0 ground.obj 0\n1 wall.obj 0\n2 EMPTY\n</Objects>\n"
    )
