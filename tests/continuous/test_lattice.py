"""The default spacing of CAD-made meshes (:mod:`csplab.continuous.lattice`, issue 25.1)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from csplab.cli.common import load_model
from csplab.continuous.csp3d import snapped3
from csplab.continuous.lattice import Lattice, derived_spacing
from csplab.errors import InputError

pytest.importorskip("manifold3d")
from csplab.testing import cad


def test_exact_examples_keep_their_lattice() -> None:
    tet = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], dtype=float)
    lat = Lattice.of_points(tet, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    assert not lat.derived and lat.spacing == 4 and lat.snapped == 0


def test_float_tetrahedron_gets_a_derived_spacing(tmp_path: Path) -> None:
    # (2, 3.5, 0) and (2, 1.2, 3) written by STL as float32: no exact rational form
    ex = load_model(str(cad.export(cad.build("tetra"), tmp_path / "tetra.stl")))
    lat = Lattice.of_model(ex)
    assert lat.derived and float(lat.spacing) == derived_spacing(ex.indexed_faces()[0]) == 0.5
    assert 0.3 < lat.snapped <= 0.5  # 1.2 -> 1.0: 0.4 spacings
    assert 0 < lat.normal_change < 10
    snapped = snapped3(ex, lat)
    assert snapped.volume() > 0
    uv = lat.to_lattice(np.concatenate([s.vertices for s in snapped.solids]))
    assert np.abs(uv - np.rint(uv)).max() < 1e-9


def test_snapping_that_breaks_a_part_is_refused_in_one_line(tmp_path: Path) -> None:
    # the holes' cylinders at spacing 0.5: triangles flattened to zero area
    ex = load_model(str(cad.export(cad.build("holes"), tmp_path / "holes.stl")))
    with pytest.raises(InputError) as e:
        snapped3(ex, Lattice.of_model(ex))
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{tmp_path / 'holes.stl'}: snapping onto")
    assert "pass a smaller --spacing" in msg


def test_cli_reports_the_snapping_error_and_refuses_over_budget(tmp_path: Path) -> None:
    stl = cad.export(cad.build("tetra"), tmp_path / "tetra.stl")
    cmd = [sys.executable, "-m", "csplab", "synthesize", str(stl), "--size", "40x40x20",
           "--seed", "1", "--memory-limit", "1.073741824"]  # fmt: skip
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 2, p.stderr
    err = [ln for ln in p.stderr.splitlines() if "reading" not in ln]
    assert len(err) == 1 and "Traceback" not in p.stderr
    assert "the memory budget is 1.0 GiB: --memory-limit" in err[0]
    assert "a larger --spacing" in err[0]
