import shutil

import numpy as np
import pytest

import csplab
from csplab.errors import FormatError
from csplab.io import model_format, read_model
from csplab.io.markovjunior import parse_markovjunior, read_markovjunior, transform_voxels
from csplab.io.symmetry import cube_group

from ._helpers import DATA, anchor, installed_solvers

FACES = [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)]


def socket_relation(rs, sockets):
    """T from the tile voxels: an arm voxel at the middle of a's +d face iff one at the middle
    of b's -d face."""
    T = np.zeros_like(rs.relations)
    for d in range(3):
        hi = [1, 1, 1]
        lo = [1, 1, 1]
        hi[d], lo[d] = 2, 0
        a = np.array([s[tuple(hi)] > 0 for s in sockets])
        b = np.array([s[tuple(lo)] > 0 for s in sockets])
        T[d] = a[:, None] == b[None, :]
    return T


def test_voxel_tiles_give_exact_symmetries_and_rules():
    rs = read_markovjunior(DATA / "pipes3d.xml")
    assert model_format(DATA / "pipes3d.xml") == "markovjunior"
    assert rs.meta["symmetry_source"] == "voxel data"
    assert rs.meta["orientations"] == {"Empty": 1, "Line": 3, "Turn": 12}
    assert rs.warnings == [] and rs.closure_violations() == []
    # every label's voxels: the base tile turned by its orientation
    from csplab.io.vox import read_vox

    G = cube_group()
    base = {n: read_vox(DATA / "pipes3d" / f"{n}.vox").grid for n in ("Empty", "Line", "Turn")}
    vox = []
    for name in rs.names:
        word, _, tile = name.rpartition(" ")
        vox.append(transform_voxels(base[tile], G.elements[G.index(word)]))
    assert np.array_equal(rs.relations, socket_relation(rs, vox))
    assert rs.empty == 0


def test_inferred_symmetries_match_the_voxels(tmp_path):
    shutil.copy(DATA / "pipes3d.xml", tmp_path / "pipes3d.xml")  # without the .vox tiles
    with pytest.warns(UserWarning, match="inferred"):
        inferred = read_markovjunior(tmp_path / "pipes3d.xml")
    exact = read_markovjunior(DATA / "pipes3d.xml")
    assert inferred.names == exact.names
    assert np.array_equal(inferred.relations, exact.relations)


def test_knots3d_shared_file():
    p = anchor("MarkovJunior/Knots3D.xml")
    with pytest.warns(UserWarning):
        rs = read_model(p)
    assert rs.meta["orientations"] == {"Empty": 1, "Line": 3, "Turn": 12}
    assert rs.closure_violations() == []
    # Knots3D states the same geometry as our pipes: the same closed rule set
    exact = read_markovjunior(DATA / "pipes3d.xml")
    assert np.array_equal(rs.relations, exact.relations)


@pytest.mark.parametrize("solver", installed_solvers())
def test_knots3d_every_solver_20x20x10(solver):
    p = anchor("MarkovJunior/Knots3D.xml")
    with pytest.warns(UserWarning):
        rs = read_model(p)
    P = rs.problem((20, 20, 10), boundary={f"{a}{s}": 0 for a in "xyz" for s in "-+"})
    r = csplab.solve(P, solver, rng=1)
    assert r.ok and P.is_solution(r.grid)


def test_square_symmetry_top_bottom():
    xml = (
        "<tileset><tiles><tile name='A'/><tile name='B'/></tiles><neighbors>"
        "<neighbor left='A' right='z B'/><neighbor top='A' bottom='B'/></neighbors></tileset>"
    )
    with pytest.warns(UserWarning):
        rs = parse_markovjunior(xml, path="sq.xml")
    assert rs.meta["full_symmetry"] is False
    iA, iB = rs.names.index("A"), [i for i, n in enumerate(rs.names) if n.endswith("B")]
    assert all(rs.relations[2, b, iA] for b in iB if rs.names[b] == "B")


@pytest.mark.parametrize(
    ("xml", "what"),
    [
        ("<tileset fullSymmetry='1'><tiles><tile name='A'/></tiles><neighbors>"
         "<neighbor left='q A' right='A'/></neighbors></tileset>", "unknown symmetry"),
        ("<tileset fullSymmetry='True'><tiles><tile name='A'/></tiles><neighbors>"
         "<neighbor top='A' bottom='A'/></neighbors></tileset>", "top/bottom"),
        ("<tileset><tiles><tile name='A'/></tiles><neighbors><neighbor left='x A' right='A'/>"
         "</neighbors></tileset>", "only z turns"),
        ("<tileset><tiles/></tileset>", "no tiles"),
    ],
)  # fmt: skip
def test_errors(xml, what):
    with pytest.raises(FormatError, match=what):
        parse_markovjunior(xml, path="bad.xml")


def test_tile_voxels_are_composited_in_pictures_and_exports(tmp_path):
    from csplab.io import write_labels
    from csplab.io.obj import read_obj
    from csplab.io.vox import read_vox

    rs = read_markovjunior(DATA / "pipes3d.xml")
    assert rs.voxels is not None and rs.voxels.shape == (16, 3, 3, 3)
    empty = {f"{a}{s}": 0 for a in "xyz" for s in "-+"}
    P = rs.problem((5, 4, 3), boundary=empty)
    r = csplab.solve(P, "catalog", rng=2)
    assert r.ok
    write_labels(r.grid, tmp_path / "m.vox", model=rs)
    v = read_vox(tmp_path / "m.vox")
    assert np.array_equal(v.grid, rs.expand_voxels(r.grid))  # MarkovJunior-style output
    base = read_vox(DATA / "pipes3d" / "Turn.vox")
    assert np.array_equal(v.palette[1:3], base.palette[1:3])  # the tiles' own colours
    # pipes are closed: every arm voxel on a cell's +d face meets one across the border
    vox = v.grid > 0
    assert vox.sum() > 0
    for d in range(3):
        idx = np.indices(vox.shape)
        on_face = (idx[d] % 3 == 2) & np.all([idx[e] % 3 == 1 for e in range(3) if e != d], axis=0)
        arms = np.argwhere(vox & on_face)
        nxt = arms.copy()
        nxt[:, d] += 1
        assert (nxt[:, d] < vox.shape[d]).all() and vox[tuple(nxt.T)].all()
    write_labels(r.grid, tmp_path / "m.obj", model=rs)
    assert len(read_obj(tmp_path / "m.obj").faces) > 0
    assert rs.render(r.grid).size[0] > 0


def test_inferred_tiles_get_pipe_pictures(tmp_path):
    shutil.copy(DATA / "pipes3d.xml", tmp_path / "pipes3d.xml")
    with pytest.warns(UserWarning):
        inferred = read_markovjunior(tmp_path / "pipes3d.xml")
    exact = read_markovjunior(DATA / "pipes3d.xml")
    # same shapes (arms towards the connected faces), colours by tile
    assert np.array_equal(inferred.voxels > 0, exact.voxels > 0)
