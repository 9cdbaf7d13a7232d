"""The baselines experiment (thesis Fig. 5.1/5.2): model synthesis breaks no arc, the
texture methods are measured by the same checker, the figure is written."""

import numpy as np
import pytest

from csplab.experiments import run
from csplab.experiments.measures import pattern_distance

pytest.importorskip("maxflow")


def test_quick_table(tmp_path):
    s, rep = run("baselines", quick=True, store=tmp_path / "r.sqlite", out=tmp_path, jobs=1,
                 progress=False)  # fmt: skip
    assert not s.errors and s.ran == 2 * 3
    rows = {(r["example"], r["method"]): r for r in rep.tables["methods"]}
    for ex in ("loops", "castle"):
        assert rows[(ex, "model-synthesis")]["broken arcs (median)"] == 0
        assert 0 <= rows[(ex, "texture:efros-leung")]["pattern TV (median)"] <= 1
    assert rows[("loops", "model-synthesis")]["dead ends (median)"] == 0
    assert rows[("castle", "model-synthesis")]["dead ends (median)"] == "–"
    assert (tmp_path / "baselines.png").exists()


def test_pattern_distance_bounds():
    e = np.array([[0, 1, 0], [1, 0, 1]])
    assert pattern_distance(e, e) == 0.0
    assert pattern_distance(np.zeros((3, 3), dtype=int), np.ones((3, 3), dtype=int)) == 1.0
