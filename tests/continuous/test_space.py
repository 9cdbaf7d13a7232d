"""Regressions of the exact 3D plane arrangement (:mod:`csplab.continuous.space`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from csplab.cli.common import load_model
from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.lattice import Lattice
from csplab.continuous.space import Arrangement3, central_cells, estimate3
from csplab.errors import MemoryLimitError


def test_central_cells_of_nearly_parallel_families() -> None:
    # (-2600, -7801, -7799) is within 2e-4 rad of -(1, 3, 3); the line of it and (0, 0, 1)
    # passes that close to the plane of (1, 3, 2): a fixed 1e-3 step off that line crossed
    # the plane, filed the sample under the wrong cell and raised "a cell's representative
    # direction left the cell" (the dome at --spacing 0.5 --snap)
    N = np.array([[-2600, -7801, -7799], [1, 3, 2], [0, 0, 1]], dtype=np.int64)
    signs, dirs = central_cells(N)
    assert len(signs) == 8  # three planes in general position
    assert (np.sign(dirs @ N.T.astype(np.float64)) == signs).all()
    assert len({tuple(s) for s in signs.tolist()}) == 8


def test_arrangement_refused_over_the_memory_budget() -> None:
    tet = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], dtype=float)
    lat = Lattice.of_points(tet, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    # 3 planes per axis family and 7 of (1, 1, 1) in 2x2x2: each of the 4 triples has
    # det 1 (1 point per unit volume: 27 of the 3*3*3 or 3*3*7 meeting points in the box)
    assert estimate3(lat, (2, 2, 2))[:2] == (108, 324)
    assert Arrangement3(lat, (2, 2, 2)).n_vertices == 27  # the lattice points
    Arrangement3(lat, (2, 2, 2), max_memory=10**6)  # within the budget: built
    with pytest.raises(MemoryLimitError) as e:
        Arrangement3(lat, (40, 40, 20), max_memory=10**6, where="box.obj")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("box.obj: ")
    assert "the memory budget is 1 MiB: --memory-limit" in msg
    assert "a larger --spacing or a smaller --size" in msg


def test_slanted_cad_part_refused_in_one_line_not_overflow(tmp_path: Path) -> None:
    # at spacing 0.5 with snap, the slanted L-bracket's snapped faces have normals such as
    # (105, 32, 2): the lattice of their meeting points overflowed int64 (OverflowError in
    # Arrangement3); now the estimate refuses it before building
    pytest.importorskip("manifold3d")
    from csplab.testing import cad

    path = cad.export(cad.build("slanted"), tmp_path / "slanted.stl")
    ex = load_model(str(path))
    with pytest.raises(MemoryLimitError) as e:
        ContinuousCSP3(ex, (40, 40, 20), spacing=0.5, snap=True, max_memory=2**30)
    msg = str(e.value)
    assert "\n" not in msg and "slanted.stl" in msg
    assert "the memory budget is 1.0 GiB: --memory-limit" in msg
