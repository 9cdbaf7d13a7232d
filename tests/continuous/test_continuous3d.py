"""Continuous model synthesis in 3D (thesis Sec. 4.5.3-4.5.6, 2008 paper Sec. 3.4): the exact
plane arrangement, the example's neighbourhoods and the binary CSP."""

from __future__ import annotations

import numpy as np
import pytest

from csplab.continuous._geom import labels_at
from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.lattice import Lattice
from csplab.continuous.space import Arrangement3, central_cells
from csplab.errors import InputError
from csplab.solvers import solve
from tests._meshes import box as _box

polyhedra = pytest.importorskip("csplab.continuous.polyhedra")
pytest.importorskip("trimesh")

TET = {"label": 1, "vertices": [[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]],
       "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}  # fmt: skip


def _scaled(d: dict[str, object], t: int, off: int) -> dict[str, object]:
    return {**d, "vertices": (np.array(d["vertices"]) * t + off).tolist()}


def test_tetrahedron_labels_and_fig9() -> None:
    """Sec. 4.5.3: the tetrahedron has 16 labels; 2008 paper Fig. 9: its top vertex (three
    planes) has 9 states; a vertex on the three axis planes (a corner) 9 as well; a vertex
    on two planes only edge/face/empty/full states."""
    C = ContinuousCSP3(polyhedra.PolyhedralModel([TET]), (3, 3, 3))
    assert len(C.signatures) == 16
    assert C.states_at_planes([(1, 0, 0), (0, 1, 0), (1, 1, 1)]) == 9
    assert C.states_at_planes([(1, 0, 0), (0, 1, 0), (0, 0, 1)]) == 9
    assert C.states_at_planes([(1, 0, 0), (0, 1, 0)]) == 5  # empty, full, 2 faces, 1 edge


def test_central_cells_count() -> None:
    """k planes through a point in general position cut space into k(k-1)+2 cells."""
    for k, normals in ((3, [(1, 0, 0), (0, 1, 0), (0, 0, 1)]),
                       (4, [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)])):  # fmt: skip
        signs, dirs = central_cells(np.array(normals))
        assert len(signs) == k * (k - 1) + 2
        assert (np.sign(dirs @ np.array(normals).T) == signs).all()


def test_the_checker_finds_the_same_cells_its_own_way() -> None:
    """The 3D checker's cone_cells (corner triangles) and the CSP's central_cells (sector
    bisectors) are two constructions of one set of cells: equal on random normals."""
    from csplab.continuous.check3d import cone_cells

    rng = np.random.default_rng(7)
    for _ in range(60):
        N = np.concatenate([rng.integers(-3, 4, size=(int(rng.integers(1, 8)), 3)), np.eye(3)])
        keep: list[int] = []
        for i, n in enumerate(N):
            u = n / (np.linalg.norm(n) or 1.0)
            if np.abs(n).sum() and all(
                abs(abs(u @ N[j]) / np.linalg.norm(N[j]) - 1) > 1e-9 for j in keep
            ):
                keep.append(i)
        N = N[keep].astype(np.int64)
        want = {s.tobytes() for s in central_cells(N)[0]}
        signs, dirs = cone_cells(N.astype(np.float64))
        assert {s.tobytes() for s in signs} == want
        assert (np.sign(dirs @ N.T) == signs).all()


def test_every_lattice_point_meets_every_family() -> None:
    """Sec. 4.5.8 by construction: the pyramid's apex needs four planes to meet."""
    pyr = {"label": 1, "vertices": [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [1, 1, 1]],
           "faces": [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]}  # fmt: skip
    E = polyhedra.PolyhedralModel([pyr])
    lat = Lattice.of_points(np.array(pyr["vertices"], dtype=float), pyr["faces"])
    assert len(lat.normals) == 5
    A = Arrangement3(lat, (4, 4, 3))
    lattice_pts = (A.X % A.D == 0) & (A.Y % A.D == 0) & (A.Z % A.D == 0)
    assert A.on[lattice_pts][:, ~A.boundary_only].all()  # the side planes: sides only
    C = ContinuousCSP3(E, (4, 4, 3))
    apex = [tuple(n) for n in lat.normals if n != (0, 0, 1)]
    assert C.states_at_planes(apex) >= 6  # empty, full, apex, ...: the apex label exists


@pytest.mark.parametrize("solver", ["catalog", "sat", "blocks"])
def test_solvers_run_unchanged(solver: str) -> None:
    C = ContinuousCSP3(polyhedra.PolyhedralModel([TET]), (4, 4, 3))
    r = solve(C.problem, solver, rng=2, restarts=10, **({"block": 2} if solver == "blocks" else {}))
    assert r.status == "solved" and C.problem.is_solution(r.grid)


@pytest.mark.parametrize("t", [1, 2])
def test_stretched_copies_are_solutions(t: int) -> None:
    """Sec. 4.5.6: the example and its stretched copies satisfy its own constraints."""
    E = polyhedra.PolyhedralModel([TET])
    C = ContinuousCSP3(E, (2 * t + 2, 2 * t + 2, 2 * t + 2))
    s = int(C.lattice.spacing)
    M = polyhedra.PolyhedralModel([_scaled(TET, t, s)])
    g = C.encode(M)
    assert len(C.problem.violations(g)) == 0


def test_two_labels_stacked() -> None:
    """Two boxes of different labels, one on the other: both labels and the contact face
    are states; a stretched copy is a solution; a copy upside down is not."""
    E = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 1]), _box(2, [0, 0, 1], [2, 2, 2])])
    C = ContinuousCSP3(E, (5, 5, 5))
    g = C.encode(polyhedra.PolyhedralModel([_box(1, [1, 1, 1], [3, 3, 2]),
                                            _box(2, [1, 1, 2], [3, 3, 4])]))  # fmt: skip
    assert len(C.problem.violations(g)) == 0
    g = C.encode(polyhedra.PolyhedralModel([_box(2, [1, 1, 1], [3, 3, 2]),
                                            _box(1, [1, 1, 2], [3, 3, 3])]))  # fmt: skip
    assert len(C.problem.violations(g)) > 0
    r = solve(C.problem, "sat", rng=0)
    assert r.status == "solved"


def test_point_location_by_winding_number() -> None:
    tri = {1: np.array(TET["vertices"], dtype=float)[np.array(TET["faces"])]}
    pts = np.array([[0.5, 0.5, 0.5], [3, 3, 3], [1, 1, 1.9], [1, 1, 2.1], [-1, 0, 0]])
    assert labels_at(pts, tri).tolist() == [1, 0, 1, 0, 0]


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_output_solids_are_closed_and_describe_the_solution(solver: str) -> None:
    """The output mesh of a solution: closed, outward solids (validated by PolyhedralModel),
    and encoding it back gives the solution itself."""
    E = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 1]), _box(2, [0, 0, 1], [2, 2, 2])])
    for E_, size in ((E, (6, 6, 5)), (polyhedra.PolyhedralModel([TET]), (5, 5, 4))):
        C = ContinuousCSP3(E_, size)
        r = solve(C.problem, solver, rng=4, restarts=10)
        assert r.status == "solved"
        M = C.model(r.grid)
        assert all(s.to_trimesh().is_watertight for s in M.solids)
        assert (C.encode(M) == np.asarray(r.grid).reshape(-1)).all()
        # the trusted output passes every check of a model read from a file
        V = polyhedra.PolyhedralModel([s.to_json() for s in M.solids])
        assert V.n_polygons == M.n_polygons and "reoriented" not in V.meta


HOUSE = [_box(1, [0, 0, 0], [2, 2, 2]),
         {"label": 2, "vertices": [[0, 0, 2], [2, 0, 2], [2, 2, 2], [0, 2, 2], [1, 0, 3],
                                   [1, 2, 3]],
          "faces": [[0, 1, 4], [3, 5, 2], [0, 4, 5, 3], [1, 2, 5, 4], [0, 3, 2, 1]]}]  # fmt: skip


@pytest.mark.parametrize("solver", ["catalog", "sat", "blocks"])
def test_outputs_pass_the_3d_checker(solver: str) -> None:
    from csplab.continuous.check3d import violations3

    E = polyhedra.PolyhedralModel(HOUSE)
    C = ContinuousCSP3(E, (8, 8, 6))
    assert len(violations3(E, E)) == 0
    for seed in range(2):
        r = solve(C.problem, solver, rng=seed, restarts=10,
                  **({"block": 3} if solver == "blocks" else {}))  # fmt: skip
        assert r.status == "solved"
        v = violations3(E, C.model(r.grid))
        assert len(v) == 0, v.describe()


def test_3d_checker_catches_planted_defects() -> None:
    from csplab.continuous.check3d import violations3

    E = polyhedra.PolyhedralModel(HOUSE)
    assert len(violations3(E, polyhedra.PolyhedralModel([_box(2, [0, 0, 0], [2, 2, 2])]))) > 0
    tet = polyhedra.PolyhedralModel([TET])
    assert violations3(E, tet).counts().get("direction", 0) >= 1
    floating = polyhedra.PolyhedralModel([HOUSE[1]])  # a roof without its house
    assert violations3(E, floating).counts().get("neighbourhood", 0) >= 1


def test_cli_synthesizes_a_mesh_example(tmp_path: pytest.TempPathFactory) -> None:
    """``csplab synthesize HOUSE.obj --size AxBxC --out out.obj``, then ``check`` and
    ``show``."""
    from pathlib import Path

    from csplab.cli import main
    from csplab.io.meshes import write_obj_model as write_obj

    d = Path(str(tmp_path))
    ex, out, png = d / "house.obj", d / "town.obj", d / "town.png"
    write_obj(polyhedra.PolyhedralModel(HOUSE), ex)
    for solver in ("catalog", "sat", "blocks"):
        args = ["synthesize", str(ex), "--size", "8x8x5", "--seed", "1", "--solver", solver,
                "--out", str(out)]  # fmt: skip
        if solver == "blocks":
            args += ["--block", "4"]
        assert main(args) == 0
        assert main(["check", str(ex), str(out)]) == 0
    assert main(["show", str(out), "--out", str(png)]) == 0 and png.exists()
    assert main(["synthesize", str(ex), "--size", "8x8"]) == 2
    # equal plane spacing (the default for meshes in real coordinates) applies in 3D too
    args = ["synthesize", str(ex), "--size", "8x8x5", "--lines", "equal", "--seed", "1",
            "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    assert main(["check", str(ex), str(out)]) == 0


def test_ground_below_the_region() -> None:
    """A ground (label 1 below z = 0, like Merrell's landscapes) under an example of a slab
    (1) carrying a box (2): the output stands on it; its solids are closed (the region's
    bottom closes them) and satisfy Eq. 4.1 inside the region."""
    from csplab.continuous.check3d import violations3

    E = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [4, 4, 1]), _box(2, [1, 1, 1], [2, 2, 3])])
    C = ContinuousCSP3(E, (6, 6, 4), boundary={"z-": 1})
    assert C.problem.meta["boundary"]["z-"] == 1 and C.problem.meta["boundary"]["x-"] == 0
    for seed in range(2):
        r = solve(C.problem, "sat", rng=seed)
        assert r.status == "solved"
        M = C.model(r.grid)
        assert all(s.to_trimesh().is_watertight for s in M.solids)
        assert (C.encode(M) == np.asarray(r.grid).reshape(-1)).all()
        # the trusted output passes every check of a model read from a file
        V = polyhedra.PolyhedralModel([s.to_json() for s in M.solids])
        assert V.n_polygons == M.n_polygons and "reoriented" not in V.meta
        region = (0.0, 0.0, 0.0, 6.0, 6.0, 4.0)
        assert len(violations3(E, M, region=region, outside={"z-": 1})) == 0
        if any(float(np.asarray(s.vertices)[:, 2].min()) == 0 for s in M.solids):
            assert len(violations3(E, M, region=region)) > 0  # without the ground: wrong
    with pytest.raises(InputError, match="boundary faces"):
        ContinuousCSP3(E, (4, 4, 4), boundary={"bottom": 1})
    with pytest.raises(InputError, match="no neighbourhood of the example fits"):
        ContinuousCSP3(polyhedra.PolyhedralModel(HOUSE), (4, 4, 4), boundary={"z-": 1})


def test_output_faces_with_holes_and_pinches_stay_closed() -> None:
    """A square frame (its top face is an annulus: a polygon with a hole) and two boxes
    meeting along an edge only (a face ring that touches itself is not possible there, but
    the frame's corners are): the output mesh of the encoded example is closed, outward and
    has the example's volume; the checker finds nothing wrong."""
    from csplab.continuous.check3d import violations3

    frame = [_box(1, [0, 0, 0], [3, 1, 1]), _box(1, [0, 2, 0], [3, 3, 1]),
             _box(1, [0, 1, 0], [1, 2, 1]), _box(1, [2, 1, 0], [3, 2, 1])]  # fmt: skip
    E = polyhedra.PolyhedralModel(frame)
    C = ContinuousCSP3(E, (5, 5, 3))
    moved = [{**b, "vertices": (np.array(b["vertices"]) + 1).tolist()} for b in frame]
    g = C.encode(polyhedra.PolyhedralModel(moved))
    assert len(C.problem.violations(g)) == 0
    M = C.model(g)
    V = polyhedra.PolyhedralModel([s.to_json() for s in M.solids])
    assert len(V.solids) == 1 and V.volume() == pytest.approx(8.0)
    assert V.solids[0].to_trimesh().is_watertight
    assert len(violations3(E, M)) == 0


def test_ray_point_location_agrees_with_winding_numbers() -> None:
    """The checker's compiled point location (first face along two generic rays) gives
    the generalised winding number's labels, here on random points and on points just off
    the lattice vertices of a house model (where rays graze edges most)."""
    from csplab.continuous._geom import point_labels

    M = polyhedra.PolyhedralModel(HOUSE)
    tris = [(s.label, s.vertices[s.faces]) for s in M.solids]
    rng = np.random.default_rng(5)
    pts = np.concatenate([
        rng.uniform(-0.5, 3.5, size=(400, 3)),
        np.array([[x, y, z] for x in range(3) for y in range(3) for z in range(4)], dtype=float)
        + 1e-4 * rng.normal(size=(36, 3)),
    ])  # fmt: skip
    assert point_labels(pts, tris).tolist() == labels_at(pts, tris).tolist()
