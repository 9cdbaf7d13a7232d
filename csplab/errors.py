"""Exceptions raised by csplab.

Every error csplab raises on purpose derives from :class:`CsplabError`. Subclasses also
derive from the builtin exception they refine, so ``except ValueError`` keeps working.

Examples
--------
>>> from csplab.errors import CsplabError, FormatError
>>> issubclass(FormatError, ValueError) and issubclass(FormatError, CsplabError)
True
"""

from __future__ import annotations

__all__ = [
    "CsplabError",
    "DependencyError",
    "FormatError",
    "InputError",
    "NoTrivialSolutionError",
    "UnknownSolverError",
]


class CsplabError(Exception):
    """Root of all csplab errors."""


class InputError(CsplabError, ValueError):
    """A bad argument: a label out of range, an impossible shape, an unknown option."""


class FormatError(CsplabError, ValueError):
    """A malformed model file; the message names the file and line (or element)."""

    def __init__(self, message: str, *, path: object = None, line: int | None = None) -> None:
        where = ""
        if path is not None:
            where = f"{path}"
            if line is not None:
                where += f", line {line}"
            where += ": "
        super().__init__(where + message)
        self.path = path
        self.line = line


class UnknownSolverError(CsplabError, KeyError):
    """A solver name that is not in the registry."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class DependencyError(CsplabError, ImportError):
    """An optional dependency (python-sat, ortools, distributed, ...) is missing."""


class NoTrivialSolutionError(CsplabError, ValueError):
    """Modify-in-blocks needs a consistent starting model and none could be built."""


class MemoryLimitError(CsplabError, MemoryError):
    """A problem would need more memory than is available (estimated before allocating)."""
