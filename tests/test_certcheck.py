"""csplab.certcheck, the independent checker of ``prove``'s certificates (issue 26).

The checker must accept what the prover proves, on a 2D example, a 3D built-in and a
tileset, and reject planted defects: a state removed, a transition altered (with or
without a new hash), a configuration or a recorded key dropped, a failing run altered.
Check and prove times are printed (not asserted).
"""

from __future__ import annotations

import copy
import itertools
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
def test_planted_defects_rejected(spec, region, order, monkeypatch):
    cert = _cert(spec, region, order)
    for what, bad in _defects(cert).items():
        for path in ("one state at a time", "polynomial codes"):
            with monkeypatch.context() as m:
                _use_path(m, path)
                ok, msg = check_certificate(bad)
            assert not ok, (what, path)
            assert msg.startswith("invalid:"), (what, path, msg)


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


# ----------------------------------------------------------------------------- one defect per check
#
# Each planted defect below can be seen by one part of the checker only; the message says
# which. The prover's state set is the least closed one (every state is reached from the
# start), so removing any state must leave a state whose successor is missing.


@pytest.fixture(scope="module")
def small_cert():
    """fig3_15 with 2x2 regions, scan:yx: 9 configurations, ~400 states, 10 labels."""
    return _cert("fig3_15", "2x2", "scan:yx")


@pytest.fixture(scope="module")
def face_cert():
    """fig3_4a with its ground and empty space (face rules), 2x4 regions."""
    v = prove_infallible(load_model("fig3_4a"), "2x4", boundary="auto", refute=False,
                         certificate=True)  # fmt: skip
    return json.loads(json.dumps(v.witness["certificate"]))


@pytest.fixture(scope="module")
def class_cert():
    """fig3_15 with 2x2 regions, scan:yx, labels recorded by class (as decide proves)."""
    v = prove_infallible(load_model("fig3_15"), "2x2", order="scan:yx", refute=False,
                         classes=True, certificate=True)  # fmt: skip
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert cert.get("label_classes") and check_certificate(cert)[0]
    return cert


@pytest.fixture(scope="module")
def dead_cert():
    """fig3_15 with its ground and empty space: label classes and dead labels by place."""
    v = prove_infallible(load_model("fig3_15"), "2x2", order="scan:yx", boundary="auto",
                         refute=False, classes=True, certificate=True)  # fmt: skip
    cert = json.loads(json.dumps(v.witness["certificate"]))
    assert cert.get("dead") and check_certificate(cert)[0]
    return cert


CHECKER_PATHS = ["one state at a time", "polynomial codes", "ranked codes", "one frame per chunk"]


def _use_path(monkeypatch, path: str) -> None:
    """Make the checker take ``path``: small certificates one state at a time (the
    default below _LEAN_STATES), or the array check (polynomial or ranked state codes,
    frames verified together or one at a time)."""
    import csplab.certcheck as cc

    if path != "one state at a time":
        monkeypatch.setattr(cc, "_LEAN_STATES", -1)
    if path == "ranked codes":
        monkeypatch.setattr(cc, "_CODE_LIMIT", 0)
    elif path == "one frame per chunk":
        monkeypatch.setattr(cc, "_FRAME_CHUNK", 1)


@pytest.fixture(params=CHECKER_PATHS)
def checker_path(request, monkeypatch):
    """The checker's alternative paths (:func:`_use_path`)."""
    _use_path(monkeypatch, request.param)
    return request.param


def _without_state(cert: dict, k: int) -> tuple[dict, list]:
    """``cert`` without its ``k``-th state (over all configurations, start states skipped)."""
    bad = copy.deepcopy(cert)
    for conf in bad["configs"]:
        rest = [s for s in conf["states"] if s[0] != 0]
        if k < len(rest):
            gone = rest[k]
            conf["states"] = [s for s in conf["states"] if s is not gone]
            return bad, gone
        k -= len(rest)
    raise IndexError(k)


@pytest.mark.parametrize("which", ["small_cert", "face_cert", "class_cert", "dead_cert"])
def test_removing_any_state_breaks_the_closure(which, checker_path, request):
    cert = request.getfixturevalue(which)
    assert check_certificate(cert)[0]
    total = sum(len(c["states"]) - 1 for c in cert["configs"])
    rng = np.random.default_rng(26)
    for k in sorted(rng.choice(total, size=min(total, 60), replace=False).tolist()):
        bad, gone = _without_state(cert, k)
        ok, msg = check_certificate(bad)
        assert not ok and "not closed" in msg, (gone, msg)
        assert f"leads to {gone}" in msg or "which is missing" in msg


@pytest.mark.parametrize("which", ["small_cert", "class_cert"])
def test_a_state_with_a_wrong_label_is_rejected(which, checker_path, request):
    bad = copy.deepcopy(request.getfixturevalue(which))
    K = bad["rules"]["labels"]

    def other() -> tuple[list, int, int]:  # a state changed into one the set lacks
        for conf in bad["configs"]:
            have = {(s[0], tuple(s[1])) for s in conf["states"]}
            for k, (step, labs) in enumerate(conf["states"]):
                for b in range(K):
                    if labs and (step, (b, *labs[1:])) not in have:
                        return conf["states"], k, b
        raise AssertionError("every variant is present")

    states, k, b = other()
    states[k] = [states[k][0], [b, *states[k][1][1:]]]
    ok, msg = check_certificate(bad)
    assert not ok and "not closed" in msg, msg


def test_no_start_state(small_cert, checker_path):
    bad = copy.deepcopy(small_cert)
    bad["configs"][3]["states"] = [s for s in bad["configs"][3]["states"] if s[0] != 0]
    ok, msg = check_certificate(bad)
    assert not ok and "no start state" in msg, msg


@pytest.mark.parametrize("which", ["small_cert", "class_cert"])
def test_a_point_with_an_empty_catalog(which, checker_path, request):
    # the catalog of every point of some state is empty once a label loses its successors
    # (with label classes, a point whose region has no other open cell is checked without
    # arc consistency: this must still see it)
    bad = copy.deepcopy(request.getfixturevalue(which))
    a0 = bad["rules"]["pairs"][0][0][0]
    bad["rules"]["pairs"][0] = [p for p in bad["rules"]["pairs"][0] if p[0] != a0]
    bad["rules_sha256"] = rules_hash(bad["rules"])
    ok, msg = check_certificate(bad)
    assert not ok and "the point's catalog is empty" in msg, msg


def _conf_with_keys(cert: dict) -> tuple[dict, int]:
    """A copy of ``cert`` and the index of a configuration with at least 4 steps."""
    bad = copy.deepcopy(cert)
    return bad, next(k for k, c in enumerate(bad["configs"]) if len(c["keys"]) >= 4)


def test_keys_defects(small_cert, checker_path):
    def rejected(bad: dict, what: str) -> None:
        ok, msg = check_certificate(bad)
        assert not ok and what in msg, (what, msg)

    bad, c = _conf_with_keys(small_cert)
    bad["configs"][c]["keys"] = bad["configs"][c]["keys"][:-1]
    rejected(bad, "keys must list")
    bad, c = _conf_with_keys(small_cert)
    bad["configs"][c]["keys"][0] = [0]
    rejected(bad, "keys must list")
    bad, c = _conf_with_keys(small_cert)
    keys = bad["configs"][c]["keys"]
    i = next(i for i, k in enumerate(keys) if len(k) >= 2)
    keys[i] = keys[i][::-1]
    rejected(bad, f"keys[{i}] must be sorted earlier steps")
    bad, c = _conf_with_keys(small_cert)
    keys = bad["configs"][c]["keys"]
    keys[1] = [1]  # step 1 recording itself
    rejected(bad, "keys[1] must be sorted earlier steps")
    # a label recorded again after a step forgot it
    bad, c = _conf_with_keys(small_cert)
    keys = bad["configs"][c]["keys"]
    i = next(i for i in range(1, len(keys) - 1) if set(keys[i + 1]) - {i})
    j = sorted(set(keys[i + 1]) - {i})[0]
    keys[i] = [t for t in keys[i] if t != j]
    rejected(bad, f"keys[{i + 1}] records a label step {i} forgot")
    # a label a step's own region needs, not recorded (nor later)
    bad, c = _conf_with_keys(small_cert)
    keys = bad["configs"][c]["keys"]
    n = len(keys)
    i = next(i for i in range(n) if set(keys[i]) - set(keys[i + 1] if i + 1 < n else []))
    j = sorted(set(keys[i]) - set(keys[i + 1] if i + 1 < n else []))[0]
    keys[i] = [t for t in keys[i] if t != j]
    rejected(bad, f"step {i} depends on cell")


def test_state_shape_defects(small_cert, checker_path):
    def rejected(change, what: str) -> None:
        bad = copy.deepcopy(small_cert)
        conf = max(bad["configs"], key=lambda c: len(c["states"]))
        k = next(i for i, s in enumerate(conf["states"]) if len(s[1]) >= 2)
        change(bad, conf, k)
        ok, msg = check_certificate(bad)
        assert not ok and what in msg, (what, msg)

    def step_out(bad, conf, k):
        conf["states"][k][0] = len(conf["keys"])

    def negative_step(bad, conf, k):
        conf["states"][k][0] = -1

    def short(bad, conf, k):
        conf["states"][k][1] = conf["states"][k][1][1:]

    def out_of_range(bad, conf, k):
        conf["states"][k][1][0] = bad["rules"]["labels"]

    def not_in_use(bad, conf, k):
        b = conf["states"][k][1][0]
        bad["rules"]["used"][b] = 0
        bad["rules_sha256"] = rules_hash(bad["rules"])

    def fractional(bad, conf, k):
        conf["states"][k][1][0] += 0.5

    def triple(bad, conf, k):
        conf["states"][k].append(0)

    rejected(step_out, "is not one of its")
    rejected(negative_step, "is not one of its")
    rejected(short, "does not fit keys")
    rejected(out_of_range, "has a label not in use")
    rejected(not_in_use, "has a label not in use")
    rejected(fractional, "not integers")
    rejected(triple, "not a pair")


@pytest.mark.parametrize("dtype", [np.int8, np.int64])
@pytest.mark.parametrize("which", ["small_cert", "class_cert"])
def test_numpy_labels_read_as_their_values(which, checker_path, dtype, request):
    # a certificate built in memory may hold numpy integers: the last configuration's labels
    # as numpy, the earlier ones' the same values as Python ints (a set of the labels keeps
    # the first of 7 and np.int8(7), so the types are read from the labels themselves);
    # int8 shifts would overflow
    good = request.getfixturevalue(which)
    cert = copy.deepcopy(good)
    for s in cert["configs"][-1]["states"]:
        s[1] = [dtype(x) for x in s[1]]
    assert check_certificate(cert) == check_certificate(good)


def test_configuration_defects(small_cert, checker_path):
    bad = copy.deepcopy(small_cert)
    bad["configs"].append(copy.deepcopy(bad["configs"][0]))
    ok, msg = check_certificate(bad)
    assert not ok and "positions of a point" in msg, msg
    bad = copy.deepcopy(small_cert)
    bad["configs"][0]["lower"] = [9, 9]
    ok, msg = check_certificate(bad)
    assert not ok and "positions of a point" in msg, msg


def test_configurations_without_face_flags(small_cert, checker_path):
    # without at_lower / at_upper (no face rules), a frame edge is on the face exactly
    # where the region is clipped there; a flag that says otherwise is a wrong position
    bare = copy.deepcopy(small_cert)
    for conf in bare["configs"]:
        conf.pop("at_lower", None)
        conf.pop("at_upper", None)
    ok, msg = check_certificate(bare)
    assert ok, msg
    bad = copy.deepcopy(small_cert)
    conf = next(c for c in bad["configs"] if not all(c["at_lower"]))
    conf["at_lower"] = [True] * len(conf["lower"])  # an edge the region reaches past
    ok, msg = check_certificate(bad)
    assert not ok and "positions of a point" in msg, msg


def test_dead_labels_in_use_at_some_places(dead_cert, checker_path):
    # one place's dead labels left out: those labels are in use again (dead everywhere
    # else), so the cells that may lie elsewhere lose them from their domains -- which the
    # states need (a check that ignored dead labels in use rejects this certificate)
    cert = copy.deepcopy(dead_cert)
    del cert["dead"]["stages"][0][1][0]
    ok, msg = check_certificate(cert)
    assert ok, msg


def test_dead_stage_places_checked(dead_cert, checker_path):
    # a stage's place must lie off its face and within the cap -- also for an entry whose
    # labels an earlier entry already had
    face, got = dead_cert["dead"]["stages"][0]
    d, side = "xyzw".index(face[0]), "-+".index(face[1])
    k = next(k for k in range(1, len(got)) if got[k][1] == got[0][1])
    for value in (0, dead_cert["dead"]["cap"] + 1):
        bad = copy.deepcopy(dead_cert)
        bad["dead"]["stages"][0][1][k][0][d][side] = value
        ok, msg = check_certificate(bad)
        assert not ok and "is not a place off" in msg, (value, msg)


@pytest.fixture(scope="module")
def poms_cert():
    """tiny_poms as decide proves it: 2x2x2 regions, no history, labels by class, face
    rules; 1,200 states in 216 configurations (checked one state at a time)."""
    v = prove_infallible(load_model(str(DATA / "tiny_poms.json")), "2", history=0,
                         classes=True, refute=False, certificate=True)  # fmt: skip
    return json.loads(json.dumps(v.witness["certificate"]))


def test_face_domains_of_the_cells(poms_cert, checker_path):
    # tiny_poms' frames' cells on a face have that face's domain, which the states need
    # (a check that gave every cell all labels in use rejects it); with the rule that
    # removes label 1 above the ground dropped, the states no longer close
    cert = poms_cert
    ok, msg = check_certificate(cert)
    assert ok, msg
    bad = copy.deepcopy(cert)
    bad["rules"]["faces"] = [f for f in bad["rules"]["faces"] if f[1] != "!z-"]
    bad["rules_sha256"] = rules_hash(bad["rules"])
    ok, msg = check_certificate(bad)
    assert not ok and "not closed" in msg, msg


def test_each_configuration_checked_with_its_own_domains(poms_cert, checker_path):
    # two configurations of one frame differ in which of its edges lie on a face, so in
    # their cells' domains: the states of one, given to a later one, are checked with the
    # later one's domains (one of them, at least, must then fail)
    groups: dict[tuple, list[int]] = {}
    for k, c in enumerate(poms_cert["configs"]):
        groups.setdefault((str(c["lower"]), str(c["upper"]), str(c["keys"])), []).append(k)
    for members in groups.values():
        for a, b in itertools.combinations(members, 2):
            states = poms_cert["configs"][a]["states"]
            if states == poms_cert["configs"][b]["states"]:
                continue
            bad = copy.deepcopy(poms_cert)
            bad["configs"][b]["states"] = copy.deepcopy(states)
            ok, msg = check_certificate(bad)
            if not ok:
                assert msg.startswith("invalid: configuration"), msg
                return
    raise AssertionError("every configuration takes the states of every other of its frame")


def test_a_certificate_too_large_to_hold_is_refused(small_cert, monkeypatch):
    import csplab.certcheck as cc
    from csplab.errors import MemoryLimitError

    monkeypatch.setattr(cc, "_MAX_BYTES", 1000)
    monkeypatch.setattr(cc, "_LEAN_STATES", -1)  # one state at a time needs no arrays
    with pytest.raises(MemoryLimitError, match="GB"):
        check_certificate(small_cert)


@pytest.mark.parametrize(("region", "order", "back", "history"),
                         [("4x2", "scan:yx", 1, 1), ("3x3", "scanline", (1, 2), 0)])  # fmt: skip
def test_both_paths_agree_on_every_rule_removed(region, order, back, history, monkeypatch):
    # fig3_16 with 4x2 regions (scan:yx) or 3x3 regions reaching back 1x2 and no history
    # (scanline, as decide proves it): points with cells after them in their region, where
    # the catalog needs arc consistency (the latter has rules whose removal only the
    # point's arc consistency sees); each pair of the rules removed in turn (the hash
    # updated), the one-state-at-a-time check and the array check give the same verdict
    v = prove_infallible(load_model("fig3_16"), region, order=order, back=back, history=history,
                         refute=False, classes=True, certificate=True)  # fmt: skip
    cert = json.loads(json.dumps(v.witness["certificate"]))
    verdicts = []
    for d, pairs in enumerate(cert["rules"]["pairs"]):
        for k in range(len(pairs)):
            bad = copy.deepcopy(cert)
            del bad["rules"]["pairs"][d][k]
            bad["rules_sha256"] = rules_hash(bad["rules"])
            got = []
            for path in ("one state at a time", "polynomial codes"):
                with monkeypatch.context() as m:
                    _use_path(m, path)
                    got.append(check_certificate(bad))
            assert got[0][0] == got[1][0], (d, pairs[k], got)
            verdicts.append(got[0][0])
    assert False in verdicts and True in verdicts  # both kinds occur
