"""Grid variants of thesis Sec. 3.5.1: hexagonal, triangular, cylindrical and affine grids."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import csplab
from csplab import ExampleModel, Problem, load_example
from csplab.errors import FormatError, InputError
from csplab.grids import from_example
from csplab.io.gridtext import format_grid, parse_grid
from csplab.render import render
from csplab.topology import Topology

from .io._helpers import installed_solvers

HEX = ["hex:odd-r", "hex:even-r", "hex:odd-q", "hex:even-q"]


@pytest.mark.parametrize("name", [*HEX, "tri"])
def test_neighbourhoods(name):
    T = Topology.parse(name)
    shape = (7, 6)
    a = T.arcs(shape)
    pairs = {tuple(sorted(p)) for p in a[:, :2].tolist()}
    assert len(pairs) == len(a)  # each neighbour pair once
    deg = np.bincount(a[:, :2].ravel(), minlength=42).reshape(shape)
    assert deg[2:-2, 2:-2].min() == deg[2:-2, 2:-2].max() == (6 if name != "tri" else 3)
    # neighbours are near in the picture: centres closer than 1.2 cell sizes
    polys = T.polygons(shape)
    c = np.array([p.mean(axis=0) for p in polys])
    d = np.linalg.norm(c[a[:, 0]] - c[a[:, 1]], axis=1)
    assert d.max() < (1.9 if name != "tri" else 0.8) and d.min() > 0.4
    prism = T.arcs((4, 3, 2))
    assert (prism[:, 2] == 3).sum() == 12  # T_z between the two layers


def test_offset_conventions_differ():
    a = {n: Topology.parse(n).neighbours((4, 4), (1, 1)) for n in HEX}
    assert a["hex:odd-r"] != a["hex:even-r"] and a["hex:odd-q"] != a["hex:even-q"]
    assert len(set(map(frozenset, a.values()))) == 4


def brute(P: Problem) -> set[bytes]:
    out = set()
    for g in itertools.product(range(P.K), repeat=P.n):
        arr = np.array(g, dtype=np.int32).reshape(P.shape)
        if P.is_solution(arr):
            out.add(arr.tobytes())
    return out


@pytest.mark.parametrize("name", ["hex:odd-r", "hex:odd-q", "tri"])
def test_exact_solvers_agree_with_brute_force(name):
    E = ExampleModel([[0, 1, 1, 0], [1, 0, 0, 1], [1, 1, 0, 0]], meta={"topology": name})
    P = from_example(E, (3, 3))
    assert P.meta["topology"] == name and P.R == 3
    sols = brute(P)
    from csplab.engine.sat import enumerate_solutions

    assert {g.tobytes() for g in enumerate_solutions(P)} == sols
    for solver in [s for s in ("sat", "backtrack", "cpsat", "asp") if s in installed_solvers()]:
        r = csplab.solve(P, solver, rng=1)
        assert (r.status == "solved") == bool(sols)
        if sols:
            assert r.grid.astype(np.int32).tobytes() in sols


def test_builtin_examples_synthesize_with_every_solver():
    for name in ("hexriver", "trifan"):
        E = load_example(name)
        P = from_example(E, (12, 10))
        for solver in installed_solvers():
            r = csplab.solve(P, solver, rng=2, restarts=10)
            assert r.status == "solved" and P.is_solution(r.grid), (name, solver)
        # the example itself is a solution at its own size
        assert from_example(E, E.shape).is_solution(E.labels)
        with pytest.raises(InputError, match="square grids"):
            E.transitions()


def test_grid_text_round_trip_and_pictures():
    E = load_example("hexriver")
    again = parse_grid(format_grid(E), path="x.grid")
    assert again.topology == "hex:odd-r" and np.array_equal(again.labels, E.labels)
    sq = render(E.labels, K=3, scale=10)
    hx = render(E.labels, K=3, scale=10, topology="hex:odd-r")
    assert sq.size != hx.size and hx.getpixel((hx.width // 2, hx.height // 2)) != (255, 255, 255)
    for t in ("tri", "cylinder", "affine:1,0.5,0,1"):
        assert render(E.labels, K=3, scale=6, topology=t).width > 0


def test_cylinder_and_affine_grids():
    E = load_example("loops")
    P = from_example(E, (6, 12), topology="cylinder")
    assert P.meta["periodic"] == (False, True) and P.meta["topology"] == "cylinder"
    r = csplab.solve(P, "sat", rng=0)
    assert r.ok and P.is_solution(r.grid)
    A = from_example(E, (6, 6), topology="affine:1,0.5,0,1")
    assert len(A.arcs) == len(from_example(E, (6, 6)).arcs)
    for bad in ("pentagon", "affine:1,2", "affine:1,1,1,1"):
        with pytest.raises(InputError):
            Topology.parse(bad)
    with pytest.raises(InputError, match="cannot be periodic"):
        from_example(load_example("hexriver"), (6, 6), periodic=True)


def _run(capsys, *args):
    from csplab.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli(tmp_path, capsys):
    out = tmp_path / "h.grid"
    code, o, err = _run(capsys, "synthesize", "hexriver", "--size", "16x12", "--seed", "1",
                        "--out", out)  # fmt: skip
    assert code == 0, err
    assert "topology: hex:odd-r" in out.read_text()
    code, o, _ = _run(capsys, "check", "hexriver", out)
    assert code == 0 and o.startswith("0 violations")
    code, o, _ = _run(capsys, "check", "hexriver", out, "--grid", "square")
    assert code == 1  # the same labels break the square reading of the example
    png = tmp_path / "t.png"
    code, _, err = _run(capsys, "synthesize", "loops", "--size", "12x8", "--grid", "tri",
                        "--seed", "3", "--out", png)  # fmt: skip
    assert code == 0 and png.stat().st_size > 0, err
    code, _, err = _run(capsys, "synthesize", "loops", "--size", "8x8", "--grid", "pentagon")
    assert code == 2 and "unknown grid 'pentagon'" in err and len(err.strip().splitlines()) == 1


def test_tiled_maps_and_debroglie_hex_configs(tmp_path):
    from csplab.examples import load_model
    from csplab.io.tiled import parse_tmx

    data = Path(__file__).parent / "io" / "data"
    E = load_model(data / "hexmap.tmx")
    # 6 rows, odd ones shifted in the file: after the flip (y up) the even rows are
    assert E.topology == "hex:even-r" and E.shape == (8, 6) and E.K == 3
    assert E.names == ("gid 1", "gid 2", "gid 3")
    P = from_example(E, (12, 9))
    r = csplab.solve(P, "sat", rng=1)
    assert r.ok and P.is_solution(r.grid)
    # the map's own river is consistent with what the map teaches
    assert from_example(E, E.shape).is_solution(E.labels)
    rs = load_model(data / "tiled" / "hex_debroglie.json")
    assert rs.topology == "hex:even-r" and rs.ndim == 2 and rs.shape == (16, 12)
    assert np.array_equal(rs.relations, Topology.parse(E.topology).learn(E.labels, E.K))
    Q = rs.problem()
    assert Q.meta["topology"] == "hex:even-r"
    r = csplab.solve(Q, "catalog", rng=2, restarts=10)
    assert r.ok and Q.is_solution(r.grid)
    assert rs.render(r.grid).width > 0
    # base64 + zlib, columns offset, and the errors
    import base64
    import zlib

    ids = np.array([1, 2, 2, 1, 1, 2], dtype="<u4").tobytes()
    b64 = base64.b64encode(zlib.compress(ids)).decode()
    text = (f'<map orientation="hexagonal" staggeraxis="x" staggerindex="odd" width="3" '
            f'height="2"><layer><data encoding="base64" compression="zlib">{b64}</data>'
            '</layer></map>')  # fmt: skip
    M = parse_tmx(text, path="m.tmx")
    assert M.topology == "hex:even-q" and M.labels.tolist() == [[0, 0], [0, 1], [1, 1]]
    for bad, what in [
        ('<map orientation="isometric" width="1" height="1"/>', "not supported"),
        ('<map width="2" height="1"><layer><data encoding="csv">1</data></layer></map>',
         "1 tiles for a 2x1 layer"),
        ("<set/>", "root <map>"),
    ]:  # fmt: skip
        with pytest.raises(FormatError, match=what):
            parse_tmx(bad, path="m.tmx")


def test_connectivity_uses_the_grid_s_own_neighbours():
    from csplab.constraints import Connected, MaxRun, grid_edges

    P = from_example(load_example("hexriver"), (6, 5))
    lo = grid_edges(P)[0]
    assert len(lo) == len(P.arcs)  # every hexagonal neighbour pair, diagonal ones too
    # two cells that touch only through a hex diagonal (odd-r: row 1 is shifted right, so
    # (0, 1) touches (1, 2)) connect
    g = np.zeros((6, 5), dtype=np.int32)
    g[0, 1] = g[1, 2] = 2
    Q = P.with_constraints([Connected([2])])
    assert Q.constraints[0].check(Q, g.reshape(-1).astype(np.int64)) is None
    with pytest.raises(InputError, match="needs a square grid"):
        P.with_constraints([MaxRun([2], 2)])
