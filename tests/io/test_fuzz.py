"""Loaders only ever raise CsplabError on damaged files, and never hang."""

import warnings

import pytest
from hypothesis import HealthCheck, given, settings

from csplab.errors import CsplabError
from csplab.io import read_model
from csplab.testing.strategies import corrupted, tile_rule_sets

from ._helpers import ANCHORS, DATA

SMALL = {
    "wfc.xml": (DATA / "pipes.xml").read_bytes(),
    "mj.xml": (DATA / "pipes3d.xml").read_bytes(),
    "poms.json": (DATA / "tiny_poms.json").read_bytes(),
    "debroglie.json": (DATA / "tiny_debroglie.json").read_bytes(),
    "sample.png": (DATA / "sample.png").read_bytes(),
    "model.vox": (DATA / "pipes3d" / "Turn.vox").read_bytes(),
}
if (ANCHORS / "MarkovJunior" / "Knots3D.xml").is_file():
    SMALL["knots.xml"] = (ANCHORS / "MarkovJunior" / "Knots3D.xml").read_bytes()
    SMALL["edged.json"] = (ANCHORS / "DeBroglie" / "edged_path_constraint.json").read_bytes()


def load(tmp_path, name, data):
    p = tmp_path / name
    p.write_bytes(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            m = read_model(p)
        except CsplabError:
            return None
    # whatever loads must also build a small problem or fail cleanly
    try:
        shape = (3,) * m.ndim
        m.problem(shape) if hasattr(m, "problem") else None
    except CsplabError:
        pass
    return m


@pytest.mark.parametrize("name", sorted(SMALL))
@settings(deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=__import__("hypothesis").strategies.data())
def test_corrupted_files_raise_only_csplab_errors(tmp_path, name, data):
    bad = data.draw(corrupted(SMALL[name]))
    load(tmp_path, name, bad)


@settings(
    max_examples=40, deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(xml=tile_rule_sets())
def test_random_wfc_tilesets_are_closed_and_solvable_or_fail_cleanly(tmp_path, xml):
    import csplab

    p = tmp_path / "r.xml"
    p.write_text(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rs = read_model(p)
    assert rs.closure_violations() == []
    r = csplab.solve(rs.problem((4, 3)), "catalog", rng=0)
    assert r.status in ("solved", "failed", "unsat")
