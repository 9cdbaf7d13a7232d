"""Optional dependencies: one place that imports them and says which extra installs them.

Every path that needs python-sat, OR-Tools, clingo, Ganak, ApproxMC or Dask calls
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
}


def available(module: str) -> bool:
    """True when ``module`` can be imported (without importing it)."""
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
    if not available(top):
        extra = extra or EXTRAS.get(top, "all")
        who = what or "this feature"
        raise DependencyError(f"{who} needs {top}; install it with pip install 'csplab[{extra}]'")
    return importlib.import_module(module)
