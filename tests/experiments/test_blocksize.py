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


def test_alg31_can_build_the_large_square_of_fig3_10h():
    """Fig. 3.10(h): the large square is consistent and Alg. 3.1 reaches it with positive
    probability (each of its labels is in the catalog when its cell comes up), while blocks
    of side m keep the smaller side of every rectangle at most m (test above)."""
    import numpy as np

    from csplab.catalog import Propagator
    from csplab.examples import load_example
    from csplab.grids import from_example

    E = load_example("fig3_10").labels
    M = np.zeros((14, 14), dtype=np.int32)
    M[1:13, 1:13] = E[2, 2]  # interior
    M[1:13, 1], M[1:13, 12], M[1, 1:13], M[12, 1:13] = E[2, 1], E[2, 4], E[1, 2], E[4, 2]
    M[1, 1], M[12, 1], M[1, 12], M[12, 12] = E[1, 1], E[4, 1], E[1, 4], E[4, 4]
    P = from_example(load_example("fig3_10"), (14, 14))
    assert P.is_solution(M)
    eng = Propagator(P)
    for cell in range(P.n):  # Alg. 3.1's scan-line order
        b = int(M.reshape(-1)[cell])
        assert b in eng.domain(cell)
        assert eng.assign(cell, b)
