"""The public API has numpydoc docstrings: a summary, Parameters for every parameter, and
Returns for everything that returns a value (checked with numpydoc's own validator).

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
