"""User-defined constraints of continuous model synthesis in 3D (thesis Sec. 4.6):
dimensional and large-scale constraints restrict the CSP (every solver honours them),
connectivity is the grid solvers' Connected constraint on the CSP's problem (exact with sat,
cpsat and asp, propagated by catalog); the checker (user_violations3) catches each planted
breach."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from csplab.continuous.check3d import user_violations3
from csplab.continuous.synthesis import synthesize
from csplab.continuous.user3d import parse_user_constraints, read_user_constraints
from csplab.errors import FormatError, InputError
from tests._meshes import box as _box

polyhedra = pytest.importorskip("csplab.continuous.polyhedra")
pytest.importorskip("trimesh")
pytest.importorskip("pysat")


E = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 2])], name="box")
ORIGIN = [0.0, 0.0, 0.0]


def _c(*items: dict[str, object]) -> object:
    return parse_user_constraints({"constraints": list(items)}, source="c.json")


@pytest.mark.parametrize("solver", ["catalog", "sat", "blocks"])
def test_dimensional_objects_are_one_spacing_thick(solver: str) -> None:
    c = _c({"type": "dimensional", "labels": [1], "normals": ["z"]})
    s = synthesize(E, (6, 6, 4), solver=solver, rng=3, restarts=5, constraints=c)
    assert s.ok and s.model is not None and len(s.violations) == 0
    assert s.model.solids, "an empty output would say nothing"
    for sol in s.model.solids:  # spacing 2 (the box's side): every solid 2 high
        z = sol.vertices[:, 2]
        assert z.max() - z.min() == pytest.approx(2.0)


def test_dimensional_breach_is_found() -> None:
    c = _c({"type": "dimensional", "labels": [1], "normals": ["z"]})
    tall = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 4])])
    d = user_violations3(tall, c, origin=ORIGIN, spacing=2.0)
    assert [x.kind for x in d] == ["dimensional"] and "spans 2" in d[0].detail
    assert not user_violations3(E, c, origin=ORIGIN, spacing=2.0)


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_large_scale_keeps_labels_in_their_voxels(solver: str) -> None:
    c = _c({"type": "large-scale", "voxel": [3, 3, 4], "allowed": {"1": [[0, 0, 0], [1, 1, 0]]}})
    s = synthesize(E, (6, 6, 4), solver=solver, rng=1, restarts=5, constraints=c)
    assert s.ok and s.model is not None and len(s.violations) == 0
    for sol in s.model.solids:  # voxels of 3 spacings = 6 units: [0, 6) or [6, 12) squared
        lo, hi = sol.vertices.min(axis=0), sol.vertices.max(axis=0)
        assert (hi[:2] <= 6 + 1e-9).all() or (lo[:2] >= 6 - 1e-9).all()
    planted = polyhedra.PolyhedralModel([_box(1, [6, 0, 0], [8, 2, 2])])
    d = user_violations3(planted, c, origin=ORIGIN, spacing=2.0)
    assert [x.kind for x in d] == ["large-scale"]


@pytest.mark.parametrize("solver", ["sat", "asp"])  # cpsat: exact too, minutes here
def test_connected_exact_with_sat_and_the_breach_is_found(solver: str) -> None:
    pytest.importorskip({"sat": "pysat", "asp": "clingo"}[solver])
    c = _c({"type": "connected", "labels": [1]})
    s = synthesize(E, (6, 6, 3), solver=solver, rng=2, constraints=c)
    assert s.result.status == "solved" and s.model is not None and len(s.violations) == 0
    (con,) = s.csp.problem.constraints  # one global constraint, seen by the solver
    assert con.kind == "connected" and con.check(s.csp.problem, s.result.grid) is None
    two = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 2]), _box(1, [4, 4, 0], [6, 6, 2])])
    d = user_violations3(two, c, origin=ORIGIN, spacing=2.0)
    assert [x.kind for x in d] == ["connected"] and "2 separate groups" in d[0].detail
    touching = polyhedra.PolyhedralModel([_box(1, [0, 0, 0], [2, 2, 2]),
                                          _box(1, [2, 2, 0], [4, 4, 2])])  # fmt: skip
    assert not user_violations3(touching, c, origin=ORIGIN, spacing=2.0)
    none = user_violations3(polyhedra.PolyhedralModel([]), c, origin=ORIGIN, spacing=2.0)
    assert [x.kind for x in none] == ["connected"] and "0 separate groups" in none[0].detail
    labels = [x.label for x in s.model.solids]
    assert labels.count(1) == 1  # exactly one group of label 1


@pytest.mark.parametrize("solver", ["catalog", "blocks"])
def test_incomplete_solvers_never_report_solved_with_a_broken_constraint(solver: str) -> None:
    c = _c({"type": "connected", "labels": [1]})
    for seed in range(3):
        s = synthesize(E, (8, 8, 3), solver=solver, rng=seed, restarts=2, constraints=c)
        broken = user_violations3(s.model, c, origin=ORIGIN, spacing=2.0) if s.model else []
        assert (s.result.status == "solved") == (s.model is not None and not broken)
        if broken:
            assert s.result.status == "failed" and "connected" in s.result.stats["broken"]


@pytest.mark.parametrize(
    ("entry", "msg"),
    [
        ({"type": "count", "labels": [1]}, "does not apply to polyhedral models"),
        ({"type": "dimensional", "labels": [0]}, "not an object label"),
        ({"type": "dimensional", "labels": [1], "normals": [[0, 0, 0]]}, "normal"),
        ({"type": "large-scale", "voxel": 0, "allowed": {"1": []}}, "voxel"),
        ({"type": "connected"}, "labels"),
    ],
)
def test_bad_entries_are_one_line(entry: dict[str, object], msg: str) -> None:
    with pytest.raises(InputError, match=rf"c\.json: constraint 0: .*{msg}"):
        _c(entry)


def test_unknown_normal_and_label_name_the_file(tmp_path: Path) -> None:
    f = tmp_path / "c.json"
    f.write_text(json.dumps({"constraints": [{"type": "dimensional", "labels": [1],
                                              "normals": [[1, 1, 0]]}]}))  # fmt: skip
    with pytest.raises(InputError, match="not a plane family"):
        synthesize(E, (4, 4, 2), constraints=read_user_constraints(f))
    f.write_text("{")
    with pytest.raises(FormatError, match=r"c\.json, line 1: not valid JSON"):
        read_user_constraints(f)


def test_cli_synthesize_and_check_with_constraints(tmp_path: Path) -> None:
    f = tmp_path / "c.json"
    f.write_text(json.dumps({"constraints": [{"type": "dimensional", "labels": [1],
                                              "normals": ["z"]}]}))  # fmt: skip
    out = tmp_path / "out.obj"
    cmd = [sys.executable, "-m", "csplab", "synthesize", "houses", "--size", "8x8x6",
           "--seed", "1", "--constraints", str(f), "--out", str(out)]  # fmt: skip
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    assert "constraints=dimensional 1:[0, 0, 1]" in r.stdout
    chk = [sys.executable, "-m", "csplab", "check", "houses", str(out), "--constraints", str(f)]
    r = subprocess.run(chk, capture_output=True, text=True, check=False)
    assert r.returncode == 0 and r.stdout.startswith("0 violations"), r.stdout + r.stderr


def test_connected_on_the_csp_agrees_with_the_solids() -> None:
    """The CSP's Connected (variables touching label 1, joined by the arcs) holds exactly
    when the output's label-1 solids form one group (the independent check)."""
    c = _c({"type": "connected", "labels": [1]})
    seen = set()
    for seed in range(8):
        s = synthesize(E, (3, 3, 2), solver="catalog", rng=seed)
        if s.model is None:
            continue
        (con,) = s.csp.connected([1])
        on_csp = con.check(s.csp.problem, s.result.grid) is None
        on_solids = not user_violations3(s.model, c, origin=ORIGIN, spacing=2.0)
        assert on_csp == on_solids, seed
        seen.add(on_csp)
    assert seen == {True, False}, "both outcomes should occur over these seeds"
