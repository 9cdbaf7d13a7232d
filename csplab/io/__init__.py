"""Reading and writing models: Merrell's format, the csplab grid format, ``.npy``, ``.png``.

:func:`read_example` detects the format from the extension and the content:
``.npy`` is a numpy int array; ``.grid`` (or a first line ``# csplab grid``) is
:mod:`csplab.io.gridtext`; other text files are Merrell's format (:mod:`csplab.io.merrell`)
for ``.txt`` files (unless they start with the grid magic line or are a bare numeric
grid) and for other files whose fourth line starts with three positive integers; anything
else is read as the grid format.
:func:`write_example` picks the format from the extension (``.txt`` = Merrell).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.io.gridtext import MAGIC, format_grid, parse_grid, write_grid
from csplab.io.merrell import format_merrell, parse_merrell, write_merrell

__all__ = [
    "detect_format",
    "format_grid",
    "format_merrell",
    "parse_grid",
    "parse_merrell",
    "read_example",
    "write_example",
    "write_labels",
]

TEXT_FORMATS = ("merrell", "grid")


def detect_format(path: str | Path, text: str | None = None) -> str:
    """``"npy"``, ``"grid"`` or ``"merrell"`` for a file (extension, then content)."""
    p = Path(path)
    ext = p.suffix.lower()
    if ext == ".npy":
        return "npy"
    if ext == ".grid":
        return "grid"
    if text is None:
        return "merrell" if ext == ".txt" else "grid"
    lines = text.splitlines()
    if lines and lines[0].strip().lower().startswith(MAGIC[:12]):
        return "grid"
    rows = [ln.split() for ln in lines[:4]]
    if len(rows) == 4 and all(r and all(t.lstrip("-").isdigit() for t in r) for r in rows):
        if len({len(r) for r in rows}) == 1:
            # Merrell header lines are free text: four numeric rows of one length are a grid
            return "grid"
    if ext == ".txt":
        return "merrell"
    if len(lines) >= 4:
        toks = lines[3].split()[:3]
        if len(toks) == 3 and all(t.isdigit() and int(t) > 0 for t in toks):
            return "merrell"
    return "grid"


def read_example(path: str | Path, format: str | None = None) -> ExampleModel:
    """Read an example model from a file (format detected unless given)."""
    p = Path(path)
    if not p.exists():
        raise FormatError("no such file", path=p)
    if p.is_dir():
        raise FormatError("is a directory, not a model file", path=p)
    fmt = format or detect_format(p)
    if fmt == "npy":
        try:
            arr = np.load(p, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise FormatError(f"not a readable .npy array ({e})", path=p) from None
        if not np.issubdtype(arr.dtype, np.integer):
            raise FormatError(f".npy array must hold integers, got {arr.dtype}", path=p)
        try:
            return ExampleModel(arr, name=p.stem, metadata={"format": "npy", "source": str(p)})
        except InputError as e:
            raise FormatError(str(e), path=p) from None
    try:
        text = p.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise FormatError(f"cannot read file: {e.strerror}", path=p) from None
    if format is None:
        fmt = detect_format(p, text)
    if fmt == "merrell":
        return parse_merrell(text, path=p, name=p.stem)
    if fmt == "grid":
        return parse_grid(text, path=p, name=p.stem)
    raise InputError(f"unknown model format {fmt!r}; use merrell, grid or npy")


def write_example(example: ExampleModel, path: str | Path, format: str | None = None) -> None:
    """Write an example: ``.txt`` Merrell, ``.grid`` csplab grid, ``.npy`` numpy."""
    p = Path(path)
    ext = p.suffix.lower()
    fmt = format or {".npy": "npy", ".grid": "grid", ".txt": "merrell"}.get(ext)
    if fmt is None:
        raise InputError(f"cannot tell the format of {p}: use .txt, .grid or .npy")
    if fmt == "npy":
        np.save(p, np.asarray(example.labels, dtype=np.int32))
    elif fmt == "grid":
        write_grid(example, p)
    elif fmt == "merrell":
        write_merrell(example, p)
    else:
        raise InputError(f"unknown model format {fmt!r}")


def write_labels(
    grid: ArrayLike,
    path: str | Path,
    *,
    names: Any = None,
    name: str = "",
    metadata: dict[str, Any] | None = None,
) -> None:
    """Write a synthesized grid: ``.npy`` (int32 ``[x, y, z]``), ``.txt`` (Merrell), ``.grid``
    or ``.png`` (2D: one colour per label; 3D: a rendered preview of non-empty cells).

    Cells left unassigned (``-1``) can only be written to ``.npy`` and ``.png``.
    """
    p = Path(path)
    g = np.asarray(grid, dtype=np.int32)
    ext = p.suffix.lower()
    if ext == ".png":
        from csplab.render import save_png

        save_png(g, p, names=names)
        return
    if ext == ".npy":
        np.save(p, g)
        return
    if ext not in (".txt", ".grid"):
        raise InputError(f"unknown output format {p.suffix!r}: use .npy, .txt, .grid or .png")
    if g.min() < 0:
        raise InputError(f"{p}: the grid has unassigned cells; write it as .npy or .png")
    ex = ExampleModel(g, names=names, name=name, metadata=metadata or {})
    write_example(ex, p)
