"""The texture baseline (Efros & Leung 1999) and the `csplab baseline` command: outputs are
ordinary grids of the example's labels, reproducible by seed, checked by the same
`violations()` as model synthesis."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from csplab.baselines import BASELINES, run_baseline
from csplab.baselines.texture import _offsets, efros_leung
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.grids import from_example


def test_causal_offsets_are_the_cells_already_grown() -> None:
    off = _offsets(2, 3)
    assert sorted(map(tuple, off.tolist())) == [(-1, -1), (-1, 0), (-1, 1), (0, -1)]
    assert len(_offsets(3, 3)) == 13  # half of the 26 neighbours


@pytest.mark.parametrize("name", ["fig3_10", "castle"])
def test_labels_of_the_example_and_reproducible(name: str) -> None:
    E = load_example(name)
    size = (10, 10) if E.ndim == 2 else (8, 8, 4)
    a = efros_leung(E, size, window=3, rng=4)
    b = run_baseline("texture", E, size, rng=4, window=3)
    assert a.dtype == np.int32 and a.shape == size and np.array_equal(a, b)
    assert set(np.unique(a).tolist()) <= set(np.unique(E.labels).tolist())
    assert not np.array_equal(a, efros_leung(E, size, window=3, rng=5))


def test_violations_are_counted_by_the_one_checker() -> None:
    """Texture synthesis does not keep the adjacency constraint (thesis Sec. 5.1): on castle
    with a 5-wide window it breaks arcs that model synthesis never breaks."""
    E = load_example("castle")
    g = efros_leung(E, (24, 24, 8), window=5, rng=2)
    assert len(from_example(E, (24, 24, 8)).violations(g)) > 0


def test_bad_options_are_one_line() -> None:
    E = load_example("fig3_10")
    with pytest.raises(InputError, match="window must be a positive odd number"):
        efros_leung(E, (5, 5), window=4)
    with pytest.raises(InputError, match="has 3 axes, the example has 2"):
        efros_leung(E, (5, 5, 5))
    with pytest.raises(InputError, match="no option"):
        run_baseline("texture", E, (5, 5), radius=2)
    with pytest.raises(InputError, match="unknown baseline"):
        run_baseline("nosuch", E, (5, 5))
    assert "texture" in BASELINES


def test_cli_baseline_then_check(tmp_path) -> None:
    out = tmp_path / "t.npy"
    cmd = [sys.executable, "-m", "csplab", "baseline", "texture", "castle", "--size", "12x12x6",
           "--seed", "3", "--window", "5", "--out", str(out)]  # fmt: skip
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    n = int(r.stdout.split(" adjacency violations")[0].rsplit(" ", 1)[1])
    chk = subprocess.run([sys.executable, "-m", "csplab", "check", "castle", str(out)],
                         capture_output=True, text=True, check=False)  # fmt: skip
    assert chk.stdout.startswith(f"{n} violations"), chk.stdout


@pytest.mark.parametrize("name", ["fig3_10", "castle"])
def test_graphcut_patches(name: str) -> None:
    """Graph-cut patch synthesis (Kwatra et al. 2003): every cell written, labels of the
    example, reproducible by seed, violations counted by the same checker."""
    pytest.importorskip("maxflow")
    from csplab.baselines.texture import graphcut

    E = load_example(name)
    size = (20, 20) if E.ndim == 2 else (16, 16, 6)
    a = run_baseline("texture", E, size, rng=3, method="graphcut", patch=4, overlap=2)
    assert a.shape == size and int(a.min()) >= 0
    assert set(np.unique(a).tolist()) <= set(np.unique(E.labels).tolist())
    assert np.array_equal(a, graphcut(E, size, patch=4, overlap=2, rng=3))
    assert len(from_example(E, size).violations(a)) >= 0
    with pytest.raises(InputError, match="overlap"):
        graphcut(E, size, patch=4, overlap=4)


def test_graphcut_seams_follow_the_cheapest_cut() -> None:
    """A copy of the example placed over itself needs no seam: on an example that tiles
    (a checkerboard) every patch matches exactly and the output breaks nothing."""
    pytest.importorskip("maxflow")
    E = load_example("fig3_1b")  # checkerboard
    g = run_baseline("texture", E, (12, 12), rng=1, method="graphcut", patch=2, overlap=1)
    assert len(from_example(E, (12, 12)).violations(g)) == 0
