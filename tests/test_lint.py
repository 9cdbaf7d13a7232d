"""The package stays `ruff` clean and `mypy --strict` clean (skipped when the tools are absent)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _tool(name):
    exe = Path(sys.executable).parent / name
    return str(exe) if exe.exists() else shutil.which(name)


@pytest.mark.parametrize(
    "cmd",
    [
        ["ruff", "check", "csplab", "tests", "benchmarks", "experiments"],
        ["mypy"],
        ["lint-imports"],
    ],
    ids=["ruff", "mypy", "import-layers"],
)
def test_clean(cmd):
    exe = _tool(cmd[0])
    if exe is None:
        pytest.skip(f"{cmd[0]} not installed")
    args = cmd[1:2] + [a for a in cmd[2:] if (ROOT / a).exists()]
    r = subprocess.run([exe, *args], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]


def _private_imports():
    """(file, line, what) for every import of a ``_private`` name or module of another
    package (``from csplab.x import _y`` where the importer is not in ``csplab.x``'s package)."""
    import ast

    out = []
    for path in sorted((ROOT / "csplab").rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        pkg = ".".join(parts if path.name == "__init__.py" else parts[:-1])
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom) or not (node.module or "").startswith("csplab"):
                continue
            mod = node.module or ""
            for alias in node.names:
                full = f"{mod}.{alias.name}"
                private = [
                    p for p in full.split(".") if p.startswith("_") and not p.startswith("__")
                ]
                if not private:
                    continue
                owner = full.split("." + private[0])[0]  # the package that holds the private part
                if pkg != owner and not pkg.startswith(owner + "."):
                    out.append(f"{rel}.py:{node.lineno}: {full}")
    return out


def test_no_module_imports_another_packages_private_names():
    assert _private_imports() == []


def test_the_core_keeps_its_own_order():
    """The core's layers contract (enforced by ``lint-imports`` above) stays in the config,
    without ignored imports: examples over file formats over the grid builder over the data
    types, type-only imports excluded."""
    import tomllib

    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    cfg = tomllib.loads(text)["tool"]["importlinter"]
    assert cfg.get("exclude_type_checking_imports") is True
    (core,) = [
        c for c in cfg["contracts"] if c["type"] == "layers" and c["layers"][0] == "csplab.examples"
    ]
    names = ("csplab.examples", "csplab.io", "csplab.grids", "csplab.catalog", "csplab.problem")
    layers = [{m.strip() for m in layer.split("|")} for layer in core["layers"]]
    order = [next(i for i, ms in enumerate(layers) if m in ms) for m in (*names, "csplab.errors")]
    assert order == sorted(order) and "ignore_imports" not in core
