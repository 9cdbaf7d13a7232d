from csplab.experiments import run


def test_quick_run_is_always_consistent(tmp_path):
    s, rep = run("blocksize", quick=True, store=tmp_path / "r.sqlite", out=tmp_path,
                 jobs=1, progress=False)  # fmt: skip
    assert not s.errors
    table = rep.tables["block size"]
    assert all(t["consistent"] == 1.0 for t in table)
    assert [t["m"] for t in table if t["setting"].startswith("blocks")] == [2, 3, 4, 12]
    ref = next(t for t in table if t["setting"].startswith("Alg. 3.1"))
    full = next(t for t in table if "(full)" in t["setting"])
    # with the full model as block Alg. 3.4 is Alg. 3.1 (same seeds, no failure here)
    assert full["union"] == ref["union"] and full["a31_missed"] == 0
    assert (tmp_path / "blocksize_outputs.png").exists()


def test_small_blocks_cannot_build_thick_rectangles(tmp_path):
    """Fig. 3.10: with blocks of side m a rectangle's smaller side never exceeds m, while
    Alg. 3.1 builds thicker ones; m = 2 is too small for any 3x3 rectangle."""
    _, rep = run(
        "blocksize", examples=["fig3_10"], size="14x14", blocks=[2, 3, 4, "full"],
        seeds=6, store=tmp_path / "r.sqlite", out=tmp_path, jobs=1, progress=False,
        figures=False,
    )  # fmt: skip
    table = {t["m"] if t["setting"].startswith("blocks") else "a31": t
             for t in rep.tables["block size"]}  # fmt: skip
    assert table["a31"]["thin_side_max"] > 4
    for m in (2, 3, 4):
        assert table[m]["consistent"] == 1.0
        assert table[m]["thin_side_max"] <= m
        assert table[m]["a31_missed"] > 0  # some of Alg. 3.1's 3x3 patterns are out of reach
    assert table[2]["largest_max"] == 0 and table[2]["union"] == 1
    assert table[3]["largest_max"] > 0
