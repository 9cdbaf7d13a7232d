"""Reading a constraints file (the schema and the meaning: :mod:`csplab.constraints`).

The file is JSON read by the one JSON reader of csplab's files
(:func:`csplab.io.common.read_json_file`: size, special files, nesting depth), so the
global constraints (core) read no file themselves.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from csplab.constraints import Constraint, parse_constraints
from csplab.errors import FormatError
from csplab.io.common import read_json_file
from csplab.problem import Problem

__all__ = ["read_constraints", "read_entries", "read_world_constraints"]


def read_entries(path: str | Path) -> list[Any]:
    """The entries of a constraints file, unparsed (a bad file is one
    :class:`FormatError` line)."""
    p = Path(path)
    data = read_json_file(p)  # size, special files, nesting depth: one line each
    items = data.get("constraints") if isinstance(data, Mapping) else data
    if not isinstance(items, list):
        raise FormatError('a constraints file is {"constraints": [ ... ]}', path=p)
    return items


def read_constraints(path: str | Path, problem: Problem) -> list[Constraint]:
    """:func:`~csplab.constraints.parse_constraints` of a JSON file.

    Parameters
    ----------
    path : str or Path
        The constraints file.
    problem : Problem
        The problem the constraints apply to (labels are checked against it).

    Returns
    -------
    list of Constraint
        The parsed constraints.

    Raises
    ------
    FormatError
        One line naming the file and the entry.
    """
    return parse_constraints(read_entries(path), problem, Path(path))


def read_world_constraints(
    path: str | Path, problem: Problem
) -> tuple[list[Constraint], list[Constraint]]:
    """The constraints of a file for a world (:class:`csplab.World`): on the whole world,
    and per chunk (entries with ``"per": "chunk"``).

    Parameters
    ----------
    path : str or Path
        The constraints file.
    problem : Problem
        The chunk's grid (regions and cells of per-chunk entries are chunk coordinates).

    Returns
    -------
    tuple of list of Constraint
        The whole world's constraints (a world refuses them with its reason) and the
        per-chunk ones.

    Raises
    ------
    FormatError
        One line naming the file and the entry (also for a ``per`` other than
        ``"chunk"``).
    """
    p = Path(path)
    items = read_entries(p)
    per = []
    for i, c in enumerate(items):
        v = c.get("per") if isinstance(c, Mapping) else None
        if v is not None and v != "chunk":
            raise FormatError(f'constraints[{i}]: "per" must be "chunk", not {v!r}', path=p)
        per.append(v == "chunk")
    plain = [{k: v for k, v in c.items() if k != "per"} if isinstance(c, Mapping) else c
             for c in items]  # fmt: skip
    parsed = parse_constraints(plain, problem, p)
    return (
        [c for c, f in zip(parsed, per, strict=True) if not f],
        [c for c, f in zip(parsed, per, strict=True) if f],
    )
