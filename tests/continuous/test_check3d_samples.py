"""Where the 3D checker takes its neighbourhoods: the sample points of a model, exactly.

:func:`csplab.continuous.check3d.violations3` compares the neighbourhoods of an output,
taken at its vertices, the middles of its edge pieces and its triangle centres, with those
of the example, taken densely (``dense`` points along each edge, a grid of points inside
each triangle). The planted-defect tests (``test_check3d_planted.py``) show that each
sampling of the output matters; these tests pin down the sample points themselves, computed
here independently (barycentric weights, edges from the triangles of a box), so a sampling
that misses an edge, misplaces the grid or gives the example the output's sampling fails
(issue 32: these were the surviving mutants of the sampling code).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tests._meshes import box

polyhedra = pytest.importorskip("csplab.continuous.polyhedra")
pytest.importorskip("trimesh")

from csplab.continuous.check3d import _samples  # noqa: E402


def _box_triangles() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and the 12 triangles of a box with sides 1, 2 and 3 (not a cube, so that no
    two of its points coincide by symmetry)."""
    s = polyhedra.PolyhedralModel([box(1, [0, 0, 0], [1, 2, 3])]).solids[0]
    return np.asarray(s.vertices, dtype=float), np.asarray(s.faces, dtype=np.int64)


def _solids(v: np.ndarray, f: np.ndarray) -> SimpleNamespace:
    return SimpleNamespace(solids=[SimpleNamespace(vertices=v, faces=f)])


def _rows(p: np.ndarray) -> list[tuple[float, ...]]:
    """The points as sorted rounded tuples (a multiset)."""
    return sorted(tuple(r) for r in np.round(np.asarray(p, dtype=float), 9).tolist())


def _edges(f: np.ndarray) -> list[tuple[int, int]]:
    return sorted({(min(a, b), max(a, b)) for t in f.tolist() for a, b in
                   ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))})  # fmt: skip


@pytest.mark.parametrize("seed", range(6))
def test_an_output_is_sampled_at_vertices_edge_middles_and_triangle_centres(seed: int) -> None:
    """``dense=1`` (outputs): the vertices, the middle of every edge (once, whichever of its
    two triangles lists it and in which order) and the centre of every triangle; the same
    points whatever vertex each triangle starts with."""
    v, f = _box_triangles()
    rng = np.random.default_rng(seed)
    rolled = np.array([np.roll(t, int(k)) for t, k in zip(f, rng.integers(0, 3, len(f)),
                                                           strict=True)])  # fmt: skip
    edges = _edges(f)
    assert len(edges) == 18  # 12 sides of the box and one diagonal per face
    expect = [*v, *(0.5 * (v[a] + v[b]) for a, b in edges), *v[f].mean(axis=1)]
    assert _rows(_samples(_solids(v, rolled), 1)) == _rows(np.array(expect))


@pytest.mark.parametrize("dense", [2, 3, 8])
def test_an_example_is_sampled_densely_along_edges_and_inside_triangles(dense: int) -> None:
    """``dense > 1`` (the example): ``dense`` points spread along every edge (at
    ``(k + 1/2) / dense``), the triangle grid of barycentric weights ``(d - i - j, i, j) / d``
    with ``i, j >= 1`` and ``i + j < d``, and every triangle's centre."""
    v, f = _box_triangles()
    expect: list[np.ndarray] = list(v)
    for a, b in _edges(f):
        expect += [v[a] + (k + 0.5) / dense * (v[b] - v[a]) for k in range(dense)]
    for t in f:
        a, b, c = v[t]
        for i in range(1, dense):
            for j in range(1, dense):
                if i + j < dense:
                    expect.append(((dense - i - j) * a + i * b + j * c) / dense)
        expect.append((a + b + c) / 3)
    got = _samples(_solids(v, f), dense)
    assert _rows(got) == _rows(np.array(expect))
