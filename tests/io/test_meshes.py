"""Polyhedral models (3D continuous model synthesis) and their files: OBJ, OFF, STL, PNG."""

import struct
import warnings

import numpy as np
import pytest

pytest.importorskip("trimesh")
pytest.importorskip("manifold3d")

from csplab.continuous.polyhedra import PolyhedralModel
from csplab.errors import FormatError, InputError
from csplab.io import model_format, read_example, read_model
from csplab.io.common import Output
from csplab.io.meshes import read_obj_model, read_off, read_stl, write_obj_model, write_png
from csplab.io.registry import FORMATS, output_extensions, output_format

from ._helpers import DATA

CUBE = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
QUADS = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
TRIS = [[q[0], q[1], q[2]] for q in QUADS] + [[q[0], q[2], q[3]] for q in QUADS]


def cube(at=(0, 0, 0), size=1.0):
    return (np.asarray(CUBE, float) * size + np.asarray(at, float)).tolist()


def obj_text(solids, header=""):
    """OBJ text of ``[(statements, vertices, faces)]`` (faces 0-based within the solid)."""
    lines, base = [header] if header else [], 1
    for stmts, verts, faces in solids:
        lines += stmts
        lines += [f"v {x} {y} {z}" for x, y, z in verts]
        lines += ["f " + " ".join(str(base + i) for i in f) for f in faces]
        base += len(verts)
    return "\n".join(lines) + "\n"


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text) if isinstance(text, str) else p.write_bytes(text)
    return p


def binary_stl(verts, faces):
    v = np.asarray(verts, np.float32)
    out = bytearray(b"binary stl".ljust(80, b" ") + struct.pack("<I", len(faces)))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0) + v[list(f)].tobytes() + b"\0\0"
    return bytes(out)


def ascii_stl(verts, faces):
    lines = ["solid s"]
    for f in faces:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [
            f"vertex {x!r} {y!r} {z!r}" for x, y, z in np.asarray(verts, float)[list(f)].tolist()
        ]
        lines += ["endloop", "endfacet"]
    return "\n".join([*lines, "endsolid s"]) + "\n"


# ---------------------------------------------------------------------------- round trips
def test_obj_round_trip_keeps_labels_volumes_and_vertices(tmp_path):
    text = obj_text(
        [
            (["o a", "usemtl label_3"], cube(), QUADS),
            (["o b", "usemtl label_1"], cube((2, 0, 0), 0.5), QUADS),
            (["o c", "usemtl label_3"], cube((0, 2, 0), 2.0), TRIS),
        ]
    )
    m = read_obj_model(write(tmp_path, "m.obj", text))
    assert m.labels == (1, 3) and len(m) == 3 and m.ndim == 3
    assert m.volume(3) == pytest.approx(9.0) and m.volume(1) == pytest.approx(0.125)
    assert m.n_polygons == 18  # the triangulated cube counts 6 (coplanar triangles merged)
    assert [s.extra["group"] for s in m.solids] == ["a", "b", "c"]
    write_obj_model(m, tmp_path / "out.obj")
    assert (tmp_path / "out.mtl").read_text().count("newmtl label_") == 2
    assert "mtllib out.mtl" in (tmp_path / "out.obj").read_text()
    b = read_model(tmp_path / "out.obj")
    assert isinstance(b, PolyhedralModel) and b.meta["format"] == "mesh-obj"
    assert [s.label for s in b.solids] == [s.label for s in m.solids]
    assert b.n_polygons == m.n_polygons and b.volume() == pytest.approx(m.volume())
    for s, t in zip(m.solids, b.solids, strict=True):
        assert np.array_equal(s.vertices, t.vertices) and s.polygons == t.polygons
    assert np.allclose(b.bounds, (0, 0, 0, 2.5, 4, 2))


def test_off_and_stl_read_as_the_same_solid(tmp_path):
    off = read_off(DATA / "tiny.off")
    assert off.labels == (1,) and off.volume() == pytest.approx(1.0) and off.n_polygons == 6
    for data in (ascii_stl(CUBE, TRIS), binary_stl(CUBE, TRIS)):
        p = write(tmp_path, "c.stl", data)
        assert model_format(p) == "stl"
        m = read_model(p)
        assert m.n_polygons == 6 and m.volume() == pytest.approx(1.0)
        assert sorted(map(tuple, m.solids[0].vertices.tolist())) == sorted(map(tuple, CUBE))
        out = tmp_path / "c.obj"
        write_obj_model(m, out)
        assert read_obj_model(out).volume(1) == pytest.approx(1.0)
    tet = read_stl(DATA / "tiny.stl")
    assert tet.n_polygons == 4 and tet.volume() == pytest.approx(1 / 6)


def test_off_with_counts_on_the_header_line_and_triangles(tmp_path):
    text = "OFF 8 12 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in CUBE)
    text += "".join(f"3 {a} {b} {c}\n" for a, b, c in TRIS)
    m = read_model(write(tmp_path, "c.off", text))
    assert m.volume() == pytest.approx(1.0) and m.n_polygons == 6


# ---------------------------------------------------------------------------- labels
def test_labels_by_material_group_comment_and_component(tmp_path):
    two = [
        (["o first", "usemtl red"], cube(), QUADS),
        (["o second", "usemtl blue"], cube((3, 0, 0)), QUADS),
        (["o third", "usemtl red"], cube((6, 0, 0)), QUADS),
    ]
    p = write(tmp_path, "m.obj", obj_text(two))
    m = read_model(p)
    assert [s.label for s in m.solids] == [1, 2, 1]
    assert m.meta["label_names"] == {"1": "red", "2": "blue"}
    assert [s.label for s in read_model(p, labels="groups").solids] == [1, 2, 3]
    assert [s.label for s in read_model(p, labels="one").solids] == [1, 1, 1]
    assert [s.label for s in read_model(p, labels="components").solids] == [1, 2, 3]
    # explicit label names are kept; other names skip them
    named = [(["g label_2"], cube(), QUADS), (["g other"], cube((3, 0, 0)), QUADS)]
    assert [s.label for s in read_model(write(tmp_path, "n.obj", obj_text(named))).solids] == [
        2, 1,
    ]  # fmt: skip
    # a `# csplab label N` comment labels the rest of its group
    com = [(["o x", "# csplab label 7"], cube(), QUADS), (["o y"], cube((3, 0, 0)), QUADS)]
    assert [s.label for s in read_model(write(tmp_path, "c.obj", obj_text(com))).solids] == [7, 1]
    # one group holding two separate cubes: two solids of one label
    both = [(["o both"], cube(), QUADS), ([], cube((3, 0, 0)), QUADS)]
    m = read_model(write(tmp_path, "b.obj", obj_text(both)))
    assert [s.label for s in m.solids] == [1, 1] and m.volume(1) == pytest.approx(2.0)


def test_off_and_stl_components_option(tmp_path):
    v = cube() + cube((3, 0, 0))
    faces = QUADS + [[i + 8 for i in f] for f in QUADS]
    text = f"OFF\n{len(v)} {len(faces)} 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in v)
    text += "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in faces)
    p = write(tmp_path, "two.off", text)
    assert read_model(p).labels == (1,) and len(read_model(p)) == 2
    assert read_model(p, labels="components").labels == (1, 2)
    tris = TRIS + [[i + 8 for i in f] for f in TRIS]
    s = write(tmp_path, "two.stl", binary_stl(v, tris))
    assert read_model(s, labels="components").labels == (1, 2)
    with pytest.raises(InputError, match="one of one, components"):
        read_model(s, labels="materials")


# ---------------------------------------------------------------------------- validation
def one_line(excinfo):
    msg = str(excinfo.value)
    assert "\n" not in msg
    return msg


SHARED = {0: 2, 4: 6}  # the second cube's vertices on the first one's edge 2-6
EDGE_PAIR = QUADS + [[SHARED.get(i, i + 8) for i in f] for f in QUADS]

BAD = {
    "open box": ([([], cube(), QUADS[1:])], r"m\.obj: solid 0: not closed \(not watertight\)"),
    "non-manifold": (  # the second cube uses the first one's vertices of the shared edge
        [([], cube() + cube((1, 1, 0)), EDGE_PAIR)],
        r"m\.obj: solid 0: non-manifold edge between vertices \d+ and \d+ \(shared by 4 faces",
    ),
    "zero-area face": (  # a sliver whose longest edge 4-5 is open on the other side
        [([], [*cube(), [0.5, 0, 1]], [*QUADS[2:], [0, 1, 5, 8, 4], [4, 8, 5]])],
        r"m\.obj: solid 0: face 5 has zero area",
    ),
    "NaN": (
        [([], [[float("nan"), 0, 0], *cube()[1:]], QUADS)],
        r"m\.obj: line 1: a vertex with a non-finite coordinate \(nan, 0\.0, 0\.0\)",
    ),
    "huge": (
        [([], [[4e9, 0, 0], *cube()[1:]], QUADS)],
        r"m\.obj: line 1: coordinate 4e\+09 beyond the 1e\+07 csplab reads",
    ),
    "overlap": (
        [(["usemtl a"], cube(), QUADS), (["usemtl b"], cube((0.5, 0.5, 0.5)), QUADS)],
        r"m\.obj: solids 0 \(label 1\) and 1 \(label 2\) overlap \(volume 0\.125\)",
    ),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_solids_are_one_line_naming_the_solid_and_face(tmp_path, case):
    solids, want = BAD[case]
    with pytest.raises(InputError, match=want) as e:
        read_model(write(tmp_path, "m.obj", obj_text(solids)))
    one_line(e)


REPAIRED = {
    "inconsistent winding": (
        [([], cube(), [QUADS[0][::-1], *QUADS[1:]])],
        r"m\.obj: repaired 1 face wound against their neighbours \(reversed\)$",
        {"rewound_faces": 1},
    ),
    "mostly inverted": (
        [([], cube(), [*QUADS[:1], *(q[::-1] for q in QUADS[1:])])],
        r"m\.obj: repaired 5 faces wound against their neighbours \(reversed\)$",
        {"rewound_faces": 5},
    ),
    "zero-area face": (  # a sliver triangle along the edge 4-5, the front face split there
        [([], [*cube(), [0.5, 0, 1]], [*QUADS[:2], [0, 1, 5, 8, 4], *QUADS[3:], [4, 8, 5]])],
        r"m\.obj: repaired 1 zero-area triangle \(an edge flip each\)$",
        {"zero_area_triangles": 1},
    ),
    "duplicates and a repeated vertex": (
        [([], [*cube(), *cube()], [*QUADS[1:], [0, 11, 10, 9], [0, 0, 1]])],
        r"m\.obj: repaired 3 duplicate vertices \(merged\), 1 face with fewer than 3 distinct",
        {"duplicate_vertices": 3, "degenerate_faces": 1},
    ),
}


@pytest.mark.parametrize("case", list(REPAIRED))
def test_repairs_are_one_warning_line_and_recorded(tmp_path, case):
    solids, want, counts = REPAIRED[case]
    with pytest.warns(UserWarning, match=want) as rec:
        m = read_model(write(tmp_path, "m.obj", obj_text(solids)))
    assert len(rec) == 1
    assert m.meta["repaired"] == counts
    assert m.volume() == pytest.approx(1.0) and len(m.solids) == 1


def test_inverted_solids_are_fixed_with_a_warning_or_rejected(tmp_path):
    inside_out = [[f[::-1] for f in QUADS]]
    p = write(tmp_path, "m.obj", obj_text([([], cube(), inside_out[0])]))
    with pytest.warns(UserWarning, match=r"m\.obj: solid 0 \(label 1\) was inside out"):
        m = read_model(p)
    assert m.volume() == pytest.approx(1.0) and m.meta["reoriented"] == [0]
    with pytest.raises(InputError, match=r"solid 0: inverted: the faces point inwards"):
        PolyhedralModel([{"label": 1, "vertices": CUBE, "faces": inside_out[0]}],
                        fix_inverted=False)  # fmt: skip


def test_solids_touching_along_an_edge_in_one_group_stay_apart(tmp_path):
    # each cube has its own vertices (as csplab writes OBJ and OFF): two solids, not a
    # non-manifold one
    text = obj_text([([], cube() + cube((1, 1, 0)), QUADS + [[i + 8 for i in f] for f in QUADS])])
    m = read_model(write(tmp_path, "m.obj", text))
    assert len(m.solids) == 2 and m.volume() == pytest.approx(2.0)


def test_touching_solids_and_same_label_overlaps_are_fine():
    m = PolyhedralModel(
        [
            {"label": 1, "vertices": cube(), "faces": QUADS},
            {"label": 2, "vertices": cube((1, 0, 0)), "faces": QUADS},
            {"label": 2, "vertices": cube((1.5, 0, 0)), "faces": QUADS},
        ]
    )
    assert m.volume(2) == pytest.approx(1.5) and m.volume() == pytest.approx(2.5)
    assert len(m.to_trimesh(2).faces) == 24 and m.solids[0].to_trimesh().is_watertight


@pytest.mark.parametrize(
    ("name", "text", "want"),
    [
        ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", r"a\.obj, line 4: vertex 9 does not"),
        ("a.obj", "v 0 0\n", r"a\.obj, line 1: a vertex needs 3 numbers"),
        ("a.obj", "v 0 0 0\n", r"a\.obj: no faces"),
        ("a.off", "OFF\n3 1 0\n0 0 0\n", r"a\.off, line 2: 3 vertices and 1 faces announced"),
        ("a.stl", b"x" * 90, r"a\.stl: \d+ triangles announced"),
        ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", r"a\.obj: solid 0: not closed"),
    ],
)
def test_bad_files_are_one_line(tmp_path, name, text, want):
    with pytest.raises((FormatError, InputError), match=want) as e:
        read_model(write(tmp_path, name, text))
    one_line(e)


# ---------------------------------------------------------------------------- registry, PNG
def test_registry_keeps_grid_polygon_and_mesh_writers_apart(tmp_path):
    assert FORMATS["mesh-obj"].gives == FORMATS["off"].gives == "PolyhedralModel"
    assert output_extensions(gives="PolyhedralModel") == [".obj", ".off", ".stl", ".glb", ".png"]
    assert output_format("a.obj").name == "obj" and output_format("a.png").name == "png"
    assert output_format("a.png", gives="PolygonModel").name == "polygon-png"
    assert output_format("a.obj", gives="PolyhedralModel").name == "mesh-obj"
    assert output_format("a.png", gives="PolyhedralModel").name == "mesh-png"
    m = read_model(DATA / "tiny_mesh.obj")
    assert m.labels == (1, 2)
    with pytest.raises(InputError, match="obj files hold label grids, not polyhedral models"):
        FORMATS["obj"].write(m, tmp_path / "g.obj")
    with pytest.raises(InputError, match="mesh-obj files hold polyhedral models, not label grids"):
        FORMATS["mesh-obj"].write(Output.of([[0, 1]]), tmp_path / "g.obj")
    with pytest.raises(FormatError, match=r"\.obj files are read as .*not as example grids"):
        read_example(DATA / "tiny_mesh.obj")
    for ext in (".obj", ".png"):
        output_format(f"x{ext}", gives="PolyhedralModel").write(m, tmp_path / f"x{ext}")
    assert read_model(tmp_path / "x.obj").volume() == pytest.approx(m.volume())


def test_png_preview_is_a_picture_in_the_label_colours(tmp_path):
    from PIL import Image

    from csplab.render import palette

    m = read_model(DATA / "tiny_mesh.obj")
    write_png(m, tmp_path / "m.png", size_px=128)
    img = Image.open(tmp_path / "m.png")
    assert img.format == "PNG" and img.size == (128, 128)
    rgb = np.asarray(img.convert("RGB")).reshape(-1, 3).astype(int)
    assert (rgb == 255).all(axis=1).mean() > 0.3  # white background
    for b in (1, 2):  # some pixel of each label's hue (shaded: a multiple of the colour)
        c = palette(3)[b].astype(float)
        cos = (rgb @ c) / (np.linalg.norm(rgb, axis=1) * np.linalg.norm(c) + 1e-9)
        assert (cos > 0.999).any()
    with pytest.raises(InputError, match="size_px"):
        write_png(m, tmp_path / "x.png", size_px=1)


def test_a_missing_mesh_package_is_one_line(monkeypatch):
    import sys

    from csplab.errors import DependencyError

    monkeypatch.setitem(sys.modules, "manifold3d", None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(DependencyError, match=r"needs manifold3d; .*csplab\[mesh\]"):
            PolyhedralModel(
                [
                    {"label": 1, "vertices": cube(), "faces": QUADS},
                    {"label": 2, "vertices": cube((0.5, 0, 0)), "faces": QUADS},
                ]
            )
