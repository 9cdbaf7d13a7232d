"""Polyhedral outputs for other tools: .glb, .stl and .off, loaded back with trimesh."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("trimesh")
pytest.importorskip("manifold3d")

import trimesh

from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.io import read_model
from csplab.io.meshes import solid_triangles
from csplab.io.registry import output_format
from csplab.testing import cad


@pytest.fixture(scope="module")
def synthesized():
    from csplab.continuous.synthesis import synthesize3

    ex = read_model("csplab/examples/continuous3d/houses.obj")
    s = synthesize3(ex, (10, 10, 4), rng=1)
    assert s.model is not None and len(s.model.solids) > 5
    return s.model


@pytest.fixture(scope="module")
def engraved(tmp_path_factory):
    p = cad.export(cad.build("engraved"), tmp_path_factory.mktemp("cad") / "engraved.stl")
    return read_model(p)


def _per_solid(tris, model):
    """The loaded triangles (n, 3, 3) cut into the model's solids, in order."""
    counts = [len(solid_triangles(s)) for s in model.solids]
    assert len(tris) == sum(counts)
    return np.split(tris, np.cumsum(counts)[:-1])


def _check(tris, model, rotate=False):
    if rotate:  # glTF is y up: (x, y, z) was written as (x, z, -y)
        tris = tris[..., [0, 2, 1]] * np.array([1.0, -1.0, 1.0])
    total = 0.0
    for part, s in zip(_per_solid(tris, model), model.solids, strict=True):
        faces = np.arange(3 * len(part)).reshape(-1, 3)
        m = trimesh.Trimesh(vertices=part.reshape(-1, 3), faces=faces)
        m.merge_vertices()
        assert m.is_watertight and m.is_winding_consistent
        assert m.area_faces.min() > 1e-9
        assert float(m.volume) == pytest.approx(s.volume, rel=1e-5)
        total += float(m.volume)
    assert total == pytest.approx(model.volume(), rel=1e-5)


@pytest.mark.parametrize("which", ["synthesized", "engraved"])
def test_stl_is_watertight_per_solid_without_zero_area_triangles(tmp_path, request, which):
    model = request.getfixturevalue(which)
    p = tmp_path / "m.stl"
    output_format(p, gives="PolyhedralModel").write(model, p)
    m = trimesh.load(p, process=False)
    _check(np.asarray(m.triangles), model)


@pytest.mark.parametrize("which", ["synthesized", "engraved"])
def test_glb_has_one_mesh_and_material_per_label_and_the_volumes(tmp_path, request, which):
    model = request.getfixturevalue(which)
    p = tmp_path / "m.glb"
    output_format(p, gives="PolyhedralModel").write(model, p)
    scene = trimesh.load(p, force="scene", process=False)
    assert sorted(scene.geometry) == [f"label_{b}" for b in model.labels]
    for b in model.labels:
        g = scene.geometry[f"label_{b}"]
        assert g.visual.material.name == f"label_{b}"
        sub = PolyhedralModel.trusted([s for s in model.solids if s.label == b])
        _check(np.asarray(g.triangles), sub, rotate=True)


def test_off_reads_back_as_the_same_solids(tmp_path, synthesized):
    p = tmp_path / "m.off"
    output_format(p, gives="PolyhedralModel").write(synthesized, p)
    back = read_model(p, labels="components")
    assert len(back.solids) == len(synthesized.solids)
    assert back.n_polygons == synthesized.n_polygons
    assert back.volume() == pytest.approx(synthesized.volume(), rel=1e-9)


def test_zero_area_triangles_of_a_solid_are_ear_clipped_again():
    # a unit cube whose front face has a midpoint 8 on its bottom edge, fanned from 8:
    # the fan's triangle (8, 1, ...) is fine but (0, 8, 1) has zero area
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1],
                  [0, 1, 1], [0.5, 0, 0]], dtype=float)  # fmt: skip
    polys = ((0, 3, 2, 1, 8), (4, 5, 6, 7), (0, 8, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
             (3, 0, 4, 7))  # fmt: skip
    good = PolyhedralModel([{"label": 1, "vertices": v, "faces": [list(p) for p in polys]}])
    s = good.solids[0]
    fan = [(p[0], p[k], p[k + 1]) for p in s.polygons for k in range(1, len(p) - 1)]
    owner = [j for j, p in enumerate(s.polygons) for _ in range(len(p) - 2)]
    bad = Solid(1, s.vertices, np.asarray(fan), s.polygons, np.asarray(owner))
    t = bad.vertices[bad.faces]
    assert (np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1) < 1e-12).any()
    T = solid_triangles(bad)
    m = trimesh.Trimesh(vertices=s.vertices, faces=T, process=False)
    assert m.is_watertight and m.area_faces.min() > 1e-6 and float(m.volume) == pytest.approx(1)
    assert len(T) == len(fan)


@pytest.mark.parametrize("which", ["synthesized", "engraved"])
def test_glb_reads_back_as_the_same_solids_labels_and_volumes(tmp_path, request, which):
    model = request.getfixturevalue(which)
    p = tmp_path / "m.glb"
    output_format(p, gives="PolyhedralModel").write(model, p)
    back = read_model(p)
    assert back.meta["format"] == "glb"
    assert back.labels == model.labels
    assert len(back.solids) == len(model.solids)
    for b in model.labels:  # float32 coordinates in glTF
        assert back.volume(b) == pytest.approx(model.volume(b), rel=1e-5)
    # z up again (glTF's y up turned back): the same extent per axis
    ext = lambda m: np.vstack([s.vertices for s in m.solids])  # noqa: E731
    assert np.allclose(ext(back).min(0), ext(model).min(0), atol=1e-4)
    assert np.allclose(ext(back).max(0), ext(model).max(0), atol=1e-4)


def test_glb_of_another_tool_names_transforms_and_y_up(tmp_path):
    # two CAD parts as a modelling tool exports them: named nodes without label_N, one
    # moved by its node transform, glTF's y up
    a, b = cad.build("tetra"), cad.build("holes")
    scene = trimesh.Scene()
    scene.add_geometry(a, node_name="roof", geom_name="roof")
    t = np.eye(4)
    t[:3, 3] = [100.0, 0.0, 0.0]
    scene.add_geometry(b, node_name="wall", geom_name="wall", transform=t)
    p = tmp_path / "tool.glb"
    p.write_bytes(scene.export(file_type="glb"))
    m = read_model(p)
    assert m.labels == (1, 2)
    assert m.meta["label_names"] == {"1": "roof", "2": "wall"}
    assert m.volume(1) == pytest.approx(a.volume, rel=1e-5)
    assert m.volume(2) == pytest.approx(b.volume, rel=1e-5)
    # glTF (x, y, z) is csplab (x, -z, y): the moved part lies at x >= 100 - its extent
    wall = [s for s in m.solids if s.label == 2]
    assert min(float(s.vertices[:, 0].min()) for s in wall) == pytest.approx(
        100.0 + float(b.vertices[:, 0].min()), abs=1e-4
    )
    assert float(m.solids[0].vertices[:, 2].max()) == pytest.approx(
        float(a.vertices[:, 1].max()), abs=1e-4
    )
    assert len(read_model(p, labels="one").labels) == 1


def test_bad_glb_is_one_line(tmp_path):
    from csplab.errors import CsplabError

    p = tmp_path / "bad.glb"
    p.write_bytes(b"glTF" + bytes(30))
    with pytest.raises(CsplabError, match=r"bad\.glb"):
        read_model(p)
