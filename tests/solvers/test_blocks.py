import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, load_example, solve
from csplab.errors import InputError, NoTrivialSolutionError
from csplab.grids import from_example
from csplab.solvers.blocks import block_starts, trivial_solution
from csplab.testing.strategies import problems


@given(problems(max_side=5, fixed=False, masks=False), st.integers(0, 2**31))
def test_blocks_with_full_size_block_equals_alg_3_1(P, seed):
    try:
        trivial_solution(P)
    except NoTrivialSolutionError:
        return
    a = solve(P, "catalog", rng=seed)
    b = solve(P, "blocks", rng=seed, block=max(P.shape), retries=0)
    assert b.stats["blocks_tried"] == 1
    if a.status == "solved":
        assert b.stats["blocks_accepted"] == 1
        assert np.array_equal(a.grid, b.grid)
    else:
        assert b.stats["blocks_accepted"] == 0


@given(problems(max_side=6, fixed=False, masks=False), st.integers(1, 4), st.integers(0, 99))
def test_blocks_output_always_consistent(P, m, seed):
    try:
        trivial_solution(P)
    except NoTrivialSolutionError:
        return
    r = solve(P, "blocks", rng=seed, block=m, retries=2)
    assert r.status == "solved" and r.stats["final_violations"] == 0


def test_block_starts_cover_everything():
    for n in range(1, 30):
        for m in range(1, 12):
            s = block_starts(n, m)
            mm = min(m, n)
            covered = np.zeros(n, bool)
            for a in s:
                covered[a : a + mm] = True
                assert a + mm <= n
            assert covered.all()


def test_trivial_solution_layers_and_errors():
    E = ExampleModel(np.array([[[1, 0, 0]] * 2] * 2))  # ground below empty space
    P = from_example(E, (4, 4, 3), boundary="auto")
    g = trivial_solution(P)
    assert (g[:, :, 0] == 1).all() and (g[:, :, 1:] == 0).all()
    # no empty space: the checkerboard starts from an Alg. 3.1 run
    g = trivial_solution(from_example(load_example("E1"), (4, 4)))
    assert from_example(load_example("E1"), (4, 4)).is_solution(g)
    with pytest.raises(NoTrivialSolutionError, match="unsatisfiable"):
        trivial_solution(from_example(load_example("E3"), (5, 5)))
    # a parity constraint arc consistency cannot see: a checkerboard on an odd torus
    P = from_example(load_example("E1"), (3, 3), periodic=True)
    with pytest.raises(NoTrivialSolutionError, match="failed 5 times"):
        trivial_solution(P)


def test_blocks_from_given_init_and_bad_init():
    P = from_example(load_example("line"), (10, 8))
    init = solve(P, "catalog", rng=1).grid
    r = solve(P, "blocks", rng=2, init=init, block=4)
    assert r.ok and r.stats["init"] == "given"
    bad = init.copy()
    bad[0, 0] = 1
    bad[0, 1] = 1
    with pytest.raises(InputError):
        solve(P, "blocks", rng=2, init=bad)
    with pytest.raises(InputError):
        solve(P, "blocks", rng=2, block=0)


def test_block_stats_and_timeout():
    # 6x6 blocks on 20 cells start every 3 cells, the last flush with the end:
    # 0, 3, 6, 9, 12, 14 -> 6 x 6 = 36 blocks
    P = from_example(load_example("line"), (20, 20))
    r = solve(P, "blocks", rng=0, block=(6, 6))
    assert r.stats["blocks_tried"] == 36
    assert r.stats["acceptance_rate"] == r.stats["blocks_accepted"] / 36
    # every pair of labels is adjacent on both axes in this example, so Alg. 3.1 cannot fail
    # in any block: all 36 are accepted at the first attempt
    E = ExampleModel([[0, 0, 1, 1], [0, 0, 1, 1], [1, 1, 0, 0], [1, 1, 0, 0]])
    assert E.transitions().all()
    r = solve(from_example(E, (20, 20)), "blocks", rng=0, block=(6, 6), retries=5)
    stats = {k: r.stats[k] for k in ("blocks_tried", "blocks_accepted", "retries")}
    assert stats == {"blocks_tried": 36, "blocks_accepted": 36, "retries": 0}
    t = solve(P, "blocks", rng=0, block=4, time_limit=1e-9)
    assert t.status == "timeout" and P.is_solution(t.grid)


@pytest.mark.parametrize("shape", [(4, 4), (5, 5)])
def test_acceptance_and_retries_replay_alg31_attempts(shape):
    """One block covering the model: Alg. 3.4 runs Alg. 3.1 on it up to ``retries + 1``
    times from one generator, so the attempts can be replayed with the catalog solver
    (same generator, same order): the block is accepted iff one attempt solves it, the
    retries are the failed attempts before that one, and the output is that attempt's grid
    (or the untouched trivial solution). This example makes Alg. 3.1 fail often."""
    R = 3
    P = from_example(ExampleModel(np.array([[0, 0, 0], [1, 2, 2], [0, 1, 2]])), shape)
    start = trivial_solution(P)
    seen = set()
    for seed in range(25):
        gen = np.random.default_rng(seed)
        runs = [solve(P, "catalog", rng=gen) for _ in range(R + 1)]
        first = next((i for i, a in enumerate(runs) if a.status == "solved"), None)
        r = solve(P, "blocks", rng=seed, block=max(shape), retries=R)
        assert r.stats["blocks_tried"] == 1
        if first is None:
            assert (r.stats["blocks_accepted"], r.stats["retries"]) == (0, R)
            assert np.array_equal(r.grid, start)
        else:
            assert (r.stats["blocks_accepted"], r.stats["retries"]) == (1, first)
            assert np.array_equal(r.grid, runs[first].grid)
        seen.add(first)
    assert None in seen and len(seen) >= 3  # rejections and several retry counts occurred


# ----------------------------------------------------------------------------- compiled sweep
@pytest.mark.parametrize(
    "name,shape,block,kw",
    [
        ("fig3_10", (24, 24), 8, {}),
        ("castle", (14, 14, 10), 8, {}),
        ("city", (12, 12, 8), (6, 6, 8), {"boundary": "auto"}),  # K = 119: two words
        ("loops", (20, 20), 6, {"periodic": True}),
    ],
)
@pytest.mark.parametrize("order", ["scanline", "scan:yx", "min-entropy", "min-domain"])
def test_compiled_sweep_same_as_python_sweep(monkeypatch, name, shape, block, kw, order):
    """One kernel for the whole sweep (:func:`csplab._kernels.blocks_sweep`) gives the
    Python sweep's grids and counts, draw for draw (the Python sweep runs when the engine
    is the interpreted one)."""
    from csplab import _interp
    from csplab.solvers import blocks as blocks_mod

    E = load_example(name)
    real = blocks_mod.sweep_blocks
    order = order if len(shape) == 2 or not order.startswith("scan:") else "scan:zyx"
    for choice in ("uniform", "weighted"):
        out = []
        for engine in ("interp", "kernels"):
            monkeypatch.setattr(_interp, "ENGINE", engine)
            P = from_example(E, shape, **kw)
            calls: list[int] = []

            def counted(*a, calls=calls, **k):
                calls.append(1)
                return real(*a, **k)

            monkeypatch.setattr(blocks_mod, "sweep_blocks", counted)
            r = solve(P, "blocks", rng=3, block=block, order=order, choice=choice, sweeps=2,
                      retries=3)  # fmt: skip
            out.append((r, bool(calls)))
        (a, used_a), (b, used_b) = out
        assert not used_a and used_b  # the Python sweep, then the kernel
        assert a.status == b.status == "solved"
        assert np.array_equal(a.grid, b.grid)
        for k in ("blocks_tried", "blocks_accepted", "retries", "revisions"):
            assert a.stats[k] == b.stats[k], k
        assert P.is_solution(b.grid)
    assert a.stats["blocks_accepted"] > 0
