"""The public API has numpydoc docstrings: a summary, Parameters for every parameter, and
Returns for everything that returns a value (checked with numpydoc's own validator), and a
Raises section naming every csplab error a function raises in its own body (found in its
source: ``raise InputError(...)``; errors raised deeper down are documented by hand).

The public API is derived, never listed by hand: the names of ``csplab.__all__`` (classes
with their public methods), every solver class of the registry, every reader and writer of
the format registry, and the continuous entry points of ``csplab.continuous.__all__``.
"""

from __future__ import annotations

import inspect

import pytest

numpydoc_validate = pytest.importorskip("numpydoc.validate")

#: numpydoc's codes for a missing summary or docstring (GL08), undocumented or unknown
#: parameters (PR01, PR02) and a missing Returns section (RT01)
CODES = ("GL08", "PR01", "PR02", "RT01")


def _members(obj: object, prefix: str) -> list[str]:
    out = [prefix]
    if inspect.isclass(obj):
        for name, value in vars(obj).items():
            if name.startswith("_"):
                continue
            if callable(value) or isinstance(value, classmethod | staticmethod | property):
                out.append(f"{prefix}.{name}")
    return out


def public_api() -> list[str]:
    """Dotted names of every public API object (see the module docstring)."""
    import csplab
    import csplab.continuous
    from csplab.io.registry import FORMATS
    from csplab.solvers import REGISTRY

    names: list[str] = []
    for package in (csplab, csplab.continuous):
        for name in package.__all__:
            obj = getattr(package, name)
            if inspect.isclass(obj) or inspect.isfunction(obj):
                names += _members(obj, f"{obj.__module__}.{obj.__qualname__}")
    for fmt in FORMATS.values():
        for ref in (fmt.reader, fmt.writer):
            if ref:
                names.append(ref.replace(":", "."))
    for ref in REGISTRY.values():
        names.append(ref.replace(":", "."))
    return sorted(set(names))


def test_the_public_api_is_found():
    api = public_api()
    assert "csplab.solvers.solve" in api or any(n.endswith(".solve") for n in api)
    assert len(api) > 50


@pytest.mark.parametrize("name", public_api())
def test_numpydoc(name):
    found = numpydoc_validate.validate(name)
    errors = [f"{code}: {text}" for code, text in found["errors"] if code in CODES]
    assert not errors, f"{name}: " + "; ".join(errors)


def _resolve(name: str) -> object:
    """The object of a dotted name (module, then attributes)."""
    import importlib

    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            obj = inspect.getattr_static(obj, attr) if inspect.isclass(obj) else getattr(obj, attr)
        return obj
    raise LookupError(name)


def direct_raises(func: object) -> set[str]:
    """The csplab errors a function raises in its own body: ``raise Error(...)`` statements
    whose class resolves, in the function's module, to a subclass of
    :class:`~csplab.errors.CsplabError` (nested functions, bare re-raises and raises through
    helpers such as ``raise bad(...)`` are not followed: what is found is certain)."""
    import ast
    import textwrap

    from csplab.errors import CsplabError

    if isinstance(func, classmethod | staticmethod):
        func = func.__func__
    func = inspect.unwrap(func)  # type: ignore[arg-type]
    if not inspect.isfunction(func):
        return set()
    try:
        source = inspect.getsource(func)
    except (OSError, TypeError):  # generated (a dataclass __init__): nothing of ours
        return set()
    tree = ast.parse(textwrap.dedent(source))
    (top,) = tree.body
    found: set[str] = set()

    nested = ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda | ast.ClassDef

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, nested):
                continue
            if isinstance(child, ast.Raise) and isinstance(child.exc, ast.Call):
                f = child.exc.func
                nm = f.id if isinstance(f, ast.Name) else None
                cls = func.__globals__.get(nm) if nm else None  # type: ignore[attr-defined]
                if isinstance(cls, type) and issubclass(cls, CsplabError):
                    found.add(cls.__name__)
            visit(child)

    visit(top)
    return found


def _raises_cases() -> list[tuple[str, str]]:
    """``(name, error)`` for every public API function or method (a class: its
    ``__init__``) that raises a csplab error in its own body."""
    cases = []
    for name in public_api():
        try:
            obj = _resolve(name)
        except (LookupError, AttributeError):
            continue
        func = vars(obj).get("__init__") if inspect.isclass(obj) else obj
        for err in sorted(direct_raises(func)) if func is not None else ():
            cases.append((name, err))
    return cases


def test_the_raises_check_finds_raising_functions():
    cases = _raises_cases()
    assert ("csplab.problem.Problem.cell", "InputError") in cases
    assert ("csplab.problem.Problem", "InputError") in cases
    assert len(cases) > 20


@pytest.mark.parametrize(("name", "error"), _raises_cases())
def test_raises_section_names_the_error(name, error):
    """A csplab error raised directly by a public function is in its Raises section (a
    section naming a base class, e.g. ``CsplabError``, counts)."""
    import csplab.errors

    parsed = numpydoc_validate.get_doc_object(numpydoc_validate.Validator._load_obj(name))
    # numpydoc keeps a Raises entry's exception in ``type`` (``name`` is empty)
    named = {(p.type or p.name).strip().split(".")[-1] for p in parsed["Raises"]}
    cls = getattr(csplab.errors, error)
    ok = any(b.__name__ in named for b in cls.__mro__)
    assert ok, f"{name} raises {error}; its Raises section names {sorted(named) or 'nothing'}"
