import numpy as np
import pytest

from csplab import ExampleModel
from csplab.errors import CsplabError, InputError


def test_transitions_eq_3_2_by_definition():
    rng = np.random.default_rng(0)
    for _ in range(20):
        shape = tuple(rng.integers(1, 5, size=rng.integers(1, 4)))
        lab = rng.integers(0, 4, size=shape)
        E = ExampleModel(lab)
        T = E.transitions()
        assert T.shape == (lab.ndim, E.K, E.K)
        for d in range(lab.ndim):
            want = np.zeros((E.K, E.K), dtype=bool)
            for idx in np.ndindex(*shape):
                nb = list(idx)
                nb[d] += 1
                if nb[d] < shape[d]:
                    want[lab[idx], lab[tuple(nb)]] = True
            assert np.array_equal(T[d], want)


def test_K_counts_unused_ids_and_inputs_not_mutated():
    lab = np.array([[0, 5], [5, 0]])
    E = ExampleModel(lab)
    assert E.K == 6
    assert E.counts().tolist() == [2, 0, 0, 0, 0, 2]
    assert not E.labels.flags.writeable
    lab[0, 0] = 3
    assert E.labels[0, 0] == 0


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((0, 3), dtype=int),
        np.zeros((2,) * 5, dtype=int),
        np.array([[0, -1]]),
        np.array([0.5, 1.0]),
        np.array([True, False]),
    ],
)
def test_bad_labels_raise(bad):
    with pytest.raises(InputError):
        ExampleModel(bad)


def test_names_weights_and_errors():
    E = ExampleModel([0, 1, 1], names=["air", "rock"], weights=[1.0, 2.0], name="toy")
    assert E.label_name(1) == "rock" and E.K == 2
    assert E.label_weights().tolist() == [1.0, 2.0]
    assert "toy" in repr(E)
    with pytest.raises(CsplabError):
        ExampleModel([0, 1], names=["only-one"])
    with pytest.raises(ValueError):
        ExampleModel([0, 1], weights=[1.0, -1.0])


def test_hash_and_equality():
    a = ExampleModel([[0, 1], [1, 0]])
    b = ExampleModel(np.array([[0, 1], [1, 0]], dtype=np.int64))
    c = ExampleModel([[1, 0], [0, 1]])
    assert a == b and a.hash() == b.hash()
    assert a != c and a.hash() != c.hash()
