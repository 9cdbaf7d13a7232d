"""Lazy ``@njit``: csplab's compiled functions import numba on their first call, not before.

Importing numba and loading one cached function costs about 0.3–0.45 s on a 2-core machine
(numba's import, its target registries, and scipy's BLAS check when scipy is installed), more
than a whole synthesis of a small model takes with :mod:`csplab._interp`. So csplab's modules
decorate their kernels with :func:`njit` from here: the decorator only records the function.
The first call of any kernel of a module imports numba, turns *every* kernel of that module
into a numba dispatcher with the recorded options (``cache=True`` keeps numba's on-disk
cache: the cached machine code is keyed by the same file and function) and puts the
dispatchers into the module's namespace, so kernels that call kernels of their own module
(:mod:`csplab._kernels`) resolve to dispatchers when numba types them. A module's ``prange``
placeholder (:data:`prange`) is replaced by :func:`numba.prange` at the same moment, and its
``trailing_zeros`` placeholder (:func:`trailing_zeros`) by numba's intrinsic of that name
(one ``tzcnt`` instruction, where a multiply-and-lookup took six).

:func:`on_load` registers a callback run once per module just after its kernels became
dispatchers (before any compiles): the CLI registers there a listener of numba's
``numba:compile`` event (a cache miss) that prints its one-line "compiling" notice before
the first kernel numba actually compiles. :func:`loaded` says
whether numba has been imported by csplab in this process.

Examples
--------
>>> @njit(cache=False)
... def twice(x):
...     return 2 * x
>>> twice.py_func(3)          # the plain Python function, no numba involved
6
"""

from __future__ import annotations

import functools
import sys
import threading
from collections.abc import Callable
from typing import Any, TypeVar, overload

__all__ = [
    "Kernel",
    "compile_seconds",
    "compiled",
    "load",
    "loaded",
    "njit",
    "on_load",
    "prange",
    "trailing_zeros",
]

_PENDING: dict[str, list[Kernel]] = {}
_HOOKS: list[Callable[[str], None]] = []
_LOCK = threading.RLock()
_STATE = {"loaded": False}
_TIMER: list[Any] = [None]


def prange(*args: int) -> range:
    """Placeholder for :func:`numba.prange` until a module's kernels are compiled."""
    return range(*args)


def trailing_zeros(x: Any) -> int:
    """Placeholder for numba's ``trailing_zeros`` intrinsic (LLVM's ``cttz``: one ``tzcnt``
    instruction) until a module's kernels are compiled: the index of the lowest set bit of
    a non-zero integer.

    Examples
    --------
    >>> trailing_zeros(40)
    3
    """
    v = int(x)
    return (v & -v).bit_length() - 1


class Kernel:
    """A function decorated with :func:`njit`, not yet handed to numba.

    Calls and attribute reads (``py_func`` excepted) make the module's kernels dispatchers
    first and then go to this function's dispatcher.
    """

    def __init__(self, func: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]):
        self.py_func = func
        self._args, self._kwargs = args, kwargs
        self._real: Any = None
        functools.update_wrapper(self, func)
        with _LOCK:
            _PENDING.setdefault(func.__module__, []).append(self)

    def dispatcher(self) -> Any:
        """The numba dispatcher of this function (imports numba on first use)."""
        if self._real is None:
            _materialize(self.py_func.__module__)
        return self._real

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.dispatcher()(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") or name in ("_real", "_args", "_kwargs", "py_func"):
            raise AttributeError(name)
        return getattr(self.dispatcher(), name)

    def __repr__(self) -> str:
        return f"<csplab kernel {self.py_func.__module__}.{self.py_func.__qualname__}>"


_F = TypeVar("_F", bound=Callable[..., Any])


@overload
def njit(func: _F, /) -> _F: ...
@overload
def njit(*args: Any, **kwargs: Any) -> Callable[[_F], _F]: ...
def njit(*args: Any, **kwargs: Any) -> Any:
    """Record a function for numba's ``njit`` with these options (``@njit`` or
    ``@njit(cache=True, ...)``); see the module docstring. (Typed as the function itself:
    a :class:`Kernel` is called like it.)"""
    if len(args) == 1 and callable(args[0]) and not kwargs:
        return Kernel(args[0], (), {})

    def deco(func: Callable[..., Any]) -> Kernel:
        return Kernel(func, args, kwargs)

    return deco


def _materialize(module: str) -> None:
    with _LOCK:
        kernels = _PENDING.pop(module, None)
        if kernels is None:
            return
        import numba

        if not _STATE["loaded"]:  # time numba's compilations from now on (cache loads: 0)
            from numba.core import event

            _TIMER[0] = event.TimingListener()  # type: ignore[no-untyped-call]
            event.register("numba:compile", _TIMER[0])  # type: ignore[no-untyped-call]
        _STATE["loaded"] = True
        mod = sys.modules[module]
        if getattr(mod, "prange", None) is prange:
            mod.prange = numba.prange  # type: ignore[attr-defined]
        if getattr(mod, "trailing_zeros", None) is trailing_zeros:
            from numba.cpython.unsafe.numbers import trailing_zeros as cttz

            mod.trailing_zeros = cttz  # type: ignore[attr-defined]
        for k in kernels:
            k._real = numba.njit(*k._args, **k._kwargs)(k.py_func)
            if getattr(mod, k.py_func.__name__, None) is k:
                setattr(mod, k.py_func.__name__, k._real)
        for hook in list(_HOOKS):
            hook(module)


def load(module: str) -> None:
    """Make the kernels of the (imported) ``module`` numba dispatchers now."""
    _materialize(module)


def on_load(hook: Callable[[str], None]) -> None:
    """Call ``hook(module_name)`` each time a module's kernels become numba dispatchers."""
    with _LOCK:
        _HOOKS.append(hook)


def compile_seconds() -> float:
    """Seconds numba has spent compiling csplab's kernels in this process (0 when numba is
    not loaded or every kernel came from its on-disk cache): the one-time cost a first run
    reports apart from the solve.

    Examples
    --------
    >>> compile_seconds() >= 0
    True
    """
    t = _TIMER[0]
    return float(t.duration) if t is not None and t.done else 0.0


def loaded() -> bool:
    """Whether csplab has imported numba in this process (a kernel was used)."""
    return _STATE["loaded"]


def compiled(module: str) -> bool:
    """Whether the kernels of ``module`` are numba dispatchers already (``True`` also for a
    module without kernels)."""
    return module not in _PENDING
