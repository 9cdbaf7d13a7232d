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


# ---------------------------------------------------------------- sparse label ids (issue 12)
def test_sparse_labels_are_compacted_and_synthesize_fast():
    import time

    from csplab.grids import from_example
    from csplab.solvers import solve

    t = time.perf_counter()
    E = ExampleModel([[0, 100000], [100000, 0]])
    assert E.K == 2 and E.labels.tolist() == [[0, 1], [1, 0]]
    assert E.meta["label_ids"] == (0, 100000)
    assert E.file_labels().tolist() == [[0, 100000], [100000, 0]]
    r = solve(from_example(E, (4, 4)), "catalog", rng=0)
    assert r.ok and set(np.unique(r.grid).tolist()) == {0, 1}
    assert time.perf_counter() - t < 1.0


def test_dense_labels_are_not_compacted():
    E = ExampleModel([[0, 2], [2, 0]])  # small gaps keep their ids (K = max + 1)
    assert E.K == 3 and "label_ids" not in E.meta
    E = ExampleModel(np.arange(300).reshape(3, 100) * 2)  # 300 labels up to 598: dense enough
    assert E.K == 599 and "label_ids" not in E.meta


def test_compaction_keeps_weights_and_hash():
    E = ExampleModel([0, 5000, 7000], weights=np.arange(7001, dtype=float))
    assert E.K == 3 and E.weights.tolist() == [0.0, 5000.0, 7000.0]
    assert E.hash() != ExampleModel([0, 5000, 9000]).hash()


def test_labels_beyond_64_bits_are_one_line():
    with pytest.raises(InputError, match=r"^label 1180591620717411303424 does not fit in 64 bits$"):
        ExampleModel([[0, 2**70]])
    with pytest.raises(InputError, match="does not fit in 64 bits"):
        ExampleModel(np.array([0, 2**63 + 5], dtype=np.uint64))
    E = ExampleModel([0, 2**62])  # fits: compacted
    assert E.K == 2 and E.file_labels().tolist() == [0, 2**62]


@pytest.mark.parametrize("ext", [".txt", ".npy", ".grid"])
def test_sparse_ids_round_trip_through_files(tmp_path, ext):
    from csplab.grids import from_example
    from csplab.io import read_example, write_example, write_labels
    from csplab.solvers import solve

    E = ExampleModel(np.array([[0, 100000], [100000, 0]]).reshape(2, 2, 1))
    src = tmp_path / f"e{ext}"
    write_example(E, src)
    F = read_example(src)
    assert F.K == 2 and F.meta["label_ids"] == (0, 100000)
    assert F.file_labels().tolist() == E.file_labels().tolist()
    r = solve(from_example(F, (3, 3, 1)), "catalog", rng=1)
    assert r.ok
    out = tmp_path / f"out{ext}"
    write_labels(r.grid, out, model=F)
    G = read_example(out)
    assert set(np.unique(G.file_labels()).tolist()) <= {0, 100000}
    assert G.file_labels().tolist() == F.file_labels(r.grid).tolist()


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("b.txt", "a\nb\nc\n2 2 1\n0 1180591620717411303424\n1 0\n"),
        ("b.grid", "# csplab grid\nshape: 2x2\n0 1180591620717411303424\n1 0\n"),
    ],
)
def test_cli_label_beyond_64_bits_is_one_line(tmp_path, capsys, name, text):
    from csplab.cli import main

    p = tmp_path / name
    p.write_text(text)
    assert main(["synthesize", str(p), "--size", "3x3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("csplab: error: ")
    assert err[0].endswith("label 1180591620717411303424 does not fit in 64 bits")


def test_cli_sparse_merrell_file_round_trips(tmp_path, capsys):
    from csplab.cli import main

    src = tmp_path / "s.txt"
    src.write_text("a\nb\nc\n2 2 1\n0 100000\n100000 0\n")
    out = tmp_path / "o.txt"
    assert main(["synthesize", str(src), "--size", "4x4x1", "--out", str(out), "--seed", "1"]) == 0
    assert "(K=2)" in capsys.readouterr().out
    rows = out.read_text().splitlines()[4:]
    assert {int(v) for r in rows for v in r.split()} == {0, 100000}
