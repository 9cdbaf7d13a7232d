"""Drawing an experiment's figures leaves matplotlib's global state as it was."""

import sys

import matplotlib
import pytest

from csplab.experiments import run


def _snapshot():
    return {k: repr(v) for k, v in matplotlib.rcParams.items() if k != "backend"}


@pytest.fixture
def other_backend():
    """Switch to a non-Agg backend for the test, restore the previous one afterwards."""
    before = matplotlib.get_backend()
    matplotlib.use("svg")
    try:
        yield "svg"
    finally:
        matplotlib.use(before)


def _open_pyplot_figures():
    plt = sys.modules.get("matplotlib.pyplot")
    return plt.get_fignums() if plt is not None else []


@pytest.mark.parametrize(
    "name,kw",
    [
        ("fig3_8", {"examples": ["line"], "seeds": 2}),
        ("blocksize", {}),  # two figures: the plot and the montage of outputs
    ],
)
def test_plots_leave_backend_rcparams_and_pyplot_alone(tmp_path, other_backend, name, kw):
    rc = _snapshot()
    figs = _open_pyplot_figures()
    s, rep = run(name, quick=True, store=tmp_path / "r.sqlite", out=tmp_path, jobs=1,
                 progress=False, **kw)  # fmt: skip
    assert not s.errors
    pngs = [f for f in rep.figures if f.suffix == ".png"]
    assert pngs and all(f.read_bytes()[:4] == b"\x89PNG" for f in pngs)
    assert matplotlib.get_backend() == other_backend
    changed = {k for k, v in _snapshot().items() if rc.get(k) != v}
    assert not changed, f"rcParams changed: {sorted(changed)}"
    assert _open_pyplot_figures() == figs


def test_svg_is_reproducible(tmp_path):
    kw = {"examples": ["line"], "seeds": 2, "store": tmp_path / "r.sqlite", "jobs": 1,
          "progress": False, "quick": True}  # fmt: skip
    run("fig3_8", out=tmp_path / "a", **kw)
    run("fig3_8", out=tmp_path / "b", **kw)  # report only: the trials are stored
    for ext in ("svg", "png"):
        a = (tmp_path / "a" / f"fig3_8.{ext}").read_bytes()
        assert a == (tmp_path / "b" / f"fig3_8.{ext}").read_bytes()
