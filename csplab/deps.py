"""Optional dependencies: one place that imports them and says which extra installs them.

Every path that needs python-sat, OR-Tools, clingo, Ganak, ApproxMC, Dask or the mesh
packages (trimesh, manifold3d, scipy, mapbox-earcut) calls
:func:`require` (or :func:`available`), so a missing package ends in one
:class:`~csplab.errors.DependencyError` line naming the extra -- never a raw
``ModuleNotFoundError`` (the CLI turns it into exit code 2).

Examples
--------
>>> import csplab.deps as deps
>>> deps.available("numpy")
True
>>> try:
...     deps.require("no_such_module_xyz", "sat", "the SAT oracle")
... except Exception as e:
...     print(type(e).__name__, "-", e)
DependencyError - the SAT oracle needs no_such_module_xyz; install it with pip install 'csplab[sat]'
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from types import ModuleType

from csplab.errors import DependencyError

__all__ = ["EXTRAS", "available", "require"]

# top-level module -> the pyproject extra that installs it
EXTRAS: dict[str, str] = {
    "pysat": "sat",
    "ortools": "cpsat",
    "clingo": "asp",
    "pyganak": "count",
    "pyapproxmc": "count",
    "distributed": "dask",
    "trimesh": "mesh",
    "manifold3d": "mesh",
    "scipy": "mesh",
    "mapbox_earcut": "mesh",
    "maxflow": "baselines",
    "skimage": "baselines",
    "starlette": "web",
    "uvicorn": "web",
}


def available(module: str) -> bool:
    """True when ``module`` can be imported (without importing it).

    A module or parent package set to ``None`` in :data:`sys.modules` (how Python, and the
    tests, block an import) is unavailable even when it is installed.
    """
    parts = module.split(".")
    for i in range(1, len(parts) + 1):
        if sys.modules.get(".".join(parts[:i]), importlib) is None:
            return False
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent package is missing or broken
        return False


def require(module: str, extra: str | None = None, what: str | None = None) -> ModuleType:
    """Import ``module`` or raise one :class:`DependencyError` line naming the extra.

    Parameters
    ----------
    module : str
        The module to import, e.g. ``"pysat.solvers"``.
    extra : str, optional
        The ``pip install 'csplab[EXTRA]'`` extra; default from :data:`EXTRAS`.
    what : str, optional
        What needs it (``"solver 'sat'"``), for the message.
    """
    top = module.split(".")[0]
    extra = extra or EXTRAS.get(top, "all")
    who = what or "this feature"
    if not available(module):
        raise DependencyError(f"{who} needs {top}; install it with pip install 'csplab[{extra}]'")
    try:
        return importlib.import_module(module)
    except ImportError as e:  # installed but broken (a missing shared library, say)
        first = (str(e).strip().splitlines() or [type(e).__name__])[0]
        raise DependencyError(
            f"{who} needs {top}, which is installed but does not import ({first}); "
            f"reinstall it with pip install --force-reinstall 'csplab[{extra}]'"
        ) from None
