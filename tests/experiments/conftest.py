import numpy as np
import pytest


@pytest.fixture
def fallible_npy(tmp_path):
    """A tiny 2D example on which Alg. 3.1 often fails at 4x4 (found by random search)."""
    p = tmp_path / "fallible.npy"
    np.save(p, np.array([[0, 0, 0], [1, 2, 2], [0, 1, 2]]))
    return p


@pytest.fixture
def rectangle_npy(tmp_path):
    """One rectangle in empty space (the idea of thesis Fig. 3.10(a)): corners 1 3 7 9,
    edges 2 4 6 8, inside 5."""
    R = np.zeros((7, 6), dtype=int)
    R[1, 1], R[5, 1], R[1, 4], R[5, 4] = 1, 3, 7, 9
    R[2:5, 1], R[2:5, 4], R[1, 2:4], R[5, 2:4], R[2:5, 2:4] = 2, 8, 4, 6, 5
    p = tmp_path / "rectangle.npy"
    np.save(p, R)
    return p
