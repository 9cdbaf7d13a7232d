"""Overlap defects of the 2D checker on models built internally (issue 32).

csplab's own outputs are built with ``PolygonModel._trusted`` (no validation: the checker
:func:`csplab.continuous.check.violations` verifies them), so the checker itself must see
two labels claiming the same area, whether the rings meet at vertices or cross."""

from __future__ import annotations

import pytest

from csplab.continuous.check import violations
from csplab.continuous.model import Polygon, PolygonModel


def _sq(b: int, x0: float, y0: float, x1: float, y1: float) -> Polygon:
    return Polygon(b, ((x0, y0), (x1, y0), (x1, y1), (x0, y1)))


E = PolygonModel._trusted([_sq(1, 0, 0, 1, 1), _sq(2, 3, 0, 4, 1)])  # two labels, apart
E_TOUCH = PolygonModel._trusted([_sq(1, 0, 0, 1, 1), _sq(2, 1, 0, 2, 1)])  # side by side


def test_controls_without_overlap_pass() -> None:
    assert len(violations(E, E)) == 0
    assert len(violations(E, PolygonModel._trusted([_sq(1, 0, 0, 2, 2),
                                                    _sq(2, 5, 5, 6, 9)]))) == 0  # fmt: skip
    assert (
        len(violations(E_TOUCH, PolygonModel._trusted([_sq(1, 0, 0, 2, 1), _sq(2, 2, 0, 3, 1)])))
        == 0
    )


def test_overlap_with_shared_vertices_is_a_label_defect() -> None:
    """Label 2 laid over half of label 1 (their rings share the vertices of the overlap)."""
    M = PolygonModel._trusted([_sq(1, 0, 0, 2, 1), _sq(2, 1, 0, 3, 1)])
    v = violations(E_TOUCH, M)
    labels = [d for d in v if d.kind == "label"]
    assert labels and all("overlap" in d.detail for d in labels)
    assert all(1 <= d.point[0] <= 2 and 0 <= d.point[1] <= 1 for d in labels)


@pytest.mark.parametrize("example", [E, E_TOUCH], ids=["apart", "touching"])
def test_overlap_with_crossing_edges_is_a_label_defect(example: PolygonModel) -> None:
    """Two squares of different labels overlapping in a corner: their rings cross inside
    edges (no vertex of one lies on the other), each vertex inside the other square looks
    like an ordinary corner; only the overlap itself is wrong."""
    M = PolygonModel._trusted([_sq(1, 0, 0, 2, 2), _sq(2, 1, 1, 3, 3)])
    v = violations(example, M)
    labels = [d for d in v if d.kind == "label" and "overlap" in d.detail]
    assert len(labels) >= 1, v.describe()
    assert all(1 <= d.point[0] <= 2 and 1 <= d.point[1] <= 2 for d in labels)
    # one square inside the other: no ring meets another at all
    inner = PolygonModel._trusted([_sq(1, 0, 0, 4, 4), _sq(2, 1, 1, 2, 2)])
    assert any(d.kind == "label" and "overlap" in d.detail for d in violations(example, inner))
