"""The csplab grid text format: a plain, picture-like text format for 1D to 4D label grids.

Layout::

    # csplab grid v1            optional magic line; any line starting with # is a comment
    shape: 4x3x2                optional header lines "key: value" before the data:
    labels: empty ground wall   names of labels 0, 1, 2, ... (then names may be used as tokens)
    topology: hex:odd-r         the grid (csplab.topology; default square)
    weights: 5 1 1              optional per-label weights
    0 0 0 0                     data: a 2D slice is drawn as a picture, one line per row,
    0 2 2 0                     the top line is the highest y, tokens run along x
    1 1 1 1
                                a blank line separates z-slices (z = 0 first)
    0 0 0 0
    ...
    ---                         a line of dashes separates 3D blocks of a 4D grid (w = 0 first)

Without ``shape:`` the dimension follows from the layout: one line is 1D, one block of lines
2D, blank-line separated slices 3D, ``---`` separated blocks 4D.

Examples
--------
>>> E = parse_grid("labels: air ground\\n0 0 0\\n1 1 1\\n", path="x.grid")
>>> E.shape, E.labels.tolist(), E.names
((3, 2), [[1, 0], [1, 0], [1, 0]], ('air', 'ground'))
>>> parse_grid(format_grid(E)) == E
True
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.grids import parse_shape
from csplab.io.common import KIND, NO, SURE, Output, read_text, text_lines

__all__ = [
    "MAGIC",
    "format_grid",
    "grid_safe_names",
    "parse_grid",
    "read_grid",
    "sniff",
    "write_grid",
    "write_output",
]

MAGIC = "# csplab grid v1"
_HEADER = re.compile(r"^\s*(shape|labels|weights|name|topology)\s*:(.*)$", re.IGNORECASE)
_SEP4 = re.compile(r"^\s*-{3,}\s*$")


def parse_grid(text: str, *, path: object = "<string>", name: str = "") -> ExampleModel:
    """Parse csplab grid text into an :class:`ExampleModel` (labels indexed ``[x, y, ...]``)."""
    header: dict[str, tuple[str, int]] = {}
    blocks: list[list[list[list[tuple[str, int]]]]] = [[[]]]  # w -> z -> rows -> tokens
    seen_data = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].rstrip()
        if raw.lstrip().startswith("#"):
            continue
        m = _HEADER.match(line)
        if m and not seen_data:
            key = m.group(1).lower()
            if key in header:
                raise FormatError(f"duplicate header {key!r}", path=path, line=lineno)
            header[key] = (m.group(2).strip(), lineno)
            continue
        if m:
            raise FormatError(
                f"header {m.group(1)!r} after the grid data; headers go first",
                path=path,
                line=lineno,
            )
        if _SEP4.match(line):
            if blocks[-1][-1] or len(blocks[-1]) > 1:
                blocks.append([[]])
            continue
        if not line.strip():
            if blocks[-1][-1]:
                blocks[-1].append([])
            continue
        seen_data = True
        blocks[-1][-1].append([(t, lineno) for t in line.split()])
    # drop empty trailing slices/blocks
    for blk in blocks:
        while len(blk) > 1 and not blk[-1]:
            blk.pop()
    while len(blocks) > 1 and blocks[-1] == [[]]:
        blocks.pop()
    if not any(rows for blk in blocks for rows in blk):
        raise FormatError("no grid data found", path=path)

    names: tuple[str, ...] | None = None
    lookup: dict[str, int] = {}
    if "labels" in header:
        names = tuple(header["labels"][0].split())
        if not names:
            raise FormatError("empty 'labels:' header", path=path, line=header["labels"][1])
        if len(set(names)) != len(names):
            raise FormatError("label names repeat", path=path, line=header["labels"][1])
        lookup = {nm: i for i, nm in enumerate(names)}

    def value(tok: str, lineno: int) -> int:
        if tok in lookup:
            return lookup[tok]
        try:
            v = int(tok)
        except ValueError:
            raise FormatError(
                f"label {tok!r} is not an integer" + (" or a label name" if lookup else ""),
                path=path,
                line=lineno,
            ) from None
        if v < 0:
            raise FormatError(f"negative label {v}", path=path, line=lineno)
        if v >= 2**63:
            raise FormatError(f"label {v} does not fit in 64 bits", path=path, line=lineno)
        return v

    # every row must have the same length, every slice the same number of rows
    nx = len(blocks[0][0][0])
    ny = len(blocks[0][0])
    nz = len(blocks[0])
    for blk in blocks:
        if len(blk) != nz:
            raise FormatError(
                f"every 3D block needs {nz} slices, found {len(blk)}",
                path=path,
                line=blk[-1][-1][-1][1] if blk[-1] else None,
            )
        for rows in blk:
            if len(rows) != ny:
                raise FormatError(
                    f"every slice needs {ny} rows, this one has {len(rows)}",
                    path=path,
                    line=rows[0][0][1],
                )
            for toks in rows:
                if len(toks) != nx:
                    raise FormatError(
                        f"every row needs {nx} labels, this one has {len(toks)}",
                        path=path,
                        line=toks[0][1],
                    )
    nw = len(blocks)
    # data[w][z][row][x] with row 0 = top (highest y)
    arr = np.array(
        [[[[value(t, ln) for t, ln in toks] for toks in rows] for rows in blk] for blk in blocks],
        dtype=np.int64,
    )
    arr = arr[:, :, ::-1, :]  # row -> y ascending
    labels4 = arr.transpose(3, 2, 1, 0)  # [x, y, z, w]
    if nw > 1:
        labels = labels4
    elif nz > 1:
        labels = labels4[:, :, :, 0]
    elif ny > 1:
        labels = labels4[:, :, 0, 0]
    else:
        labels = labels4[:, 0, 0, 0]
    if "shape" in header:
        txt, ln = header["shape"]
        try:
            shp = parse_shape(txt, what="shape")
        except Exception:
            raise FormatError(f"bad shape {txt!r}", path=path, line=ln) from None
        if int(np.prod(shp)) != labels.size:
            raise FormatError(
                f"shape {txt} needs {int(np.prod(shp))} labels, the data has {labels.size}",
                path=path,
                line=ln,
            )
        nat = labels.shape + (1,) * (4 - labels.ndim)
        want = shp + (1,) * (4 - len(shp))
        if nat != want:
            raise FormatError(
                f"shape {txt} does not match the layout of the data "
                f"({'x'.join(map(str, labels.shape))})",
                path=path,
                line=ln,
            )
        labels = labels.reshape(shp)
    weights = None
    if "weights" in header:
        txt, ln = header["weights"]
        try:
            weights = [float(t) for t in txt.split()]
        except ValueError:
            raise FormatError("weights must be numbers", path=path, line=ln) from None
    if names is not None and labels.max() >= len(names):
        raise FormatError(
            f"label {int(labels.max())} has no name ({len(names)} names given)", path=path
        )
    nm = header["name"][0] if "name" in header else name
    meta: dict[str, Any] = {"format": "grid", "source": str(path)}
    if "topology" in header:  # thesis Sec. 3.5.1 grids: hex:odd-r, tri, cylinder, ...
        from csplab.topology import Topology

        txt, ln = header["topology"]
        try:
            meta["topology"] = Topology.parse(txt).name
        except InputError as e:
            raise FormatError(str(e), path=path, line=ln) from None
    try:
        return ExampleModel(labels, names=names, weights=weights, name=nm, meta=meta)
    except ValueError as e:
        raise FormatError(str(e), path=path) from None


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for the magic line, :data:`~csplab.io.common.KIND`
    for four numeric rows of one length (a bare grid; Merrell's header lines are free text).

    Examples
    --------
    >>> sniff(b"# csplab grid v1\\n0\\n"), sniff(b"0 1\\n1 0\\n0 1\\n1 0\\n"), sniff(b"<set>")
    (3, 2, 0)
    """
    lines = text_lines(head, 4)
    if lines and lines[0].strip().lower().startswith(MAGIC[:12]):
        return SURE
    rows = [ln.split() for ln in lines]
    if len(rows) == 4 and all(r and all(t.lstrip("-").isdigit() for t in r) for r in rows):
        if len({len(r) for r in rows}) == 1:
            return KIND
    return NO


def read_grid(path: str | Path) -> ExampleModel:
    """Read a csplab grid-format file (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The file to read.

    Returns
    -------
    ExampleModel
        The labels indexed ``[x, y, ...]`` with the header's names, weights and topology,
        named by the ``name:`` header or else the file's stem.

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid grid file (a duplicate or late
        header, a token that is neither an integer nor a label name, ragged rows or slices, a
        ``shape:`` that does not fit the data ...).
    """
    p = Path(path)
    return parse_grid(read_text(p), path=p, name=p.stem)


def format_grid(example: ExampleModel, comments: str = "") -> str:
    """csplab grid text for an example (1D to 4D)."""
    lab = example.file_labels()
    out = [MAGIC]
    for c in comments.splitlines():
        out.append(f"# {c}" if c else "#")
    if example.name:
        out.append(f"name: {example.name}")
    out.append(f"shape: {'x'.join(map(str, lab.shape))}")
    if example.meta.get("topology", "square") != "square":
        out.append(f"topology: {example.meta['topology']}")
    if example.names is not None:
        out.append("labels: " + " ".join(example.names))
    if example.weights is not None:
        out.append("weights: " + " ".join(f"{w:g}" for w in example.weights))
    shp4: tuple[int, ...] = (*lab.shape, *(1,) * (4 - lab.ndim))
    lab4 = lab.reshape(shp4)
    ny, nz, nw = shp4[1], shp4[2], shp4[3]
    width = len(str(int(lab.max())))
    for w in range(nw):
        if w:
            out.append("---")
        for z in range(nz):
            if z:
                out.append("")
            for y in reversed(range(ny)):
                out.append(" ".join(f"{int(v):>{width}d}" for v in lab4[:, y, z, w]))
    return "\n".join(out) + "\n"


def write_grid(example: ExampleModel, path: str | Path, comments: str = "") -> None:
    from csplab.io.common import write_atomic

    write_atomic(path, format_grid(example, comments))


def grid_safe_names(names: Sequence[str]) -> list[str]:
    """Label names usable as tokens of the grid format: no whitespace or ``#``, not a
    number (tokens that are numbers mean label ids), all different.

    Examples
    --------
    >>> grid_safe_names(["corner 1", "1", "#_0", "corner_1"])
    ['corner_1', 't1', '__0', 'corner_1.3']
    """
    out: list[str] = []
    seen: set[str] = set()
    for i, n in enumerate(names):
        t = re.sub(r"[\s#]+", "_", str(n)) or f"label{i}"
        if t.lstrip("-").isdigit():
            t = "t" + t
        if t in seen:
            t = f"{t}.{i}"
        seen.add(t)
        out.append(t)
    return out


def write_output(out: Output, path: Path) -> None:
    """The grid (no unassigned cells) in the grid format.

    Label names are made :func:`grid_safe_names` (tokens of the format).

    Parameters
    ----------
    out : Output
        The grid to write, with its model's names, meta and weights.
    path : Path
        The file to write (overwritten).

    Raises
    ------
    InputError
        When the grid has unassigned (negative) cells.
    """
    ex = out.to_example()
    if ex.names is not None:
        safe = grid_safe_names(ex.names)
        if safe != list(ex.names):
            ex = ExampleModel(ex.labels, names=safe, weights=ex.weights, name=ex.name, meta=ex.meta)
    write_grid(ex, path)
