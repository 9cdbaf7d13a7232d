"""``tests/`` mirrors the package layout: a test of ``csplab/pkg/mod.py`` lives in
``tests/pkg/``, a test of the top-level ``csplab/mod.py`` (or ``csplab/_mod.py``) is
``tests/test_mod*.py``, and only the cross-cutting tests below stay top-level without naming
a module."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"
PACKAGE = ROOT / "csplab"

#: top-level tests of the whole package rather than of one module
CROSS_CUTTING = {
    "test_docstrings.py",  # numpydoc sections of the public API
    "test_general_csp.py",  # Problem, solvers and tools on CSPs that are not grids
    "test_hand_mutations.py",  # the hand mutations of issue 32 across checkers and engines
    "test_import_cycles.py",
    "test_layout.py",
    "test_lint.py",
    "test_notebook_display.py",  # _repr_png_ of models and results
    "test_optional_deps.py",  # every path that needs an optional package
    "test_runtime_contract.py",
}


def _names(paths: list[Path]) -> list[str]:
    return sorted(p.name.removesuffix(".py").lstrip("_") for p in paths)


def _names_module(stem: str, module: str) -> bool:
    """Whether a test file stem (``test_`` removed) names ``module``: ``soft_resemblance``
    names ``soft``, ``continuous3d`` names ``continuous``, ``examples_3d`` names ``examples``
    (not ``example``)."""
    rest = stem.removeprefix(module)
    return rest != stem and (not rest or rest[0] == "_" or rest[0].isdigit())


def misplaced(tests: Path = TESTS) -> list[str]:
    """Every test file under ``tests`` that breaks the rule (see the module docstring), with
    the reason."""
    packages = _names([p.parent for p in PACKAGE.glob("*/__init__.py")])
    modules = _names([p for p in PACKAGE.glob("*.py") if p.name != "__init__.py"])
    out = []
    for path in sorted(tests.rglob("test_*.py")):
        rel = path.relative_to(tests)
        if "data" in rel.parts[:-1]:
            continue  # fixture files
        if len(rel.parts) > 1:
            if not (PACKAGE.joinpath(*rel.parts[:-1]) / "__init__.py").is_file():
                out.append(f"{rel}: csplab/{'/'.join(rel.parts[:-1])} is not a package")
            continue
        if rel.name in CROSS_CUTTING:
            continue
        stem = rel.stem.removeprefix("test_")
        pkg = next((p for p in packages if _names_module(stem, p)), None)
        if pkg is not None:
            out.append(f"{rel}: tests the package csplab/{pkg}/, move it to tests/{pkg}/")
        elif not any(_names_module(stem, m) for m in modules):
            out.append(f"{rel}: names no top-level module of csplab (nor is it cross-cutting)")
    return out


def test_tests_mirror_the_package_layout():
    assert misplaced() == []


def test_the_cross_cutting_tests_exist():
    assert {p.name for p in TESTS.glob("test_*.py")} >= CROSS_CUTTING


def test_the_rule_catches_misplaced_tests(tmp_path):
    """A top-level test of a subpackage, or a folder that mirrors no package, is caught."""
    fake = tmp_path / "tests"
    (fake / "nowhere").mkdir(parents=True)
    for name in ("test_cli_stuff.py", "test_examples_3d.py", "test_example.py", "test_foo.py"):
        (fake / name).write_text("")
    (fake / "nowhere" / "test_x.py").write_text("")
    (fake / "io").mkdir()
    (fake / "io" / "test_y.py").write_text("")
    found = "\n".join(misplaced(fake))
    assert "test_cli_stuff.py: tests the package csplab/cli/" in found
    assert "test_examples_3d.py: tests the package csplab/examples/" in found
    assert "test_foo.py: names no top-level module" in found
    assert "nowhere/test_x.py: csplab/nowhere is not a package" in found
    assert "test_example.py" not in found and "io/test_y.py" not in found
