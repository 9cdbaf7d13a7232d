"""Planted defects that only one sampling of the 3D checker can see (issue 32).

:func:`csplab.continuous.check3d.violations3` samples an output at its vertices, at the
middle of every edge piece and at the centre of every triangle. Each test below plants a
defect in a hand-made output that exactly one of these samplings reaches (the test checks
that geometric premise from the model itself), so removing that sampling from the checker
makes the test fail (``benchmarks/hand_mutations.py`` applies each removal and runs these).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests._meshes import box

polyhedra = pytest.importorskip("csplab.continuous.polyhedra")
pytest.importorskip("trimesh")

from csplab.continuous.check3d import violations3  # noqa: E402


def _model(*solids: dict[str, object]) -> object:
    return polyhedra.PolyhedralModel(list(solids))


def _triangles(model: object) -> np.ndarray:
    return np.concatenate([np.asarray(s.vertices, dtype=float)[np.asarray(s.faces)]
                           for s in model.solids])  # type: ignore[attr-defined]  # fmt: skip


def _vertices(model: object) -> np.ndarray:
    return np.concatenate([np.asarray(s.vertices, dtype=float)
                           for s in model.solids])  # type: ignore[attr-defined]  # fmt: skip


def _inside(p: np.ndarray, lo: list[float], hi: list[float]) -> np.ndarray:
    """Rows of ``p`` in the closed box ``lo``-``hi``."""
    return ((p >= np.array(lo) - 1e-12) & (p <= np.array(hi) + 1e-12)).all(axis=1)


def test_a_valid_output_passes_and_the_example_passes_itself() -> None:
    """The control: the examples of the tests below accept a translated, enlarged copy."""
    E = _model(box(1, [0, 0, 0], [1, 1, 1]))
    assert len(violations3(E, E)) == 0
    assert len(violations3(E, _model(box(1, [5, 5, 5], [8, 6, 9])))) == 0
    E2 = _model(box(1, [0, 0, 0], [1, 1, 1]), box(2, [3, 0, 0], [4, 1, 1]))
    assert (
        len(violations3(E2, _model(box(2, [0, 0, 0], [2, 2, 2]), box(1, [9, 0, 0], [10, 5, 1]))))
        == 0
    )


def test_crossing_bars_only_edge_pieces_see() -> None:
    """Two bars stacked crosswise (a single cube as the example): where the upper bar
    crosses the lower bar's top edges, each edge is concave, a neighbourhood no cube has.
    No vertex of either bar is there (the crossings are inside edges of both) and no
    triangle centre either (the bars are long, the crossing off their middles), so only the
    middles of the edge pieces find it."""
    E = _model(box(1, [0, 0, 0], [1, 1, 1]))
    # sizes that are not whole units: an edge moved by a unit lands on no other edge
    M = _model(box(1, [0, 1, 0], [10, 2.5, 0.75]), box(1, [4.5, -7, 0.75], [6, 3, 1.5]))
    crossing_lo, crossing_hi = [4.5, 1, 0.75], [6, 2.5, 0.75]
    # the premise: the crossing holds no vertex and no triangle centre
    assert not _inside(_vertices(M), crossing_lo, crossing_hi).any()
    assert not _inside(_triangles(M).mean(axis=1), crossing_lo, crossing_hi).any()
    v = violations3(E, M)
    assert v.counts() == {"neighbourhood": len(v)} and len(v) >= 1
    # every defect lies on a side of the crossing, none off it
    for d in v:
        x, y = d.point
        assert 4.5 <= x <= 6 and 1 <= y <= 2.5 and (x in (4.5, 6) or y in (1, 2.5)), d
    # the upper bar lifted off the lower one: nothing to report
    assert (
        len(
            violations3(
                E, _model(box(1, [0, 1, 0], [10, 2.5, 0.75]), box(1, [4.5, -7, 1], [6, 3, 1.75]))
            )
        )
        == 0
    )


def test_a_box_on_part_of_a_triangle_only_triangle_centres_see() -> None:
    """A box of label 2 lying across the middle of a slab of label 1, where the example
    has the two labels only apart: the contact (2 above 1) is a neighbourhood of no point
    of the example. The contact region holds the centre of one of the slab's top triangles
    but no vertex and no middle of an edge piece of either solid: only triangle centres
    see it."""
    E = _model(box(1, [0, 0, 0], [1, 1, 1]), box(2, [3, 0, 0], [4, 1, 1]))
    slab = _model(box(1, [0, 0, 0], [12, 3, 1]))
    top = [t for t in _triangles(slab) if np.allclose(t[:, 2], 1)]
    c = min((t.mean(axis=0) for t in top), key=lambda p: p[0])  # a top triangle's centre
    x0 = float(np.floor(c[0])) + 0.5  # a bar 1 wide over that centre
    bar = box(2, [x0, -17, 1], [x0 + 1, 9, 2])  # long and off-centre: its edge middles miss
    M = _model(box(1, [0, 0, 0], [12, 3, 1]), bar)
    contact_lo, contact_hi = [x0, 0, 1], [x0 + 1, 3, 1]
    # the premise: no vertex, no edge middle (the edges are whole here: no vertex lies
    # inside another solid's edge) and exactly the chosen triangle centre in the contact
    tris = _triangles(M)
    mids = np.concatenate([(tris[:, i] + tris[:, (i + 1) % 3]) / 2 for i in range(3)])
    assert not _inside(_vertices(M), contact_lo, contact_hi).any()
    assert not _inside(mids, contact_lo, contact_hi).any()
    assert _inside(tris.mean(axis=1), contact_lo, contact_hi).sum() >= 1
    v = violations3(E, M)
    assert v.counts() == {"neighbourhood": len(v)} and len(v) >= 1
    for d in v:
        assert x0 <= d.point[0] <= x0 + 1 and 0 <= d.point[1] <= 3, d
    # the same bar on the slab's end, clear of the slab: nothing to report
    assert (
        len(
            violations3(
                E, _model(box(1, [0, 0, 0], [12, 3, 1]), box(2, [x0, 5, 1], [x0 + 1, 9, 2]))
            )
        )
        == 0
    )


def test_cubes_meeting_at_a_corner_only_vertices_see() -> None:
    """Two cubes touching at one corner: every edge and face of each is a cube's, only the
    shared corner (two opposite octants full) is a neighbourhood the example lacks."""
    E = _model(box(1, [0, 0, 0], [1, 1, 1]))
    M = _model(box(1, [0, 0, 0], [1, 1, 1]), box(1, [1, 1, 1], [2, 2, 2]))
    v = violations3(E, M)
    assert len(v) == 1 and v[0].kind == "neighbourhood"
    assert v[0].point == pytest.approx((1.0, 1.0))
    # a gap between them: valid
    assert (
        len(violations3(E, _model(box(1, [0, 0, 0], [1, 1, 1]), box(1, [2, 2, 2], [3, 3, 3])))) == 0
    )
    # an example that has such a corner accepts it
    assert len(violations3(M, M)) == 0


def test_an_edge_split_by_a_vertex_is_sampled_piece_by_piece() -> None:
    """A box B stands flush on the front of a slab A (the example): B's corner splits A's
    front top edge into two pieces. In the output a bar C crosses that edge on its second
    piece; the crossing (a concave edge) is found at the middle of that piece, not at the
    middle of the whole edge, which is B's corner (a neighbourhood of the example)."""
    A, B = box(1, [0, 0, 0], [4, 1, 1]), box(1, [0, 0, 1], [2, 1, 2])
    E = _model(A, B)
    assert len(violations3(E, E)) == 0
    M = _model(A, B, box(1, [2.5, -7, 1], [3.5, 0.5, 1.6]))
    v = violations3(E, M)
    at_crossing = [d for d in v if 2.5 <= d.point[0] <= 3.5 and d.point[1] == 0]
    assert at_crossing, v.describe()
