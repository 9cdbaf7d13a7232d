"""Continuous model synthesis (thesis Ch. 4, 2008 paper): properties of the CSP and checker.

Every solved output has zero violations of Eq. 4.1 (checked on the polygons, independently
of the CSP); the example, stretched by an integer factor and placed in the region, is a
solution of its own CSP (Sec. 4.5.6); exact solvers agree; the checker catches planted
defects.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from csplab.continuous import ContinuousCSP, PolygonModel, synthesize, violations
from csplab.continuous.arrangement import Arrangement, Lattice
from csplab.continuous.csp import reduce_signature
from csplab.errors import InputError
from csplab.solvers import solve
from csplab.testing.strategies import polygon_models

TRIANGLE = {"polygons": [{"label": 1, "points": [[0, 0], [4, 0], [2, 3]]}]}
PROPS = settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))


def _stretched(E: PolygonModel, t: int, offset: float) -> PolygonModel:
    x0, y0, _, _ = E.bounds
    shapes = {
        b: shapely.affinity.translate(
            shapely.affinity.scale(E.shape(b), t, t, origin=(x0, y0)), offset, offset
        )
        for b in E.labels
    }
    return PolygonModel.from_shapes(shapes)


def _region_for(E: PolygonModel, C: ContinuousCSP, t: int) -> bool:
    x0, y0, x1, y1 = E.bounds
    s = float(C.lattice.spacing)
    W, H = C.problem.meta["size"]
    return (x1 - x0) * t / s + 1 <= W and (y1 - y0) * t / s + 1 <= H


@PROPS
@given(polygon_models(), st.integers(0, 2**16))
def test_solved_outputs_satisfy_eq_4_1(E: PolygonModel, seed: int) -> None:
    C = ContinuousCSP(E, (8, 8))
    for solver in ("catalog", "sat"):
        r = solve(C.problem, solver, rng=seed)
        if r.status != "solved":
            assert solver == "catalog" and r.status == "failed"  # never unsat: empty works
            continue
        M = C.model(r.grid)
        v = violations(E, M, region=C.region())
        assert len(v) == 0, v.describe()
        # and the polygons describe the solution exactly
        assert (C.encode(M) == np.asarray(r.grid).reshape(-1)).all()


@PROPS
@given(polygon_models(), st.sampled_from([1, 2]))
def test_stretched_copies_are_solutions(E: PolygonModel, t: int) -> None:
    C = ContinuousCSP(E, (14, 14))
    if not _region_for(E, C, t):
        return
    M = _stretched(E, t, float(C.lattice.spacing))
    assert len(C.problem.violations(C.encode(M))) == 0
    assert len(violations(E, M)) == 0


@PROPS
@given(polygon_models(max_extent=4), st.integers(0, 3))
def test_exact_solvers_agree(E: PolygonModel, where: int) -> None:
    """With one edge forced to carry an object edge the problem may be unsatisfiable; the
    exact solvers agree on which."""
    C = ContinuousCSP(E, (5, 4))
    P = C.problem
    nonzero = [i for i in range(C.Kl * C.Kl) if i != 0]
    e = int(C.var_edge[(where * 7919) % len(C.var_edge)])
    allowed = np.ones((P.n, P.K), dtype=bool)
    allowed[e] = False
    allowed[e, nonzero] = True
    Q = P.restrict(allowed)
    verdicts = {s: solve(Q, s, rng=0).status for s in ("sat", "cpsat", "backtrack")}
    assert len(set(verdicts.values())) == 1, verdicts
    assert verdicts["sat"] in ("solved", "unsat")


def test_triangle_counts_of_the_thesis() -> None:
    """Sec. 4.5.2: a horizontal edge takes 3 of the 8 labels (Fig. 4.15), the vertex of
    Fig. 4.16 (lines parallel to h2 and h3) 5, a vertex on all three families 8."""
    C = ContinuousCSP(PolygonModel.from_json(TRIANGLE), (10, 8))
    assert len(C.signatures) == 8
    assert C.edge_states_allowed(0) == [(0, 0), (1, 0), (1, 1)]
    counts = C.vertex_state_counts()
    fams = {tuple(d) for d in C.arrangement.dirs.tolist()}
    assert fams == {(1, 0), (2, 3), (-2, 3), (0, 1)}  # (0, 1): the region's sides only
    h2h3 = [k for k in counts if len(k) == 2 and 0 not in k]
    assert [counts[k] for k in h2h3] == [5]
    assert max(counts.values()) == 8


def test_vertex_count_is_quadratic_in_lines() -> None:
    """Sec. 4.5.7 (2D): O(m^2 n^2) vertices; doubling the region quadruples them."""
    lat = Lattice.of([[(0, 0), (4, 0), (2, 3)]])
    n1, n2 = Arrangement(lat, 20, 20).n_vertices, Arrangement(lat, 40, 40).n_vertices
    assert 3.7 < n2 / n1 < 4.1


def test_three_lines_meet_exactly() -> None:
    """Every lattice point is a vertex where all families meet (Sec. 4.5.8 by construction)."""
    lat = Lattice.of([[(0, 0), (3, 0), (3, 1), (1, 2)]])
    A = Arrangement(lat, 6, 5)
    on_lattice = (A.X % A.D == 0) & (A.Y % A.D == 0)
    F = A.F
    rays = np.array([bin(int(m)).count("1") for m in A.ray_mask])
    side = A.on_side() != 0
    assert (rays[on_lattice & ~side] == 2 * F).all()


def test_checker_catches_planted_defects() -> None:
    E = PolygonModel.from_json(TRIANGLE)
    s = synthesize(E, (12, 9), rng=5)
    assert s.ok
    M = s.model
    assert M is not None and len(M) > 0
    # 1. a foreign direction: shear one polygon's first vertex sideways
    p = M.polygons[0]
    pts = list(p.points)
    pts[0] = (pts[0][0] + 0.25, pts[0][1])
    bad = PolygonModel([{"label": 1, "points": pts}, *[q.to_json() for q in M.polygons[1:]]])
    v = violations(E, bad)
    assert v.counts().get("direction", 0) >= 1
    # 2. an upside-down copy: right directions, wrong sides
    flipped = PolygonModel.from_shapes({1: shapely.affinity.scale(E.shape(1), 1, -1)})
    assert {"edge", "vertex"} <= set(violations(E, flipped).counts())
    # 3. a label the example does not have
    extra = PolygonModel([*[q.to_json() for q in M.polygons], {"label": 7, "points":
                          [[100, 100], [104, 100], [102, 103]]}])  # fmt: skip
    assert violations(E, extra).counts().get("label") == 1
    # 4. a solution with one edge value changed is caught by the CSP checker too
    g = np.asarray(s.result.grid).reshape(-1).copy()
    e = int(s.csp.var_edge[0])
    g[e] = 3  # (1, 1): inside on both sides of a boundary edge
    assert len(s.csp.problem.violations(g)) > 0


def test_blocks_work_in_line_spacings() -> None:
    E = PolygonModel.from_json(TRIANGLE)
    s = synthesize(E, (24, 20), solver="blocks", rng=2, block=8)
    assert s.ok and s.result.stats["block"] == [8, 8]
    assert s.result.stats["blocks_tried"] == len(range(0, 24 - 8 + 1, 4)) * len(
        range(0, 20 - 8 + 1, 4)
    )


def test_boundary_label_outside_the_region() -> None:
    """With label 1 outside, the triangle (no vertical edges) must have label 1 all along
    the region's left and right sides; the checker sees the outside as label 1."""
    E = PolygonModel.from_json(TRIANGLE)
    for seed in range(3):
        s = synthesize(E, (10, 6), boundary=1, solver="sat", rng=seed)
        assert s.ok, s.violations.describe()
        x0, y0, x1, y1 = s.csp.region()
        ys = np.linspace(y0 + 0.01, y1 - 0.01, 25)
        assert s.model is not None
        one = s.model.shape(1)
        for x in (x0 + 1e-3, x1 - 1e-3):
            assert shapely.contains_xy(one, np.full_like(ys, x), ys).all()
        # without the outside label the same polygons break Eq. 4.1 on the sides
        assert len(violations(E, s.model)) > 0


def test_spacing_and_snap() -> None:
    E = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [10, 0], [5, 7.5]]}]})
    assert float(Lattice.of([E.polygons[0].points]).spacing) == 2.5
    C = ContinuousCSP(E, (6, 6), spacing=5.0, snap=True)  # (5, 7.5) -> (5, 10)
    assert C.lattice.snapped == pytest.approx(0.5)
    with pytest.raises(InputError, match="off the lattice"):
        ContinuousCSP(E, (6, 6), spacing=5.0)
    with pytest.raises(InputError, match="positive"):
        ContinuousCSP(E, (6, 6), spacing=-1.0)


def test_signatures_are_reduced() -> None:
    assert reduce_signature([0, 2], [1, 1]) == ((-1, 1),)
    assert reduce_signature([0, 1, 2, 3], [0, 0, 0, 0]) == ((-1, 0),)


@pytest.mark.parametrize(
    "bad, match",
    [
        ({"polygons": []}, "at least one polygon"),
        ({"polygons": [{"label": 0, "points": [[0, 0], [1, 0], [0, 1]]}]}, "label must be >= 1"),
        ({"polygons": [{"label": 1, "points": [[0, 0], [1, 0], [2, 0]]}]}, "zero area"),
        ({"polygons": [{"label": 1, "points": [[0, 0], [1, 0], [float("nan"), 1]]}]},
         "non-finite"),
        ({"polygons": [{"label": 1, "points": [[0, 0], [2, 0], [0, 2]]},
                       {"label": 2, "points": [[0, 0], [1, 0], [0, 1]]}]}, "overlap"),
    ],
)  # fmt: skip
def test_bad_examples_end_in_one_line(bad: dict[str, object], match: str) -> None:
    with pytest.raises(InputError, match=match) as e:
        ContinuousCSP(PolygonModel.from_json(bad, source="bad.json"), (4, 4))
    assert "\n" not in str(e.value) and "bad.json" in str(e.value)


@pytest.mark.parametrize("name", ["triangle", "pentagon", "fallible"])
def test_equal_line_spacing(name: str) -> None:
    """``lines="equal"``: every family about one spacing apart (the 2008 paper); fewer
    vertices, outputs still satisfy Eq. 4.1, and the example stretched by the lcm of the
    line steps is still a solution."""
    from csplab.examples.continuous import load_polygon_example

    E = load_polygon_example(name)
    C = ContinuousCSP(E, (30, 30), lines="equal")
    L = ContinuousCSP(E, (30, 30))
    A = C.arrangement
    assert C.problem.meta["lines"] == "equal"
    if (A.step > 1).any():
        assert A.n_vertices < L.arrangement.n_vertices
    norm = np.hypot(A.normals[:, 0], A.normals[:, 1])
    gap = A.step / norm  # distance between a family's lines, in spacings
    assert (np.abs(gap - 1) <= 0.5).all()
    t = int(np.lcm.reduce(A.step))
    x0, y0, x1, y1 = E.bounds
    s = float(C.lattice.spacing)
    if ((x1 - x0) / s + 1) * t <= 30 and ((y1 - y0) / s + 1) * t <= 30:
        M = _stretched(E, t, t * s)  # corners on lines of every family: multiples of t
        assert len(C.problem.violations(C.encode(M))) == 0
    r = solve(C.problem, "sat", rng=1)
    assert r.status == "solved"
    assert len(violations(E, C.model(r.grid), region=C.region())) == 0
