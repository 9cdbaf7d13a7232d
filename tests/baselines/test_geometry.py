"""The geometry baseline (Lagae et al. 2004): the search tree finds a best block (as good as
a linear search), the synthesized field gives a closed mesh, the CLI writes it."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("trimesh")
pytest.importorskip("skimage")

from csplab.baselines.geometry import (
    SearchTree,
    geometry,
    match_speedup,
    signed_distance,
)
from csplab.errors import InputError
from csplab.examples.continuous3d import load_polyhedral_example


def test_signed_distance_is_negative_inside() -> None:
    f = signed_distance(load_polyhedral_example("houses"), 16)
    assert f.min() < 0 < f.max()
    assert f[0, 0, -1] > 0  # a corner of the bounding box above the houses is outside


def test_tree_search_matches_linear_search() -> None:
    f = signed_distance(load_polyhedral_example("terrain"), 20)
    t = SearchTree.build(f, 4)
    rng = np.random.default_rng(0)
    for _ in range(15):
        c = t.corners[int(rng.integers(len(t.corners)))]
        q = f[tuple(slice(a, a + 4) for a in c)] + rng.normal(0, 1.0, (4, 4, 4))
        b, visited = t.best(q)
        lin = t.linear(q)
        pq = t.pyramid(q)[-1]
        d = ((t.levels[-1] - pq) ** 2).mean(axis=1)
        assert d[b] == pytest.approx(d[lin])  # Eq. 2: the first leaf popped is a best block
        assert visited >= 1
    with pytest.raises(InputError, match="power of 2"):
        SearchTree.build(f, 6)


def test_speedup_measure_agrees() -> None:
    m = match_speedup(load_polyhedral_example("terrain"), resolution=24, block=8, queries=4)
    assert m["agree"] == 1.0 and m["blocks"] > 0 and m["speedup"] > 0


def test_synthesized_mesh_is_closed(tmp_path) -> None:
    mesh = geometry(load_polyhedral_example("terrain"), (16, 16, 8), resolution=16, block=4,
                    rng=2)  # fmt: skip
    assert mesh.is_watertight and mesh.volume > 0
    out = tmp_path / "g.obj"
    cmd = [sys.executable, "-m", "csplab", "baseline", "geometry", "terrain", "--size",
           "16x16x8", "--resolution", "16", "--block", "4", "--seed", "1",
           "--out", str(out)]  # fmt: skip
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert r.returncode == 0 and "closed True" in r.stdout, r.stdout + r.stderr
    assert out.exists()


def test_multiresolution_is_closed_and_seeded_by_the_coarse_pass() -> None:
    E = load_polyhedral_example("terrain")
    one = geometry(E, (16, 16, 8), resolution=16, block=4, levels=1, rng=3)
    two = geometry(E, (16, 16, 8), resolution=16, block=4, levels=2, rng=3)
    assert one.is_watertight and two.is_watertight
    assert not np.array_equal(one.vertices.shape, ()) and two.volume > 0
    with pytest.raises(InputError, match="levels"):
        geometry(E, (16, 16, 8), resolution=16, block=4, levels=0)


def test_a_block_of_the_source_finds_an_identical_block() -> None:
    """Lagae et al. Sec. 4.3: the search returns a best block; a query that is a block of
    the source has an exact match (distance 0 at every level of its pyramid)."""
    f = signed_distance(load_polyhedral_example("houses"), 16)
    t = SearchTree.build(f, 4)
    rng = np.random.default_rng(1)
    for i in rng.choice(len(t.corners), 12, replace=False).tolist():
        c = t.corners[i]
        q = f[tuple(slice(a, a + 4) for a in c)]
        b, _ = t.best(q)
        pyr = t.pyramid(q)
        for lvl, qq in enumerate(pyr):  # every level of the found block equals the query's
            assert np.array_equal(t.levels[lvl][b], qq), (i, lvl)
