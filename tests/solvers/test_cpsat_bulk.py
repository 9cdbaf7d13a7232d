"""The ``cpsat`` one-hot model serialized in bulk (numba + numpy, one protobuf parse).

Checks: the varint writer against protobuf's own serializer; the parsed model equals the
one built element by element through the proto API (on random problems, with and without
a solution hint); the solver gives the same answers either way (incl. an unsatisfiable
problem that arc consistency does not refute); the deadline is checked while building.
"""

import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("ortools")

from ortools.sat import cp_model_pb2
from ortools.sat.python import cp_model

from csplab import ExampleModel, Problem, load_example, solve
from csplab.cnf import encode
from csplab.engine.sat import preferred_labels
from csplab.grids import from_example
from csplab.solvers import cpsat
from csplab.testing.strategies import problems, random_problems
from csplab.testing.synthetic import box_town

pytestmark = pytest.mark.skipif(
    cpsat._proto_parser() is None, reason="this OR-Tools build offers no bulk parser"
)


def _models(P: Problem, hint: bool, seed: int = 0) -> tuple[str, str]:
    """Text of the bulk-built and of the element-by-element model of ``P``."""
    enc = encode(P)
    assert enc.ok
    pref = preferred_labels(enc.catalog, None, np.random.default_rng(seed)) if hint else None
    a = cp_model.CpModel()
    _read, loader, _size = cpsat.CpsatSolver._onehot(a, enc, pref, None)
    assert loader == "proto-bytes"
    b = cp_model.CpModel()
    cpsat._onehot_elementwise(b, enc, pref, None)
    return str(a.proto), str(b.proto)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-(2**31), 2**31 - 1), max_size=50),
       st.lists(st.integers(0, 2**53 - 1), max_size=20))  # fmt: skip
def test_varints_match_protobuf(int32s: list[int], int64s: list[int]) -> None:
    msg = cp_model_pb2.PartialVariableAssignment()
    msg.vars.extend(int32s)  # packed int32 (negative: 10 bytes)
    want = msg.SerializeToString()
    got = bytes(cpsat._packed(cpsat._field("PartialVariableAssignment", "vars"),
                              np.array(int32s, dtype=np.int64)))  # fmt: skip
    assert got == want
    values = np.array(int64s, dtype=np.int64)
    assert bytes(cpsat._varints(values)) == b"".join(_varint(v) for v in int64s)
    assert cpsat._varint_sizes(values).tolist() == [len(_varint(v)) for v in int64s]


def _varint(v: int) -> bytes:
    out = bytearray()
    v &= 2**64 - 1
    while v >= 128:
        out.append((v & 127) | 128)
        v >>= 7
    out.append(v)
    return bytes(out)


@settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck))
@given(P=st.one_of(problems(max_side=5, max_labels=5), random_problems(max_side=5, max_labels=5)),
       hint=st.booleans(), seed=st.integers(0, 100))  # fmt: skip
def test_bulk_model_equals_elementwise_model(P: Problem, hint: bool, seed: int) -> None:
    if not encode(P).ok:
        return
    bulk, ref = _models(P, hint, seed)
    assert bulk == ref


@pytest.mark.parametrize("name", ["fig3_10", "castle"])
def test_bulk_model_equals_elementwise_model_on_examples(name: str) -> None:
    E = load_example(name)
    shape = (9, 11) if E.ndim == 2 else (7, 6, 4)
    P = from_example(E, shape)
    assert encode(P).nx > 0  # a model with variables and clauses
    for hint in (True, False):
        bulk, ref = _models(P, hint)
        assert bulk == ref


def _odd_cycle() -> Problem:
    """A checkerboard on a periodic axis of odd length: unsatisfiable, arc consistent."""
    return from_example(ExampleModel([[0, 1], [1, 0]]), (3, 4), periodic=(True, False))


@pytest.mark.parametrize(
    "P",
    [
        from_example(load_example("castle"), (8, 8, 4), boundary="auto"),
        from_example(load_example("fig3_10"), (12, 12)),
        _odd_cycle(),
    ],
    ids=["castle", "fig3_10", "odd-cycle"],
)
def test_same_answers_as_the_elementwise_build(P: Problem, monkeypatch: pytest.MonkeyPatch) -> None:
    bulk = solve(P, "cpsat", rng=3)
    assert bulk.stats["loader"] == "proto-bytes"
    monkeypatch.setattr(cpsat, "_PARSER", [None])  # force the element-by-element build
    ref = solve(P, "cpsat", rng=3)
    assert ref.stats["loader"] == "proto-api"
    assert bulk.status == ref.status
    np.testing.assert_array_equal(bulk.grid, ref.grid)
    if bulk.status == "solved":
        assert len(P.violations(bulk.grid)) == 0
    else:
        assert bulk.status == "unsat" and bulk.stats["proof"] == "CP-SAT: infeasible"


def test_odd_cycle_is_not_refuted_by_arc_consistency() -> None:
    assert encode(_odd_cycle()).ok


def test_building_checks_the_deadline() -> None:
    P = from_example(load_example("castle"), (8, 8, 4), boundary="auto")
    enc = encode(P)
    with pytest.raises(cpsat._Deadline):
        cpsat._onehot_bytes(enc, None, time.perf_counter() - 1.0)
    with pytest.raises(cpsat._Deadline):
        cpsat.CpsatSolver._onehot(cp_model.CpModel(), enc, None, time.perf_counter() - 1.0)


def test_time_limit_is_respected() -> None:
    big = from_example(box_town(2, rng=0), (30, 30, 8))
    solve(from_example(box_town(1, rng=0), (3, 3, 3)), "cpsat", rng=0)  # warm up
    limit = 0.3
    t0 = time.perf_counter()
    r = solve(big, "cpsat", rng=0, time_limit=limit)
    wall = time.perf_counter() - t0
    assert r.status in ("timeout", "solved")
    assert wall < limit + 1.0, wall


@pytest.mark.parametrize("model", ["onehot", "table"])
def test_a_setup_the_time_left_cannot_hold_is_not_started(model, monkeypatch) -> None:
    # CP-SAT's set-up ignores its time limit: with a (pretend) slow machine csplab returns
    # at once, saying what it estimated, rather than overrunning the limit
    P = from_example(load_example("castle"), (8, 8, 4), boundary="auto")
    monkeypatch.setitem(cpsat._SETUP_RATE, model, 1.0)  # one unit per second
    t0 = time.perf_counter()
    r = solve(P, "cpsat", rng=0, time_limit=5.0, model=model)
    assert time.perf_counter() - t0 < 2.0
    assert r.status == "timeout" and r.stats["setup_estimate_s"] > 5.0
    assert "solve_s" not in r.stats  # Solve was never called
    # without a limit the same run solves, and the rate is learned from it
    r = solve(P, "cpsat", rng=0, model=model)
    assert r.status == "solved" and len(P.violations(r.grid)) == 0


def test_setup_rate_learning() -> None:
    rate = dict(cpsat._SETUP_RATE)
    try:
        cpsat._learn_setup("onehot", 10 << 20, 0.5, searched=False, solved=False)
        assert cpsat._SETUP_RATE["onehot"] == pytest.approx((10 << 20) / 0.5)  # measured
        cpsat._learn_setup("onehot", 10 << 20, 2.0, searched=True, solved=True)
        assert cpsat._SETUP_RATE["onehot"] == pytest.approx((10 << 20) / 0.5)  # bound: no fall
        cpsat._learn_setup("onehot", 10 << 20, 0.1, searched=True, solved=True)
        assert cpsat._SETUP_RATE["onehot"] == pytest.approx((10 << 20) / 0.1)  # bound: rise
        cpsat._learn_setup("onehot", 1000, 1e-6, searched=False, solved=False)
        assert cpsat._SETUP_RATE["onehot"] == pytest.approx((10 << 20) / 0.1)  # too small
    finally:
        cpsat._SETUP_RATE.update(rate)
