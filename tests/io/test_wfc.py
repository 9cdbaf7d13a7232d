import shutil

import numpy as np
import pytest

import csplab
from csplab.errors import CsplabError, FormatError
from csplab.io import model_format, read_model
from csplab.io.symmetry import Orientations, square_group
from csplab.io.wfc import _ORDER, _STAB, CARDINALITY, parse_wfc, read_wfc, wfc_action

from ._helpers import DATA, installed_solvers


def edge_compat(images):
    """T from the pictures alone: a pipe pixel in the middle of a's right edge iff one in the
    middle of b's left edge (rows top to bottom, so 'up' is row 0)."""
    dark = images[..., :3].sum(axis=-1) < 200
    r, l_, u, d = dark[:, 2, -1], dark[:, 2, 0], dark[:, 0, 2], dark[:, -1, 2]
    Tx = r[:, None] == l_[None, :]
    Ty = u[:, None] == d[None, :]  # b above a: a's top meets b's bottom
    return np.stack([Tx, Ty])


def test_pipes_rules_match_the_pictures():
    rs = read_wfc(DATA / "pipes.xml")
    assert model_format(DATA / "pipes.xml") == "wfc"
    assert rs.K == 1 + 2 + 4 + 4 + 1
    assert rs.names[:4] == ("empty 0", "line 0", "line 1", "corner 0")
    assert rs.images is not None and rs.images.shape == (12, 5, 5, 4)
    assert np.array_equal(rs.relations, edge_compat(rs.images))
    assert rs.closure_violations() == [] and rs.warnings == []
    assert rs.weights.tolist() == [1, 2, 2, 1, 1, 1, 1, 0.5, 0.5, 0.5, 0.5, 0.25]


def test_subset_keeps_only_its_tiles():
    rs = read_model(DATA / "pipes.xml", subset="straight")
    assert rs.names == ("empty 0", "line 0", "line 1", "cross 0")
    with pytest.raises(FormatError, match="no subset 'nope'; subsets: straight"):
        read_wfc(DATA / "pipes.xml", subset="nope")


@pytest.mark.parametrize("solver", installed_solvers())
def test_every_solver_gives_valid_pipes(solver):
    rs = read_wfc(DATA / "pipes.xml")
    P = rs.problem((12, 10), boundary={f: 0 for f in ("x-", "x+", "y-", "y+")})
    r = csplab.solve(P, solver, rng=3)
    assert r.status in ("solved", "failed", "timeout")
    if r.ok:
        assert P.violations(r.grid).arcs.size == 0
        img = np.asarray(rs.render(r.grid, scale=1))
        assert img.shape == (50, 60, 3)
        # every drawn pipe continues into its neighbour: compare pixels across tile borders
        dark = img.sum(axis=-1) < 200
        assert np.array_equal(dark[:, 4::5][:, :-1], dark[:, 5::5])
        assert np.array_equal(dark[4::5][:-1], dark[5::5])


def test_picture_orientation_y_up():
    rs = read_wfc(DATA / "pipes.xml")
    g = np.zeros((2, 2), dtype=int)
    g[0, 1] = rs.names.index("cross 0")  # x = 0, y = 1: top-left in the picture
    img = np.asarray(rs.render(g, scale=1))
    assert img[2, 2].sum() < 200 and img[7, 2].sum() > 600  # top-left tile holds the cross


def test_unique_tileset_and_symmetry_warning(tmp_path):
    xml = (
        '<set unique="True"><tiles><tile name="arrow" symmetry="T"/><tile name="dot"/></tiles>'
        '<neighbors><neighbor left="arrow 1" right="dot"/><neighbor left="dot" right="dot"/>'
        "</neighbors></set>"
    )
    (tmp_path / "u.xml").write_text(xml)
    (tmp_path / "u").mkdir()
    from PIL import Image

    for k in range(4):
        a = np.full((3, 3, 3), 255, np.uint8)
        a[k % 3, 0] = 0
        Image.fromarray(a).save(tmp_path / "u" / f"arrow {k}.png")
    Image.fromarray(np.zeros((3, 3, 3), np.uint8)).save(tmp_path / "u" / "dot 0.png")
    rs = read_wfc(tmp_path / "u.xml")
    assert rs.K == 5 and rs.images is not None
    assert rs.images[1, 1, 0, 0] == 0  # "arrow 1.png" is used as is
    # a non-unique tile declared symmetric whose picture is not
    (tmp_path / "v.xml").write_text(xml.replace(' unique="True"', ""))
    (tmp_path / "v").mkdir()
    bad = np.full((3, 3, 3), 255, np.uint8)
    bad[0, 0] = 0
    Image.fromarray(bad).save(tmp_path / "v" / "arrow.png")
    Image.fromarray(bad).save(tmp_path / "v" / "dot.png")
    with pytest.warns(UserWarning, match="declared symmetry"):
        rs2 = read_wfc(tmp_path / "v.xml")
    assert any("declared symmetry T" in w for w in rs2.warnings)


def test_without_images_colours_are_used(tmp_path):
    shutil.copy(DATA / "pipes.xml", tmp_path / "p.xml")
    with pytest.warns(UserWarning, match="no tile pictures"):
        rs = read_wfc(tmp_path / "p.xml")
    assert rs.images is None
    assert rs.render(np.zeros((3, 3), int)).size[0] > 0


@pytest.mark.parametrize(
    ("xml", "line", "what"),
    [
        ('<set><tiles><tile name="a"/>\n<tile name="a"/></tiles><neighbors/></set>', 2, "twice"),
        ('<set><tiles>\n<tile name="a" symmetry="Q"/></tiles><neighbors/></set>', 2, "symmetry"),
        ('<set><tiles><tile name="a"/></tiles><neighbors>\n<neighbor left="a 8" right="a"/>'
         "</neighbors></set>", 2, "orientation 8 is not 0..7"),
        ('<set><tiles><tile name="a"/></tiles><neighbors>\n<neighbor left="a -1" right="a"/>'
         "</neighbors></set>", 2, "orientation -1 is not 0..7"),
        ('<set><tiles><tile name="a"/></tiles><neighbors>\n\n<neighbor left="b" right="a"/>'
         "</neighbors></set>", 3, "unknown tile"),
        ('<set><tiles><tile name="a" weight="-1"/></tiles><neighbors/></set>', 1, "non-negative"),
        ('<set><tiles><tile name="a"/></tiles>\n<neighbors><neighbor left="a"/></neighbors></set>',
         2, "no 'right'"),
        ("<set><tiles>\n<tile name='a'></set>", 2, "not well-formed"),
        ('<!DOCTYPE set [<!ENTITY e "x">]><set/>', 1, "DOCTYPE"),
    ],
)  # fmt: skip
def test_errors_name_the_line(xml, line, what):
    with pytest.raises(FormatError, match=what) as e:
        parse_wfc(xml, path="bad.xml")
    assert e.value.line == line and "bad.xml" in str(e.value)
    assert isinstance(e.value, CsplabError)


def test_unknown_xml_encoding_is_a_format_error():
    """expat asks Python's codecs for the declared encoding (found by the fuzz test)."""
    with pytest.raises(FormatError, match="unknown XML encoding") as e:
        parse_wfc(b'<?xml version="1.0" encoding="ATF-8"?><set/>', path="bad.xml")
    assert "bad.xml" in str(e.value)


@pytest.mark.parametrize("sym", list(CARDINALITY))
def test_wfc_action_table_is_the_group_action(sym):
    """WFC's table (its maps a, b on orientation indices) agrees with csplab's group: entry
    [t][k] is orientation t transformed by the k-th symmetry."""
    G = square_group()
    O = Orientations(
        G, [G.subgroup(_STAB[sym])], [[G.index(w) for w in _ORDER[: CARDINALITY[sym]]]]
    )
    table = wfc_action(sym)
    assert len(table) == CARDINALITY[sym] and all(len(r) == 8 for r in table)
    for t, row in enumerate(table):
        assert row == [int(O.perm[G.index(w), t]) for w in _ORDER]


def test_indices_beyond_the_orientations_as_wfc_resolves_them():
    with pytest.warns(UserWarning, match="no tile pictures found"):
        beyond = read_wfc(DATA / "wfc_index" / "beyond.xml")
    within = read_wfc(DATA / "wfc_index" / "within.xml", images=False)
    assert beyond.names == within.names
    assert np.array_equal(beyond.relations, within.relations)
    assert beyond.relations.any() and beyond.closure_violations() == []
    # "line 3" of a symmetry-I tile (2 orientations) is "line 1", not an error
    xml = (
        '<set><tiles><tile name="line" symmetry="I"/><tile name="e"/></tiles><neighbors>'
        '<neighbor left="line K" right="e"/></neighbors></set>'
    )
    one = parse_wfc(xml.replace("K", "3"))
    assert one.names == ("line 0", "line 1", "e 0")
    assert np.array_equal(one.relations, parse_wfc(xml.replace("K", "1")).relations)
    assert one.relations[0, 1, 2] and not one.relations[0, 0, 2]


def test_missing_pictures_are_reported(tmp_path):
    shutil.copy(DATA / "pipes.xml", tmp_path / "p.xml")
    with pytest.warns(UserWarning, match=r"no tile pictures found \(looked for p/empty.png"):
        rs = read_wfc(tmp_path / "p.xml")
    assert rs.images is None and any("one colour per tile" in w for w in rs.warnings)
    rs = read_wfc(tmp_path / "p.xml", images=False)  # not asked for: nothing to say
    assert rs.warnings == []
