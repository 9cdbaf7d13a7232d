from csplab.examples import load_example
from csplab.experiments import run


def test_quick_table_columns_follow_the_thesis_rule(tmp_path):
    s, rep = run(
        "table3_1", quick=True, seeds=3, displayed="castle=14x14x6", compare="10x10x6",
        store=tmp_path / "r.sqlite", out=tmp_path, jobs=1, progress=False,
    )  # fmt: skip
    assert not s.errors and s.ran == 2 * 2 * 3
    (row,) = rep.tables["Table 3.1"]
    assert row["k"] == load_example("castle").K and row["output size"] == "14x14x6"
    long = {(x["size"], x["solver"]): x for x in rep.tables["per solver"]}
    for label, size in (("displayed", "14x14x6"), ("10x10x6", "10x10x6")):
        cat = long[(size, "catalog")]
        want = "Alg. 3.1" if cat["solved"] == cat["trials"] else "Alg. 3.4 (blocks)"
        assert row[f"method {label}"] == want
        method = "catalog" if want == "Alg. 3.1" else "blocks"
        assert row[f"time {label} (s)"] == long[(size, method)]["median_s"]
        assert long[(size, "blocks")]["solved"] == 3  # Alg. 3.4 always returns a model
    assert (tmp_path / "table3_1.png").exists() and (tmp_path / "table3_1.md").exists()
