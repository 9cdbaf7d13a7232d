"""A fuzz suite over the command line (issue 30): generated bad model files, constraints
files and option values, through ``csplab.cli.main``.

Every run must end in exit 0, 1 or 2; an exit 2 is exactly one line ``csplab: error: ...``
on stderr and no traceback; inputs built to be bad must exit 2; peak Python allocations
(tracemalloc, which numpy reports to) stay under :data:`PEAK_BYTES`. The default suite runs
a bounded number of examples per test (about a minute in all); ``-m slow`` runs many more.
"""

from __future__ import annotations

import contextlib
import io
import json
import tempfile
import tracemalloc
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from csplab.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "csplab" / "examples"
TETRA = (EXAMPLES / "continuous3d" / "tetrahedron.obj").read_text()
PEAK_BYTES = 400e6
FAST = settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
SLOW = settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))


def cli(argv, *, bad: bool):
    """Run ``csplab ARGV``; check the error contract; return (code, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    tracemalloc.start()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main([str(a) for a in argv])
            except SystemExit as e:  # argparse's own errors
                code = e.code
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    text = err.getvalue()
    assert "Traceback" not in text, (argv, text)
    assert code in (0, 1, 2), (argv, code, text)
    if code == 2:
        lines = [ln for ln in text.splitlines() if ln.startswith("csplab: error:")]
        others = [  # warnings and progress notices ("csplab: reading X ...") may come first
            ln for ln in text.splitlines()
            if not ln.startswith("csplab: warning:") and not ln.endswith(" ...")
        ]  # fmt: skip
        assert len(lines) == 1 and len(others) == 1, (argv, text)
    if bad:
        assert code == 2, (argv, code, out.getvalue(), text)
    assert peak < PEAK_BYTES, (argv, peak)
    return code, text


# ----------------------------------------------------------------- strategies
HUGE = st.one_of(st.integers(65536, 10**40), st.integers(-(10**40), 0))
NONFINITE = st.sampled_from(["NaN", "Infinity", "-Infinity", "1e400", "-1e400"])
JUNK_LABEL = st.one_of(
    HUGE.map(str), NONFINITE, st.sampled_from(['"one"', "true", "null", "[1]", "{}", "1.5"])
)


@st.composite
def bad_polygon_files(draw):
    """A polygon JSON with one bad thing: a label, a coordinate, or the nesting."""
    kind = draw(st.sampled_from(["label", "point", "deep", "points"]))
    label, pt, pts = "1", "4", "[[0, 0], [4, 0], [4, PT]]"
    if kind == "label":
        label = draw(JUNK_LABEL)
    elif kind == "point":
        pt = draw(st.one_of(NONFINITE, st.sampled_from(['"x"', "null", "[]"])))
    elif kind == "points":
        pts = draw(st.sampled_from(["[]", "[[0, 0]]", '"abc"', "[[0, 0], [1]]", "7"]))
    points = pts.replace("PT", pt)
    text = '{"polygons": [{"label": ' + label + ', "points": ' + points + "}]}"
    if kind == "deep":
        n = draw(st.integers(2000, 60000))
        text = '{"polygons": ' + "[" * n + "]" * n + "}"
    return text


@st.composite
def bad_obj_files(draw):
    """The tetrahedron OBJ with one bad thing: a material label, a vertex, a face."""
    kind = draw(st.sampled_from(["label", "vertex", "face"]))
    if kind == "label":
        n = draw(st.integers(65536, 10**30))
        return TETRA.replace("usemtl label_1", f"usemtl label_{n}")
    lines = TETRA.splitlines()
    if kind == "vertex":
        i = next(k for k, ln in enumerate(lines) if ln.startswith("v "))
        lines[i] = "v " + " ".join(draw(st.lists(NONFINITE.map(str.lower), min_size=3, max_size=3)))
    else:
        i = next(k for k, ln in enumerate(lines) if ln.startswith("f "))
        lines[i] = "f " + " ".join(str(draw(st.integers(-(10**9), 10**9))) for _ in range(3))
    return "\n".join(lines) + "\n"


@st.composite
def bad_constraints_files(draw, labels_3d=False):
    kind = draw(st.sampled_from(["deep", "nan", "type", "label", "shape"]))
    if kind == "deep":
        n = draw(st.integers(2000, 60000))
        return '{"constraints": ' + "[" * n + "]" * n + "}"
    if kind == "nan":
        value = draw(NONFINITE)
        return '{"constraints": [{"type": "count", "labels": [1], "min": ' + value + "}]}"
    if kind == "type":
        t = draw(st.text(st.characters(codec="ascii", exclude_characters='"\\'), max_size=8))
        return json.dumps({"constraints": [{"type": "x" + t, "labels": [1]}]})
    if kind == "label":
        lab = draw(st.integers(100, 10**30))
        return json.dumps({"constraints": [{"type": "connected", "labels": [lab]}]})
    return draw(st.sampled_from(['{"constraints": 5}', "[1, 2]", '{"constraints": [7]}', "{"]))


SIZE_BAD = st.one_of(
    st.sampled_from(["-5x5", "0x4", "x", "5x", "5xx5", "abc", "", "1e3x4", "5x5x5x5x5", "nan"]),
    st.tuples(st.integers(10**5, 10**9), st.integers(10**5, 10**9)).map(lambda t: f"{t[0]}x{t[1]}"),
)
FLOAT_BAD = st.sampled_from(["nan", "inf", "-1", "0", "abc", "-inf", "1e-320", ""])


def _write(d: Path, name: str, text: str) -> Path:
    p = d / name
    p.write_text(text)
    return p


# --------------------------------------------------------------------- tests
def _models(d, data):
    kind = data.draw(st.sampled_from(["json", "obj"]))
    if kind == "json":
        return _write(d, "m.json", data.draw(bad_polygon_files())), "6x6"
    return _write(d, "m.obj", data.draw(bad_obj_files())), "3x3x3"


def _run_bad_models(data):
    with tempfile.TemporaryDirectory() as t:
        d = Path(t)
        model, size = _models(d, data)
        command = data.draw(st.sampled_from(["synthesize", "show", "check"]))
        out = d / data.draw(st.sampled_from(["r.svg", "r.png", "r.json", "r.obj"]))
        argv = {
            "synthesize": ["synthesize", model, "--size", size, "--out", out],
            "show": ["show", model, "--out", d / "s.png"],
            "check": ["check", model, model],
        }[command]
        cli(argv, bad=True)
        assert not out.exists()


def _run_bad_constraints(data):
    with tempfile.TemporaryDirectory() as t:
        d = Path(t)
        model, size = data.draw(
            st.sampled_from([("fig3_5a", "6x6"), ("castle", "6x6x4"), ("tetrahedron", "3x3x3")])
        )
        c = _write(d, "c.json", data.draw(bad_constraints_files()))
        out = d / ("r.obj" if model == "tetrahedron" else "r.npy")
        cli(["synthesize", model, "--size", size, "--constraints", c, "--out", out], bad=True)
        assert not out.exists()


def _run_bad_options(data):
    with tempfile.TemporaryDirectory() as t:
        d = Path(t)
        model = data.draw(st.sampled_from(["fig3_5a", "castle", "triangle", "tetrahedron"]))
        ok_size = {"fig3_5a": "6x6", "castle": "6x6x4", "triangle": "8x8",
                   "tetrahedron": "3x3x3"}[model]  # fmt: skip
        flag = data.draw(st.sampled_from(
            ["--size", "--spacing", "--seed", "--block", "--memory-limit", "--out", "--grid",
             "--boundary", "--time-limit", "--restarts"]))  # fmt: skip
        argv = ["synthesize", model, "--size", ok_size]
        continuous = model in ("triangle", "tetrahedron")
        if flag == "--size":
            argv[3] = data.draw(SIZE_BAD)
        elif flag == "--spacing":
            argv += ["--spacing", data.draw(FLOAT_BAD)]
        elif flag in ("--memory-limit", "--time-limit"):
            argv += [flag, data.draw(FLOAT_BAD)]
        elif flag == "--seed":
            argv += ["--seed", data.draw(st.sampled_from(["-1", "x", "1.5", "-99999999999"]))]
        elif flag == "--restarts":
            argv += ["--restarts", data.draw(st.sampled_from(["-1", "x", "1.5"]))]
        elif flag == "--block":
            argv += ["--solver", "blocks", "--block", data.draw(SIZE_BAD.filter(bool))]
        elif flag == "--out":
            (d / "dir.png").mkdir()
            (d / "r.mtl").mkdir()
            argv += ["--out", data.draw(st.sampled_from(
                [d / "no" / "r.npy", d / "r.xyz", d / "dir.png", d / "r.obj", d]))]  # fmt: skip
        elif flag == "--grid":
            value = data.draw(st.sampled_from(["hex:odd-r", "tri", "nope", "affine:x"]))
            if not continuous and value in ("hex:odd-r", "tri"):
                value = "nope"
            argv += ["--grid", value]
        else:
            argv += ["--boundary", data.draw(st.sampled_from(["x", "z-=999", "q+=1", "7,"]))]
        cli(argv, bad=True)


@FAST
@given(data=st.data())
def test_bad_model_files(data):
    _run_bad_models(data)


@FAST
@given(data=st.data())
def test_bad_constraints_files(data):
    _run_bad_constraints(data)


@FAST
@given(data=st.data())
def test_bad_option_values(data):
    _run_bad_options(data)


@pytest.mark.slow
@SLOW
@given(data=st.data())
def test_many_bad_inputs(data):
    which = data.draw(st.sampled_from([_run_bad_models, _run_bad_constraints, _run_bad_options]))
    which(data)
