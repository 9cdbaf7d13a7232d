"""The retarget baseline (Wu et al.): dominant offsets of a model with a repeated structure,
sparse offsets give a smaller graph than all offsets (the paper's Fig. 1 point), and the
retargeted mesh is closed."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("maxflow")
pytest.importorskip("skimage")
pytest.importorskip("trimesh")

from csplab.baselines.retarget import dominant_offsets, retarget, retarget_labels, voxelize
from csplab.errors import InputError
from csplab.examples.continuous3d import load_polyhedral_example


def test_dominant_offsets_find_a_period() -> None:
    occ = np.zeros((12, 4, 4), dtype=bool)
    for x in range(0, 12, 3):  # slabs repeating every 3 voxels along x
        occ[x, 1:3, 1:3] = True
    peaks, principal = dominant_offsets(occ, tau=2)
    assert peaks and principal[0] == 3


def test_labels_cover_the_output_and_copy_the_input() -> None:
    occ = np.zeros((4, 4, 4), dtype=bool)
    occ[1:3, 1:3, 1:3] = True
    out, info = retarget_labels(occ, (8, 4, 4), (4, 0, 0), cell=(4, 1, 1), rng=0)
    assert out.shape == (8, 4, 4) and info["labels"] == 2 and info["nodes"] == 2 * 4 * 4
    assert out[:4].sum() == occ.sum() and out[4:].sum() == occ.sum()  # two exact copies


def test_sparse_offsets_make_a_smaller_graph_and_closed_meshes() -> None:
    E = load_polyhedral_example("skyscrapers")
    a = retarget(E, (24, 24, 12), resolution=12, offsets="sparse", rng=1)
    b = retarget(E, (24, 24, 12), resolution=12, offsets="all", regular=1, rng=1)
    ia, ib = a.metadata["retarget"], b.metadata["retarget"]
    assert ia["nodes"] < ib["nodes"] and ia["labels"] < ib["labels"]
    assert a.is_watertight and b.is_watertight and a.volume > 0
    assert voxelize(E, 12).any()
    with pytest.raises(InputError, match="offsets must be"):
        retarget(E, (8, 8, 8), offsets="some")


@pytest.mark.parametrize("length", [16, 18, 21])
def test_retargeting_keeps_the_period_of_a_regular_structure(length: int) -> None:
    """Wu et al.: a model made of repeated parts is resized by repeating them, so the
    output keeps the input's period: slabs every 3 voxels along x stay slabs every 3
    voxels, however long the output, never a seam that breaks the rhythm."""
    occ = np.zeros((12, 4, 4), dtype=bool)
    for x in range(0, 12, 3):
        occ[x, 1:3, 1:3] = True
    _, principal = dominant_offsets(occ, tau=2)
    for seed in range(2):
        out, info = retarget_labels(occ, (length, 4, 4), principal, rng=seed)
        want = np.zeros((length, 4, 4), dtype=bool)
        want[::3, 1:3, 1:3] = True
        assert np.array_equal(out, want), seed
        assert info["labels_used"] > 1  # more than one copy of the input was needed


def _energy(lab: np.ndarray, copies: np.ndarray, valid: np.ndarray) -> float:
    """The retargeting energy as the module docstring states it: ``OUTSIDE`` per voxel
    whose translation copies from outside the input, and for neighbours ``x, y`` with
    different labels ``a, b`` the seam ``[c_a(x) != c_b(x)] + [c_a(y) != c_b(y)]``."""
    from csplab.baselines.retarget import OUTSIDE

    idx = np.indices(lab.shape)
    e = OUTSIDE * float((~valid[(lab, *idx)]).sum())
    for axis in range(3):
        x = [slice(None)] * 3
        y = [slice(None)] * 3
        x[axis], y[axis] = slice(0, -1), slice(1, None)
        la, lb = lab[tuple(x)], lab[tuple(y)]
        px = tuple(i[tuple(x)] for i in idx)
        py = tuple(i[tuple(y)] for i in idx)
        cut = la != lb
        e += float(((copies[(la, *px)] != copies[(lb, *px)]) & cut).sum())
        e += float(((copies[(la, *py)] != copies[(lb, *py)]) & cut).sum())
    return e


def _tiny(seed: int) -> tuple[np.ndarray, dict, dict, np.ndarray, np.ndarray, tuple]:
    """A tiny retargeting (a random 3x2x1 input to 6x2x1, 4 translations along x, one node
    per x) and the energy of every labelling of its 6 nodes (4^6, by brute force)."""
    import itertools

    occ = np.random.default_rng(seed).random((3, 2, 1)) < 0.5
    size = (6, 2, 1)
    out, info = retarget_labels(occ, size, (1, 0, 0), cell=(1, 2, 1), rng=seed)
    assert info["labels"] == 4 and info["nodes"] == 6
    copies = np.zeros((4, *size), dtype=bool)
    valid = np.zeros((4, *size), dtype=bool)
    for t in range(4):  # translation t voxels along x
        valid[t, t : t + 3] = True
        copies[t, t : t + 3] = occ
    energies = {
        labs: _energy(_voxels(labs, size), copies, valid)
        for labs in itertools.product(range(4), repeat=6)
    }
    return out, info, energies, copies, valid, size


def _voxels(labs: tuple[int, ...], size: tuple[int, int, int]) -> np.ndarray:
    return np.broadcast_to(np.array(labs)[:, None, None], size).copy()


def _output_labellings(out, info, energies, copies, size) -> list[tuple[int, ...]]:
    idx = np.indices(size)
    return [
        labs
        for labs, e in energies.items()
        if e == pytest.approx(info["energy"])
        and np.array_equal(copies[(_voxels(labs, size), *idx)], out)
    ]


@pytest.mark.parametrize("seed", range(3))
def test_reported_energy_is_the_outputs_and_never_above_the_start(seed: int) -> None:
    """The output is a labelling with the energy ``info`` reports (the docstring's energy,
    recomputed by brute force), and the moves never raise it above the start labelling
    (each voxel shifted back into the input by the least multiple of the step)."""
    out, info, energies, copies, _, size = _tiny(seed)
    assert _output_labellings(out, info, energies, copies, size)
    assert info["energy"] <= energies[(0, 0, 0, 1, 2, 3)]


@pytest.mark.xfail(
    strict=True,
    reason="the cut of a move prices a seam against the current output (Kwatra's patch "
    "seams), not against each neighbour's own label, so it is not an exact expansion move: "
    "here switching two nodes to the last translation lowers the energy from 6 to 1 and "
    "is not found",
)
def test_expansion_moves_end_in_a_local_minimum_by_brute_force() -> None:
    """Expansion moves (Boykov et al.) end where no expansion lowers the energy: checked by
    every expansion (any label, any set of nodes switching to it) from the output."""
    import itertools

    out, info, energies, copies, _, size = _tiny(0)
    for labs in _output_labellings(out, info, energies, copies, size):
        better = any(
            energies[tuple(alpha if s else a for a, s in zip(labs, sub, strict=True))]
            < energies[labs]
            for alpha in range(4)
            for sub in itertools.product((0, 1), repeat=6)
        )
        if not better:
            return
    raise AssertionError("an expansion move lowers the energy of the output")
