import numpy as np

from csplab.experiments import ResultsStore, run
from csplab.experiments.measures import label_counts
from csplab.grids import from_example
from csplab.io import read_example
from csplab.testing.brute import solutions


def test_exact_row_is_the_brute_force_average_and_bias_is_detected(tmp_path, fallible_npy):
    db = tmp_path / "r.sqlite"
    s, rep = run(
        "sampling_bias", examples=[str(fallible_npy)], size="5x3", seeds=150, n_boot=200,
        solvers=["catalog", "blocks@block=2"], store=db, out=tmp_path, jobs=1, progress=False,
    )  # fmt: skip
    assert not s.errors
    with ResultsStore(db) as st:
        exact = next(r for r in st.rows("sampling_bias") if r["solver"] == "exact")
    P = from_example(read_example(fallible_npy), (5, 3))
    sols = list(solutions(P))
    want = np.mean([label_counts(g, P.K) for g in sols], axis=0)
    assert np.allclose(exact["stats"]["labels"], want)
    assert np.isclose(np.exp(exact["stats"]["log_count"]), len(sols))
    table = {t["setting"]: t for t in rep.tables["bias"]}
    assert table["uniform"]["verdict"] == "reference"
    # blocks of 2 cells from the trivial solution strongly prefer some models
    assert table["blocks@block=2"]["verdict"] == "biased"
    assert table["blocks@block=2"]["p_uniform"] < 0.01
    assert (tmp_path / "sampling_bias.png").exists()


def test_quick_default_runs(tmp_path):
    s, rep = run("sampling_bias", quick=True, store=tmp_path / "r.sqlite", out=tmp_path,
                 jobs=1, progress=False)  # fmt: skip
    assert not s.errors
    assert {t["setting"] for t in rep.tables["bias"]} == {"uniform", "catalog"}
    assert all(t["outputs"] == 8 for t in rep.tables["bias"])
