"""WaveFunctionCollapse's run list ``samples.xml``: one entry becomes a rule set.

WaveFunctionCollapse (mxgmn) describes its runs in a list file::

    <samples>
      <overlapping name="Flowers" N="3" periodic="True" symmetry="2" ground="True"
                   heuristic="Scanline"/>
      <simpletiled name="Castle" size="20" heuristic="MRV"/>
      <simpletiled name="Knots" subset="Dense" periodic="True"/>
    </samples>

An ``<overlapping>`` entry is the overlapping model of ``samples/NAME.png``
(:meth:`csplab.io.overlap.OverlapModel.from_png`), a ``<simpletiled>`` entry the tileset
``tilesets/NAME.xml`` (:func:`csplab.io.wfc.read_wfc`; older WaveFunctionCollapse
versions kept it as ``samples/NAME/data.xml``, which is read too), both relative to the
list's folder. The entry is chosen with the options ``name=`` and ``index=`` (the ``K``-th
entry, from 0, of those called ``name``, or of all entries); a list of one entry needs
neither. The entry's attributes become the reader's options, and options given to
:func:`read_wfc_samples` (``--model-option``) override them:

==============================  ====================================================
attribute (WFC default)         csplab
==============================  ====================================================
``N`` (3), ``symmetry`` (8),    the overlapping reader's ``N``, ``symmetry``,
``periodicInput`` (True),       ``periodic_input``, ``ground`` (an older WFC's
``ground`` (False)              ``ground="-1"``, the last pattern, is ``True``)
``subset``                      the tiled reader's ``subset``
``heuristic`` (Entropy)         ``meta["heuristic"]`` (``Entropy``, ``MRV`` or
                                ``Scanline``): the cell order ``csplab synthesize``
                                uses when none is given
``periodic`` (False)            the rule set's default periodicity
``size`` (48 overlapping, 24    the rule set's default size, ``width x height``
tiled), ``width``, ``height``   cells; a non-periodic overlapping output gets
                                ``width - N + 1`` cells across, so that its picture
                                is ``width`` pixels wide, as WFC's
``limit``, ``screenshots``,     ignored (how WFC runs and saves; ``textOutput`` and
``blackBackground``,            the picture background are not csplab settings)
``textOutput``
==============================  ====================================================

Other attributes are ignored with a warning. Problems with the list or the entry (no such
entry, a missing sample or tileset, a bad attribute value, an error in the file the entry
names) are one error line naming the list, its line and the entry.

Examples
--------
>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> (d / "tilesets").mkdir()
>>> _ = (d / "tilesets" / "Toy.xml").write_text(
...     '<set><tiles><tile name="sea"/><tile name="land"/></tiles><neighbors>'
...     '<neighbor left="sea" right="land"/><neighbor left="sea" right="sea"/></neighbors></set>')
>>> _ = (d / "samples.xml").write_text(
...     '<samples><simpletiled name="Toy" width="6" height="4" heuristic="Scanline"/></samples>')
>>> rs = read_wfc_samples(d / "samples.xml")
>>> rs.name, rs.shape, rs.periodic, rs.meta["heuristic"]
('Toy', (6, 4), False, 'Scanline')
>>> read_wfc_samples(d / "samples.xml", name="Flowers")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
csplab.errors.InputError: .../samples.xml: no entry named 'Flowers'; entries: Toy
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from csplab.errors import CsplabError, FormatError, InputError
from csplab.io._xml import Node, parse_xml
from csplab.io.common import NO, SURE, LoaderWarnings, read_bytes, xml_root
from csplab.io.ruleset import RuleSet

__all__ = ["HEURISTICS", "Entry", "read_wfc_samples", "sniff"]

#: WaveFunctionCollapse's heuristics (``heuristic=`` of an entry), by lower-case name.
HEURISTICS = {"entropy": "Entropy", "mrv": "MRV", "scanline": "Scanline"}
_KINDS = ("overlapping", "simpletiled")
# attribute -> reader option, per kind of entry
_OPTIONS = {
    "overlapping": {"N": "N", "symmetry": "symmetry", "periodicInput": "periodic_input"},
    "simpletiled": {"subset": "subset"},
}
_GROUND = "ground"  # overlapping; WFC's bool, or an older WFC's pattern index
_COMMON = {"name", "size", "width", "height", "periodic", "heuristic"}
_IGNORED = {"limit", "screenshots", "blackBackground", "black", "textOutput"}
_SIZE = {"overlapping": 48, "simpletiled": 24}  # WFC's default size


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for XML whose root element is ``<samples>``."""
    return SURE if xml_root(head) == "samples" else NO


@dataclass(frozen=True)
class Entry:
    """One ``<overlapping>`` or ``<simpletiled>`` entry of a samples list.

    Attributes
    ----------
    kind : {"overlapping", "simpletiled"}
        The element's tag.
    name : str
        Its ``name`` attribute.
    attrib : dict of str to str
        All its attributes.
    line : int
        The line it starts on.
    """

    kind: str
    name: str
    attrib: dict[str, str]
    line: int


def read_wfc_samples(
    path: str | Path,
    *,
    name: str | None = None,
    index: int | None = None,
    N: int | None = None,
    symmetry: int | None = None,
    periodic_input: bool | None = None,
    ground: str | None = None,
    subset: str | None = None,
    images: bool | None = None,
) -> RuleSet:
    """Read one entry of a WaveFunctionCollapse ``samples.xml`` (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The samples list.
    name : str, optional
        The entry's ``name``; needed when the list has more than one entry.
    index : int, optional
        The ``index``-th entry (from 0) of those called ``name`` (of all entries when no
        ``name`` is given): for names used more than once.
    N, symmetry, periodic_input, ground : optional
        Override the overlapping entry's attributes (see
        :meth:`~csplab.io.overlap.OverlapModel.from_png`).
    subset, images : optional
        Override the simple tiled entry's ``subset``; ``images=False`` skips the tile
        pictures (see :func:`~csplab.io.wfc.read_wfc`).

    Returns
    -------
    RuleSet
        The entry's model (an :class:`~csplab.io.overlap.OverlapModel` for an
        overlapping entry) with the entry's size, periodicity and heuristic;
        ``meta["wfc_samples"]`` records the list, the entry and its attributes.

    Raises
    ------
    InputError
        No entry was chosen, none has this name or index, or an option does not apply to
        the entry's kind.
    FormatError
        The list is malformed, the entry's file is missing or an attribute value is bad
        (one line naming the list, the entry's line and the entry).
    """
    p = Path(path)
    warn = LoaderWarnings(p)
    root = parse_xml(read_bytes(p), path=p)
    if root.tag.lower() != "samples":
        raise FormatError(f"the root element is <{root.tag}>, not <samples>", path=p)
    entries = _entries(root, p, warn)
    entry = _choose(entries, p, name, index)
    given = {
        "N": N,
        "symmetry": symmetry,
        "periodic_input": periodic_input,
        "ground": ground,
        "subset": subset,
        "images": images,
    }
    given = {k: v for k, v in given.items() if v is not None}
    return _read_entry(entry, p, given, warn)


def _entries(root: Node, path: Path, warn: LoaderWarnings) -> list[Entry]:
    entries: list[Entry] = []
    other: list[str] = []
    for node in root.children:
        kind = node.tag.lower()
        if kind not in _KINDS:
            other.append(f"<{node.tag}>")
            continue
        nm = node.get("name")
        if not nm or not nm.strip():
            raise FormatError(f"<{node.tag}> has no name", path=path, line=node.line)
        entries.append(Entry(kind, nm, dict(node.attrib), node.line))
    if other:
        warn.add(f"ignored {', '.join(dict.fromkeys(other))} (not a WFC entry)")
    if not entries:
        raise FormatError("no <overlapping> or <simpletiled> entries", path=path)
    return entries


def _names(entries: list[Entry]) -> str:
    """The entries' names, each once (``Knots (3)`` for a name used three times)."""
    counts: dict[str, int] = {}
    for e in entries:
        counts[e.name] = counts.get(e.name, 0) + 1
    return ", ".join(n if c == 1 else f"{n} ({c})" for n, c in counts.items())


def _choose(entries: list[Entry], path: Path, name: str | None, index: int | None) -> Entry:
    pool = entries
    what = "entries"
    if name is not None:
        pool = [e for e in entries if e.name == name]
        what = f"entries named {name!r}"
        if not pool:
            raise InputError(f"{path}: no entry named {name!r}; entries: {_names(entries)}")
    if index is not None:
        if not 0 <= index < len(pool):
            raise InputError(
                f"{path}: index={index}, but there are {len(pool)} {what} "
                f"(index 0..{len(pool) - 1})"
            )
        return pool[index]
    if len(pool) == 1:
        return pool[0]
    if name is not None:
        lines = ", ".join(str(e.line) for e in pool)
        raise InputError(
            f"{path}: {len(pool)} entries are named {name!r} (lines {lines}); choose one "
            f"with index=0..{len(pool) - 1}"
        )
    raise InputError(
        f"{path} lists {len(pool)} entries; choose one with name=NAME "
        f"(--model-option name=NAME, or index=K): {_names(entries)}"
    )


def _read_entry(e: Entry, path: Path, given: dict[str, Any], warn: LoaderWarnings) -> RuleSet:
    def bad(message: str) -> FormatError:
        return FormatError(f"entry {e.name!r} ({e.kind}): {message}", path=path, line=e.line)

    def integer(key: str, default: int) -> int:
        v = e.attrib.get(key)
        if v is None:
            return default
        try:
            return int(v.strip())
        except ValueError:
            raise bad(f"{key}={v!r} is not an integer") from None

    def boolean(key: str, default: bool) -> bool:
        v = e.attrib.get(key)
        if v is None:
            return default
        t = v.strip().lower()
        if t not in ("true", "false"):
            raise bad(f"{key}={v!r} is not True or False")
        return t == "true"

    from csplab.io.registry import FORMATS

    fmt = FORMATS["overlapping" if e.kind == "overlapping" else "wfc"]
    declared = {o.name for o in fmt.options}
    wrong = sorted(set(given) - declared)
    if wrong:
        raise InputError(
            f"option(s) {wrong} do not apply to the {e.kind} entry {e.name!r} of {path} "
            f"(options: {', '.join(sorted(declared | {'name', 'index'}))})"
        )
    mapping = _OPTIONS[e.kind]
    known = _COMMON | _IGNORED | set(mapping) | ({_GROUND} if e.kind == "overlapping" else set())
    unknown = [k for k in e.attrib if k not in known]
    if unknown:
        warn.add(f"entry {e.name!r}: ignored attribute(s) {', '.join(unknown)}")
    opts: dict[str, Any] = {}
    for attr, option in mapping.items():
        if attr in e.attrib and option not in given:
            try:
                opts[option] = fmt.check_options({option: e.attrib[attr].strip()})[option]
            except InputError:
                raise bad(f"{attr}={e.attrib[attr]!r} is not {_kind(fmt, option)}") from None
    if e.kind == "overlapping" and _GROUND in e.attrib and "ground" not in given:
        opts["ground"] = _ground(e.attrib[_GROUND], bad)
    opts.update(given)
    heuristic = e.attrib.get("heuristic")
    if heuristic is not None:
        if heuristic.strip().lower() not in HEURISTICS:
            raise bad(f"heuristic={heuristic!r} is not Entropy, MRV or Scanline")
        heuristic = HEURISTICS[heuristic.strip().lower()]
    size = integer("size", _SIZE[e.kind])
    shape = [integer("width", size), integer("height", size)]
    periodic = boolean("periodic", False)
    if e.kind == "overlapping" and not periodic:  # WFC's picture has width x height pixels
        n = int(opts.get("N", 3))
        shape = [s - n + 1 for s in shape]
    if min(shape) < 1:
        raise bad(f"the output size {shape[0]}x{shape[1]} (cells) is empty")
    file = _file(e, path)
    if file is None:
        where = "samples" if e.kind == "overlapping" else "tilesets"
        ext = ".png" if e.kind == "overlapping" else ".xml"
        raise bad(f"its file {where}/{e.name}{ext} is missing (next to {path.name})")
    try:
        rs = fmt.read(file, **opts)
    except CsplabError as err:
        raise bad(str(err)) from None
    assert isinstance(rs, RuleSet)
    if rs.ndim != 2:  # a sample or tileset of another dimension
        raise bad(f"its model is {rs.ndim}-D; WaveFunctionCollapse's entries are 2D")
    rs.shape = (shape[0], shape[1])
    rs.periodic = periodic
    subset_ = opts.get("subset")
    rs.name = e.name + (f"[{subset_}]" if subset_ else "")
    if heuristic is not None:
        rs.meta["heuristic"] = heuristic
    rs.meta["wfc_samples"] = {
        "file": str(path),
        "entry": e.name,
        "kind": e.kind,
        "line": e.line,
        "attributes": dict(e.attrib),
        "model_file": str(file),
    }
    rs.meta["warnings"] = [*rs.warnings, *warn.items]
    return rs


def _kind(fmt: Any, option: str) -> str:
    kind = next(o.kind for o in fmt.options if o.name == option)
    return "an integer" if kind is int else "True or False" if kind is bool else "a name"


def _ground(value: str, bad: Any) -> str:
    """The overlapping reader's ``ground`` of an entry's ``ground`` attribute: WFC's
    ``True``/``False``, or an older WFC's pattern index (``0`` none, ``-1`` the last
    pattern, which is the current WFC's ground pattern)."""
    t = value.strip().lower()
    if t in ("true", "-1"):
        return "true"
    if t in ("false", "0"):
        return "false"
    raise bad(
        f"ground={value!r} is not True or False (of an older WaveFunctionCollapse's pattern "
        "indices, csplab reads 0 and -1)"
    )


def _file(e: Entry, path: Path) -> Path | None:
    """The sample picture or tileset an entry names, or ``None`` when it is missing."""
    folder = path.parent
    if e.kind == "overlapping":
        candidates = [folder / "samples" / f"{e.name}.png"]
    else:  # current WFC; older versions: samples/NAME/data.xml
        candidates = [
            folder / "tilesets" / f"{e.name}.xml",
            folder / "samples" / e.name / "data.xml",
        ]
    return next((c for c in candidates if c.is_file()), None)
