"""Reading and writing models and results.

Every format is declared once, in :mod:`csplab.io.registry` (``csplab info`` and the
README list them): example grids (Merrell's format, the csplab grid format, ``.npy``,
MagicaVoxel ``.vox``), tilesets (WaveFunctionCollapse, POMS, DeBroglie, MarkovJunior), the
overlapping model of a sample picture, and the outputs ``.png`` and Wavefront ``.obj``.

* :func:`read_model` reads any model file: an :class:`ExampleModel` or a rule set
  (:class:`~csplab.io.ruleset.RuleSet`); :func:`model_format` tells which format a file
  holds, from its extension and its first bytes.
* :func:`read_example` / :func:`write_example` read and write example grids.
* :func:`write_labels` writes a result grid; the format follows the extension.

Examples
--------
>>> import tempfile, pathlib
>>> from csplab.examples import load_example
>>> with tempfile.TemporaryDirectory() as d:
...     p = pathlib.Path(d) / "line.txt"
...     write_example(load_example("line"), p)
...     model_format(p), read_model(p).shape
('merrell', (4, 3, 1))
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from numpy.typing import ArrayLike

from csplab.example import ExampleModel
from csplab.io.common import Output
from csplab.io.gridtext import format_grid, grid_safe_names, parse_grid
from csplab.io.merrell import format_merrell, parse_merrell
from csplab.io.registry import FORMATS, Format, detect, get_format, output_format, sniff
from csplab.io.ruleset import RuleSet

if TYPE_CHECKING:  # csplab.continuous is imported by the loaders of continuous models
    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel

__all__ = [
    "FORMATS",
    "RULESET_FORMATS",
    "Format",
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

RULESET_FORMATS = tuple(f.name for f in FORMATS.values() if f.gives == "RuleSet")


def _existing(path: str | Path) -> Path:
    from csplab.io.common import check_file

    return check_file(path)  # a regular file within the size cap, one line otherwise


def model_format(path: str | Path) -> str:
    """The name of the format of a model file (see :mod:`csplab.io.registry`), from the
    extension and the first bytes."""
    return detect(path).name


def read_model(
    path: str | Path, format: str | None = None, **options: Any
) -> ExampleModel | RuleSet | PolygonModel | PolyhedralModel:
    """Read any model file: an example grid, a rule set, a polygon or a polyhedral model.

    ``options`` are the format's loader options (``csplab info`` lists them), e.g.
    ``subset=`` (WFC), ``up=`` (POMS), ``strict=`` (DeBroglie), ``N=``, ``symmetry=``,
    ``periodic_input=``, ``ground=`` (overlapping model); others raise an
    :class:`~csplab.errors.InputError`. Loaders report what they cannot represent exactly
    as :class:`UserWarning` (and in the rule set's ``warnings``).
    """
    p = _existing(path)
    fmt = get_format(format) if format else detect(p)
    return fmt.read(p, **options)


def detect_format(path: str | Path, text: str | None = None) -> str:
    """The example-grid format of a file from its extension and (when given) its text; no
    file is read.

    Examples
    --------
    >>> detect_format("a.npy"), detect_format("a.txt"), detect_format("a.txt", "# csplab grid")
    ('npy', 'merrell', 'grid')
    """
    pool = [f for f in FORMATS.values() if f.gives == "ExampleModel" and f.readable]
    ext = Path(path).suffix.lower()
    by_ext = [f for f in pool if ext in f.extensions]
    if len(by_ext) == 1:
        return by_ext[0].name
    head = (text or "").encode("utf-8")
    return sniff(head, by_ext or pool, default=by_ext[0] if by_ext else None).name


def read_example(path: str | Path, format: str | None = None) -> ExampleModel:
    """Read an example grid from a file (format detected unless given)."""
    p = _existing(path)
    fmt = get_format(format, gives="ExampleModel") if format else detect(p, gives="ExampleModel")
    model = fmt.read(p)
    assert isinstance(model, ExampleModel)
    return model


def write_example(example: ExampleModel, path: str | Path, format: str | None = None) -> None:
    """Write an example grid in a format that reads back as one (``format``, or from the
    extension: ``.txt`` is Merrell's format)."""
    p = Path(path)
    fmt = get_format(format, gives="ExampleModel") if format else None
    fmt = fmt or output_format(p, gives="ExampleModel")
    out = Output.of(
        example.labels,
        model=example,
        name=example.name,
        meta=example.meta,
        example=example,
    )
    fmt.write(out, p)


def write_labels(
    grid: ArrayLike,
    path: str | Path,
    *,
    names: Any = None,
    name: str = "",
    meta: dict[str, Any] | None = None,
    model: Any = None,
    periodic: bool | None = None,
) -> None:
    """Write a result grid in the format of the extension (``csplab info`` lists them):
    ``.npy``, ``.txt`` (Merrell), ``.grid``, ``.png`` (a picture: the rule set's tile
    pictures, or one colour per label; 3D: isometric), ``.vox`` or ``.obj`` (a voxel mesh
    or the rule set's pieces).

    ``model`` (an :class:`ExampleModel` or :class:`RuleSet`) supplies names, colours, tile
    pictures, the empty label and pieces. Cells left unassigned (``-1``) can be written
    only to the formats that allow them (``.npy``, ``.vox``, ``.png``, ``.obj``).
    """
    p = Path(path)
    fmt = output_format(p)
    out = Output.of(grid, model=model, names=names, name=name, meta=meta, periodic=periodic)
    fmt.write(out, p)
