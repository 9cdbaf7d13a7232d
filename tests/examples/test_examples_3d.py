"""csplab's own 3D examples (csplab/examples/build3d.py): files, label counts, solvability."""

from pathlib import Path

import numpy as np
import pytest

import csplab
from csplab.examples import EXAMPLES, build3d, load_example
from csplab.grids import auto_boundary, from_example

NAMES = list(build3d.EXAMPLES3D)
SIZE = (40, 40, 10)


@pytest.mark.parametrize("name", NAMES)
def test_file_is_the_builder_output(name):
    path = Path(build3d.__file__).parent / build3d.EXAMPLES3D[name].file
    assert path.read_text(encoding="utf-8") == build3d.file_text(name), (
        f"{path.name} is stale: run python -m csplab.examples.build3d"
    )


def test_check_command_agrees():
    assert build3d.main(["--check"]) == 0


@pytest.mark.parametrize("name", NAMES)
def test_registered_and_loadable(name):
    assert EXAMPLES[name][0] == build3d.EXAMPLES3D[name].file
    E = load_example(name)
    assert E == build3d.build(name)
    assert E.ndim == 3 and E.names is not None
    assert E.label_name(0) == "air"
    assert len(set(E.names)) == E.K
    assert np.all(E.counts() > 0)  # every label occurs


def _grid_file(name):
    return Path(build3d.__file__).parent / build3d.EXAMPLES3D[name].file


def _read_by_hand(path):
    """A ``.grid`` file read with plain Python and numpy, not csplab.io: the ``key: value``
    header fields and every label number of the body (layers separated by blank lines)."""
    head, nums = {}, []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#") or not line.strip():
            continue
        key, sep, val = line.partition(":")
        if sep and key.strip().isidentifier():
            head[key.strip()] = val.strip()
        else:
            nums += [int(v) for v in line.split()]
    return head, np.array(nums)


@pytest.mark.parametrize("name", NAMES)
def test_labels_counted_from_the_file_and_from_the_voxel_scene(name):
    head, data = _read_by_hand(_grid_file(name))
    shape = tuple(int(v) for v in head["shape"].split("x"))
    names = head["labels"].split()
    K = len(names)
    assert data.size == np.prod(shape)
    assert np.array_equal(np.unique(data), np.arange(K))  # labels 0..K-1, each one used
    # a label is the pattern of the four voxels a cell holds: one per distinct pattern
    V = build3d.build_scene(name).V
    quarters = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=-1)
    assert len(np.unique(quarters.reshape(-1, 4), axis=0)) == K
    # what csplab reads and builds agrees with the hand count
    E = load_example(name)
    assert E.K == K and build3d.build(name).K == K and list(E.names) == names
    assert E.shape == shape
    assert np.array_equal(E.counts(), np.bincount(data, minlength=K))


def test_label_counts():
    K = {n: len(_read_by_hand(_grid_file(n))[0]["labels"].split()) for n in NAMES}
    assert len(K) >= 3
    assert all(40 <= k <= 120 for k in K.values()), K
    assert any(55 <= k <= 65 for k in K.values()), K  # the "about 60" benchmark example
    assert any(110 <= k <= 125 for k in K.values()), K  # the "about 120" one
    assert K == {"city": 119, "castle": 63, "canal": 80}


@pytest.mark.parametrize("name", NAMES)
def test_example_is_a_solution_of_its_own_problem(name):
    E = load_example(name)
    for boundary in ("auto", None):
        P = from_example(E, E.shape, boundary=boundary)
        assert P.is_solution(E.labels), (name, boundary)


@pytest.mark.parametrize("name", NAMES)
def test_auto_boundary_is_ground_and_air(name):
    E = load_example(name)
    b = auto_boundary(E)
    assert b.pop("z-") == 1  # the ground label
    assert set(b.values()) == {0}  # air on the other five faces
    P = from_example(E, SIZE, boundary="auto")
    assert P.shape == SIZE and P.K == E.K


@pytest.mark.parametrize("name", NAMES)
def test_pieces_and_material_grid(name):
    E = build3d.build(name)
    scene = build3d.build_scene(name)
    pcs = build3d.pieces(name)
    assert pcs.shape == (E.K, 4)
    # the label of a cell is the pattern of the four voxels it holds
    V = scene.V
    quarters = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=-1)
    assert np.array_equal(pcs[E.labels], quarters)
    assert np.array_equal(build3d.material_grid(name, E.labels), V[1:, 1:])
    assert build3d.material_grid(name, np.full((2, 2, 2), -1)).min() == -1


def test_piece_names():
    V = np.zeros((3, 3, 1), dtype=np.int64)
    V[1:, 1:, 0] = 1
    V[2, 2, 0] = 2
    V[2, 1, 0] = 0
    lab, names, _ = build3d.dual_labels(V, ["air", "wall", "roof"], "AWR")
    assert names == ["wall_cnr_ne", "wall_cnr_nw", "wall_edge_e", "mix_WAWR"]
    assert lab[:, :, 0].tolist() == [[0, 2], [1, 3]]
    V[2, 1, 0] = 1
    _, names, _ = build3d.dual_labels(V, ["air", "wall", "roof"], "AWR")
    assert names[-1] == "roof_cnr_ne_wall"


def test_headers_record_the_measurement():
    for name in NAMES:
        text = build3d.file_text(name)
        assert f"K = {build3d.build(name).K} labels" in text
        assert "boundary='auto': solved" in text
        assert f"--measure {name} --seeds 200" in text


@pytest.mark.parametrize("boundary", ["auto", None])
def test_city_alg31_solves_40x40x10(boundary):
    P = from_example(load_example("city"), SIZE, boundary=boundary)
    for seed in range(3):
        r = csplab.solve(P, "catalog", rng=seed)
        assert r.status == "solved", (boundary, seed, r.stats)
        assert P.is_solution(r.grid)


def test_castle_alg31_fails_often():
    P = from_example(load_example("castle"), SIZE, boundary="auto")
    failed = sum(csplab.solve(P, "catalog", rng=s).status == "failed" for s in range(10))
    assert failed >= 8


def test_castle_blocks_solver_solves_40x40x10():
    P = from_example(load_example("castle"), SIZE, boundary="auto")
    r = csplab.solve(P, "blocks", rng=0, block=10)
    assert r.status == "solved" and r.stats["final_violations"] == 0
    assert P.is_solution(r.grid)
    assert len(np.unique(r.grid)) > 10  # not just the trivial ground-and-air model


@pytest.mark.slow
def test_measured_rates_200_seeds():
    for name, want in build3d.MEASURED.items():
        for bnd, key in (("auto", "auto"), (None, "none")):
            m = build3d.measure(name, want[key][1], boundary=bnd)
            assert (m["solved"], m["seeds"]) == want[key], (name, bnd)
