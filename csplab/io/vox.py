"""MagicaVoxel ``.vox`` files: write a 3D label grid, read voxel models back.

The format (version 150): ``"VOX "``, a version int, then a ``MAIN`` chunk whose children are
``SIZE`` (``x y z``), ``XYZI`` (a count and ``x y z colour-index`` bytes per voxel) and
``RGBA`` (256 colours; entry ``i`` is colour index ``i + 1``). Every chunk is
``id, content bytes, children bytes, content, children``. MagicaVoxel's ``z`` axis points
up, like csplab's; one model holds at most 256 cells per axis.

:func:`write_vox` stores label ``b`` as colour index ``b + 1`` (so at most 255 labels) and
leaves out the empty-space label; :func:`read_vox` returns the colour indices (0 = empty)
of the first model, and :func:`read_vox_example` an :class:`ExampleModel` whose labels are
``0`` for empty and ``1, 2, ...`` for the colour indices in use.

Examples
--------
>>> import numpy as np, io
>>> g = np.zeros((3, 2, 2), dtype=np.int32); g[0, 0, 0] = 2; g[2, 1, 1] = 1
>>> data = vox_bytes(g, empty=0)
>>> vox = parse_vox(data)
>>> vox.grid.shape, int(vox.grid[0, 0, 0]), int(vox.grid[2, 1, 1]), int(vox.grid.sum())
((3, 2, 2), 3, 2, 5)
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import FormatError, InputError
from csplab.io.common import NO, SURE, Output, read_bytes

__all__ = [
    "VoxModel",
    "parse_vox",
    "read_vox",
    "read_vox_example",
    "sniff",
    "vox_bytes",
    "write_output",
    "write_vox",
]

MAX_SIDE = 256


@dataclass
class VoxModel:
    """The first model of a ``.vox`` file: colour indices ``grid[x, y, z]`` (0 = empty) and
    the 256-entry RGBA ``palette`` (``palette[i]`` is the colour of index ``i``; index 0 is
    unused)."""

    grid: NDArray[np.uint8]
    palette: NDArray[np.uint8]
    models: int = 1


def _chunk(cid: bytes, content: bytes, children: bytes = b"") -> bytes:
    return cid + struct.pack("<ii", len(content), len(children)) + content + children


def vox_bytes(
    grid: ArrayLike, *, empty: int | None = None, colors: ArrayLike | None = None
) -> bytes:
    """The ``.vox`` file content for a 3D label grid (see :func:`write_vox`)."""
    from csplab.render import empty_label_guess, palette

    g = np.asarray(grid)
    if g.ndim == 2:
        g = g[:, :, None]
    if g.ndim != 3:
        raise InputError(f".vox holds 3D grids; this grid has shape {g.shape}")
    if any(s > MAX_SIDE for s in g.shape):
        raise InputError(
            f".vox models hold at most {MAX_SIDE} cells per axis; the grid is "
            f"{'x'.join(map(str, g.shape))}"
        )
    g = g.astype(np.int64)
    K = int(g.max()) + 1 if g.size and g.max() >= 0 else 1
    if colors is not None:
        K = max(K, len(np.asarray(colors)))
    if K > 255:
        raise InputError(f".vox has 255 colours; the grid has {K} labels")
    if empty is None:
        empty = empty_label_guess(g)
    filled = (g >= 0) & (g != empty)
    xs, ys, zs = np.nonzero(filled)
    xyzi = np.stack([xs, ys, zs, g[xs, ys, zs] + 1], axis=1).astype(np.uint8)
    cols = palette(K) if colors is None else np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
    rgba = np.zeros((256, 4), dtype=np.uint8)
    rgba[:, 3] = 255
    rgba[: len(cols), :3] = cols  # entry i = colour index i + 1 = label i
    size = _chunk(b"SIZE", struct.pack("<iii", *g.shape))
    body = _chunk(b"XYZI", struct.pack("<i", len(xyzi)) + xyzi.tobytes())
    pal = _chunk(b"RGBA", rgba.tobytes())
    return b"VOX " + struct.pack("<i", 150) + _chunk(b"MAIN", b"", size + body + pal)


def write_vox(
    grid: ArrayLike,
    path: str | Path,
    *,
    empty: int | None = None,
    colors: ArrayLike | None = None,
) -> None:
    """Write a 3D label grid as a MagicaVoxel model.

    Parameters
    ----------
    grid : int array ``[x, y, z]``
        Labels; ``-1`` (unassigned) and ``empty`` cells are left out.
    empty : int, optional
        The empty-space label (default: the most frequent label of the top layer).
    colors : uint8 array ``(K, 3)``, optional
        One colour per label (default: csplab's palette, as in the PNG pictures).
    """
    from csplab.io.common import write_atomic

    write_atomic(path, vox_bytes(grid, empty=empty, colors=colors))


def parse_vox(data: bytes, *, path: object = "<bytes>") -> VoxModel:
    """Parse ``.vox`` bytes (every chunk is checked; unknown chunks are skipped)."""

    def bad(msg: str) -> FormatError:
        return FormatError(msg, path=path)

    if len(data) < 8 or data[:4] != b"VOX ":
        raise bad("not a MagicaVoxel file (no 'VOX ' magic)")
    pos = 8
    sizes: list[tuple[int, int, int]] = []
    voxels: list[NDArray[np.uint8]] = []
    rgba: NDArray[np.uint8] | None = None
    end = len(data)
    seen_main = False
    while pos < end:
        if pos + 12 > end:
            raise bad(f"truncated chunk header at byte {pos}")
        cid = data[pos : pos + 4]
        n_content, n_children = struct.unpack_from("<ii", data, pos + 4)
        if n_content < 0 or n_children < 0 or pos + 12 + n_content > end:
            raise bad(f"chunk {cid!r} at byte {pos} has an impossible size")
        content = data[pos + 12 : pos + 12 + n_content]
        if cid == b"MAIN":
            if seen_main:
                raise bad("two MAIN chunks")
            seen_main = True
            if pos + 12 + n_content + n_children > end:
                raise bad("MAIN chunk is truncated")
            pos += 12 + n_content  # descend into the children
            continue
        if cid == b"SIZE":
            if n_content < 12:
                raise bad("SIZE chunk is too short")
            sx, sy, sz = struct.unpack_from("<iii", content)
            if not all(1 <= s <= MAX_SIDE for s in (sx, sy, sz)):
                raise bad(f"model size {sx}x{sy}x{sz} is outside 1..{MAX_SIDE}")
            sizes.append((sx, sy, sz))
        elif cid == b"XYZI":
            if n_content < 4:
                raise bad("XYZI chunk is too short")
            (nv,) = struct.unpack_from("<i", content)
            if nv < 0 or 4 + 4 * nv > n_content:
                raise bad(f"XYZI chunk claims {nv} voxels but holds {(n_content - 4) // 4}")
            voxels.append(np.frombuffer(content, dtype=np.uint8, count=4 * nv, offset=4))
        elif cid == b"RGBA":
            if n_content < 1024:
                raise bad("RGBA chunk is too short")
            rgba = np.frombuffer(content, dtype=np.uint8, count=1024).reshape(256, 4)
        pos += 12 + n_content + (n_children if cid != b"MAIN" else 0)
    if not sizes or len(voxels) < 1:
        raise bad("no voxel model (SIZE and XYZI chunks) found")
    sx, sy, sz = sizes[0]
    v = voxels[0].reshape(-1, 4).astype(np.int64)
    if v.size and ((v[:, 0] >= sx).any() or (v[:, 1] >= sy).any() or (v[:, 2] >= sz).any()):
        raise bad(f"a voxel lies outside the model size {sx}x{sy}x{sz}")
    grid = np.zeros((sx, sy, sz), dtype=np.uint8)
    grid[v[:, 0], v[:, 1], v[:, 2]] = v[:, 3]
    pal = np.zeros((256, 4), dtype=np.uint8)
    if rgba is not None:
        pal[1:] = rgba[:255]  # RGBA entry i is colour index i + 1
    else:
        from csplab.render import palette

        pal[1:, :3] = palette(256)[1:]
        pal[:, 3] = 255
    return VoxModel(grid, pal, models=len(sizes))


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for the ``"VOX "`` magic number."""
    return SURE if head.startswith(b"VOX ") else NO


def read_vox(path: str | Path) -> VoxModel:
    """Read the first model of a ``.vox`` file."""
    return parse_vox(read_bytes(path), path=Path(path))


def read_vox_example(path: str | Path) -> Any:
    """A voxel model as an :class:`~csplab.example.ExampleModel`.

    Label 0 is empty space, labels ``1, 2, ...`` the colour indices in use.

    Parameters
    ----------
    path : str or Path
        The ``.vox`` file to read (its first model).

    Returns
    -------
    ExampleModel
        The labels ``[x, y, z]`` (``z`` up) named ``"empty"`` and ``"c<index>"``, with
        the palette colours in ``meta["colors"]`` and ``meta["empty"] = 0``.

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid MagicaVoxel file (no ``VOX``
        magic, a damaged chunk, no model ...).
    """
    from csplab.example import ExampleModel

    vox = read_vox(path)
    used = np.unique(vox.grid)
    used = used[used > 0]
    lut = np.zeros(256, dtype=np.int32)
    lut[used] = np.arange(1, used.size + 1)
    labels = lut[vox.grid]
    names = ["empty", *(f"c{int(c)}" for c in used)]
    colors = np.concatenate([[[225, 225, 225]], vox.palette[used, :3]]).astype(int).tolist()
    meta = {
        "format": "vox",
        "source": str(path),
        "colors": colors,
        "empty": 0,
        "models": vox.models,
    }
    return ExampleModel(labels, names=names, name=Path(path).stem, meta=meta)


def write_output(out: Output, path: Path) -> None:
    """The grid as a MagicaVoxel model (a rule set's voxel tiles composited when they fit).

    Label ``b`` is colour index ``b + 1``; unassigned and empty-space cells are left out.
    When the composited tile voxels exceed 256 per axis, one voxel per cell is written
    with a :class:`UserWarning`.

    Parameters
    ----------
    out : Output
        The grid to write, with its model (voxel tiles), colours and empty-space label.
    path : Path
        The file to write (overwritten).

    Raises
    ------
    InputError
        When the grid is not 2D or 3D, has more than 256 cells along an axis or more than
        255 labels.
    """
    vox = out.tile_voxels()
    if vox is not out and max(vox.grid.shape) > MAX_SIDE:
        import warnings

        warnings.warn(
            f"{path}: the tile voxels make a {'x'.join(map(str, vox.grid.shape))} model, more "
            f"than .vox holds ({MAX_SIDE} per axis); writing one voxel per cell",
            UserWarning,
            stacklevel=3,
        )
    else:
        out = vox
    write_vox(out.grid, path, empty=out.empty, colors=out.colors)
