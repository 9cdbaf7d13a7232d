"""Bounds every reader and command applies before it works: object labels, and the peak
memory a command may plan to use.

A polygon or polyhedral object label is an id the renderers turn into a colour and the
formats store as text (``"label": N``, ``usemtl label_N``); :data:`MAX_LABEL` bounds it in
every reader, so a picture never needs a palette of two billion colours.

The memory budget (:func:`memory_budget`) is a share of the machine's RAM; commands
estimate their peak from the sizes and refuse a larger one with
:func:`check_memory` (one line: the estimate, the budget and what to change).

Examples
--------
>>> check_label(7, "polygon 0")
7
>>> check_label(2_000_000_000, "polygon 0")
Traceback (most recent call last):
...
csplab.errors.InputError: polygon 0: label 2000000000 is larger than 65535 (csplab's labels \
are 1..65535)
>>> check_memory(2e9, "synthesize", "use a smaller --size", budget=1e9)
Traceback (most recent call last):
...
csplab.errors.MemoryLimitError: synthesize would need about 2.0 GB, over the memory budget \
of 1.0 GB: use a smaller --size, or raise --memory-limit
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from csplab.errors import InputError, MemoryLimitError

__all__ = [
    "FALLBACK_MEMORY",
    "MAX_LABEL",
    "MEMORY_SHARE",
    "SMALL_ESTIMATE",
    "available_memory",
    "check_label",
    "check_memory",
    "memory_budget",
    "memory_limit",
]

#: The largest object label of a polygon or polyhedral model (16 bits).
MAX_LABEL = 65535

#: The share of the machine's RAM a command may plan to use by default.
MEMORY_SHARE = 0.5


def check_label(label: int, where: str) -> int:
    """``label`` when ``1 <= label <= MAX_LABEL``; one :class:`InputError` line naming
    ``where`` otherwise."""
    if label > MAX_LABEL:
        raise InputError(
            f"{where}: label {label} is larger than {MAX_LABEL} (csplab's labels are "
            f"1..{MAX_LABEL})"
        )
    return label


#: assumed available memory (bytes) where ``/proc/meminfo`` cannot be read
FALLBACK_MEMORY = 8 * 2**30


def available_memory() -> int:
    """Bytes of memory available to a new allocation: ``MemAvailable`` of
    ``/proc/meminfo`` (Linux), else :data:`FALLBACK_MEMORY`."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return FALLBACK_MEMORY


def total_ram() -> float | None:
    """The machine's RAM in bytes (``None`` when the system does not tell)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return None


#: the command's ``--memory-limit`` (GB) while it runs (:func:`memory_limit`), else None
_LIMIT_GB: ContextVar[float | None] = ContextVar("csplab_memory_limit", default=None)


@contextmanager
def memory_limit(limit_gb: float | None) -> Iterator[None]:
    """Within the block, :func:`memory_budget` without an argument (so every estimate
    checked against the default budget: the mesh readers' face counts, the synthesis
    estimates) is ``limit_gb`` GB; ``None`` keeps the default. The CLI runs each command
    inside its ``--memory-limit``.

    Raises
    ------
    InputError
        When ``limit_gb`` is not a positive finite number.

    Examples
    --------
    >>> with memory_limit(2.5):
    ...     memory_budget()
    2500000000.0
    """
    if limit_gb is not None:
        memory_budget(limit_gb)  # refused here when not a positive number
    token = _LIMIT_GB.set(limit_gb)
    try:
        yield
    finally:
        _LIMIT_GB.reset(token)


def memory_budget(limit_gb: float | None = None) -> float:
    """The bytes a command may plan to use: ``limit_gb`` GB when given, else the limit of
    the enclosing :func:`memory_limit` (the command's ``--memory-limit``), else
    :data:`MEMORY_SHARE` of the machine's RAM, or the memory available now when that is
    less (:func:`available_memory`)."""
    if limit_gb is None:
        limit_gb = _LIMIT_GB.get()
    if limit_gb is not None:
        if not limit_gb > 0 or limit_gb == float("inf"):
            raise InputError(f"--memory-limit must be a positive number of GB, not {limit_gb:g}")
        return float(limit_gb) * 1e9
    ram = total_ram()
    return min(MEMORY_SHARE * (ram if ram else 16e9), float(available_memory()))


def fmt_bytes(n: float) -> str:
    """``n`` bytes as ``"1.5 GB"`` (MB below a gigabyte, kB below a megabyte)."""
    if n >= 1e9:
        return f"{n / 1e9:.1f} GB"
    return f"{n / 1e6:.0f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"


#: estimates up to this many bytes are always allowed against the memory available (not
#: worth reading ``/proc/meminfo``: modify in blocks builds many small problems)
SMALL_ESTIMATE = 256 * 2**20


def check_memory(
    estimate: float,
    what: str,
    change: str,
    *,
    budget: float | None = None,
    available: bool = False,
) -> None:
    """Refuse (:class:`MemoryLimitError`, one line) a command or an allocation whose
    ``estimate`` bytes exceed the bound: ``budget`` (default :func:`memory_budget`, which
    ``--memory-limit`` raises), or with ``available=True`` the memory available now
    (:func:`available_memory`: the library's own guard before it allocates a grid problem;
    estimates up to :data:`SMALL_ESTIMATE` pass without looking). ``what`` names the work,
    ``change`` says what to change. The one memory refusal of csplab.

    Examples
    --------
    >>> check_memory(2e5, "a 10x10 problem", "a smaller --size", available=True)  # tiny
    >>> check_memory(3e9, "x", "a smaller --size", budget=4e9)                      # fits
    """
    if available:
        if estimate <= SMALL_ESTIMATE:
            return
        limit, bound = float(available_memory()), "the memory available"
    else:
        limit = memory_budget() if budget is None else budget
        bound = "the memory budget"
    if estimate > limit:
        raise MemoryLimitError(
            f"{what} would need about {fmt_bytes(estimate)}, over {bound} of "
            f"{fmt_bytes(limit)}: {change}" + ("" if available else ", or raise --memory-limit")
        )
