"""``boundary="auto"`` on 3D examples: the current rule when it has a solution, else
Merrell's rule (bottom = E[0, 0, 0], top = E[0, 0, nz - 1], sides free)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.examples import load_example
from csplab.grids import auto_boundary, from_example, merrell_boundary
from csplab.solvers import solve


def _layered(nx: int = 3, layers: tuple[int, ...] = (1, 2, 0, 0)) -> ExampleModel:
    """An example whose bottom layer is ground 1, then a floor 2, then empty space 0:
    empty space never sits directly on the bottom layer."""
    lab = np.broadcast_to(np.array(layers), (nx, nx, len(layers))).copy()
    return ExampleModel(lab, name="layered")


def test_auto_falls_back_to_merrell_when_the_auto_rule_has_no_solution() -> None:
    E = _layered()
    assert auto_boundary(E) == {"x-": 0, "x+": 0, "y-": 0, "y+": 0, "z+": 0, "z-": 1}
    P = from_example(E, (5, 5, 4), boundary="auto")
    assert P.meta["boundary"] == {"z-": 1, "z+": 0} == merrell_boundary(E)
    assert P.meta["boundary_rule"].startswith("merrell: z-=1, z+=0, sides free")
    r = solve(P, "backtrack", rng=0)
    assert r.status == "solved" and P.is_solution(r.grid)
    assert (r.grid[:, :, 1] == 2).all()
    # the auto rule itself really has no solution there
    assert (
        solve(from_example(E, (5, 5, 4), boundary=auto_boundary(E)), "backtrack").status == "unsat"
    )


def test_auto_falls_back_when_the_example_has_no_empty_space_label() -> None:
    E = _layered(layers=(1, 2, 0))  # nothing tiles itself vertically; top layer 0
    P = from_example(E, (4, 4, 3), boundary="auto")
    assert P.meta["boundary_rule"].startswith("merrell: z-=1, z+=0")
    assert solve(P, "catalog", rng=1).status == "solved"


def test_auto_keeps_the_current_rule_when_it_works() -> None:
    E = _layered(layers=(1, 0, 0))  # empty space right on the ground
    P = from_example(E, (5, 5, 4), boundary="auto")
    assert P.meta["boundary"] == auto_boundary(E)
    assert P.meta["boundary_rule"] == "auto: ground z-=1, empty space 0 on every other face"


@pytest.mark.parametrize("name", ["city", "castle", "canal"])
def test_builtin_3d_examples_keep_the_auto_rule(name: str) -> None:
    E = load_example(name)
    P = from_example(E, (10, 10, 6), boundary="auto")
    assert P.meta["boundary"] == {"x-": 0, "x+": 0, "y-": 0, "y+": 0, "z+": 0, "z-": 1}
    assert P.meta["boundary_rule"].startswith("auto: ")
    explicit = from_example(E, (10, 10, 6), boundary=auto_boundary(E, 3))
    assert np.array_equal(P.domains, explicit.domains)


def test_2d_auto_is_unchanged() -> None:
    E = ExampleModel([[1, 0, 0], [1, 0, 0], [1, 0, 0]])
    P = from_example(E, (4, 4), boundary="auto")
    assert P.meta["boundary"] == auto_boundary(E)
    assert P.meta["boundary_rule"].startswith("auto: ground y-=1")


_MERRELL = Path(__file__).resolve().parents[2] / "shared" / "anchors-data"


@pytest.mark.parametrize(
    "path",
    sorted(p for d in _MERRELL.glob("*erell*") for p in d.rglob("*.txt"))
    or [pytest.param(None, marks=pytest.mark.skip(reason="no Merrell 3D models in anchors-data"))],
)
def test_merrell_models_are_satisfiable_with_auto(path: Path) -> None:
    from csplab.io import read_model

    E = read_model(path)
    if not isinstance(E, ExampleModel) or E.ndim != 3:
        pytest.skip("not a 3D example model")
    P = from_example(E, (6, 6, E.shape[2]), boundary="auto")
    assert solve(P, "backtrack", rng=0, time_limit=30).status == "solved"


def test_synthesize_says_which_boundary_rule_it_used(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from csplab.cli import main
    from csplab.io import write_example

    write_example(_layered(), tmp_path / "layered.npy")
    code = main(["synthesize", str(tmp_path / "layered.npy"), "--size", "5x5x4",
                 "--boundary", "auto", "--seed", "1"])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    assert "  boundary merrell: z-=1, z+=0, sides free" in out


def test_auto_never_makes_the_problem_unsat() -> None:
    E = _layered()  # ground 1, floor 2, then empty space 0
    # nz = 2: Merrell's top label 0 cannot sit on the ground; the ground alone can
    P = from_example(E, (4, 4, 2), boundary="auto")
    assert P.meta["boundary"] == {"z-": 1}
    assert P.meta["boundary_rule"].startswith("merrell, bottom only: z-=1")
    assert solve(P, "backtrack", rng=0).status == "solved"
    # nz = 1: the bottom face holds every cell, the ground tiles sideways: auto works
    P1 = from_example(E, (3, 3, 1), boundary="auto")
    assert P1.meta["boundary_rule"].startswith("auto: ground z-=1")
    assert solve(P1, "backtrack", rng=0).status == "solved"


# ----------------------------------------------------------------------------- GridWindows
@pytest.mark.parametrize(
    "name,shape,boundary",
    [
        ("castle", (9, 7, 6), "auto"),
        ("fig3_4a", (11, 5), {"x-": 0, "y+": 1}),
        ("line", (8, 6), None),
    ],
)
def test_a_window_is_the_whole_problem_restricted(name, shape, boundary):
    """Every box's domains and arcs are the whole problem's, renumbered."""
    from csplab.grids import GridWindows

    E = load_example(name)
    P = from_example(E, shape, boundary=boundary)
    W = GridWindows(E, shape, boundary=boundary)
    assert (W.K, W.reach, W.n) == (P.K, 1, P.n)
    idx = np.arange(P.n).reshape(P.shape)
    rng = np.random.default_rng(0)
    for _ in range(12):
        lo = [int(rng.integers(0, s)) for s in shape]
        hi = [int(rng.integers(a + 1, s + 1)) for a, s in zip(lo, shape, strict=True)]
        Q = W.window(lo, hi)
        cells = idx[tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))].reshape(-1)
        assert np.array_equal(Q.domains, P.domains[cells])
        inside = np.zeros(P.n, dtype=np.int64) - 1
        inside[cells] = np.arange(cells.size)
        keep = (inside[P.arcs[:, 0]] >= 0) & (inside[P.arcs[:, 1]] >= 0)
        mine = {(int(inside[s]), int(inside[d]), int(r)) for s, d, r in P.arcs[keep]}
        assert mine == {tuple(map(int, a)) for a in Q.arcs}
        assert W.window(lo, hi) is Q  # built once per shape and faces
    with pytest.raises(InputError, match="not a box"):
        W.window((0,) * len(shape), [s + 1 for s in shape])


def test_windowed_check_counts_what_the_whole_check_counts():
    """Planted defects: violated arcs across slab seams, out-of-domain face cells, an
    unassigned cell; the slab check (small slabs) counts each once."""
    from csplab.grids import GridWindows

    E = load_example("castle")
    shape = (13, 6, 5)
    P = from_example(E, shape, boundary="auto")
    W = GridWindows(E, shape, boundary="auto")
    g = solve(P, "blocks", rng=2, block=5).grid.copy()
    assert W.violations(g, cells=30) == 0
    rng = np.random.default_rng(3)
    for k in range(1, 6):
        x, y, z = (int(rng.integers(0, s)) for s in shape)
        g[x, y, z] = int(rng.integers(-1, P.K))
        g[k, 0, 0] = (g[k, 0, 0] + 1) % P.K  # a face cell, often on a seam
        want = len(P.violations(g))
        for cells in (1, 30, 60, 10**6):
            assert W.violations(g, cells=cells) == want
    assert want > 0
    with pytest.raises(InputError, match="shape"):
        W.violations(g[:3])
