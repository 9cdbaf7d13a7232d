"""csplab.certcheck, the independent checker of ``prove``'s certificates (issue 26).

The checker must accept what the prover proves, on a 2D example, a 3D built-in and a
tileset, and reject planted defects: a state removed, a transition altered (with or
without a new hash), a configuration or a recorded key dropped, a failing run altered.
Check and prove times are printed (not asserted).
"""

from __future__ import annotations

import copy
import json
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from csplab.analysis.infallible import proof_scope, prove_infallible
from csplab.certcheck import check_certificate, rules_hash
from csplab.errors import InputError
from csplab.examples import load_example, load_model
from csplab.io.ruleset import DomainOp, RuleSet

DATA = Path(__file__).resolve().parent / "io" / "data"
_ROOT = Path(__file__).resolve().parents[1]
ANCHORS = next(
    (p for p in (_ROOT.parent / "shared" / "anchors-data",
                 _ROOT.parents[1] / "shared" / "anchors-data") if p.is_dir()),
    None,
)  # fmt: skip

PROVED = [
    ("fig3_15", "2x2", "scan:yx"),
    ("fig3_16", "4x2", "scan:yx"),
    ("pillar", "2", "scanline"),  # 3D built-in
    (str(DATA / "pipes.xml"), "2", "scanline"),  # WFC simple tiled
]


def _cert(spec: str, region: str, order: str) -> dict:
    M = load_model(spec)
    t0 = time.perf_counter()
    v = prove_infallible(M, region, order=order, certificate=True)
    t_prove = time.perf_counter() - t0
    cert = json.loads(json.dumps(v.witness["certificate"]))  # as read back from a file
    t0 = time.perf_counter()
    ok, msg = check_certificate(cert)
    t_check = time.perf_counter() - t0
    print(f"{Path(spec).name}: prove {t_prove:.3f} s, check {t_check:.3f} s ({msg[:40]})")
    assert ok, msg
    return cert


@pytest.mark.parametrize(("spec", "region", "order"), PROVED)
def test_proved_certificates_check(spec, region, order):
    cert = _cert(spec, region, order)
    assert cert["claim"] == "infallible" and cert["version"] == 1
    assert sum(len(c["states"]) for c in cert["configs"]) == cert["prover"]["states"]


def _defects(cert: dict) -> dict[str, dict]:
    out = {}
    c = copy.deepcopy(cert)  # one reachable state removed (not the start)
    conf = max(c["configs"], key=lambda k: len(k["states"]))
    conf["states"] = [s for s in conf["states"] if s[0] != 1][:] + [
        s for s in conf["states"] if s[0] == 1
    ][1:]
    out["state removed"] = c
    out["transition added"] = _altered(cert)
    c = copy.deepcopy(cert)  # one transition removed, hash not updated
    c["rules"]["pairs"][0].pop()
    out["stale hash"] = c
    c = copy.deepcopy(cert)
    c["configs"].pop()
    out["configuration dropped"] = c
    c = copy.deepcopy(cert)  # a step forgets a label a later catalog needs
    conf = next(k for k in c["configs"] if any(k["keys"]))
    i = next(i for i, k in enumerate(conf["keys"]) if k)
    conf["keys"][i] = conf["keys"][i][1:]
    out["key dropped"] = c
    return out


def _states(cert: dict) -> set:
    return {
        (tuple(c["lower"]), tuple(c["upper"]), s[0], tuple(s[1]))
        for c in cert["configs"] for s in c["states"]
    }  # fmt: skip


def _altered(cert: dict) -> dict:
    """The certificate with one transition added (hash updated) such that the prover, run
    on the altered rules, reaches a state the certificate lacks: its set cannot be closed
    under the altered rules (the least closed set is the reachable one)."""
    assert all(cert["rules"]["used"])
    K, ndim = cert["rules"]["labels"], len(cert["rules"]["pairs"])
    have = _states(cert)
    for d in range(ndim):
        T = np.zeros((ndim, K, K), dtype=bool)
        for e, pairs in enumerate(cert["rules"]["pairs"]):
            for a, b in pairs:
                T[e, a, b] = True
        for a, b in zip(*np.nonzero(~T[d]), strict=True):
            T2 = T.copy()
            T2[d, a, b] = True
            v = prove_infallible(
                RuleSet(T2), "x".join(map(str, cert["region"])), order=cert["order"],
                history=cert["history"], realize=False, refute=False, certificate=True,
            )  # fmt: skip
            c2 = (v.witness or {}).get("certificate")
            if c2 is None or _states(c2) <= have:
                continue
            bad = copy.deepcopy(cert)
            bad["rules"]["pairs"][d] = sorted([*bad["rules"]["pairs"][d], [int(a), int(b)]])
            bad["rules_sha256"] = rules_hash(bad["rules"])
            return bad
    raise AssertionError("no added transition reaches a new state")


@pytest.mark.parametrize(("spec", "region", "order"), [PROVED[0], PROVED[2], PROVED[3]])
def test_planted_defects_rejected(spec, region, order):
    cert = _cert(spec, region, order)
    for what, bad in _defects(cert).items():
        ok, msg = check_certificate(bad)
        assert not ok, what
        assert msg.startswith("invalid:"), (what, msg)


def test_removing_a_transition_that_matters_is_rejected():
    # fig3_15 is proved with 2x2 regions; dropping T_x pairs until a used label has no
    # successor along x makes some point's catalog empty (with the hash updated)
    cert = _cert("fig3_15", "2x2", "scan:yx")
    bad = copy.deepcopy(cert)
    a0 = bad["rules"]["pairs"][0][0][0]
    bad["rules"]["pairs"][0] = [p for p in bad["rules"]["pairs"][0] if p[0] != a0]
    bad["rules_sha256"] = rules_hash(bad["rules"])
    ok, msg = check_certificate(bad)
    assert not ok and "invalid" in msg


def test_refuted_certificate_replays_and_rejects_an_altered_run():
    v = prove_infallible(load_example("fig3_5a"), "2x2", order="scan:yx", certificate=True)
    assert v.holds is False
    cert = json.loads(json.dumps(v.witness["certificate"]))
    ok, msg = check_certificate(cert)
    assert ok and "fallible" in msg, msg
    bad = copy.deepcopy(cert)
    bad["run"]["choices"] = bad["run"]["choices"][:-1]  # stops before the wipe-out
    assert not check_certificate(bad)[0]
    bad = copy.deepcopy(cert)
    c, b = bad["run"]["choices"][0]
    bad["run"]["choices"][0] = [c, (b + 1) % cert["rules"]["labels"]]
    assert not check_certificate(bad)[0]


def test_checker_imports_nothing_of_csplab_but_errors():
    # static, imports inside functions included (``import csplab`` itself loads the
    # package's __init__, which is not the checker's code); import-linter checks it too
    import ast

    import csplab.certcheck as cc

    tree = ast.parse(Path(cc.__file__).read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    assert {n for n in names if n.split(".")[0] == "csplab"} == {"csplab.errors"}


def test_rule_sets_outside_the_proof_say_why():
    M = load_model(str(DATA / "tiny_debroglie.json"))
    assert "global constraints" in proof_scope(M)
    with pytest.raises(InputError, match="global constraints"):
        prove_infallible(M)
    T = np.ones((2, 2, 2), dtype=bool)
    box = DomainOp("force", np.array([True, False]), region=[(2, 4), (1, 3)], key="lake")
    assert "boxes of cells" in proof_scope(RuleSet(T, constraint_ops=[box]))
    assert "periodic" in proof_scope(RuleSet(T, periodic=True))


def test_poms_face_rules_proved_and_checked():
    # tiny_poms: 5 boundary rules on faces, label 1 forced on z- and removed elsewhere
    cert = _cert(str(DATA / "tiny_poms.json"), "2", "scanline")
    assert len(cert["rules"]["faces"]) == 7 and len(cert["configs"]) == 512
    bad = copy.deepcopy(cert)  # drop the rule that removes label 1 above the ground
    bad["rules"]["faces"] = [f for f in bad["rules"]["faces"] if f[1] != "!z-"]
    bad["rules_sha256"] = rules_hash(bad["rules"])
    ok, msg = check_certificate(bad)
    assert not ok and "not closed" in msg


@pytest.mark.skipif(ANCHORS is None, reason="no shared/anchors-data")
def test_anchor_rule_sets_get_a_verdict_or_a_reason():
    assert ANCHORS is not None
    files = sorted(p for p in ANCHORS.rglob("*") if p.suffix in (".json", ".xml"))
    assert files
    for f in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            M = load_model(str(f))
        why = proof_scope(M)
        if why is not None:  # one line naming what the proof does not cover
            assert "\n" not in why
            continue
        v = prove_infallible(M, max_states=200_000, refute=False, certificate=True)
        print(f"{f.name}: {v.message}")
        if v.holds is True:
            assert check_certificate(json.loads(json.dumps(v.witness["certificate"])))[0]


# ----------------------------------------------------------------------------- face rules


@st.composite
def rule_sets_with_faces(draw):
    """Random 2D rule sets (2-3 labels) with 1-3 domain rules on faces, the whole grid or
    every cell but a face, as POMS and DeBroglie files state them."""
    K = draw(st.integers(2, 3))
    T = np.array(draw(st.lists(st.booleans(), min_size=2 * K * K, max_size=2 * K * K)))
    T = T.reshape(2, K, K)
    ops = []
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["keep", "remove", "force", "add"]))
        labels = np.array(draw(st.lists(st.booleans(), min_size=K, max_size=K)))
        where = draw(st.sampled_from(["x-", "x+", "y-", "y+", "*", "!y-"]))
        if where == "*":
            ops.append(DomainOp(op, labels))
        elif where == "!y-":
            ops.append(DomainOp(op, labels, region=[(None, None), (1, None)]))
        else:
            ops.append(DomainOp(op, labels, face=where, kind="boundary"))
    return RuleSet(T, boundary_ops=ops)


@settings(max_examples=60, deadline=None)
@given(rule_sets_with_faces(), st.sampled_from(["scanline", "scan:yx"]))
def test_face_rule_proofs_are_sound_against_exhaustive_runs(rs, order):
    from csplab.analysis import alg31_exhaustive

    assert proof_scope(rs) is None
    v = prove_infallible(rs, 2, order=order, refute=False, max_states=20_000, certificate=True)
    if v.holds is not True:
        return
    for shape in [(1, 3), (3, 1), (2, 2), (2, 3), (3, 2), (3, 3), (4, 3), (3, 4)]:
        ex = alg31_exhaustive(rs.problem(shape), order, max_states=20_000)
        assert ex.holds is not False, (shape, ex.witness)
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert check_certificate(cert)[0]
    bad = copy.deepcopy(cert)  # the face rules are part of the hashed rules
    bad["rules"]["faces"] = bad["rules"]["faces"][:-1]
    assert not check_certificate(bad)[0]


@settings(max_examples=40, deadline=None)
@given(rule_sets_with_faces())
def test_face_rule_refutations_check(rs):
    v = prove_infallible(rs, 2, realize=False, certificate=True, max_states=20_000)
    if v.holds is False:
        cert = json.loads(json.dumps(v.witness["certificate"]))
        ok, msg = check_certificate(cert)
        assert ok, msg
