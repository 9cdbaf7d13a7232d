"""The CAD-made test meshes (csplab.testing.cad) are closed, outward and deterministic."""

from __future__ import annotations

import numpy as np
import pytest

from csplab.testing import cad

VOLUMES = {"engraved": 197.3275, "chamfered": 52.152, "bevelled": 112.2917, "holes": 122.1194,
           "dome": 75.7349, "lathe": 40.5434, "tetra": 7.0, "slanted": 44.31}  # fmt: skip


@pytest.mark.parametrize("name", sorted(cad.BUILDERS))
def test_builders_are_closed_outward_float_meshes(name):
    m = cad.build(name)
    assert m.is_watertight and m.is_winding_consistent
    assert float(m.volume) == pytest.approx(VOLUMES[name], abs=1e-3)
    again = cad.build(name)
    assert np.array_equal(m.vertices, again.vertices) and np.array_equal(m.faces, again.faces)


def test_export_adds_slivers_duplicates_and_flips(tmp_path):
    import trimesh

    p = cad.export(cad.build("bevelled"), tmp_path / "b.off", slivers=2, duplicate_vertices=True,
                   flip=1, seed=3)  # fmt: skip
    m = trimesh.load(p, process=False)
    assert len(m.faces) == 20 + 2 * 2 and len(m.vertices) == 3 * len(m.faces)
    assert (m.area_faces < 1e-9).sum() == 2
