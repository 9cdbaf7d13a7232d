"""Helpers the format modules share: reading files, loader warnings, XML attributes,
images, content sniffing and :class:`Output` (a label grid on its way to a file).

Every name here is public within :mod:`csplab.io`; a format module never imports another
format module's private names.

Examples
--------
>>> xml_root(b'<?xml version="1.0"?>\\n<tileset size="3">'), xml_root(b"3 3 1")
('tileset', None)
>>> json_like(b"// a comment\\n{}"), json_like(b"0 1 2")
(True, False)
>>> out = Output.of([[0, 1], [1, 0]], names=["sea", "land"])
>>> out.grid.dtype, out.names, out.to_example().K
(dtype('int32'), ('sea', 'land'), 2)
"""

from __future__ import annotations

import os
import re
import stat
import tempfile
import warnings
from collections.abc import Container, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import FormatError, InputError

if TYPE_CHECKING:
    from csplab.example import ExampleModel
    from csplab.io._xml import Node
    from csplab.io.ruleset import RuleSet

__all__ = [
    "KIND",
    "MAX_FILE_BYTES",
    "NO",
    "PLAUSIBLE",
    "SURE",
    "LoaderWarnings",
    "Output",
    "check_file",
    "json_like",
    "load_image",
    "neighbor_side",
    "read_bytes",
    "read_json_file",
    "read_text",
    "text_lines",
    "xml_bool",
    "xml_float",
    "xml_neighbors",
    "xml_root",
]

# sniffing scores (the highest wins, see csplab.io.registry): not this format; text that
# could be it; the right kind of file (XML, JSON, a numeric grid); certain (a magic number,
# a distinguishing root element or key)
NO, PLAUSIBLE, KIND, SURE = 0, 1, 2, 3

_LEAD = b"\xef\xbb\xbf \t\r\n"  # a UTF-8 byte order mark and white space


# ---------------------------------------------------------------------------- files
#: The largest model file csplab reads (bytes): 256 MiB, far beyond any real example or
#: tileset; a bigger file (or a device such as ``/dev/zero``) is refused before reading.
MAX_FILE_BYTES = 256 * 2**20

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def check_file(path: str | Path, *, limit: int | None = None) -> Path:
    """``path`` when it names a regular file csplab may read: a :class:`FormatError` naming
    the file when it is missing, not a regular file (a directory, FIFO, device: checked with
    :func:`os.stat` before anything opens it, so a FIFO cannot hang and ``/dev/zero`` is
    not read forever) or larger than :data:`MAX_FILE_BYTES` (unless only its first
    ``limit`` bytes are wanted).

    Examples
    --------
    >>> check_file("/dev/zero")
    Traceback (most recent call last):
    ...
    csplab.errors.FormatError: /dev/zero: a character device, not a regular file; csplab \
reads model files only from regular files
    """
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError as e:
        what = (
            "no such file"
            if isinstance(e, FileNotFoundError)
            else f"cannot read file: {e.strerror}"
        )
        raise FormatError(what, path=p) from None
    if not stat.S_ISREG(st.st_mode):
        kind = next((k for test, k in _KINDS if test(st.st_mode)), "a special file")
        raise FormatError(
            f"{kind}, not a regular file; csplab reads model files only from regular files",
            path=p,
        )
    if (limit is None or limit > MAX_FILE_BYTES) and st.st_size > MAX_FILE_BYTES:
        raise FormatError(
            f"the file has {st.st_size / 2**20:.0f} MiB; csplab reads model files of at "
            f"most {MAX_FILE_BYTES // 2**20} MiB (csplab.io.common.MAX_FILE_BYTES)",
            path=p,
        )
    return p


def read_bytes(path: str | Path, limit: int | None = None) -> bytes:
    """The file's bytes (the first ``limit`` only, if given); a :class:`FormatError` naming
    the file when it cannot be read, is not a regular file or is larger than
    :data:`MAX_FILE_BYTES` (see :func:`check_file`)."""
    p = check_file(path, limit=limit)
    cap = MAX_FILE_BYTES if limit is None else min(limit, MAX_FILE_BYTES)
    try:
        with open(p, "rb") as fh:
            data = fh.read(cap + (1 if limit is None else 0))
    except OSError as e:
        raise FormatError(f"cannot read file: {e.strerror}", path=p) from None
    if len(data) > cap:  # it grew after the check
        raise FormatError(
            f"the file has more than {MAX_FILE_BYTES // 2**20} MiB; csplab reads model files "
            f"of at most {MAX_FILE_BYTES // 2**20} MiB (csplab.io.common.MAX_FILE_BYTES)",
            path=p,
        )
    return data


def read_text(path: str | Path) -> str:
    """The file as UTF-8 text (undecodable bytes replaced), as :func:`read_bytes`."""
    return read_bytes(path).decode("utf-8", errors="replace")


# ---------------------------------------------------------------------------- writing
def write_atomic(path: str | Path, data: bytes | str | Iterable[bytes]) -> None:
    """Write a file atomically: a temporary file beside ``path``, renamed over it.

    A reader never sees half a file, and a failed write leaves the old one as it was (the
    one atomic writer of csplab's outputs).

    Parameters
    ----------
    path : str or Path
        The file to write.
    data : bytes, str or iterable of bytes
        Its contents (text is written as UTF-8; an iterable, piece by piece: a large
        file is never held whole).

    Raises
    ------
    InputError
        One line naming ``path`` when the folder refuses the file.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_atomic(Path(d) / "a.txt", "hello")
    ...     (Path(d) / "a.txt").read_text()
    'hello'
    """
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent or Path("."), prefix=f".{path.name}.")
    except OSError as e:
        raise InputError(f"{path}: cannot write: {e.strerror}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            for piece in [data] if isinstance(data, bytes) else data:
                fh.write(piece)
            fh.flush()
            os.fsync(fh.fileno())
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    except OSError as e:
        Path(tmp).unlink(missing_ok=True)
        raise InputError(f"{path}: cannot write: {e.strerror}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def exact_text(x: float) -> str:
    """Shortest exact text of a float (integral values without ``.0``), for the model
    writers."""
    if x == 0:
        return "0"
    if x.is_integer() and abs(x) < 2**53:
        return str(int(x))
    return repr(x)


def png_target(path: str | Path, size_px: int, smallest: int, largest: int) -> Path:
    """``path`` for a PNG writer, once ``size_px`` is checked to be an integer from
    ``smallest`` to ``largest`` (else an :class:`~csplab.errors.InputError`)."""
    whole = isinstance(size_px, int) and not isinstance(size_px, bool)
    if not whole or not smallest <= size_px <= largest:
        raise InputError(
            f"{path}: size_px must be an integer from {smallest} to {largest}, not {size_px!r}"
        )
    return Path(path)


# ---------------------------------------------------------------------------- sniffing
def xml_root(head: bytes) -> str | None:
    """The lower-case root tag of XML bytes (``""`` when none is visible), or ``None``
    when the bytes do not start like XML."""
    if not head.lstrip(_LEAD).startswith(b"<"):
        return None
    m = re.search(rb"<\s*([A-Za-z_][\w.-]*)", re.sub(rb"<[?!][^>]*>", b"", head))
    return m.group(1).decode().lower() if m else ""


def json_like(head: bytes) -> bool:
    """Whether the bytes start like JSON (an object or array, or a ``//``/``/*`` comment)."""
    return head.lstrip(_LEAD).startswith((b"{", b"[", b"//", b"/*"))


def text_lines(head: bytes, n: int) -> list[str]:
    """The first ``n`` lines of the bytes as text."""
    return head.decode("utf-8", errors="replace").splitlines()[:n]


# ---------------------------------------------------------------------------- loaders
@dataclass
class LoaderWarnings:
    """Collects a loader's warnings (each also emitted as a :class:`UserWarning` naming the
    file); ``items`` goes into the model's ``meta["warnings"]``."""

    path: object
    items: list[str] = field(default_factory=list)

    def add(self, message: str) -> None:
        self.items.append(message)
        warnings.warn(f"{self.path}: {message}", UserWarning, stacklevel=3)


def xml_bool(node: Node, key: str, default: bool, path: object) -> bool:
    """A ``True``/``False`` attribute of an XML element."""
    v = node.get(key)
    if v is None:
        return default
    if v.strip().lower() in ("true", "1", "yes"):
        return True
    if v.strip().lower() in ("false", "0", "no"):
        return False
    raise FormatError(f"<{node.tag}> {key}={v!r} is not True or False", path=path, line=node.line)


def xml_float(node: Node, key: str, default: float, path: object) -> float:
    """A non-negative number attribute of an XML element."""
    v = node.get(key)
    if v is None:
        return default
    try:
        f = float(v)
    except ValueError:
        raise FormatError(
            f"<{node.tag}> {key}={v!r} is not a number", path=path, line=node.line
        ) from None
    if not np.isfinite(f) or f < 0:
        raise FormatError(
            f"<{node.tag}> {key}={v!r} must be a non-negative number", path=path, line=node.line
        )
    return f


def xml_neighbors(root: Node, path: object) -> Iterator[Node]:
    """The ``<neighbor>`` rules of a tileset's ``<neighbors>`` element (WFC, MarkovJunior)."""
    xn = root.find("neighbors")
    if xn is None:
        raise FormatError(f"<{root.tag}> has no <neighbors> element", path=path, line=root.line)
    return xn.iter("neighbor")


def neighbor_side(
    node: Node,
    side: str,
    path: object,
    tiles: Container[str],
    *,
    name_first: bool,
    forms: tuple[str, str],
) -> tuple[str, str | None]:
    """A ``<neighbor>``'s ``side`` attribute (``left``, ``right``, ...): one word, the tile
    name, or two, the tile name (``name_first`` or last) and a turn; ``forms`` spells the
    two for messages (``("name", "name k")``). Returns the tile name, one of ``tiles``,
    and the turn (``None`` when not given)."""
    text = node.get(side)
    if text is None:
        raise FormatError(f"<neighbor> has no {side!r} attribute", path=path, line=node.line)
    parts = text.split()
    if not 1 <= len(parts) <= 2:
        raise FormatError(
            f"<neighbor> {side}={text!r}: expected {forms[0]!r} or {forms[1]!r}",
            path=path,
            line=node.line,
        )
    nm = parts[0] if name_first else parts[-1]
    if nm not in tiles:
        raise FormatError(f"<neighbor> {side}: unknown tile {nm!r}", path=path, line=node.line)
    turn = None if len(parts) == 1 else parts[1] if name_first else parts[0]
    return nm, turn


def load_image(path: Path, *, where: object = None) -> NDArray[np.uint8]:
    """An RGBA uint8 array (rows top to bottom) from an image file, as a FormatError on
    anything unreadable."""
    from PIL import Image

    check_file(path)
    try:
        with Image.open(path) as im:
            if im.width * im.height > 4_000_000:
                raise FormatError(f"image {im.width}x{im.height} is too large", path=path)
            arr = np.asarray(im.convert("RGBA"), dtype=np.uint8)
    except FormatError:
        raise
    except Exception as e:  # PIL raises many kinds of errors on bad files
        raise FormatError(
            f"cannot read image ({type(e).__name__}: {e})", path=where or path
        ) from None
    return arr


# ---------------------------------------------------------------------------- writers
@dataclass(frozen=True, eq=False)
class Output:
    """A label grid to write, with what its model says about the labels.

    Build it with :meth:`of`; every writer of :mod:`csplab.io.registry` takes one.

    Attributes
    ----------
    grid : int32 array
        Labels, ``-1`` for unassigned cells.
    names, name, meta :
        Label names, the model's name and meta (kept by the text formats).
    model : ExampleModel or RuleSet, optional
        Supplies tile pictures, voxels and pieces.
    periodic : bool, optional
        Whether the grid wraps around (pictures of the overlapping model depend on it).
    colors, empty, pieces :
        One RGB colour per label, the empty-space label and label -> mesh file.
    example : ExampleModel, optional
        Written as it is by the example formats (set by :func:`csplab.io.write_example`).
    """

    grid: NDArray[np.int32]
    names: tuple[str, ...] | None = None
    name: str = ""
    meta: Mapping[str, Any] = field(default_factory=dict)
    model: ExampleModel | RuleSet | None = None
    periodic: bool | None = None
    colors: NDArray[np.uint8] | None = None
    empty: int | None = None
    pieces: Mapping[int, str] = field(default_factory=dict)
    example: ExampleModel | None = None

    @classmethod
    def of(
        cls,
        grid: ArrayLike,
        *,
        model: ExampleModel | RuleSet | None = None,
        names: Sequence[str] | None = None,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        periodic: bool | None = None,
        example: ExampleModel | None = None,
    ) -> Output:
        """The output of ``grid``; names, colours, the empty label and pieces come from
        ``model`` unless given."""
        from csplab.example import ExampleModel
        from csplab.io.ruleset import RuleSet

        g = np.asarray(grid, dtype=np.int32)
        if names is None and model is not None:
            names = model.names
        meta = dict(meta or {})
        if isinstance(model, ExampleModel) and "label_ids" in model.meta:
            meta.setdefault("label_ids", model.meta["label_ids"])  # write the file's ids
        if isinstance(model, ExampleModel) and "topology" in model.meta:
            meta.setdefault("topology", model.meta["topology"])  # hex, tri ... (pictures, .grid)
        colors = empty = None
        pieces: dict[int, str] = {}
        if isinstance(model, RuleSet):
            colors = model.label_colors()
            empty = model.empty
            pieces = dict(model.meta.get("pieces", {}))
        elif isinstance(model, ExampleModel) and model.meta.get("colors") is not None:
            colors = np.asarray(model.meta["colors"], dtype=np.uint8)
            empty = model.meta.get("empty")
        return cls(
            g,
            names=None if names is None else tuple(str(n) for n in names),
            name=name,
            meta=dict(meta or {}),
            model=model,
            periodic=periodic,
            colors=colors,
            empty=empty,
            pieces=pieces,
            example=example,
        )

    def to_example(self) -> ExampleModel:
        """The grid as an :class:`ExampleModel` (``example`` when set)."""
        from csplab.example import ExampleModel

        if self.example is not None:
            return self.example
        return ExampleModel(self.grid, names=self.names, name=self.name, meta=self.meta)

    def tile_voxels(self) -> Output:
        """The grid with every cell replaced by its tile's voxels (a rule set with voxel
        tiles, as MarkovJunior writes them): colour ``c`` becomes label ``c - 1``, empty
        voxels ``-1``; ``self`` when the model has no voxel tiles."""
        from csplab.io.ruleset import RuleSet

        m = self.model
        if not isinstance(m, RuleSet) or m.voxels is None:
            return self
        vox = m.expand_voxels(self.grid)
        assert m.voxel_palette is not None
        return Output(
            vox.astype(np.int32) - 1,
            name=self.name,
            meta=self.meta,
            model=m,
            periodic=self.periodic,
            colors=m.voxel_palette[1:],
            empty=-1,
        )


def read_json_file(path: str | Path) -> Any:
    """A JSON file (no comments) parsed, with the checks of every csplab reader: a regular
    file of at most 50 MB (``csplab.io._json.MAX_JSON_BYTES``), valid JSON without ``NaN``
    or ``Infinity``, nesting the parser can follow; a :class:`FormatError` line naming the
    file otherwise. A parse over :data:`csplab.progress.DELAY_S` gets one line on stderr
    (``csplab: parsing FILE (N MB) ...``)."""
    from csplab import progress
    from csplab.io._json import MAX_JSON_BYTES, load_json

    p = Path(path)
    data = read_bytes(p)
    if len(data) > MAX_JSON_BYTES:
        raise FormatError(
            f"the file has {len(data) / 1e6:.0f} MB; csplab reads JSON files of at most "
            f"{MAX_JSON_BYTES // 1_000_000} MB",
            path=p,
        )

    with progress.notice_after(f"parsing {p} ({len(data) / 1e6:.0f} MB)"):
        return load_json(data, path=p)
