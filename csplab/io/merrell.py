"""Merrell's tiled-model text format (the thesis' example-model files).

Layout::

    <header line 1>            free text, kept as meta
    <header line 2>
    <header line 3>
    nx ny nz [anything]        the size line starts with three positive integers
    <nx*ny*nz integers>        order: for z: for x: for y  (each z-slice as nx lines of ny)
    <trailer>                  optional free text (a label -> object table), kept verbatim

Labels are read as a stream of integers (any whitespace or line breaks between them); the
data must end at a line end, and everything after that line is the trailer.

Examples
--------
>>> text = "model\\nmade by hand\\n\\n2 3 1\\n0 1 0\\n1 2 1\\n0 ground.obj\\n"
>>> E = parse_merrell(text, path="toy.txt")
>>> E.shape, E.labels[:, :, 0].tolist()
((2, 3, 1), [[0, 1, 0], [1, 2, 1]])
>>> E.meta["merrell_trailer"]
'0 ground.obj\\n'
>>> format_merrell(E) == text
True
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from csplab.errors import FormatError
from csplab.example import ExampleModel
from csplab.io.common import NO, PLAUSIBLE, Output, read_text, text_lines

__all__ = [
    "format_merrell",
    "parse_merrell",
    "read_merrell",
    "sniff",
    "write_merrell",
    "write_output",
]


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.PLAUSIBLE` when the fourth line starts with three positive
    integers (the size line).

    Examples
    --------
    >>> sniff(b"house\\n\\n\\n3 3 2\\n1 1 1\\n"), sniff(b"0 1\\n1 0\\n")
    (1, 0)
    """
    lines = text_lines(head, 4)
    toks = lines[3].split()[:3] if len(lines) == 4 else []
    ok = len(toks) == 3 and all(t.isdigit() and int(t) > 0 for t in toks)
    return PLAUSIBLE if ok else NO


def parse_merrell(text: str, *, path: object = "<string>", name: str = "") -> ExampleModel:
    """Parse Merrell-format text into an :class:`ExampleModel` of shape ``(nx, ny, nz)``."""
    lines = text.splitlines(keepends=True)
    if len(lines) < 4:
        raise FormatError(
            f"expected 3 header lines and a size line 'nx ny nz', found {len(lines)} lines",
            path=path,
            line=len(lines) or None,
        )
    size_tokens = lines[3].split()
    try:
        nx, ny, nz = (int(t) for t in size_tokens[:3])
        if len(size_tokens) < 3:
            raise ValueError
    except ValueError:
        raise FormatError(
            f"expected the size line 'nx ny nz', got {lines[3].strip()!r}", path=path, line=4
        ) from None
    if min(nx, ny, nz) < 1:
        raise FormatError(f"sizes must be positive, got {nx} {ny} {nz}", path=path, line=4)
    total = nx * ny * nz
    if total > 100_000_000:
        raise FormatError(f"model of {nx}x{ny}x{nz} cells is too large", path=path, line=4)
    values = np.empty(total, dtype=np.int64)
    got = 0
    i = 4
    while got < total:
        if i >= len(lines):
            raise FormatError(
                f"expected {total} labels ({nx}x{ny}x{nz}) but the file ends after {got}",
                path=path,
                line=len(lines),
            )
        toks = lines[i].split()
        for j, t in enumerate(toks):
            if got == total:
                raise FormatError(
                    f"unexpected extra value {t!r} after the {total} labels "
                    f"(token {j + 1} of this line)",
                    path=path,
                    line=i + 1,
                )
            try:
                v = int(t)
            except ValueError:
                raise FormatError(f"label {t!r} is not an integer", path=path, line=i + 1) from None
            if v < 0:
                raise FormatError(f"negative label {v}", path=path, line=i + 1)
            if v >= 2**63:
                raise FormatError(f"label {v} does not fit in 64 bits", path=path, line=i + 1)
            values[got] = v
            got += 1
        i += 1
    if int(values.max()) > 10_000_000:
        raise FormatError(f"label {int(values.max())} is unreasonably large", path=path)
    # order: for z: for x: for y  ->  array [z, x, y] -> transpose to [x, y, z]
    labels = values.reshape(nz, nx, ny).transpose(1, 2, 0)
    meta = {
        "format": "merrell",
        "merrell_header": [ln.rstrip("\r\n") for ln in lines[:3]],
        "merrell_size_line": lines[3].rstrip("\r\n"),
        "merrell_trailer": "".join(lines[i:]),
        "source": str(path),
    }
    return ExampleModel(labels, name=name, meta=meta)


def read_merrell(path: str | Path) -> ExampleModel:
    """Read a Merrell-format file (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The file to read.

    Returns
    -------
    ExampleModel
        The labels, shape ``(nx, ny, nz)``, named after the file's stem; ``meta`` keeps the
        three header lines, the size line and the trailer, so it can be written back.

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid Merrell-format file (a size line
        of three positive integers, then exactly ``nx*ny*nz`` non-negative integer labels).
    """
    p = Path(path)
    return parse_merrell(read_text(p), path=p, name=p.stem)


def format_merrell(example: ExampleModel) -> str:
    """Merrell-format text for an example of up to 3 dimensions (header and trailer kept)."""
    lab = example.file_labels()
    if lab.ndim > 3:
        raise FormatError(
            f"Merrell's format holds at most 3 dimensions; this model has shape {lab.shape}"
        )
    shp3: tuple[int, ...] = (*lab.shape, *(1,) * (3 - lab.ndim))
    lab3 = lab.reshape(shp3)
    nx, ny, nz = shp3[0], shp3[1], shp3[2]
    md = example.meta
    header = list(md.get("merrell_header", []))[:3]
    if len(header) < 3:
        header = [
            example.name or "csplab model",
            "written by csplab: labels for z: for x: for y",
            "",
        ]
    size_line = str(md.get("merrell_size_line", ""))
    toks = size_line.split()
    if toks[:3] != [str(nx), str(ny), str(nz)]:
        size_line = f"{nx} {ny} {nz}"
    out = [*header, size_line]
    for z in range(nz):
        for x in range(nx):
            out.append(" ".join(str(int(v)) for v in lab3[x, :, z]))
    text = "\n".join(out) + "\n"
    return text + str(md.get("merrell_trailer", ""))


def write_merrell(example: ExampleModel, path: str | Path) -> None:
    from csplab.io.common import write_atomic

    write_atomic(path, format_merrell(example))


def write_output(out: Output, path: Path) -> None:
    """The grid (at most 3D, no unassigned cells) in Merrell's format.

    A result of an example read from Merrell's format (``out.model``) gets that example's
    trailing label -> object table verbatim, as Merrell's program writes it: his 3DS Max
    and Blender loaders read the labels up to it.

    Parameters
    ----------
    out : Output
        The grid to write, with its model's names, meta and the model whose trailer is kept.
    path : Path
        The file to write (overwritten).

    Raises
    ------
    FormatError
        When the grid has more than 3 dimensions.
    InputError
        When the grid has unassigned (negative) cells.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> E = parse_merrell("m\\n\\n\\n2 1 1\\n0\\n1\\n<Objects>\\n1 wall\\n")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "out.txt"
    ...     write_output(Output.of([[1], [0]], model=E), p)
    ...     print(p.read_text())
    csplab model
    written by csplab: labels for z: for x: for y
    <BLANKLINE>
    2 1 1
    1
    0
    <Objects>
    1 wall
    <BLANKLINE>
    """
    example = out.to_example()
    model = out.model
    if (
        out.example is None
        and isinstance(model, ExampleModel)
        and model.meta.get("merrell_trailer")
        and not example.meta.get("merrell_trailer")
    ):
        meta = {**example.meta, "merrell_trailer": model.meta["merrell_trailer"]}
        example = ExampleModel(example.labels, names=example.names, name=example.name, meta=meta)
    write_merrell(example, path)
