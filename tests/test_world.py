"""Infinite worlds (:mod:`csplab.world`): order independence, consistency, fallible models,
workers, caches and the store."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from csplab.engine.alg31 import run_alg31
from csplab.errors import InputError
from csplab.io.ruleset import RuleSet
from csplab.world import World

DATA = Path(__file__).resolve().parent / "io" / "data"
SHARED = next(
    (p / "shared" / "anchors-data" for p in Path(__file__).resolve().parents[2:4]
     if (p / "shared" / "anchors-data").is_dir()),
    Path("/nonexistent"),
)  # fmt: skip

CHUNKS = [(i, j) for i in range(-1, 2) for j in range(-1, 2)]


def three_colours() -> RuleSet:
    """Proper 3-colouring of the grid: Alg. 3.1 in WFC's order (min-entropy) fails on
    nearly every 32x32 run (a cell whose neighbours took all three colours), yet every
    consistent border has a completion (its old labels)."""
    R = ~np.eye(3, dtype=bool)
    return RuleSet(np.stack([R, R]), name="three")


_REF: dict[str, dict[tuple[int, int], np.ndarray]] = {}


def reference(name: str, **kw: object) -> dict[tuple[int, int], np.ndarray]:
    """The 3x3 chunks around the origin, generated in scan order (computed once)."""
    if name not in _REF:
        w = World(name, **kw)  # type: ignore[arg-type]
        _REF[name] = {c: w.chunk(*c) for c in CHUNKS}
    return _REF[name]


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(order=st.permutations(CHUNKS), cache=st.sampled_from([1, 300, 4096]))
def test_any_visit_order_and_cache_size_gives_the_same_chunks(
    order: list[tuple[int, int]], cache: int
) -> None:
    ref = reference("fig3_4a", seed=5, chunk=(8, 8))
    w = World("fig3_4a", seed=5, chunk=(8, 8), cache_blocks=cache, cache_chunks=2)
    for c in order:
        assert w.chunk(*c).tobytes() == ref[c].tobytes(), c
    # visited again after the chunks were evicted: the same bytes
    assert w.chunk(*order[0]).tobytes() == ref[order[0]].tobytes()


@settings(max_examples=6, deadline=None)
@given(order=st.permutations(CHUNKS[:4]))
def test_overlapping_sample_world_is_order_independent(order: list[tuple[int, int]]) -> None:
    ref = reference(str(DATA / "sample.png"), seed=2, chunk=(16, 16))
    w = World(str(DATA / "sample.png"), seed=2, chunk=(16, 16))
    for c in order:
        assert w.chunk(*c).tobytes() == ref[c].tobytes()


def test_seed_changes_the_world_and_the_world_is_not_trivial() -> None:
    a = World("fig3_4a", seed=5, chunk=(8, 8)).region((0, 24), (0, 24))
    b = World("fig3_4a", seed=6, chunk=(8, 8)).region((0, 24), (0, 24))
    assert a.tobytes() != b.tobytes()
    assert len(np.unique(a)) > 2  # more than the start model's label


@pytest.mark.parametrize(
    "model, chunk",
    [
        ("fig3_4a", (8, 8)),
        (str(DATA / "pipes.xml"), (16, 16)),
        (str(DATA / "sample.png"), (16, 16)),
    ],
)
def test_stitched_regions_have_no_violations(model: str, chunk: tuple[int, int]) -> None:
    w = World(model, seed=1, chunk=chunk)
    for xs, ys in [((0, 48), (0, 48)), ((-37, 5), (11, 60))]:
        g = w.region(xs, ys)
        assert g.shape == (xs[1] - xs[0], ys[1] - ys[0])
        P = w.problem(g.shape)
        assert len(P.violations(g)) == 0
    # a region equals the chunks it is stitched from
    X, Y = chunk
    assert (w.region((X, 2 * X), (-Y, 0)) == w.chunk(1, -1)).all()


def test_fallible_model_gives_a_consistent_world() -> None:
    rs = three_colours()
    P = rs.problem((32, 32), boundary="none")
    fails = sum(
        run_alg31(P, np.random.default_rng(s), order="min-entropy").status != "solved"
        for s in range(6)
    )
    assert fails > 3  # single-pass Alg. 3.1 fails more often than not on a 32x32 chunk
    w = World(rs, seed=3, chunk=(16, 16), order="min-entropy", retries=1)
    g = w.region((-16, 32), (0, 32))
    assert len(w.problem(g.shape).violations(g)) == 0
    assert w.stats["exact"] > 0  # the blocks random choice could not complete
    assert len(np.unique(g)) == 3
    # and order independence holds for it too
    w2 = World(rs, seed=3, chunk=(16, 16), order="min-entropy", retries=1)
    assert w2.chunk(1, 1).tobytes() == w.chunk(1, 1).tobytes()


def test_without_exact_completion_a_fallible_block_keeps_its_labels() -> None:
    w = World(three_colours(), seed=3, chunk=(16, 16), order="min-entropy", retries=0,
              exact="none")  # fmt: skip
    g = w.region((0, 32), (0, 32))
    assert len(w.problem(g.shape).violations(g)) == 0
    assert w.stats["kept"] > 0


def test_workers_give_the_same_bytes() -> None:
    a = World("fig3_4a", seed=9, chunk=(8, 8)).region((-8, 16), (0, 16))
    with World("fig3_4a", seed=9, chunk=(8, 8), workers=2) as w:
        b = w.region((-8, 16), (0, 16))
    assert a.tobytes() == b.tobytes()


def test_restart_from_the_store_gives_the_same_bytes(tmp_path: Path) -> None:
    db = tmp_path / "world.sqlite"
    with World("fig3_4a", seed=4, chunk=(8, 8), store=db) as w:
        first = {c: w.chunk(*c) for c in CHUNKS[:3]}
        assert w.stats["stored"] == 0
    with World("fig3_4a", seed=4, chunk=(8, 8), store=db) as w:
        for c, a in first.items():
            assert w.chunk(*c).tobytes() == a.tobytes()
        assert w.stats["stored"] == 3 and w.stats["alg31"] == 0
        # another seed shares the file but not the chunks
    with World("fig3_4a", seed=8, chunk=(8, 8), store=db) as w:
        w.chunk(*CHUNKS[0])
        assert w.stats["stored"] == 0
    fresh = World("fig3_4a", seed=4, chunk=(8, 8))
    assert all(fresh.chunk(*c).tobytes() == a.tobytes() for c, a in first.items())


def test_caches_are_bounded() -> None:
    w = World("fig3_4a", seed=1, chunk=(8, 8), cache_blocks=5, cache_chunks=5)
    assert w.blocks.size == w.pyramid > 5  # raised to the blocks of one chunk from scratch
    w.chunk(-7, 3)
    assert sum(w.stats.values()) == w.pyramid  # each solved once: the pyramid is exact
    for i in range(40):
        w.chunk(i, 0)
    assert len(w.blocks) == w.blocks.size and len(w.chunks) == 5


def test_fixed_cells_and_masks_in_world_coordinates() -> None:
    fixed = {(3, 4): 1, (-20, 7): 2, (40, -3): 3}
    region = ((-24, 48), (-8, 16))
    for seed, passes, unmet in [(1, 1, [(-20, 7)]), (1, 2, []), (2, 2, [(-20, 7)]), (2, 3, [])]:
        w = World("fig3_4a", seed=seed, chunk=(8, 8), fixed=fixed, passes=passes)
        # a 2 needs a 1 below, a 3 above and empty space beside it: where every pass' block
        # holding the cell has a border that rules this out, it stays unmet (and reported)
        assert w.unmet(*region) == unmet
        g = w.region(*region)
        assert len(w.problem(g.shape).violations(g)) == 0
        for (x, y), v in fixed.items():
            assert (g[x + 24, y + 8] == v) == ((x, y) not in unmet)
    assert World("fig3_4a", seed=2, chunk=(8, 8)).region(*region)[64, 5] != 3  # not by chance

    def no_label_1(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        al = np.ones((*xs.shape, w.K), dtype=bool)
        al[..., 1] = xs < 0  # label 1 only where x < 0
        return al

    m = World("fig3_4a", seed=2, chunk=(8, 8), mask=no_label_1)
    g = m.region((0, 24), (0, 24))
    assert not (g == 1).any() and len(m.problem(g.shape).violations(g)) == 0


def test_bad_input_is_one_line() -> None:
    with pytest.raises(InputError, match="do not exist in an infinite world"):
        World("city", chunk=(8, 8, 8), boundary={"x-": 0})
    with pytest.raises(InputError, match="chunk"):
        World("fig3_4a", chunk=(8,))
    with pytest.raises(InputError, match="k must be 0"):
        World("fig3_4a", chunk=(8, 8)).chunk(0, 0, 1)
    # the checkerboard with an odd period only... has period 2: accepted; a model with
    # no periodic solution at all is refused
    R = np.zeros((3, 3), dtype=bool)
    R[0, 1] = R[1, 2] = True  # 0 -> 1 -> 2 -> nothing: no infinite row exists
    with pytest.raises(InputError, match="no periodic solution"):
        World(RuleSet(np.stack([R, R | R.T]), name="dead end"), chunk=(8, 8))


@pytest.mark.slow
def test_castle_3d_world() -> None:
    w = World("castle", seed=1, chunk=(12, 12, 8))
    g = w.region((-6, 18), (0, 24))
    assert g.shape == (24, 24, 8)
    assert len(w.problem(g.shape).violations(g)) == 0
    w2 = World("castle", seed=1, chunk=(12, 12, 8))
    assert w2.chunk(1, 1).tobytes() == w.chunk(1, 1).tobytes()
    assert w.seams == "general" and w.margin == 0  # fallible: no thin seams


@pytest.mark.skipif(not (SHARED / "DeBroglie").is_dir(), reason="no shared anchors-data")
def test_external_rule_set_world() -> None:
    with pytest.warns(UserWarning, match="cannot honour the model's global constraints"):
        w = World(str(SHARED / "DeBroglie" / "edged_path_constraint.json"), seed=1, chunk=(16, 16))
    assert w.dropped == ["Connected"]  # a path constraint cannot hold on an endless plane
    g = w.region((0, 32), (0, 32))
    assert len(w.problem(g.shape).violations(g)) == 0


def test_cli_world_writes_the_region_and_checks_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from csplab.cli import main

    out = tmp_path / "w.npy"
    argv = ["world", str(DATA / "pipes.xml"), "--chunk", "16x16", "--seed", "3",
            "--region=-16:32,0:16", "--out", str(out), "--json"]  # fmt: skip
    assert main(argv) == 0
    import json

    summary = json.loads(capsys.readouterr().out)
    assert summary["violations"] == 0 and summary["shape"] == [48, 16]
    assert summary["seams"] == "general"  # pipes has no dead end: a ring can leave no label
    g = np.load(out)
    w = World(str(DATA / "pipes.xml"), seed=3, chunk=(16, 16), order=summary["order"],
              choice=summary["choice"])  # fmt: skip
    assert g.tobytes() == w.region((-16, 32), (0, 16)).tobytes()  # the library's bytes
    assert g.shape == (48, 16)
    assert len(w.problem(g.shape).violations(g)) == 0
    png = tmp_path / "w.png"
    assert (
        main(["world", "fig3_4a", "--chunk", "8x8", "--region", "0:16,0:16", "--out", str(png)])
        == 0
    )
    assert png.stat().st_size > 0


@pytest.mark.parametrize(
    "args, message",
    [
        (["--region", "0:16"], "--region must be"),
        (["--region", "5:5,0:8"], "is empty"),
        (["--region", "0:8,0:8", "--chunk", "8x8x8", "--boundary", "x-=0"], "infinite world"),
    ],
)
def test_cli_world_bad_input_exits_2(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from csplab.cli import main

    assert main(["world", "fig3_4a", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_dask_scheduler_gives_the_same_bytes() -> None:
    pytest.importorskip("distributed")
    a = World("fig3_4a", seed=9, chunk=(8, 8)).region((-8, 16), (0, 16))
    with World("fig3_4a", seed=9, chunk=(8, 8), workers=1, scheduler="local") as w:
        b = w.region((-8, 16), (0, 16))
    assert a.tobytes() == b.tobytes()


def test_global_constraints_are_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from csplab.cli import main
    from csplab.constraints import KINDS, parse_constraints
    from csplab.world import UNHONOURED

    P = World("fig3_4a", chunk=(8, 8)).problem((8, 8))
    specs = {
        "count": {"type": "count", "labels": [1], "min": 1},
        "connected": {"type": "connected", "labels": [1]},
        "mirror": {"type": "mirror", "axis": "x"},
        "separation": {"type": "separation", "labels": [1], "distance": 2},
        "max-run": {"type": "max-run", "labels": [1], "n": 2},
    }
    assert set(KINDS) - {"rotate"} == set(specs)  # rotate needs a square: mirror's kind
    for name, spec in specs.items():
        (c,) = parse_constraints({"constraints": [spec]}, P)
        with pytest.raises(InputError, match=f"cannot honour a {c.kind} constraint") as e:
            World("fig3_4a", chunk=(8, 8), constraints=[c])
        assert UNHONOURED[c.kind] in str(e.value), name
    f = tmp_path / "c.json"
    f.write_text('{"constraints": [{"type": "connected", "labels": [1]}]}')
    argv = ["world", "fig3_4a", "--chunk", "8x8", "--region", "0:16,0:16", "--constraints", str(f)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "cannot honour a connected constraint" in err and len(err.strip().splitlines()) == 1
    for chunk in ("16", "16x16x10x2"):  # the chunk is checked before the file is read
        argv = ["world", "castle", "--chunk", chunk, "--region", "0:16,0:16", "--boundary",
                "auto", "--constraints", str(f)]  # fmt: skip
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert "chunk must be 2 or 3 positive sizes" in err and len(err.strip().splitlines()) == 1


def test_blocks_of_another_size_than_the_chunk() -> None:
    kw = {"seed": 3, "chunk": (8, 8), "block": (6, 6)}
    w = World("fig3_4a", **kw)  # type: ignore[arg-type]
    assert w.block == (6, 6) and w.B == (8, 8)  # B: the chunk's x/y size, as before
    assert World("fig3_4a", chunk=(32, 32)).block == (12, 12)  # BLOCK
    a = {c: w.chunk(*c) for c in CHUNKS}
    w2 = World("fig3_4a", **kw)  # type: ignore[arg-type]
    assert all(w2.chunk(*c).tobytes() == a[c].tobytes() for c in reversed(CHUNKS))
    g = w.region((-8, 16), (-8, 16))
    assert len(w.problem(g.shape).violations(g)) == 0 and len(np.unique(g)) > 2
    # the cache floor is the most blocks a chunk needs from scratch, over its positions
    solved = []
    for i in range(3):  # 6 // gcd(6, 8) phases per axis
        f = World("fig3_4a", **kw)  # type: ignore[arg-type]
        f.chunk(i, 2 * i)
        solved.append(sum(f.stats.values()))
    assert max(solved) <= w.pyramid and w.pyramid in solved


@pytest.mark.parametrize("fixed", [None, {(3, 4): 1}])
def test_kernel_blocks_equal_the_interpreted_twin(
    monkeypatch: pytest.MonkeyPatch, fixed: dict[tuple[int, int], int] | None
) -> None:
    """A block in one kernel call (or block_arrays + solve_block_arrays with fixed cells)
    gives the bytes of Problem.subproblem + solve_block run interpreted."""
    from csplab import _interp

    kw = {"seed": 7, "chunk": (8, 8), "fixed": fixed}
    monkeypatch.setattr(_interp, "ENGINE", "kernels")
    assert _interp.compiled_engine()
    a = World("fig3_4a", **kw).region((-8, 16), (0, 16))  # type: ignore[arg-type]
    monkeypatch.setattr(_interp, "ENGINE", "interp")
    w = World("fig3_4a", **kw)  # type: ignore[arg-type]
    assert not _interp.compiled_engine()
    assert w.region((-8, 16), (0, 16)).tobytes() == a.tobytes()


ROADS = list(range(1, 12))  # every pipes tile but the empty one


def pipes_world(cons: list[object], seed: int = 1) -> World:
    return World(str(DATA / "pipes.xml"), seed=seed, chunk=(16, 16),
                 chunk_constraints=cons)  # type: ignore[arg-type]  # fmt: skip


def test_per_chunk_count_and_connectivity_hold_in_every_chunk() -> None:
    """Checked here with numpy and scipy's labelling, not with the constraints' code."""
    from scipy import ndimage

    from csplab.constraints import Connected, Count

    region = ((-16, 32), (-16, 16))
    w = pipes_world([Count([11], 4, 4), Connected(ROADS)])
    g = w.region(*region)
    assert len(w.problem(g.shape).violations(g)) == 0 and w.unmet_chunks(*region) == []
    free = World(str(DATA / "pipes.xml"), seed=1, chunk=(16, 16)).region(*region)
    crosses = (free == 11).reshape(3, 16, 2, 16).sum(axis=(1, 3))
    assert (crosses != 4).any()  # without the constraint the counts differ: not by chance
    for i in range(3):
        for j in range(2):
            c = g[16 * i : 16 * (i + 1), 16 * j : 16 * (j + 1)]
            assert int((c == 11).sum()) == 4
            lab, n = ndimage.label(np.isin(c, ROADS))  # 4-neighbourhood
            assert n == 1
            on = lab > 0
            assert on[0].any() and on[-1].any() and on[:, 0].any() and on[:, -1].any()


@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(order=st.permutations([(i, j) for i in range(-1, 1) for j in range(-1, 1)]))
def test_per_chunk_constraints_keep_any_visit_order(order: list[tuple[int, int]]) -> None:
    from csplab.constraints import Count

    cons = [Count([0], 60, 80)]  # twice the empty tiles of the free world: SAT completes
    if "pipes-cons" not in _REF:
        w = pipes_world(cons, seed=4)
        _REF["pipes-cons"] = {c: w.chunk(*c) for c in sorted(order)}
        assert w.stats["exact"] > 0  # the exact completion's path is part of the world
    ref = _REF["pipes-cons"]
    w = pipes_world(cons, seed=4)
    assert all(w.chunk(*c).tobytes() == ref[c].tobytes() for c in order)
    assert all(60 <= int((ref[c] == 0).sum()) <= 80 for c in ref)


def test_per_chunk_constraints_that_cannot_hold_are_reported_or_refused() -> None:
    from csplab.constraints import Count, MaxRun, Separation

    # more crosses than cells: no chunk can hold it; each keeps its labels (consistent)
    # and is listed
    w = pipes_world([Count([11], 257)])
    g = w.region((0, 32), (0, 16))
    assert len(w.problem(g.shape).violations(g)) == 0
    assert w.unmet_chunks((0, 32), (0, 16)) == [(0, 0), (1, 0)]
    assert pipes_world([]).unmet_chunks((0, 32), (0, 16)) == []
    for c in (Separation([11], 3), MaxRun([11], 2)):
        with pytest.raises(InputError, match=f"cannot honour a {c.kind} constraint per chunk"):
            pipes_world([c])


def test_cli_per_chunk_constraints(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from csplab.cli import main

    f = tmp_path / "c.json"
    f.write_text(json.dumps({"constraints": [
        {"type": "count", "labels": ["cross"], "min": 2, "max": 2, "per": "chunk"},
        {"type": "connected", "labels": ["line", "corner", "tee", "cross"], "per": "chunk"},
    ]}))  # fmt: skip
    argv = ["world", str(DATA / "pipes.xml"), "--chunk", "16x16", "--region", "0:32,0:32",
            "--constraints", str(f), "--json", "--out", str(tmp_path / "w.npy")]  # fmt: skip
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["violations"] == 0 and out["chunks_breaking_constraints"] == []
    g = np.load(tmp_path / "w.npy")
    assert (g == 11).reshape(2, 16, 2, 16).sum(axis=(1, 3)).tolist() == [[2, 2], [2, 2]]
    f.write_text('{"constraints": [{"type": "count", "labels": [1], "per": "world"}]}')
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert '"per" must be "chunk"' in err and len(err.strip().splitlines()) == 1


def test_per_chunk_constraints_on_workers_give_the_same_bytes() -> None:
    from csplab.constraints import Count

    a = pipes_world([Count([11], 2, 2)]).region((0, 32), (-16, 16))
    with World(str(DATA / "pipes.xml"), seed=1, chunk=(16, 16), workers=2,
               chunk_constraints=[Count([11], 2, 2)]) as w:  # fmt: skip
        assert w.region((0, 32), (-16, 16)).tobytes() == a.tobytes()
    assert (a == 11).reshape(2, 16, 2, 16).sum(axis=(1, 3)).tolist() == [[2, 2], [2, 2]]


def complete_pipes(drop: int | None = None) -> RuleSet:
    """Pipe tiles of every set of connections (bits x-, x+, y-, y+: 16 labels, dead ends
    included), two neighbours agreeing on the side they share; ``drop`` leaves one out."""
    K = 16
    T = np.zeros((2, K, K), dtype=bool)
    for a in range(K):
        for b in range(K):
            T[0, a, b] = (a >> 1 & 1) == (b & 1)
            T[1, a, b] = (a >> 3 & 1) == (b >> 2 & 1)
    if drop is not None:
        T[:, drop, :] = T[:, :, drop] = False
    return RuleSet(T, name="complete pipes")


def test_ring_completion_decides_which_worlds_take_thin_seams() -> None:
    w = World(complete_pipes(), seed=2, chunk=(16, 16))
    assert w.seams == "proved-infallible" and w.margin > 0
    for model in (three_colours(), str(DATA / "pipes.xml"), complete_pipes(drop=0b0010)):
        g = World(model, seed=2, chunk=(16, 16))
        assert g.seams == "general" and g.margin == 0, g.seams_why
    # the witness is real: checked on the rules themselves, not by the check's code
    T = complete_pipes(drop=0b0010).transitions()
    wit = World(complete_pipes(drop=0b0010), seed=2, chunk=(16, 16)).seams_why
    assert "has no label" in wit
    from csplab.analysis.rings import ring_completion

    P = complete_pipes(drop=0b0010).problem((5, 5), boundary="none")
    v = ring_completion(P, [P.cell((2, 2))])
    nb = {tuple(int(t) for t in np.unravel_index(q, P.shape)): lab
          for q, lab in v.witness["neighbours"].items()}  # fmt: skip
    ok = [c for c in range(16) if P.domains[12, c]
          and (nb.get((1, 2)) is None or T[0, nb[(1, 2)], c])
          and (nb.get((3, 2)) is None or T[0, c, nb[(3, 2)]])
          and (nb.get((2, 1)) is None or T[1, nb[(2, 1)], c])
          and (nb.get((2, 3)) is None or T[1, c, nb[(2, 3)]])]  # fmt: skip
    assert v.holds is False and ok == []
    # fixed cells restrict blocks beyond the rules: the general path
    assert World(complete_pipes(), seed=2, chunk=(16, 16), fixed={(0, 0): 5}).seams == "general"
    assert World(complete_pipes(), seed=2, chunk=(16, 16), seams="general").margin == 0


def test_thin_seams_cover_every_line_with_independent_blocks() -> None:
    w = World(complete_pipes(), seed=2, chunk=(16, 16), block=(12, 10))
    rect = ((-30, 40), (-25, 35))
    cover = np.zeros((70, 60), dtype=int)
    for s in range(1, w.S + 1):
        rects = [w._block_rect(s, b) for b in w._blocks_in(s, rect)]
        for (x0, x1), (y0, y1) in rects:  # each block of a sub-pass sees no other's cells
            for (u0, u1), (v0, v1) in rects:
                if (x0, y0) != (u0, v0):
                    assert max(u0 - x1, x0 - u1, v0 - y1, y0 - v1) >= w.reach
            if s == 1:
                cover[max(x0 + 30, 0) : x1 + 30, max(y0 + 25, 0) : y1 + 25] += 1
            else:
                cover[max(x0 + 30, 0) : x1 + 30, max(y0 + 25, 0) : y1 + 25] += 10
    assert (cover > 0).all()  # every cell is drawn: no line of the start model is left
    assert (cover % 10 <= 1).all() and (cover // 10 <= 1).all()  # at most once per kind


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(order=st.permutations(CHUNKS))
def test_thin_seams_world_is_consistent_and_order_independent(
    order: list[tuple[int, int]],
) -> None:
    ref = reference_thin()
    w = World(complete_pipes(), seed=4, chunk=(16, 16))
    for c in order:
        assert w.chunk(*c).tobytes() == ref[c].tobytes()
    g = w.region((-16, 32), (-16, 32))
    assert len(w.problem(g.shape).violations(g)) == 0
    assert w.stats["exact"] == w.stats["kept"] == 0
    assert len(np.unique(g)) == 16
    general = World(complete_pipes(), seed=4, chunk=(16, 16), seams="general")
    assert general.key != w.key  # another lattice, other bytes: another store key
    assert general.chunk(0, 0).tobytes() != ref[(0, 0)].tobytes()


def reference_thin() -> dict[tuple[int, int], np.ndarray]:
    if "thin" not in _REF:
        w = World(complete_pipes(), seed=4, chunk=(16, 16))
        _REF["thin"] = {c: w.chunk(*c) for c in CHUNKS}
    return _REF["thin"]


def pipe_networks(g: np.ndarray, ports: np.ndarray) -> int:
    """Components of the pipes of ``g`` joined through open edges facing each other
    (a plain flood fill: not the constraints' code)."""
    seen = np.zeros(g.shape, dtype=bool)
    n = 0
    steps = ((1, 0, 1, 0), (-1, 0, 0, 1), (0, 1, 3, 2), (0, -1, 2, 3))
    for start in zip(*np.nonzero(ports[g].any(axis=-1)), strict=True):
        if seen[start]:
            continue
        n += 1
        seen[start] = True
        stack = [start]
        while stack:
            x, y = stack.pop()
            for dx, dy, out, back in steps:
                u, v = x + dx, y + dy
                if (0 <= u < g.shape[0] and 0 <= v < g.shape[1] and not seen[u, v]
                        and ports[g[x, y], out] and ports[g[u, v], back]):  # fmt: skip
                    seen[u, v] = True
                    stack.append((u, v))
    return n


def test_matched_sides_make_one_network_over_a_stitched_region() -> None:
    from csplab.world import network_per_chunk

    pipes = World(str(DATA / "pipes.xml"), seed=1, chunk=(8, 8))
    rel = pipes.model.transitions()
    # an edge is open where the empty tile (0) cannot face it
    ports = np.stack([~rel[0, 0, :], ~rel[0, :, 0], ~rel[1, 0, :], ~rel[1, :, 0]], axis=1)
    free = pipes.region((0, 32), (0, 32))
    assert pipe_networks(free, ports) > 1  # without the constraints: many networks
    cons, mask = network_per_chunk((8, 8), ROADS, ports)
    w = World(str(DATA / "pipes.xml"), seed=1, chunk=(8, 8), chunk_constraints=cons, mask=mask)
    g = w.region((0, 32), (0, 32))  # 4x4 chunks
    assert len(w.problem(g.shape).violations(g)) == 0 and w.unmet_chunks((0, 32), (0, 32)) == []
    assert pipe_networks(g, ports) == 1
    assert pipe_networks(g[8:24, 0:16], ports) == 1  # any 4-connected set of chunks
    with pytest.raises(InputError, match="2D chunk"):
        network_per_chunk((8, 8, 4), ROADS)
