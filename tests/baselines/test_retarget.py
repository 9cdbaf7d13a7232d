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
