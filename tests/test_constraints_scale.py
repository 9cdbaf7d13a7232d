"""Global constraints at scale (issue 29, item 4): Alg. 3.1's withdrawal of refuted
choices and its growing choice, the SAT propagator's count-aware conflicts, the bulk
literals of ClauseContext.in_set and the choice between counter and adder. Every test
checks outputs (validity through Problem.violations, equal clauses), never times."""

from __future__ import annotations

import numpy as np
import pytest

import csplab
from csplab import ExampleModel
from csplab.cnf import encode
from csplab.constraints import ClauseContext, Connected, Count
from csplab.engine.alg31 import run_alg31
from csplab.grids import from_example
from csplab.testing.synthetic import connected_city


def _city(size, lo_frac=0.05):
    return connected_city(size, lo_frac)[1]


@pytest.mark.parametrize("order", ["scanline", "min-entropy"])
def test_alg31_with_constraints_returns_only_valid_grids_and_withdraws_refuted_choices(order):
    Q = _city((12, 12, 6), lo_frac=0.1)
    solved = probes = 0
    for seed in range(3):
        r = run_alg31(Q, np.random.default_rng(seed), order=order)
        probes += r.stats["constraint_probes"]
        if r.status == "solved":
            solved += 1
            assert not Q.violations(r.grid)
            # the trace is the run: its labels are the grid's, each cell once
            cells, labels = r.trace[:, 0], r.trace[:, 1]
            assert np.unique(cells).size == Q.n
            assert np.array_equal(r.grid.reshape(-1)[cells], labels)
        else:
            assert r.status == "failed"
    assert solved >= 1
    assert probes > 0  # the count's lower bound refuted some choices, which were withdrawn


def test_withdrawn_labels_are_in_no_solution_extending_the_run():
    """A withdrawal is a proof: replaying a run's choices up to a withdrawn step, the
    withdrawn label at that cell leaves no solution (exhaustive check by SAT)."""
    pytest.importorskip("pysat")
    from csplab.engine import alg31 as A

    E = ExampleModel([[0, 1, 0, 0], [0, 1, 1, 0], [0, 0, 1, 0], [1, 1, 1, 0]])
    P = from_example(E, (6, 6))
    Q = P.with_constraints([Connected([1]), Count([1], min=9, max=14)])
    seen: list[tuple[list[tuple[int, int]], int, int]] = []
    real = A._withdraw

    def spy(eng, run, heap, root, withdrawn):
        t = run.steps - 1
        prefix = [(int(run.trace_cell[i]), int(run.trace_label[i])) for i in range(t)]
        seen.append((prefix, int(run.trace_cell[t]), int(run.trace_label[t])))
        return real(eng, run, heap, root, withdrawn)

    A._withdraw = spy
    try:
        for seed in range(6):
            r = run_alg31(Q, np.random.default_rng(seed))
            if r.status == "solved":
                assert not Q.violations(r.grid)
    finally:
        A._withdraw = real
    assert seen
    from csplab.grids import with_fixed

    for prefix, cell, label in seen[:8]:
        fixed = {Q.coords(c): b for c, b in prefix}
        fixed[Q.coords(cell)] = label
        R = with_fixed(P, fixed).with_constraints(list(Q.constraints))
        assert csplab.solve(R, "sat", rng=0).status == "unsat"


def test_sat_count_and_connectivity_output_is_valid():
    pytest.importorskip("pysat")
    Q = _city((10, 10, 5), lo_frac=0.12)
    r = csplab.solve(Q, "sat", rng=3, time_limit=120)
    assert r.status == "solved"
    assert not Q.violations(r.grid)
    fg = np.isin(r.grid, list(Q.constraints[0].labels))
    assert fg.sum() >= int(np.ceil(0.12 * Q.n))


def test_sat_propagator_refutes_a_component_smaller_than_the_count():
    """The count's lower bound exceeds what any connected set can hold: a count over the
    set's labels with min larger than the set's largest possible component is unsat, and
    the SAT search proves it (the conflict of the count-aware propagator or the counter)."""
    pytest.importorskip("pysat")
    E = ExampleModel([[0, 0, 0, 0], [0, 1, 2, 0], [0, 0, 0, 0]])
    P = from_example(E, (8, 8))
    # a 1 is followed by a 2 and nothing else touches them: components of two cells
    Q = P.with_constraints([Connected([1, 2]), Count([1, 2], min=3)])
    assert csplab.solve(Q, "sat", rng=0).status == "unsat"
    ok = P.with_constraints([Connected([1, 2]), Count([1, 2], min=2)])
    r = csplab.solve(ok, "sat", rng=0)
    assert r.status == "solved" and not ok.violations(r.grid)


def test_in_set_reads_the_encoding_arrays_as_the_literal_calls_do():
    Q = _city((6, 6, 4))
    enc = encode(Q)
    fast = ClauseContext(Q, enc.literal, enc.nvars)
    slow = ClauseContext(Q, lambda c, b: enc.literal(c, b), enc.nvars)
    S = np.zeros(Q.K, dtype=bool)
    S[list(Q.constraints[0].labels)] = True
    got = [fast.in_set(c, S) for c in range(Q.n)]
    want = [slow.in_set(c, S) for c in range(Q.n)]
    assert got == want
    assert fast.clauses == slow.clauses and fast.top == slow.top


def test_count_of_many_cells_uses_the_adder_and_stays_exact():
    """At least 3 of 40 cells: a counter over the negations would need 40 * 37 registers per
    cell; above the register limit the adder encodes both bounds, and the models agree with
    the bounds exactly."""
    pytest.importorskip("pysat")
    from pysat.solvers import Solver

    from csplab import constraints as C

    xs = list(range(1, 41))
    saved = C._COUNTER_MAX
    try:
        C._COUNTER_MAX = 100  # force the adder
        ctx = ClauseContext(from_example(ExampleModel([[0, 1]]), (1, 2)), lambda c, b: 1, 40)
        ctx.card(xs, 3, 5)
        assert ctx.top - 40 < 40 * 37  # fewer variables than the counter's registers
    finally:
        C._COUNTER_MAX = saved
    rng = np.random.default_rng(0)
    with Solver(name="cadical195", bootstrap_with=ctx.clauses) as s:
        for _ in range(40):
            k = int(rng.integers(0, 9))
            on = set(rng.choice(40, size=k, replace=False).tolist())
            assume = [x if x - 1 in on else -x for x in xs]
            assert s.solve(assumptions=assume) == (3 <= k <= 5), k


def test_count_constraints_are_exact_in_sat_on_both_sides():
    pytest.importorskip("pysat")
    P = from_example(ExampleModel([[0, 1], [1, 0], [0, 0]]), (7, 7))
    for lo, hi in [(5, 9), (20, 30)]:
        Q = P.with_constraints([Count([1], min=lo, max=hi)])
        r = csplab.solve(Q, "sat", rng=1)
        assert r.status == "solved" and not Q.violations(r.grid)
        assert lo <= int((r.grid == 1).sum()) <= hi


def test_unchanged_judgement_with_chains_of_new_must_cells_hides_no_stray():
    """New must cells joined to old ones only through other new must cells (a pipe tile
    forcing its neighbour): when connected_unchanged skips, the full propagator removes
    no cell from the set either."""
    from csplab.constraints import grid_csr

    rng = np.random.default_rng(5)
    E = ExampleModel([[0, 1, 2, 0], [2, 0, 1, 1], [1, 2, 0, 2]])
    E3D = ExampleModel(np.array([[[0, 1], [1, 2]], [[2, 0], [1, 1]], [[1, 2], [0, 0]]]))
    judged = chains = 0
    for shape in [(7, 7), (5, 4, 3)]:
        P = from_example(E if len(shape) == 2 else E3D, shape)
        con = Connected([1])
        Q = P.with_constraints([con])
        ptr, nbr = grid_csr(Q)
        for _ in range(300):
            can = rng.random(P.n) < 0.8
            must = can & (rng.random(P.n) < 0.15)
            got = con.prune_sets(Q, can.copy(), must.copy())
            if got is None:
                continue
            can[got[0]] = False
            must[got[1]] = True
            if con.prune_sets(Q, can.copy(), must.copy()) is None:
                continue
            c2, m2 = can.copy(), must.copy()
            # grow a chain of new must cells from an old one, and drop a may-cell
            v = int(rng.choice(np.flatnonzero(must))) if must.any() else int(rng.integers(P.n))
            for _ in range(int(rng.integers(1, 4))):
                nb = [int(w) for w in nbr[ptr[v] : ptr[v + 1]] if c2[w] and not m2[w]]
                if not nb:
                    break
                v = nb[int(rng.integers(len(nb)))]
                m2[v] = True
            x = int(rng.integers(P.n))
            if c2[x] and not m2[x] and rng.random() < 0.5:
                c2[x] = False
            if con.prunes_nothing_new(Q, c2, m2, (can, must)):
                judged += 1
                fresh = np.flatnonzero(m2 & ~must)
                chains += int(any(not must[nbr[ptr[w] : ptr[w + 1]]].any() for w in fresh))
                again = con.prune_sets(Q, c2.copy(), m2.copy())
                assert again is not None and again[0].size == 0
    assert judged > 20 and chains > 5


def _separated(shape, walls, s, t):
    """Whether every path of axis neighbours from cell ``s`` to cell ``t`` of a grid of
    ``shape`` passes through a cell of ``walls`` (breadth-first search, flat indices)."""
    seen = np.zeros(int(np.prod(shape)), dtype=bool)
    seen[list(walls)] = True
    if seen[s] or seen[t]:
        return True
    seen[s] = True
    todo = [s]
    while todo:
        x = np.unravel_index(todo.pop(), shape)
        for ax in range(len(shape)):
            for d in (-1, 1):
                y = list(x)
                y[ax] += d
                if 0 <= y[ax] < shape[ax]:
                    w = int(np.ravel_multi_index(y, shape))
                    if w == t:
                        return False
                    if not seen[w]:
                        seen[w] = True
                        todo.append(w)
    return True


def _reach(shape, walls, s):
    """How many cells a path of axis neighbours reaches from ``s`` without entering
    ``walls`` (``s`` included)."""
    n = int(np.prod(shape))
    return sum(1 for c in range(n) if c == s or not _separated(shape, walls, s, c))


@pytest.mark.parametrize("shape,lo", [((7, 6), 0), ((7, 6), 14), ((5, 4, 3), 9)])
def test_every_reason_of_the_connectivity_propagator_is_a_separator(shape, lo):
    """Each reason the SAT search's connectivity propagator gives on a random partial
    assignment, ``¬y_t ∨ ¬y_s ∨ y_w...`` or ``¬y_s ∨ y_w...``, is false but for its
    propagated literal, and holds in every connected answer: the walls ``w`` cut every path
    from ``s`` to ``t``, or leave ``s`` fewer cells than the count needs (checked by a
    search of the grid, not by the propagator's components). The walls are those of the
    stray pocket when they are fewer than those of the region of ``s``: both kinds occur,
    and a wrong side would admit a path."""
    pytest.importorskip("pysat")
    from csplab.constraints import constraint_clauses
    from csplab.engine import connectivity as CN

    # every pair of labels is allowed along every axis
    bits = [[0, 0, 1], [0, 1, 1], [1, 1, 0]]
    E = ExampleModel(np.array(bits if len(shape) == 2 else [bits, bits[::-1], bits]))
    cons = [Connected([1])] + ([Count([1], min=lo)] if lo else [])
    Q = from_example(E, shape).with_constraints(cons)
    enc = encode(Q)
    ctx = constraint_clauses(Q, enc.literal, enc.nvars)
    rng = np.random.default_rng(len(shape) + lo)
    kinds, checked = set(), 0
    real_sep = CN._separators

    def spy_sep(st, comp, root, targets):
        out = real_sep(st, comp, root, targets)
        kinds.update("pocket" if v is not out[root] else "region" for v in out.values())
        return out

    CN._separators = spy_sep
    try:
        for _ in range(150):
            prop = CN.ConnectivityPropagator(Q, ctx)
            st = prop.states[0]
            cell = {abs(y): c for c, y in enumerate(st.y) if not isinstance(y, bool)}
            val = {}
            for y in st.y:
                u = rng.random()
                if isinstance(y, bool) or u > 0.55:
                    continue
                lit = int(y) if u < 0.12 else -int(y)  # in the set, or out of it
                val[abs(lit)] = lit
                prop.on_assignment(lit)
            for lit in prop.propagate():
                clause = prop.reasons[lit]
                assert clause[0] == lit
                # a reason: every other literal is false under the assignment
                assert all(val.get(abs(x)) == -x for x in clause[1:])
                neg = [cell[-x] for x in clause if x < 0]
                walls = [cell[x] for x in clause if x > 0]
                s = neg[-1]
                small = lo > 0 and _reach(Q.shape, walls, s) < lo
                if len(neg) == 2 and not small:
                    assert _separated(Q.shape, walls, neg[0], s)
                else:
                    assert len(neg) in (1, 2) and small
                checked += 1
    finally:
        CN._separators = real_sep
    assert checked > 20
    assert kinds == {"pocket", "region"}
