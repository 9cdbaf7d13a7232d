"""Reading and writing models: Merrell's format, the csplab grid format, ``.npy``, ``.png``,
tilesets (WaveFunctionCollapse, POMS, DeBroglie, MarkovJunior), the overlapping model,
MagicaVoxel ``.vox`` and Wavefront ``.obj``.

:func:`read_model` reads any model file: an example grid (an :class:`ExampleModel`) or a
rule set (a :class:`~csplab.io.ruleset.RuleSet`); :func:`model_format` tells which format a
file holds, from its extension and content:

==============  ==============================================  =====================
format          files                                           gives
==============  ==============================================  =====================
``merrell``     ``.txt``, Merrell's tiled-model text format     ExampleModel
``grid``        ``.grid``, csplab's picture-like text format    ExampleModel
``npy``         ``.npy`` int array ``[x, y, z]``                ExampleModel
``vox``         ``.vox`` MagicaVoxel model (colour = label)     ExampleModel
``wfc``         ``.xml`` with root ``<set>``                    RuleSet
``markovjunior``  ``.xml`` with root ``<tileset>``              RuleSet
``poms``        ``.json`` with a ``"rule"`` list                RuleSet
``debroglie``   ``.json`` with ``"adjacencies"`` or ``"model"``  RuleSet
``overlapping`` ``.png`` sample picture                         OverlapModel (RuleSet)
==============  ==============================================  =====================

:func:`read_example` detects the format from the extension and the content:
``.npy`` is a numpy int array; ``.grid`` (or a first line ``# csplab grid``) is
:mod:`csplab.io.gridtext`; other text files are Merrell's format (:mod:`csplab.io.merrell`)
for ``.txt`` files (unless they start with the grid magic line or are a bare numeric
grid) and for other files whose fourth line starts with three positive integers; anything
else is read as the grid format.
:func:`write_example` picks the format from the extension (``.txt`` = Merrell).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.io.gridtext import MAGIC, format_grid, parse_grid, write_grid
from csplab.io.merrell import format_merrell, parse_merrell, write_merrell
from csplab.io.ruleset import RuleSet

__all__ = [
    "RULESET_FORMATS",
    "RuleSet",
    "detect_format",
    "format_grid",
    "format_merrell",
    "grid_safe_names",
    "model_format",
    "parse_grid",
    "parse_merrell",
    "read_example",
    "read_model",
    "write_example",
    "write_labels",
]

TEXT_FORMATS = ("merrell", "grid")
RULESET_FORMATS = ("wfc", "markovjunior", "poms", "debroglie", "overlapping")
_MODEL_EXT = {
    ".xml": "xml",
    ".json": "json",
    ".png": "overlapping",
    ".bmp": "overlapping",
    ".gif": "overlapping",
    ".vox": "vox",
}


def model_format(path: str | Path) -> str:
    """The format of a model file: one of ``merrell, grid, npy, vox`` (example grids) or
    :data:`RULESET_FORMATS`, from the extension and the first bytes."""
    p = Path(path)
    kind = _MODEL_EXT.get(p.suffix.lower())
    head = b""
    if kind in (None, "xml", "json"):
        try:
            with open(p, "rb") as fh:
                head = fh.read(4096)
        except OSError as e:
            raise FormatError(f"cannot read file: {e.strerror}", path=p) from None
    if kind is None:
        if head.startswith(b"\x89PNG"):
            return "overlapping"
        if head.startswith(b"VOX "):
            return "vox"
        if head.startswith(b"\x93NUMPY"):
            return "npy"
        stripped = head.lstrip(b"\xef\xbb\xbf \t\r\n")
        if stripped.startswith(b"<"):
            kind = "xml"
        elif stripped.startswith((b"{", b"//", b"/*")):
            kind = "json"
        else:
            return detect_format(p, head.decode("utf-8", errors="replace"))
    if kind == "xml":
        m = re.search(rb"<\s*([A-Za-z_][\w.-]*)", re.sub(rb"<[?!][^>]*>", b"", head))
        tag = m.group(1).decode().lower() if m else ""
        return "markovjunior" if tag == "tileset" else "wfc"
    if kind == "json":
        if re.search(rb'"rule"\s*:', head):
            return "poms"
        if re.search(rb'"(adjacencies|model|tiles|src)"\s*:', head):
            return "debroglie"
        try:
            data = p.read_bytes()
        except OSError as e:
            raise FormatError(f"cannot read file: {e.strerror}", path=p) from None
        return "poms" if re.search(rb'"rule"\s*:', data) else "debroglie"
    return kind


def read_model(
    path: str | Path, format: str | None = None, **options: Any
) -> ExampleModel | RuleSet:
    """Read any model file: an example grid or a rule set (see the table above).

    ``options`` go to the rule-set loaders: ``subset=`` (WFC), ``up=`` (POMS),
    ``strict=`` (DeBroglie), ``N=``, ``symmetry=``, ``periodic_input=``, ``ground=``
    (overlapping model).
    """
    p = Path(path)
    if not p.exists():
        raise FormatError("no such file", path=p)
    if p.is_dir():
        raise FormatError("is a directory, not a model file", path=p)
    fmt = format or model_format(p)
    allowed = {
        "wfc": {"subset", "images"},
        "markovjunior": set(),
        "poms": {"up"},
        "debroglie": {"strict"},
        "overlapping": {"N", "symmetry", "periodic_input", "ground"},
    }.get(fmt, set())
    extra = set(options) - allowed
    if extra:
        raise InputError(
            f"option(s) {sorted(extra)} do not apply to {fmt} files"
            + (f" (options: {', '.join(sorted(allowed))})" if allowed else "")
        )
    if fmt == "wfc":
        from csplab.io.wfc import read_wfc

        return read_wfc(p, **options)
    if fmt == "markovjunior":
        from csplab.io.markovjunior import read_markovjunior

        return read_markovjunior(p)
    if fmt == "poms":
        from csplab.io.poms import read_poms

        return read_poms(p, **options)
    if fmt == "debroglie":
        from csplab.io.debroglie import read_debroglie

        return read_debroglie(p, **options)
    if fmt == "overlapping":
        from csplab.io.overlap import OverlapModel

        return OverlapModel.from_png(p, **options)
    if fmt == "vox":
        from csplab.io.vox import read_vox_example

        ex: ExampleModel = read_vox_example(p)
        return ex
    return read_example(p, format=fmt)


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
    model: Any = None,
    periodic: bool | None = None,
) -> None:
    """Write a synthesized grid: ``.npy`` (int32 ``[x, y, z]``), ``.txt`` (Merrell), ``.grid``,
    ``.png`` (2D: one colour per label or the rule set's tile pictures; 3D: a rendered
    preview of non-empty cells), ``.vox`` (MagicaVoxel) or ``.obj`` (+ ``.mtl``, a voxel
    mesh, or the rule set's pieces when it has them).

    ``model`` (an :class:`ExampleModel` or :class:`RuleSet`) supplies names, colours, tile
    pictures, the empty label and pieces. Cells left unassigned (``-1``) can only be written
    to ``.npy``, ``.png``, ``.vox`` and ``.obj`` (where they are left out).
    """
    p = Path(path)
    g = np.asarray(grid, dtype=np.int32)
    ext = p.suffix.lower()
    if model is not None and names is None:
        names = getattr(model, "names", None)
    colors = empty = None
    pieces: dict[int, str] = {}
    if isinstance(model, RuleSet):
        colors = model.label_colors()
        empty = model.empty
        pieces = dict(model.meta.get("pieces", {}))
    elif isinstance(model, ExampleModel) and model.metadata.get("colors") is not None:
        colors = np.asarray(model.metadata["colors"], dtype=np.uint8)
        if model.metadata.get("format") == "vox":
            empty = 0
    if ext == ".png":
        if isinstance(model, RuleSet):
            model.render(g, periodic=periodic).save(p, format="PNG")
            return
        from csplab.render import render

        K = len(names) if names is not None else None
        render(g, K=K, colors=colors).save(p, format="PNG")
        return
    if ext == ".npy":
        np.save(p, g)
        return
    if ext in (".vox", ".obj") and isinstance(model, RuleSet) and model.voxels is not None:
        vox = model.expand_voxels(g)  # the tiles' own voxels, as MarkovJunior writes them
        if ext == ".obj" or max(vox.shape) <= 256:
            assert model.voxel_palette is not None
            g = vox.astype(np.int32) - 1  # colour index c -> label c - 1, empty -> -1
            colors, empty, names, pieces = model.voxel_palette[1:], -1, None, {}
        else:
            import warnings

            warnings.warn(
                f"{p}: the tile voxels make a {'x'.join(map(str, vox.shape))} model, more than "
                ".vox holds (256 per axis); writing one voxel per cell",
                UserWarning,
                stacklevel=2,
            )
    if ext == ".vox":
        from csplab.io.vox import write_vox

        write_vox(g, p, empty=empty, colors=colors)
        return
    if ext == ".obj":
        from csplab.io.obj import write_obj

        write_obj(g, p, empty=empty, colors=colors, names=names, pieces=pieces)
        return
    if ext not in (".txt", ".grid"):
        raise InputError(
            f"unknown output format {p.suffix!r}: use .npy, .txt, .grid, .png, .vox or .obj"
        )
    if g.min() < 0:
        raise InputError(f"{p}: the grid has unassigned cells; write it as .npy or .png")
    if names is not None and ext == ".grid":
        names = grid_safe_names(names)
    ex = ExampleModel(g, names=names, name=name, metadata=metadata or {})
    write_example(ex, p)


def grid_safe_names(names: Any) -> list[str]:
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
