"""The infinite ground in 2D: polygons cut by the example's frame continue past it."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from csplab.continuous.check import violations
from csplab.continuous.csp import ContinuousCSP, ground_sides
from csplab.continuous.model import PolygonModel
from csplab.continuous.synthesis import synthesize
from csplab.errors import InputError

#: two houses and a slab with a block on it, all standing on the bottom of the frame
TOWERS = PolygonModel.from_json({"name": "towers", "polygons": [
    {"label": 1, "points": [[0, 0], [2, 0], [2, 3], [1, 4], [0, 3]]},
    {"label": 2, "points": [[4, 0], [7, 0], [7, 1], [4, 1]]},
    {"label": 1, "points": [[5, 1], [6, 1], [6, 2], [5, 2]]},
]})  # fmt: skip


def floating(model: PolygonModel, bottom: float) -> int:
    """Polygons touching neither the line ``y = bottom`` nor another polygon (shapely,
    apart from the CSP and the checker)."""
    geoms = [shapely.Polygon(p.points, p.holes) for p in model.polygons]
    n = 0
    for i, g in enumerate(geoms):
        if g.bounds[1] <= bottom + 1e-9:
            continue
        if any(j != i and g.distance(h) <= 1e-9 for j, h in enumerate(geoms)):
            continue
        n += 1
    return n


@pytest.mark.parametrize("seed", [1, 2])
def test_ground_stops_floating_polygons(seed: int) -> None:
    size = (24, 16)
    grounded = synthesize(TOWERS, size, solver="sat", rng=seed, ground="y-")
    free = synthesize(TOWERS, size, solver="sat", rng=seed, ground=None)
    for s in (grounded, free):
        assert s.result.ok and s.model is not None and len(s.violations) == 0
    assert grounded.csp.ground == ("y-",)
    bottom = grounded.csp.region()[1]
    assert grounded.model is not None and free.model is not None
    assert len(grounded.model) > 0
    assert floating(grounded.model, bottom) == 0
    assert floating(free.model, bottom) > 0


def test_ground_removes_the_frame_edge_from_the_example() -> None:
    # with the ground, the bottom edges of the example are no surface: no inside edge of
    # the region may have material above and empty space below
    with_g = ContinuousCSP(TOWERS, (8, 6), ground="y-")
    without = ContinuousCSP(TOWERS, (8, 6))
    assert (1, 0) in [(L, R) for L, R in without.edge_states_allowed(0)]  # label 1 above
    assert (1, 0) not in with_g.edge_states_allowed(0)
    assert with_g.problem.meta["ground"] == ["y-"]


#: a hill cut by both sides of its frame, and outputs cut otherwise
HILL = PolygonModel.from_json(
    {"polygons": [{"label": 1, "points": [[0, 0], [6, 0], [6, 2], [4, 2], [2, 4], [0, 4]]}]}
)
STEEP = PolygonModel.from_json(
    {"polygons": [{"label": 1, "points": [[0, 0], [6, 0], [6, 2], [4, 2], [0, 6]]}]}
)


def test_checker_continues_polygons_past_open_sides() -> None:
    region = (0.0, 0.0, 6.0, 7.0)
    # the slope meets the region's left side: without the ground an acute corner the
    # example lacks; with it, the slope meets a flat top continued from the left, which
    # the example has inside (at (2, 4)) but not on that side of its box
    v = violations(HILL, STEEP, region=region)
    assert v.counts() == {"vertex": 1} and v[0].point == (0.0, 6.0)
    for ground in (("x-",), ground_sides("window")):
        v = violations(HILL, STEEP, region=region, ground=ground)
        assert v.counts() == {"ground": 2} and {d.point for d in v} == {(0.0, 6.0)}
    # the hill cut by the sides elsewhere, as the example is: valid with the window
    cut = PolygonModel.from_json({"polygons": [
        {"label": 1, "points": [[0, 0], [6, 0], [6, 3], [2, 3], [1, 4], [0, 4]]}]})  # fmt: skip
    assert len(violations(HILL, cut, region=region, ground=ground_sides("window"))) == 0


def test_checker_flags_a_floating_polygon_only_with_the_ground() -> None:
    region = (0.0, 0.0, 6.0, 7.0)
    block = {"label": 1, "points": [[1, 5], [2, 5], [2, 6], [1, 6]]}
    fl = PolygonModel.from_json({"polygons": [HILL.to_json()["polygons"][0], block]})
    assert len(violations(HILL, fl, region=region)) == 0
    v = violations(HILL, fl, region=region, ground=("y-",))
    assert v.counts().get("edge", 0) >= 1  # its bottom edge: material above, empty below
    assert all(5 - 1e-9 <= d.point[1] <= 6 + 1e-9 for d in v)


def test_ground_sides_refuses_other_names() -> None:
    assert set(ground_sides("window")) == {"x-", "x+", "y-"}
    with pytest.raises(InputError, match="z-"):
        ground_sides("z-")
    with pytest.raises(InputError, match="z-"):
        violations(HILL, HILL, region=HILL.bounds, ground=("z-",))


@pytest.mark.parametrize("seed", [1, 2])
def test_weighted_choice_moves_edge_frequencies_toward_coverage(seed: int) -> None:
    # the share of edges that are a boundary (two labels): in the example's coverage, and
    # in the outputs of the uniform and the weighted choice on the same seed
    share = {}
    for choice in ("uniform", "weighted"):
        s = synthesize(TOWERS, (24, 16), rng=seed, choice=choice)
        assert s.result.ok and len(s.violations) == 0
        left, right = s.csp.edge_labels(s.result.grid)
        share[choice] = float((left != right).mean())
    C = s.csp
    assert C.problem.value_weights is not None
    Kl = C.Kl
    cover = C.problem.value_weights[0][len(C.type_states) :, : Kl * Kl] - 1.0
    L, R = divmod(np.arange(Kl * Kl), Kl)
    example = float(cover[:, L != R].sum() / cover.sum())
    assert abs(share["weighted"] - example) < abs(share["uniform"] - example)


def test_weighted_is_the_2d_default_as_in_3d() -> None:
    from csplab.continuous.synthesis import default_choice, synthesize

    C = ContinuousCSP(TOWERS, (6, 4))
    assert C.problem.value_weights is not None
    assert default_choice(C.problem, "catalog") == "weighted"
    assert default_choice(C.problem, "sat") == "weighted"
    # a solver without a weighted choice keeps its own
    assert default_choice(C.problem, "asp") is None
    # the default run is the weighted one, not the uniform one
    runs = {k: synthesize(TOWERS, (24, 16), rng=2, **kw).model
            for k, kw in (("default", {}), ("weighted", {"choice": "weighted"}),
                          ("uniform", {"choice": "uniform"}))}  # fmt: skip
    assert runs["default"] is not None and runs["uniform"] is not None
    assert runs["default"].to_json() == runs["weighted"].to_json()
    assert runs["default"].to_json() != runs["uniform"].to_json()
