"""The file-format registry: every format csplab reads or writes is declared here, once.

A :class:`Format` names its extensions, what reading gives (an
:class:`~csplab.example.ExampleModel`, a :class:`~csplab.io.ruleset.RuleSet` or, for
continuous model synthesis, a :class:`~csplab.continuous.model.PolygonModel` in 2D or a
:class:`~csplab.continuous.polyhedra.PolyhedralModel` in 3D), a content
sniffer, its loader options (the ``--model-option`` keys), its reader and writer (lazy
``"module:function"`` targets, imported on first use; ``None`` when the format is only
written or only read) and the texts of the README table and of ``csplab info``.
:func:`csplab.io.read_model`, :func:`csplab.io.write_labels`, the CLI, the README formats
table (:func:`markdown_table`) and the fuzz tests are derived from :data:`FORMATS`; adding a
format is its module plus one entry below.

Detection (:func:`detect`): the readable formats that claim the file's extension; when
several do (``.xml``, ``.json``, ``.txt``), or none (an unknown extension: then every
readable format), the one whose sniffer scores the first bytes highest
(:mod:`csplab.io.common`: 0 no, 1 plausible, 2 the right kind of file, 3 certain); on a tie
the one declared first; when nothing scores, the first format of the extension or, for an
unknown extension, :data:`FALLBACK`. An extension that only formats of another kind claim
(``.xml`` when an example grid is wanted, ``.obj`` -- read as polyhedra only) is a one-line
:class:`~csplab.errors.FormatError`. Writing (:func:`output_format`) takes the first
writable format that claims the extension and writes what is written (a label grid, a
polygon model or a polyhedral model: ``.obj`` and ``.png`` have one writer of each kind).

Examples
--------
>>> FORMATS["wfc"].extensions, FORMATS["wfc"].gives, FORMATS["wfc"].writable
(('.xml',), 'RuleSet', False)
>>> [o.name for o in FORMATS["overlapping"].options]
['N', 'symmetry', 'periodic_input', 'ground']
>>> output_format("out.txt").name, output_format("out.png").name
('merrell', 'png')
>>> get_format("zip")
Traceback (most recent call last):
...
csplab.errors.InputError: unknown model format 'zip'; use merrell, grid, tiled, npy, wfc, \
overlapping, wfc-samples, poms, debroglie, markovjunior, png, vox, obj, polygons, svg, \
polygon-png, mesh-obj, off, stl, glb or mesh-png
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, cast

from csplab.errors import FormatError, InputError
from csplab.io.common import NO, Output, read_bytes

if TYPE_CHECKING:
    from typing import TypeAlias

    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.example import ExampleModel
    from csplab.io.ruleset import RuleSet

    #: what reading a model file gives
    Model: TypeAlias = ExampleModel | RuleSet | PolygonModel | PolyhedralModel

__all__ = [
    "FALLBACK",
    "FORMATS",
    "Format",
    "Option",
    "detect",
    "formats",
    "get_format",
    "markdown_table",
    "option_help",
    "output_extensions",
    "output_format",
    "resolve",
    "synthesis_defaults",
]

Gives = Literal["ExampleModel", "RuleSet", "PolygonModel", "PolyhedralModel"]
Writes = Literal["grid", "PolygonModel", "PolyhedralModel"]
#: what each kind of writer takes, for messages
_HOLDS = {
    "grid": "label grids",
    "PolygonModel": "polygon models",
    "PolyhedralModel": "polyhedral models",
}
HEAD_SIZE = 1 << 20  # bytes a sniffer sees
FALLBACK = "grid"  # text that no sniffer recognises (its parser then says what is wrong)
BEGIN, END = "<!-- formats:begin -->", "<!-- formats:end -->"


def _or(items: Sequence[str]) -> str:
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} or {items[-1]}"


def resolve(target: str) -> Any:
    """The object a ``"module:attr.attr"`` target names (the module is imported)."""
    modname, _, attr = target.partition(":")
    obj: Any = importlib.import_module(modname)
    for part in attr.split("."):
        obj = getattr(obj, part)
    return obj


@dataclass(frozen=True)
class Option:
    """One loader option of a format (a ``--model-option KEY=VALUE`` key).

    Examples
    --------
    >>> o = Option("N", int, 3, "pattern width")
    >>> o.check("2", "overlapping"), o.usage
    (2, 'N=INT')
    >>> Option("up", str, "auto", "axes", choices=("auto", "y", "z")).check("x", "poms")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: option up='x' of poms files must be one of auto, y, z
    """

    name: str
    kind: type[bool] | type[int] | type[str]
    default: Any
    doc: str
    choices: tuple[str, ...] = ()

    @property
    def usage(self) -> str:
        """``KEY=VALUE`` with the kind of value (``KEY=A|B`` for choices)."""
        if self.choices:
            what = "|".join(self.choices)
        elif self.kind is bool:
            what = "true|false"
        else:
            what = "INT" if self.kind is int else "NAME"
        return f"{self.name}={what}"

    @property
    def help(self) -> str:
        """The documentation line with the default.

        Examples
        --------
        >>> Option("N", int, 3, "pattern width").help
        'pattern width (default 3)'
        """
        if self.default is None:
            return self.doc
        d = str(self.default).lower() if isinstance(self.default, bool) else self.default
        return f"{self.doc} (default {d})"

    def check(self, value: Any, fmt: str) -> Any:
        """``value`` as the option's type (``"true"``, ``"3"`` are accepted for the CLI)."""

        def bad(what: str) -> InputError:
            return InputError(f"option {self.name}={value!r} of {fmt} files must be {what}")

        if value is None and self.default is None:
            return None
        if self.kind is bool:
            if isinstance(value, bool):
                return value
            text = str(value).strip().lower()
            if text in ("true", "1", "yes"):
                return True
            if text in ("false", "0", "no"):
                return False
            raise bad("true or false")
        if self.kind is int:
            if isinstance(value, bool) or isinstance(value, list | dict):
                raise bad("an integer")
            try:
                n = int(value)
            except (TypeError, ValueError):
                raise bad("an integer") from None
            if n != value and str(n) != str(value).strip():
                raise bad("an integer")
            return n
        if isinstance(value, list | dict):
            raise bad("a name")
        text = str(value)
        if self.choices and text not in self.choices:
            raise bad(f"one of {', '.join(self.choices)}")
        return text


@dataclass(frozen=True, kw_only=True)
class Format:
    """A file format: how to recognise, read and write it, and how to document it.

    Attributes
    ----------
    name : str
        The format's name (``csplab.io.model_format``, ``meta["format"]``).
    extensions : tuple of str
        Lower-case extensions with the dot; the first format declared for an extension is
        its default (for writing, and for reading files no sniffer recognises).
    gives : {"ExampleModel", "RuleSet", "PolygonModel", "PolyhedralModel"} or None
        What reading gives (``None``: only written).
    writes : {"grid", "PolygonModel", "PolyhedralModel"}
        What the writer takes: a label grid (an :class:`~csplab.io.common.Output`; the
        default), a :class:`~csplab.continuous.model.PolygonModel` or a
        :class:`~csplab.continuous.polyhedra.PolyhedralModel` (continuous model synthesis
        in 2D, 3D). Grid outputs (:func:`output_format`, :func:`output_extensions` without
        ``gives="PolygonModel"`` or ``"PolyhedralModel"``) never pick a polygon or mesh
        writer, and each kind of model picks only its own writers.
    description : str
        One line, for ``csplab info`` and the README's format column.
    reader : str, optional
        ``"module:function"``; ``function(path, **options)`` reads a file.
    writer : str, optional
        ``"module:function"``; ``function(output, path)`` writes an
        :class:`~csplab.io.common.Output` (``function(model, path)`` a polygon or
        polyhedral model).
    sniffer : str, optional
        ``"module:function"``; ``function(head: bytes) -> int`` scores the first bytes.
    options : tuple of Option
        The reader's keyword options.
    partial : bool
        The writer accepts unassigned cells (``-1``).
    exact : bool
        Files hold label ids as written (result grids that ``csplab check`` reads).
    files, details, example : str
        README: what else tells the files apart, what csplab reads or writes (Markdown),
        and a command to try.
    synthesis : tuple of (option, value)
        The synthesis settings that suit models of this format when the user names none
        (:func:`synthesis_defaults`): WaveFunctionCollapse-style inputs are built for
        minimum-entropy order with weighted choice, Merrell's models for the thesis'
        scanline with uniform choice (the solvers' own defaults).
    """

    name: str
    extensions: tuple[str, ...]
    gives: Gives | None
    description: str
    writes: Writes = "grid"
    reader: str | None = None
    writer: str | None = None
    sniffer: str | None = None
    options: tuple[Option, ...] = ()
    partial: bool = False
    exact: bool = False
    files: str = ""
    details: str = ""
    example: str = ""
    synthesis: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        if (self.gives is None) != (self.reader is None):
            raise ValueError(f"format {self.name!r}: gives and reader go together")
        if self.reader is None and self.writer is None:
            raise ValueError(f"format {self.name!r} neither reads nor writes")
        if not self.extensions or any(
            not e.startswith(".") or e != e.lower() for e in self.extensions
        ):
            raise ValueError(f"format {self.name!r}: extensions are like '.txt'")

    @property
    def readable(self) -> bool:
        return self.reader is not None

    @property
    def writable(self) -> bool:
        return self.writer is not None

    def sniff(self, head: bytes) -> int:
        """How sure the sniffer is that ``head`` starts a file of this format (0 to 3)."""
        if self.sniffer is None:
            return NO
        return int(resolve(self.sniffer)(head))

    def check_options(self, options: Mapping[str, Any]) -> dict[str, Any]:
        """``options`` checked against :attr:`options` and converted to their types."""
        declared = {o.name: o for o in self.options}
        extra = set(options) - set(declared)
        if extra:
            raise InputError(
                f"option(s) {sorted(extra)} do not apply to {self.name} files"
                + (f" (options: {', '.join(sorted(declared))})" if declared else "")
            )
        return {k: declared[k].check(v, self.name) for k, v in options.items()}

    def read(self, path: str | Path, **options: Any) -> Model:
        """Read a file of this format."""
        if self.reader is None:
            raise InputError(f"csplab writes {self.name} files but does not read them")
        opts = self.check_options(options)
        reader = cast("Callable[..., Model]", resolve(self.reader))
        return reader(Path(path), **opts)

    def write(self, out: Output | PolygonModel | PolyhedralModel, path: str | Path) -> None:
        """Write ``out`` in this format: a grid (:class:`~csplab.io.common.Output`), or a
        polygon (polyhedral) model for the formats that write them (:attr:`writes`)."""
        p = Path(path)
        if self.writer is None:
            raise InputError(f"csplab reads {self.name} files but does not write them")
        kind = "grid" if isinstance(out, Output) else type(out).__name__
        if kind != self.writes:
            what = _HOLDS.get(kind, type(out).__name__)
            raise InputError(f"{p}: {self.name} files hold {_HOLDS[self.writes]}, not {what}")
        if not isinstance(out, Output):
            resolve(self.writer)(out, p)
            return
        if not self.partial and out.grid.size and int(out.grid.min()) < 0:
            exts = output_extensions(partial=True)
            raise InputError(f"{p}: the grid has unassigned cells; write it as {_or(exts)}")
        writer = cast("Callable[[Output, Path], None]", resolve(self.writer))
        writer(out, p)

    def info(self) -> dict[str, Any]:
        """What ``csplab info --json`` lists."""
        return {
            "name": self.name,
            "description": self.description,
            "extensions": list(self.extensions),
            "gives": self.gives,
            "writes": self.writes,
            "read": self.readable,
            "write": self.writable,
            "options": [
                {"name": o.name, "type": o.kind.__name__, "default": o.default, "doc": o.doc}
                | ({"choices": list(o.choices)} if o.choices else {})
                for o in self.options
            ],
        }


_SHARED = "`../shared/anchors-data/`"
_DATA = "../shared/anchors-data"  # the shared test data, from the repository root
_CONT = "csplab/examples/continuous"  # polygon examples (continuous model synthesis)
_EMPTY6 = "x-=0,x+=0,y-=0,y+=0,z-=0,z+=0"
#: the labels of the mesh formats without materials or groups (OFF, STL)
_SHELL_LABELS = Option(
    "labels",
    str,
    "one",
    "`one` label for the file or one per connected `components`",
    choices=("one", "components"),
)

# WaveFunctionCollapse's own settings (minimum entropy, weights), for its kind of inputs
_WFC_LIKE = (("order", "min-entropy"), ("choice", "weighted"))
# a file's own heuristic (WFC's samples list names one per entry) -> csplab's order
_HEURISTICS = {"entropy": "min-entropy", "mrv": "min-domain", "scanline": "scanline"}

#: Every format, in the order of the README table; the first format declared for an
#: extension is its default.
FORMATS: dict[str, Format] = {
    f.name: f
    for f in (
        Format(
            name="merrell",
            extensions=(".txt",),
            gives="ExampleModel",
            description="Merrell's tiled model",
            reader="csplab.io.merrell:read_merrell",
            writer="csplab.io.merrell:write_output",
            sniffer="csplab.io.merrell:sniff",
            exact=True,
            details="the thesis' example files: three header lines, `nx ny nz`, the labels "
            "for z: for x: for y, then an optional label table; header and table are kept "
            "when written back, and a result of the model carries its table (as Merrell's "
            "program writes it)",
            example="csplab synthesize city --size 20x20x10 --boundary auto --seed 1 "
            "--out city.txt && csplab check city city.txt",
        ),
        Format(
            name="grid",
            extensions=(".grid", ".txt"),
            gives="ExampleModel",
            description="csplab's picture-like grid text",
            reader="csplab.io.gridtext:read_grid",
            writer="csplab.io.gridtext:write_output",
            sniffer="csplab.io.gridtext:sniff",
            exact=True,
            files="(`.txt`: starting with `# csplab grid` or a bare numeric grid)",
            details="1D–4D grids drawn as text, the top line the highest `y`, blank lines "
            "between z-slices; optional `shape:`, `labels:` (names usable as tokens) and "
            "`weights:` headers (`csplab/io/gridtext.py`)",
            example="csplab synthesize line --size 12x6 --seed 2 --out line.grid "
            "&& csplab show line.grid",
        ),
        Format(
            name="tiled",
            extensions=(".tmx",),
            gives="ExampleModel",
            description="Tiled map",
            reader="csplab.io.tiled:read_tmx",
            sniffer="csplab.io.tiled:sniff",
            files="with root `<map>`",
            details="the first tile layer (csv or base64, zlib/gzip) as an example; "
            '`orientation="hexagonal"` maps give hexagonal examples (`staggeraxis`, '
            "`staggerindex` -> `hex:odd-r` ...), as DeBroglie reads them; DeBroglie configs "
            "with a `.tmx` sample learn an adjacent model on its grid",
            example="csplab synthesize tests/io/data/hexmap.tmx --size 20x16 --seed 1 "
            "--out hex.png",
        ),
        Format(
            name="npy",
            extensions=(".npy",),
            gives="ExampleModel",
            description="NumPy int array",
            reader="csplab.io.npy:read_npy",
            writer="csplab.io.npy:write_output",
            sniffer="csplab.io.npy:sniff",
            partial=True,
            exact=True,
            details="an int array indexed `[x, y, z]`; results keep unassigned cells as `-1`",
            example="csplab synthesize line --size 12x6 --seed 2 --out line.npy "
            "&& csplab check line line.npy",
        ),
        Format(
            name="wfc",
            synthesis=_WFC_LIKE,
            extensions=(".xml",),
            gives="RuleSet",
            description="WaveFunctionCollapse simple tiled",
            reader="csplab.io.wfc:read_wfc",
            sniffer="csplab.io.wfc:sniff",
            options=(
                Option("subset", str, None, "use only the tiles of this `<subset>`"),
                Option("images", bool, True, "read the tile pictures"),
            ),
            files="with root `<set>`",
            details="tiles with symmetry X/L/T/I/\\\\/F (1/4/4/2/2/8 orientations, labels "
            "`corner 1`; a rule's `corner k`, k = 0..7, is resolved through WFC's action "
            "table), weights, `left`/`right` rules closed under the square's 8 "
            "symmetries, `<subsets>`, `unique`, tile PNGs in `NAME/` next to the XML (a "
            "warning when they are missing)",
            example="csplab synthesize tests/io/data/pipes.xml --size 30x30 --seed 1 "
            "--out pipes.png",
        ),
        Format(
            name="overlapping",
            synthesis=_WFC_LIKE,
            extensions=(".png", ".bmp", ".gif"),
            gives="RuleSet",
            description="overlapping model of a sample picture",
            reader="csplab.io.overlap:OverlapModel.from_png",
            sniffer="csplab.io.overlap:sniff",
            options=(
                Option("N", int, 3, "pattern width"),
                Option(
                    "symmetry",
                    int,
                    8,
                    "1..8: how many of a pattern's 8 images (turns, mirrors) are added",
                ),
                Option("periodic_input", bool, True, "the sample wraps around"),
                Option(
                    "ground",
                    str,
                    "false",
                    "2D, symmetry 1 or 2: `true` WaveFunctionCollapse's rule (its ground "
                    "pattern fills the bottom and nowhere else; periodic outputs), `bottom` "
                    "the bottom row of cells holds only patterns of the sample's bottom row",
                ),
            ),
            files="sample",
            details="N×N patterns; weights = counts; adjacency = agreement on the overlap "
            "along each axis (2D or 3D samples)",
            example="csplab synthesize tests/io/data/sample.png --size 48x24 --periodic "
            "--model-option symmetry=2 --seed 1 --out flowers.png",
        ),
        Format(
            name="wfc-samples",
            synthesis=_WFC_LIKE,
            extensions=(".xml",),
            gives="RuleSet",
            description="WaveFunctionCollapse samples list",
            reader="csplab.io.wfc_samples:read_wfc_samples",
            sniffer="csplab.io.wfc_samples:sniff",
            options=(
                Option("name", str, None, "the entry (needed when the list has several)"),
                Option("index", int, None, "the K-th entry (from 0) of those called `name`"),
                Option("N", int, None, "overlapping entries: overrides `N`"),
                Option("symmetry", int, None, "overlapping entries: overrides `symmetry`"),
                Option(
                    "periodic_input", bool, None, "overlapping entries: overrides `periodicInput`"
                ),
                Option("ground", str, None, "overlapping entries: overrides `ground`"),
                Option("subset", str, None, "simple tiled entries: overrides `subset`"),
                Option("images", bool, None, "simple tiled entries: read the tile pictures"),
            ),
            files="with root `<samples>`",
            details="one `<overlapping>` (`samples/NAME.png`) or `<simpletiled>` "
            "(`tilesets/NAME.xml`) entry, read as those formats with the entry's `N`, "
            "`symmetry`, `periodicInput`, `ground`, `subset`; its `heuristic` "
            "(Entropy/MRV/Scanline) is the cell order, `periodic` and `width`/`height`/`size` "
            "the default output (a non-periodic overlapping output is `width - N + 1` cells "
            "across: WFC's picture size)",
            example="csplab synthesize tests/io/data/wfc_samples.xml --model-option "
            "name=sample --seed 1 --out samples.png",
        ),
        Format(
            name="poms",
            synthesis=_WFC_LIKE,
            extensions=(".json",),
            gives="RuleSet",
            description="PunchOutModelSynthesis (POMS) config",
            reader="csplab.io.poms:read_poms",
            sniffer="csplab.io.poms:sniff",
            options=(
                Option(
                    "up",
                    str,
                    "auto",
                    "3D configs: `y` reads them `y`-up, `z` keeps the axes, `auto` is `y` "
                    "when there is an `objMap`",
                    choices=("auto", "y", "z"),
                ),
            ),
            files='with `"rule"`',
            details="`[src, dst, dir, val]` rules, names, weights, size, boundary conditions "
            "(a virtual tile outside the grid), `remove`/`add`/`force`/`pin` (and `quilt…`) "
            "constraints applied in file order, `objMap` pieces, `tileset` pictures; 2D maps "
            "are flipped to `y` up, 3D configs with an `objMap` are read `y`-up",
            example=f"csplab synthesize {_DATA}/PunchOutModelSynthesis/brutal-plum_poms.json "
            "--size 20x20x10 --solver blocks --seed 1 --out plum.vox",
        ),
        Format(
            name="debroglie",
            synthesis=_WFC_LIKE,
            extensions=(".json",),
            gives="RuleSet",
            description="DeBroglie config",
            reader="csplab.io.debroglie:read_debroglie",
            sniffer="csplab.io.debroglie:sniff",
            options=(Option("strict", bool, False, "unsupported constraints are errors"),),
            files='with `"adjacencies"` (comments allowed)',
            details="tiles with `rotateCw`/`reflectX`… and frequencies, `symmetry`, "
            "`left/right`, `up/down`, `above/below` adjacencies closed under the group, "
            "`border` and `fixedTile` constraints; `path`, `edgedPath`, `count`, "
            "`mirrorX`/`mirrorY`, `maxConsecutive` and `separation` become global "
            "constraints (`csplab.constraints`); any other constraint is a one-line warning, "
            "never dropped silently; `overlapping` "
            "configs use their PNG sample; a Tiled `.tsx` tileset `src` gives the tile "
            "pictures (a number is a tile's gid, id + 1; a name its `name` property) and the "
            "per-tile properties (`meta['tile_properties']`); without one, a warning says "
            "pictures show one colour per tile",
            example=f"csplab synthesize {_DATA}/DeBroglie/edged_path_constraint.json --size 30x30 "
            "--seed 1 --out path.png",
        ),
        Format(
            name="markovjunior",
            synthesis=_WFC_LIKE,
            extensions=(".xml",),
            gives="RuleSet",
            description="MarkovJunior 3D tileset",
            reader="csplab.io.markovjunior:read_markovjunior",
            sniffer="csplab.io.markovjunior:sniff",
            files="with root `<tileset>`",
            details='tiles, `left`/`right` rules with turns `x`/`y`/`z` (`"zzx Turn"`), '
            "`fullSymmetry` = the cube's 48 symmetries (else the square's, with "
            "`top`/`bottom` rules); tile symmetries from the tiles' `.vox` files, or "
            "inferred from the rules (a warning says so); pictures and `.vox`/`.obj` "
            "outputs composite the tiles' voxels (inferred tiles are drawn as pipes towards "
            "their connected faces)",
            example=f"csplab synthesize {_DATA}/MarkovJunior/Knots3D.xml --size 20x20x10 "
            f"--boundary {_EMPTY6} --seed 1 --out knots.obj",
        ),
        Format(
            name="png",
            extensions=(".png",),
            gives=None,
            description="PNG picture of a grid",
            writer="csplab.io.picture:write_output",
            partial=True,
            details="2D: one colour per label or the tileset's tile pictures; 3D: an "
            "isometric view of the non-empty cells; `csplab show FILE` draws any model file",
            example="csplab synthesize city --size 40x40x10 --boundary auto --seed 1 "
            "--out city.png",
        ),
        Format(
            name="vox",
            extensions=(".vox",),
            gives="ExampleModel",
            description="MagicaVoxel model",
            reader="csplab.io.vox:read_vox_example",
            writer="csplab.io.vox:write_output",
            sniffer="csplab.io.vox:sniff",
            partial=True,
            details="in: a voxel model as an example grid (label 0 empty, one label per "
            "colour); out: label `b` = colour `b + 1`, the empty label left out",
            example=f"csplab synthesize tests/io/data/pipes3d.xml --size 12x12x6 "
            f"--boundary {_EMPTY6} --seed 1 --out pipes.vox && csplab show pipes.vox "
            "--out pipes3d.png",
        ),
        Format(
            name="obj",
            extensions=(".obj",),
            gives=None,
            description="Wavefront OBJ mesh",
            writer="csplab.io.obj:write_output",
            partial=True,
            files="+ `.mtl`",
            details="faces between filled and empty cells only, one material per label, "
            "`y` up (csplab `(x, y, z)` → `(x, z, -y)`); POMS `objMap` pieces are placed "
            "instead of cubes when the files exist "
            '(`csplab.io.obj.write_obj(grid, path, pieces={label: "piece.obj"})`)',
            example=f"csplab synthesize {_DATA}/PunchOutModelSynthesis/brutal-plum_poms.json "
            "--size 20x20x10 --solver blocks --seed 1 --out plum.obj",
        ),
        Format(
            name="polygons",
            extensions=(".json",),
            gives="PolygonModel",
            writes="PolygonModel",
            description="labelled polygons (continuous model synthesis)",
            reader="csplab.io.polygons:read_polygons_json",
            writer="csplab.io.polygons:write_polygons_json",
            sniffer="csplab.io.polygons:sniff_json",
            files='with `"polygons"`',
            details='`{"polygons": [{"label": 1, "points": [[x, y], ...], "holes": '
            "[[[x, y], ...]]}]}`: simple polygons, holes allowed, label `>= 1` (0 is empty "
            "space); rings are normalised (exterior counter-clockwise, holes clockwise); "
            "polygons of different labels must not overlap; other keys are kept when "
            "written back",
            example=f"csplab synthesize {_CONT}/two_objects.json --size 12x8 --seed 1 "
            "--out two.json "
            f"&& csplab check {_CONT}/two_objects.json two.json",
        ),
        Format(
            name="svg",
            extensions=(".svg",),
            gives="PolygonModel",
            writes="PolygonModel",
            description="SVG polygons (continuous model synthesis)",
            reader="csplab.io.polygons:read_svg",
            writer="csplab.io.polygons:write_svg",
            sniffer="csplab.io.polygons:sniff_svg",
            files="with root `<svg>`",
            details="in: `<polygon>`, `<rect>`, `<path>` with straight segments (`M L H V Z`), "
            "nested `<g>`, `transform`s; label from `data-label`, else one per fill colour "
            "(white/`none` is empty space); a path's subpaths nested inside a polygon are "
            "its holes; `y` is flipped (SVG's `y` points down); out: one `<path>` per "
            "polygon (even-odd), `data-label`, label colours",
            example=f"csplab synthesize {_CONT}/concave.json --size 12x8 --seed 1 "
            "--out concave.svg "
            f"&& csplab check {_CONT}/concave.json concave.svg",
        ),
        Format(
            name="polygon-png",
            extensions=(".png",),
            gives=None,
            writes="PolygonModel",
            description="PNG picture of polygons",
            writer="csplab.io.polygons:write_png",
            details="the polygons in their label colours on white, equal aspect, `y` up "
            "(`.png` files are read as overlapping-model samples, never as polygons)",
            example=f"csplab synthesize {_CONT}/two_objects.json --size 12x8 --seed 1 "
            "--out two.png",
        ),
        Format(
            name="mesh-obj",
            extensions=(".obj",),
            gives="PolyhedralModel",
            writes="PolyhedralModel",
            description="Wavefront OBJ polyhedra (3D continuous model synthesis)",
            reader="csplab.io.meshes:read_obj_model",
            writer="csplab.io.meshes:write_obj_model",
            sniffer="csplab.io.meshes:sniff_obj",
            options=(
                Option(
                    "labels",
                    str,
                    "auto",
                    "what makes a label: `auto` is `materials` when faces have materials, "
                    "else `groups` when there are `o`/`g` groups, else `one`",
                    choices=("auto", "materials", "groups", "components", "one"),
                ),
            ),
            files="+ `.mtl`",
            details="in: closed, oriented solids (`v`, polygon `f`, `o`/`g`, `usemtl`); a "
            "material or group named `label_N` is label `N`, other names get 1, 2, … in "
            "order of first appearance, a `# csplab label N` comment labels the rest of its "
            "group; a solid is one connected shell of one label and group; repaired as CAD "
            "exports need (duplicate vertices, zero-area slivers by edge flips, inconsistent "
            "winding; one warning line says what) and validated (watertight, manifold, no "
            "self-crossing, no zero-area face, different labels do not overlap, faces within "
            "the memory budget at 4 kB each, coordinates up to 1e7), inside-out solids are "
            "reversed with a warning; out: one "
            "`o solid_I` per solid, one material `label_N` per label with its colour in the "
            "`.mtl` (`.obj` results of label grids are the `obj` format)",
            example="csplab info  # in Python: "
            "csplab.io.read_model('tests/io/data/tiny_mesh.obj').volume(1)",
        ),
        Format(
            name="off",
            extensions=(".off",),
            gives="PolyhedralModel",
            writes="PolyhedralModel",
            description="OFF polyhedra (3D continuous model synthesis)",
            reader="csplab.io.meshes:read_off",
            writer="csplab.io.meshes:write_off_model",
            sniffer="csplab.io.meshes:sniff_off",
            options=(_SHELL_LABELS,),
            files="starting with `OFF`",
            details="`OFF`, counts, vertices, `k i1 … ik` polygon faces (colours ignored); "
            "every connected shell is a solid, repaired and validated as for `mesh-obj`; "
            "out: every solid's vertices and polygons, exact numbers (no labels: read back "
            "with `labels=components`)",
            example="csplab info  # in Python: "
            "csplab.io.read_model('tests/io/data/tiny.off', labels='components')",
        ),
        Format(
            name="stl",
            extensions=(".stl",),
            gives="PolyhedralModel",
            writes="PolyhedralModel",
            description="STL polyhedra (3D continuous model synthesis)",
            reader="csplab.io.meshes:read_stl",
            writer="csplab.io.meshes:write_stl_model",
            sniffer="csplab.io.meshes:sniff_stl",
            options=(_SHELL_LABELS,),
            files="ASCII or binary",
            details="triangles; coincident vertices are merged and adjacent coplanar "
            "triangles counted as one input polygon; every connected shell is a solid, "
            "repaired and validated as for `mesh-obj`; out: binary, every solid's polygons "
            "ear-clipped with all their vertices (no zero-area triangle, no T-junction), no "
            "labels",
            example="csplab info  # in Python: "
            "csplab.io.read_model('tests/io/data/tiny.stl').n_polygons",
        ),
        Format(
            name="glb",
            extensions=(".glb",),
            gives="PolyhedralModel",
            writes="PolyhedralModel",
            description="binary glTF polyhedra (game engines, three.js)",
            reader="csplab.io.meshes:read_glb",
            writer="csplab.io.meshes:write_glb",
            sniffer="csplab.io.meshes:sniff_glb",
            options=(
                Option(
                    "labels",
                    str,
                    "auto",
                    "labels from the `label_N` material or node names (`auto`), one per "
                    "connected `components`, or `one` for the file",
                    choices=("auto", "components", "one"),
                ),
            ),
            files="binary glTF 2.0 (`glTF` magic)",
            details="in (trimesh): every mesh node with its transform, `y` up turned back "
            "to csplab's `z` up; a material (or node) named `label_N` gives label N, other "
            "names the free labels 1, 2, ...; every connected shell is a solid, repaired and "
            "validated as for `mesh-obj`; out: one mesh and one PBR material `label_N` "
            "per label (the label colours), the solids' triangles as for `stl` (no "
            "zero-area triangle, no T-junction), `y` up (csplab `(x, y, z)` → `(x, z, -y)`); "
            "Godot, Unity, Unreal and three.js load it directly",
            example="csplab synthesize csplab/examples/continuous3d/houses.obj "
            "--size 12x12x4 --seed 1 --out houses.glb",
        ),
        Format(
            name="mesh-png",
            extensions=(".png",),
            gives=None,
            writes="PolyhedralModel",
            description="PNG picture of polyhedra",
            writer="csplab.io.meshes:write_png",
            details="a shaded view of the solids in their label colours (matplotlib; "
            "`csplab.io.meshes.write_png(model, path)`)",
            example="csplab info  # in Python: csplab.io.meshes.write_png(model, 'mesh.png')",
        ),
    )
}


# ---------------------------------------------------------------------------- lookups
def formats(
    *,
    gives: Gives | None = None,
    readable: bool | None = None,
    writable: bool | None = None,
    exact: bool | None = None,
) -> list[Format]:
    """The registered formats with these properties, in declaration order."""
    return [
        f
        for f in FORMATS.values()
        if (gives is None or f.gives == gives)
        and (readable is None or f.readable == readable)
        and (writable is None or f.writable == writable)
        and (exact is None or f.exact == exact)
    ]


def get_format(name: str, *, gives: Gives | None = None) -> Format:
    """The format called ``name`` (one that gives ``gives`` when given)."""
    pool = formats(gives=gives)
    for f in pool:
        if f.name == name:
            return f
    raise InputError(f"unknown model format {name!r}; use {_or([f.name for f in pool])}")


def detect(path: str | Path, *, gives: Gives | None = None, exact: bool | None = None) -> Format:
    """The readable format of a file (one that gives ``gives`` and is ``exact``, when
    given), from its extension and first bytes (see the module docstring)."""
    p = Path(path)
    pool = formats(readable=True, gives=gives, exact=exact)
    ext = p.suffix.lower()
    by_ext = [f for f in pool if ext in f.extensions]
    if len(by_ext) == 1:
        return by_ext[0]
    if not by_ext and ext:
        other = [f for f in FORMATS.values() if ext in f.extensions]
        if other and not any(f.readable for f in other):
            raise FormatError(
                f"csplab writes {ext} files ({other[0].description}) but does not read them",
                path=p,
            )
        if other:
            wanted = "model files"
            if exact:
                exts = [e for f in formats(exact=True, readable=True) for e in f.extensions]
                wanted = f"label grids (use {_or(list(dict.fromkeys(exts)))})"
            elif gives == "ExampleModel":
                wanted = "example grids"
            elif gives == "RuleSet":
                wanted = "rule sets"
            what = " or ".join(f.description for f in other if f.readable)
            raise FormatError(f"{ext} files are read as {what}, not as {wanted}", path=p)
    head = read_bytes(p, HEAD_SIZE)
    return sniff(head, by_ext or pool, default=by_ext[0] if by_ext else None)


def sniff(head: bytes, pool: Sequence[Format], default: Format | None = None) -> Format:
    """The format of ``pool`` whose sniffer scores ``head`` highest (the first on a tie);
    ``default`` (else :data:`FALLBACK` or the first of ``pool``) when none scores."""
    best, score = pool[0], NO
    for f in pool:
        s = f.sniff(head)
        if s > score:
            best, score = f, s
    if score > NO:
        return best
    if default is not None:
        return default
    return next((f for f in pool if f.name == FALLBACK), pool[0])


def _writers(gives: Gives | None) -> list[Format]:
    """The formats that write models of ``gives`` (polygon or polyhedral models: every
    writer of that kind; otherwise the grid writers, of formats giving ``gives`` when
    given)."""
    if gives in ("PolygonModel", "PolyhedralModel"):
        return [f for f in formats(writable=True) if f.writes == gives]
    return [f for f in formats(gives=gives, writable=True) if f.writes == "grid"]


def _writer_for(ext: str, gives: Gives | None) -> Format | None:
    return next((f for f in _writers(gives) if ext in f.extensions), None)


def output_format(path: str | Path, *, gives: Gives | None = None) -> Format:
    """The format written for ``path``'s extension (of the formats giving ``gives``; a
    label grid unless ``gives="PolygonModel"`` or ``"PolyhedralModel"``).

    Examples
    --------
    >>> [output_format(f"m{e}", gives="PolygonModel").name for e in (".json", ".svg", ".png")]
    ['polygons', 'svg', 'polygon-png']
    >>> [output_format(f"m{e}", gives="PolyhedralModel").name for e in (".obj", ".png")]
    ['mesh-obj', 'mesh-png']
    >>> output_format("m.obj").name
    'obj'
    """
    p = Path(path)
    f = _writer_for(p.suffix.lower(), gives)
    if f is None:
        exts = output_extensions(gives=gives)
        raise InputError(f"unknown output format {p.suffix!r} of {p}: use {_or(exts)}")
    return f


def output_extensions(*, gives: Gives | None = None, partial: bool | None = None) -> list[str]:
    """The extensions csplab writes (of formats giving ``gives``, accepting unassigned cells
    when ``partial``), in declaration order.

    Examples
    --------
    >>> output_extensions(), output_extensions(partial=True)
    (['.txt', '.grid', '.npy', '.png', '.vox', '.obj'], ['.npy', '.png', '.vox', '.obj'])
    >>> output_extensions(gives="PolygonModel")
    ['.json', '.svg', '.png']
    >>> output_extensions(gives="PolyhedralModel")
    ['.obj', '.off', '.stl', '.glb', '.png']
    """
    out: list[str] = []
    for f in _writers(gives):
        if partial is None or f.partial == partial:
            out += [e for e in f.extensions if e not in out and _writer_for(e, gives) is f]
    return out


# ---------------------------------------------------------------------------- derived texts
def synthesis_defaults(model: Any) -> tuple[dict[str, str], dict[str, str]]:
    """The synthesis settings that suit ``model`` and, per setting, where it comes from.

    A model read from a file records its format (``meta["format"]``); the format declares
    its settings (:attr:`Format.synthesis`), and a file that names its own heuristic
    (``meta["heuristic"]``: WFC's ``Entropy`` -> ``min-entropy``, ``MRV`` -> ``min-domain``,
    ``Scanline`` -> ``scanline``) wins for the order. Settings no one suggests come from
    the thesis (the key ``"*"`` of the sources says so).

    Examples
    --------
    >>> import csplab
    >>> synthesis_defaults(csplab.load_example("line"))
    ({}, {'*': 'the thesis defaults'})
    >>> from types import SimpleNamespace
    >>> synthesis_defaults(SimpleNamespace(meta={"format": "wfc", "heuristic": "MRV"}))
    ({'order': 'min-domain', 'choice': 'weighted'}, {'order': "the file's heuristic MRV", \
'choice': 'wfc defaults'})
    """
    meta = getattr(model, "meta", {}) or {}
    fmt = FORMATS.get(str(meta.get("format")))
    out = dict(fmt.synthesis) if fmt is not None else {}
    sources: dict[str, str] = {k: f"{fmt.name} defaults" for k in out} if fmt else {}
    heuristic = str(meta.get("heuristic") or "").lower()
    if heuristic in _HEURISTICS:
        out["order"] = _HEURISTICS[heuristic]
        sources["order"] = f"the file's heuristic {meta['heuristic']}"
    if not out:
        sources["*"] = "the thesis defaults"
    return out, sources


def option_help() -> str:
    """The ``--model-option`` keys of every format, for the CLI's help.

    Examples
    --------
    >>> option_help().split("; ")[0]
    'wfc: subset=NAME, images=true|false'
    """
    return "; ".join(
        f"{f.name}: {', '.join(o.usage for o in f.options)}" for f in FORMATS.values() if f.options
    )


def input_help() -> str:
    """The readable formats and their extensions, for the CLI's help.

    Examples
    --------
    >>> input_help().split(", ")[:2]
    ['merrell .txt', 'grid .grid/.txt']
    """
    return ", ".join(f"{f.name} {'/'.join(f.extensions)}" for f in formats(readable=True))


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_table() -> str:
    """The README formats table, from the declarations (``python -m csplab.readme --write``
    puts it between the README's ``<!-- formats:begin/end -->`` markers)."""
    rows = [
        "| format | file | what csplab reads or writes | `--model-option` | try it |",
        "|---|---|---|---|---|",
    ]
    for f in FORMATS.values():
        file = ", ".join(f"`{e}`" for e in f.extensions)
        file += f" {f.files}" if f.files else ""
        file += "" if f.readable else " (out)"
        opts = "; ".join(f"`{o.usage}`: {o.help}" for o in f.options)
        cells = [f"{f.description} (`{f.name}`)", file, f.details, opts, f"`{f.example}`"]
        rows.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(rows) + "\n"
