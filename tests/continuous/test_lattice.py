"""The default spacing of CAD-made meshes (:mod:`csplab.continuous.lattice`, issue 25.1)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from csplab.cli.common import load_model
from csplab.continuous.csp3d import snapped3
from csplab.continuous.lattice import (
    FIT_DEGS,
    MAX_DENOMINATOR,
    Lattice,
    denominator,
    derived_spacing,
)
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
    # snapped by planes: four families of small integer normals, every face on a plane
    # of its family (n . x = k, k on the family's equal grid), vertices moved < 1 spacing
    assert lat.moved is not None and len(lat.vectors) == 4
    assert max(abs(c) for v in lat.vectors for c in v) <= 6
    assert 0 < lat.snapped < 1.0
    assert 0 < lat.normal_change < 10
    snapped = snapped3(ex, lat)
    assert snapped.volume() == pytest.approx(7.0, rel=0.25)
    pts, polys = snapped.indexed_faces()
    uv = lat.to_lattice(pts)
    steps = dict(zip(lat.vectors, lat.steps, strict=True))
    res = dict(zip(lat.vectors, lat.residues, strict=True))
    for poly in polys:
        on = [v for v in lat.vectors if np.ptp(uv[poly] @ np.array(v, dtype=float)) < 1e-9]
        assert len(on) == 1, poly
        k = float(uv[poly[0]] @ np.array(on[0], dtype=float))
        assert abs(k - round(k)) < 1e-9 and (round(k) - res[on[0]]) % steps[on[0]] == 0


def test_rotated_part_keeps_its_four_families(tmp_path: Path) -> None:
    # an L-bracket rotated 17 deg about z and 6 about x: rounding its vertices onto the
    # lattice made 7-12 families of normals up to 28 (exact coordinates beyond int64);
    # snapping by planes keeps its 4 orientations with small normals
    ex = load_model(str(cad.export(cad.build("slanted"), tmp_path / "slanted.stl")))
    lat = Lattice.of_model(ex)
    assert lat.moved is not None and len(lat.vectors) == 4
    assert denominator(lat.families()[0]) <= MAX_DENOMINATOR
    assert lat.normal_change <= FIT_DEGS[-1]
    assert snapped3(ex, lat).volume() > 0


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
           "--seed", "1", "--memory-limit", "0.1073741824"]  # fmt: skip
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 2, p.stderr
    err = [ln for ln in p.stderr.splitlines() if "reading" not in ln]
    assert len(err) == 1 and "Traceback" not in p.stderr
    assert "the memory budget is 102 MiB: --memory-limit" in err[0]
    assert "a larger --spacing" in err[0]
