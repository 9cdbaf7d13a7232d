"""Every path that needs an optional package ends, when it is missing, in exit code 2 and
one line naming the extra to install -- never a traceback.

Each case runs ``csplab`` in a fresh interpreter with the package blocked
(``sys.modules[name] = None`` before anything is imported: ``import name`` then raises
``ModuleNotFoundError`` and ``importlib.util.find_spec`` returns ``None``), so code that
bypasses :mod:`csplab.deps` fails here as it would on a minimal install.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import csplab.deps as deps
from csplab.errors import DependencyError
from csplab.solvers import solver_names

ROOT = Path(__file__).resolve().parents[1]

_PROG = """\
import sys
for name in {blocked!r}:
    sys.modules[name] = None
from csplab.cli import main
sys.exit(main({argv!r}))
"""


def run_without(blocked, argv, cwd):
    code = _PROG.format(blocked=list(blocked), argv=list(argv))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip


def _experiment(*extra):
    return ["experiment", "fig3_8", "--quick", "--example", "line", "--seeds", "1",
            "--jobs", "1", "--no-progress", "--no-figures", "--store", "r.sqlite",
            "--out", "out", *extra]  # fmt: skip


S = ["line", "--size", "6x6"]
CASES = {
    "explain": (["pysat"], "sat", ["explain", *S]),
    "catalog-gap": (["pysat"], "sat", ["catalog-gap", *S]),
    "count ganak": (["pyganak"], "count", ["count", *S, "--method", "ganak"]),
    "count approxmc": (["pyapproxmc"], "count", ["count", *S, "--method", "approxmc"]),
    "count enumerate": (["pysat"], "sat", ["count", *S, "--method", "enumerate"]),
    "synthesize sat": (["pysat"], "sat", ["synthesize", *S, "--solver", "sat"]),
    "synthesize sat:backend": (["pysat"], "sat", ["synthesize", *S, "--solver", "sat:cadical195"]),
    "synthesize cpsat": (["ortools"], "cpsat", ["synthesize", *S, "--solver", "cpsat"]),
    "synthesize hybrid": (["pysat"], "sat", ["synthesize", *S, "--solver", "hybrid"]),
    "synthesize perfect": (["pysat"], "sat", ["synthesize", *S, "--solver", "perfect"]),
    "synthesize asp": (["clingo"], "asp", ["synthesize", *S, "--solver", "asp"]),
    "experiment solver sat": (["pysat"], "sat", _experiment("--solver", "sat")),
    "experiment solver cpsat": (["ortools"], "cpsat", _experiment("--solver", "catalog,cpsat")),
    "serve starlette": (["starlette"], "web", ["serve", "--port", "9"]),
    "serve uvicorn": (["uvicorn"], "web", ["serve", "--port", "9"]),
    "experiment scheduler": (
        ["distributed"],
        "dask",
        _experiment("--scheduler", "tcp://127.0.0.1:9"),
    ),
}
XFAIL: dict[str, str] = {}  # case -> the file that still needs deps.require


@pytest.mark.parametrize("case", list(CASES))
def test_missing_package_is_one_line_and_exit_2(case, tmp_path, request):
    blocked, extra, argv = CASES[case]
    if case == "synthesize asp" and "asp" not in solver_names():
        pytest.skip("no asp solver registered yet")
    if case in XFAIL:
        request.applymarker(pytest.mark.xfail(strict=True, reason=XFAIL[case]))
    r = run_without(blocked, argv, tmp_path)
    assert "Traceback" not in r.stderr, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(lines) == 1, (r.returncode, r.stderr, r.stdout)
    assert lines[0].startswith("csplab: error: ")
    assert f"pip install 'csplab[{extra}]'" in lines[0] and blocked[0] in lines[0]


def test_the_pure_python_paths_need_no_optional_package(tmp_path):
    blocked = list(deps.EXTRAS)
    r = run_without(blocked, ["synthesize", "line", "--size", "8x8", "--seed", "1"], tmp_path)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    r = run_without(blocked, ["count", "line", "--size", "3x40"], tmp_path)  # transfer matrix
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    r = run_without(blocked, ["info"], tmp_path)  # lists the solvers, installed or not
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr


# ------------------------------------------------------------------ csplab.deps itself
def test_available_and_require(monkeypatch):
    assert deps.available("numpy") and not deps.available("no_such_module_xyz")
    assert deps.require("numpy.linalg").__name__ == "numpy.linalg"
    monkeypatch.setitem(sys.modules, "pysat", None)
    want = r"^x needs pysat; install it with pip install 'csplab\[sat\]'$"
    with pytest.raises(DependencyError, match=want):
        deps.require("pysat.solvers", what="x")


def test_an_installed_package_that_does_not_import_is_one_line(monkeypatch, tmp_path):
    (tmp_path / "broken_pkg_xyz.py").write_text("raise ImportError('libfoo.so: not found')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(DependencyError, match=r"does not import \(libfoo.so: not found\)"):
        deps.require("broken_pkg_xyz", "sat")


@pytest.mark.parametrize("name", ["json", "json.decoder"])
def test_a_module_blocked_in_sys_modules_is_unavailable(monkeypatch, name):
    monkeypatch.setitem(sys.modules, "json", None)
    assert not deps.available(name)
    with pytest.raises(DependencyError, match="csplab\\[sat\\]"):
        deps.require(name, "sat")


def test_every_extra_is_declared_in_pyproject():
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    assert set(deps.EXTRAS.values()) <= set(extras)
