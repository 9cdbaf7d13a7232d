import numpy as np
import pytest


@pytest.fixture
def fallible_npy(tmp_path):
    """A tiny 2D example on which Alg. 3.1 often fails at 4x4 (found by random search)."""
    p = tmp_path / "fallible.npy"
    np.save(p, np.array([[0, 0, 0], [1, 2, 2], [0, 1, 2]]))
    return p
