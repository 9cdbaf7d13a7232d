"""Planes from real coordinates (issue 25.1-2): equal plane spacing per family in 3D, snapping
by planes, vertices of more than three planes (thesis Sec. 4.5.8), the cost estimate."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from csplab.cli.common import load_model
from csplab.continuous.check3d import violations3
from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.lattice import Lattice
from csplab.continuous.space import estimate3
from csplab.continuous.synthesis import synthesize

pytest.importorskip("manifold3d")
from csplab.testing import cad


def _part(name: str, tmp: Path) -> object:
    return load_model(str(cad.export(cad.build(name), tmp / f"{name}.stl")))


def test_equal_planes_keep_a_slanted_part_small(tmp_path: Path) -> None:
    ex = _part("slanted", tmp_path)
    size = (10, 10, 6)
    C = ContinuousCSP3(ex, size)  # type: ignore[arg-type]
    lat, A = C.lattice, C.arrangement
    assert lat.planes == "equal" and lat.derived
    # every family's planes about one spacing apart (step / |n| in lattice units)
    for n, st in zip(lat.vectors, lat.steps, strict=True):
        assert 0.5 <= st / math.hypot(*n) <= 1.5, (n, st)
    # the planes of every family through every lattice point would be far denser
    dense = estimate3(replace(lat, steps=(), residues=()), size)[0]
    sparse = estimate3(lat, size)[0]
    assert 3 * sparse < dense
    assert A.n_vertices <= sparse
    # the example's faces lie on planes of the arrangement: its own arrangement has them
    s = synthesize(ex, size, rng=1, restarts=10)  # type: ignore[type-var]
    assert s.result.status == "solved" and s.model is not None
    assert not s.violations
    region = s.csp.region()
    assert not violations3(s.csp.example, s.model, region=region, outside=s.csp.boundary)


def test_the_cli_check_agrees_on_a_slanted_output(tmp_path: Path) -> None:
    from csplab.cli import main

    stl = cad.export(cad.build("slanted"), tmp_path / "slanted.stl")
    out = tmp_path / "out.obj"
    args = ["synthesize", str(stl), "--size", "8x8x5", "--seed", "2", "--out", str(out)]
    assert main(args) == 0
    assert main(["check", str(stl), str(out)]) == 0  # read back and checked


def test_pyramid_apex_of_five_planes(tmp_path: Path) -> None:
    """Sec. 4.5.8: a five-sided pyramid (an over-constrained apex in the thesis) from float
    coordinates: its apex is pinned to a lattice point, so points where all five slanted
    planes meet exist in the output region, and the output is valid."""
    import manifold3d as man

    base = [(2.1 + 2 * math.cos(2 * math.pi * k / 5 + 0.3),
             2.2 + 2 * math.sin(2 * math.pi * k / 5 + 0.3), 0.0) for k in range(5)]  # fmt: skip
    mesh = cad._mesh(man.Manifold.hull_points([*base, (2.1, 2.2, 2.6)]))
    ex = load_model(str(cad.export(mesh, tmp_path / "pyramid.stl")))
    lat = Lattice.of_model(ex)
    assert lat.moved is not None  # snapped by planes, not by rounding every vertex
    C = ContinuousCSP3(ex, (8, 8, 6))  # type: ignore[arg-type]
    A = C.arrangement
    slanted = [f for f in range(A.F) if A.normals[f][2] and A.normals[f][:2].any()]
    assert len(slanted) == 5
    assert A.on[:, slanted].all(axis=1).any()
    s = synthesize(ex, (8, 8, 6), rng=1, restarts=10)  # type: ignore[type-var]
    assert s.result.status == "solved" and not s.violations


def test_estimate_bounds_the_arrangement_and_names_the_remedy(tmp_path: Path) -> None:
    from csplab.errors import MemoryLimitError

    ex = _part("tetra", tmp_path)
    lat = Lattice.of_model(ex)  # type: ignore[arg-type]
    v, e, need = estimate3(lat, (12, 12, 6))
    C = ContinuousCSP3(ex, (12, 12, 6))  # type: ignore[arg-type]
    assert C.arrangement.n_vertices <= v and C.arrangement.n_edges <= e
    with pytest.raises(MemoryLimitError) as err:
        ContinuousCSP3(ex, (40, 40, 20), max_memory=need // 4)  # type: ignore[arg-type]
    msg = str(err.value)
    assert "\n" not in msg and "--memory-limit" in msg and "a larger --spacing" in msg
    assert np.isfinite(need) and need > 0
