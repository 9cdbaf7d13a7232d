import numpy as np
import pytest
from hypothesis import given, settings

from csplab.errors import FormatError, InputError
from csplab.io import read_model, write_labels
from csplab.io.obj import parse_obj, read_obj, write_obj
from csplab.io.vox import parse_vox, read_vox, vox_bytes, write_vox
from csplab.testing.strategies import label_grids


@settings(max_examples=40, deadline=None)
@given(label_grids(ndim=3, max_side=5, max_labels=6))
def test_vox_roundtrip(g):
    data = vox_bytes(g, empty=0)
    vox = parse_vox(data)
    assert vox.grid.shape == g.shape
    # colour index = label + 1, empty label left out
    assert np.array_equal(vox.grid, np.where(g == 0, 0, g + 1))
    from csplab.render import palette

    cols = palette(int(g.max()) + 1)
    used = np.unique(g[g > 0])
    assert np.array_equal(vox.palette[used + 1, :3], cols[used])


def test_vox_file_reads_back_as_an_example(tmp_path):
    g = np.zeros((4, 3, 2), dtype=np.int32)
    g[1:3, 1, 0] = 2
    g[0, 0, 1] = 5
    write_vox(g, tmp_path / "m.vox", empty=0)
    E = read_model(tmp_path / "m.vox")
    assert E.shape == (4, 3, 2) and E.names == ("empty", "c3", "c6")
    assert np.array_equal(E.labels, np.select([g == 2, g == 5], [1, 2], 0))


def test_vox_limits_and_errors(tmp_path):
    with pytest.raises(InputError, match="255"):
        vox_bytes(np.arange(300).reshape(10, 30, 1))
    with pytest.raises(InputError, match="256"):
        vox_bytes(np.zeros((300, 1, 1), int))
    for bad, what in [(b"VOX", "magic"), (b"VOX \x96\x00\x00\x00MAIN", "truncated"),
                      (b"VOX \x96\x00\x00\x00", "no voxel model")]:  # fmt: skip
        with pytest.raises(FormatError, match=what):
            parse_vox(bad)


def exposed_faces(filled):
    pad = np.pad(filled, 1)
    n = 0
    for ax in range(3):
        for s in (1, -1):
            n += int((pad & ~np.roll(pad, -s, axis=ax)).sum())
    return n


@settings(max_examples=40, deadline=None)
@given(label_grids(ndim=3, max_side=4, max_labels=4))
def test_obj_voxel_mesh_roundtrip(tmp_path_factory, g):
    d = tmp_path_factory.mktemp("obj")
    stats = write_obj(g, d / "m.obj", empty=0)
    mesh = read_obj(d / "m.obj")
    filled = g != 0
    assert len(mesh.faces) == stats["faces"] == exposed_faces(filled)
    assert all(len(f) == 4 for f in mesh.faces)
    # closed surface: every edge is used by exactly two faces, in opposite directions
    edges: dict[tuple[int, int], int] = {}
    for f in mesh.faces:
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    assert all(edges.get((b, a), 0) == c for (a, b), c in edges.items())
    # materials: one per label in use, with the palette colour
    assert {m for m in mesh.face_material} == {f"label_{b}" for b in np.unique(g[filled])}
    # outward normals: each face's normal points away from its cell (y up in OBJ)
    if filled.any():
        lo = mesh.vertices.min(axis=0)
        hi = mesh.vertices.max(axis=0)
        x, y, z = np.nonzero(filled)
        assert np.allclose(lo, [x.min(), z.min(), -(y.max() + 1)])
        assert np.allclose(hi, [x.max() + 1, z.max() + 1, -y.min()])


def test_obj_parser_errors():
    with pytest.raises(FormatError, match="line 2"):
        parse_obj("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(FormatError, match="bad 'v'"):
        parse_obj("v 0 zero 0\n")


def test_write_labels_vox_obj_png(tmp_path):
    g = np.zeros((3, 3, 3), dtype=np.int32)
    g[:, :, 0] = 1
    for ext in ("vox", "obj", "png", "npy"):
        write_labels(g, tmp_path / f"o.{ext}")
        assert (tmp_path / f"o.{ext}").stat().st_size > 0
    assert read_vox(tmp_path / "o.vox").grid[:, :, 0].all()
    with pytest.raises(InputError, match=r"\.vox or \.obj"):
        write_labels(g, tmp_path / "o.stl")
