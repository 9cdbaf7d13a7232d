"""The format registry: declarations, detection, dispatch, the README table, a new format."""

import inspect
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from csplab.cli import main
from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.examples import load_model
from csplab.io import model_format, read_example, read_model, write_labels
from csplab.io.registry import (
    BEGIN,
    END,
    FORMATS,
    Format,
    Option,
    formats,
    markdown_table,
    output_extensions,
    output_format,
    resolve,
)

from ._helpers import DATA, format_sample

ROOT = Path(__file__).resolve().parents[2]


def test_readme_formats_table_is_generated_from_the_registry():
    from csplab.readme import render

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert BEGIN in text and END in text, "README.md lost its formats table markers"
    table = text[text.index(BEGIN) + len(BEGIN) : text.index(END)]
    assert table.strip() == render("formats") == markdown_table().strip(), (
        "README.md's formats table differs from csplab/io/registry.py; "
        "run: python -m csplab.readme --write"
    )


def test_readme_update_replaces_only_the_table():
    from csplab.readme import stale_sections, update

    text = f"# x\n\n{BEGIN}\nold\n{END}\n\nafter\n"
    assert "formats" in stale_sections(text)
    new = update(text)
    assert new.startswith("# x\n\n") and new.endswith(f"{END}\n\nafter\n")
    assert markdown_table().strip() in new and "formats" not in stale_sections(new)
    assert update(new) == new


@pytest.mark.parametrize("fmt", list(FORMATS.values()), ids=list(FORMATS))
def test_declarations_resolve_and_match_the_readers(fmt):
    assert fmt.description and fmt.details and fmt.example.startswith("csplab ")
    if fmt.readable:
        assert fmt.sniffer is not None, "a readable format declares a sniffer"
        assert fmt.sniff(b"") == 0 and 0 <= fmt.sniff(format_sample(fmt.name)[1]) <= 3
        reader = resolve(fmt.reader)
        params = inspect.signature(reader).parameters
        for o in fmt.options:  # the declared defaults are the reader's own
            assert params[o.name].default == o.default, (fmt.name, o.name)
            assert o.check(o.default, fmt.name) == o.default
        if not any(p.kind is p.VAR_KEYWORD for p in params.values()):
            assert set(params) - {"path"} == {o.name for o in fmt.options}
    if fmt.writable:
        assert callable(resolve(fmt.writer))


def test_extensions_of_reading_and_writing():
    assert output_extensions() == [".txt", ".grid", ".npy", ".png", ".vox", ".obj"]
    assert [output_format(f"x{e}").name for e in output_extensions()] == [
        "merrell", "grid", "npy", "png", "vox", "obj",
    ]  # fmt: skip
    assert {f.name for f in formats(readable=True)} >= {"wfc", "markovjunior", "overlapping"}
    for f in formats(readable=True):
        for e in f.extensions:  # every readable extension leads to a readable format
            assert any(g.readable and e in g.extensions for g in FORMATS.values())


PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("name", "data", "want"),
    [
        ("a.txt", b"house\n\n\n3 3 2\n1 1 1\n", "merrell"),
        ("a.txt", b"nonsense", "merrell"),  # the first format of .txt
        ("a.txt", b"# csplab grid v1\n0 1\n", "grid"),
        ("a.txt", b"0 1 2 3\n0 1 2 3\n0 1 2 3\n1 2 3 4\n", "grid"),
        ("a.grid", b"<set/>", "grid"),  # one format claims .grid: no sniffing
        ("a.npy", b"junk", "npy"),
        ("a.xml", b"<set/>", "wfc"),
        ("a.XML", b'<?xml version="1.0"?><!-- c -->\n<tileset/>', "markovjunior"),
        ("a.xml", b"junk", "wfc"),
        ("a.json", b'{"rule": [[0, 0, 0, 1]]}', "poms"),
        ("a.json", b'// c\n{"tiles": []}', "debroglie"),
        ("a.gif", b"GIF89a", "overlapping"),
        ("noext", PNG, "overlapping"),
        ("noext", b"VOX \x96\x00\x00\x00", "vox"),
        ("noext", b"\x93NUMPY\x01\x00", "npy"),
        ("noext", b"<tileset/>", "markovjunior"),
        ("noext", b"\xef\xbb\xbf <set/>", "wfc"),
        ("noext", b'{"rule": []}', "poms"),
        ("noext", b"/* c */ {}", "debroglie"),
        ("noext", b"x\ny\nz\n2 2 1\n0 0\n0 0\n", "merrell"),
        ("noext", b"0 1\n1 0\n", "grid"),  # nothing recognises it: the fallback
    ],
)
def test_detection(tmp_path, name, data, want):
    p = tmp_path / name
    p.write_bytes(data)
    assert model_format(p) == want


def test_wrong_kind_of_file_is_one_clear_error(tmp_path):
    (tmp_path / "m.obj").write_text("v 0 0 0\n")
    with pytest.raises(FormatError, match=r"no faces .*reads \.obj files only as polyhedral"):
        read_model(tmp_path / "m.obj")
    with pytest.raises(FormatError, match=r"\.xml files are read as .*not as example grids"):
        read_example(DATA / "pipes.xml")
    with pytest.raises(InputError, match="does not read"):
        read_model(DATA / "sample.png", format="png")
    with pytest.raises(InputError, match="unknown model format 'zip'"):
        read_model(DATA / "sample.png", format="zip")
    with pytest.raises(InputError, match=r"unknown output format '\.stl'.*use \.txt"):
        write_labels(np.zeros((2, 2), np.int32), tmp_path / "o.stl")
    with pytest.raises(InputError, match=r"unassigned cells; write it as \.npy, \.png"):
        write_labels(np.full((2, 2), -1, np.int32), tmp_path / "o.txt")


def test_options_are_checked_and_converted():
    m = read_model(DATA / "sample.png", N="2", symmetry=1.0, periodic_input="true")
    assert m.N == 2
    assert read_model(DATA / "pipes.xml", images="false").images is None
    for bad, what in (
        ({"N": "two"}, "N='two' of overlapping files must be an integer"),
        ({"N": 2.5}, "must be an integer"),
        ({"periodic_input": "maybe"}, "must be true or false"),
        ({"ground": "maybe"}, "ground='maybe' of overlapping files must be true"),
        ({"n": 3}, r"\['n'\] do not apply to overlapping files \(options: N, ground"),
    ):
        with pytest.raises(InputError, match=what):
            read_model(DATA / "sample.png", **bad)
    with pytest.raises(InputError, match="one of auto, y, z"):
        read_model(DATA / "tiny_poms.json", up="w")
    assert Option("subset", str, None, "").check(None, "wfc") is None


def test_load_model_warns_and_never_prints(capsys):
    with pytest.warns(UserWarning, match="no tile pictures"):
        rs = load_model(DATA / "tiny_debroglie.json")
    assert rs.warnings and capsys.readouterr() == ("", "")
    assert load_model("line").name == "line"
    with pytest.raises(InputError, match="model files only"):
        load_model("line", {"N": 2})
    with pytest.raises(FormatError, match="no such file"):
        load_model("missing.txt")
    with pytest.raises(InputError, match="neither a model file nor a built-in example"):
        load_model("nosuchmodel")


TOY = """
from pathlib import Path

import numpy as np

from csplab.errors import FormatError
from csplab.example import ExampleModel
from csplab.io.common import NO, SURE, read_text


def sniff(head):
    return SURE if head.startswith(b"TOY ") else NO


def read(path, *, scale=1):
    words = read_text(path).split()
    try:
        ndim = int(words[1])
        shape = [int(w) for w in words[2 : 2 + ndim]]
        grid = np.array([int(w) for w in words[2 + ndim :]]).reshape(shape) * scale
    except (IndexError, ValueError) as e:
        raise FormatError(f"not a toy grid ({e})", path=path) from None
    return ExampleModel(grid, name=Path(path).stem, meta={"format": "toy"})


def write(out, path):
    g = out.grid
    Path(path).write_text(" ".join(["TOY", str(g.ndim), *map(str, g.shape), *map(str, g.ravel())]))
"""


def test_a_new_format_is_its_module_and_one_entry(tmp_path, monkeypatch, capsys):
    (tmp_path / "toyfmt.py").write_text(TOY)
    monkeypatch.syspath_prepend(str(tmp_path))
    toy = Format(
        name="toy", extensions=(".toy",), gives="ExampleModel", description="toy grids",
        reader="toyfmt:read", writer="toyfmt:write", sniffer="toyfmt:sniff",
        options=(Option("scale", int, 1, "multiply the labels"),),
        details="whitespace-separated numbers", example="csplab show x.toy",
    )  # fmt: skip
    monkeypatch.setitem(FORMATS, "toy", toy)
    g = np.array([[0, 1, 2], [2, 1, 0]], dtype=np.int32)
    write_labels(g, tmp_path / "g.toy")
    (tmp_path / "g").write_bytes((tmp_path / "g.toy").read_bytes())
    assert model_format(tmp_path / "g.toy") == model_format(tmp_path / "g") == "toy"
    assert np.array_equal(read_model(tmp_path / "g", scale=2).labels, 2 * g)
    with pytest.raises(InputError, match="scale='x' of toy files must be an integer"):
        read_model(tmp_path / "g.toy", scale="x")
    assert isinstance(read_example(tmp_path / "g.toy"), ExampleModel)
    assert "| toy grids (`toy`) | `.toy` |" in markdown_table()
    assert ".toy" in output_extensions(gives="ExampleModel")
    name, data = format_sample("toy")  # what the fuzz test gets
    assert name == "sample.toy" and data.startswith(b"TOY 3 3 3 2 ")
    assert main(["info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert {"name": "scale", "type": "int", "default": 1, "doc": "multiply the labels"} in next(
        f["options"] for f in info["formats"] if f["name"] == "toy"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["show", str(tmp_path / "g.toy"), "--out", str(tmp_path / "g.png")]) == 0
    assert "2x3 grid g" in capsys.readouterr().out
