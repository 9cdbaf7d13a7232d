"""``csplab show``: write a PNG picture of any model file.

Example grids (the formats of :mod:`csplab.io.registry` that give an ``ExampleModel``) are
drawn as coloured cells in 2D and as an isometric view of the non-empty cells in 3D; rule
sets (tilesets and samples) as a sheet of their labels (tile pictures or colours, with
names); polygon models (continuous model synthesis) filled in their label colours.
``--tiles TILESET`` draws a result grid with a tileset's pictures. Cells a failed or
timed-out run left unassigned (-1 in its .npy) are drawn dark in 2D and left out in 3D.
An existing picture is kept unless ``--force`` is given.

Exit codes: 0 on success, 2 bad input.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from csplab.cli.common import add_model_option, check_output_path, load_model, model_options
from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE", help="model file or built-in example name")
    p.add_argument(
        "--out", help="PNG to write (default: FILE's name with .png, in the current directory)"
    )
    p.add_argument(
        "--tiles", metavar="TILESET", help="draw the grid FILE with this tileset's pictures"
    )
    p.add_argument("--force", action="store_true", help="overwrite the PNG if it exists")
    p.add_argument("--scale", type=int, help="pixels per cell (grids)")
    p.add_argument("--empty", type=int, help="3D: the label left out (default: guessed)")
    p.add_argument("--legend", action="store_true", help="grids: add a legend object -> colour")
    add_model_option(p, "FILE (or of --tiles)")


def run(args: argparse.Namespace) -> int:
    from csplab.example import ExampleModel
    from csplab.io.ruleset import RuleSet
    from csplab.render import empty_label_guess, model_objects, render

    if args.scale is not None and not 1 <= args.scale <= 64:
        raise InputError("--scale must be 1..64")
    opts = model_options(args.model_option)
    src = Path(args.file)
    out = Path(args.out) if args.out else Path.cwd() / f"{src.stem}.png"
    if out.suffix.lower() != ".png":
        raise InputError(f"--out {out}: the picture is a .png")
    if args.out is None and src.exists() and out.resolve() == src.resolve():
        out = out.with_name(f"{src.stem}.show.png")
    reads = [(r, Path(f)) for r, f in (("the file", args.file), ("--tiles", args.tiles)) if f]
    check_output_path(out, "--out" if args.out else "the picture", force=args.force,
                      inputs=[(r, p) for r, p in reads if p.is_file()])  # fmt: skip
    partial = _partial_npy(src)
    if args.tiles:
        tiles = load_model(args.tiles, opts)
        if partial is not None:
            g = partial
        else:
            grid_model = load_model(args.file)
            if not isinstance(grid_model, ExampleModel):
                raise InputError(f"{args.file} is not a grid file")
            g = np.asarray(grid_model.labels)
        if not isinstance(tiles, RuleSet):
            raise InputError(f"--tiles {args.tiles} is not a tileset")
        while g.ndim > tiles.ndim and g.shape[-1] == 1:
            g = g[..., 0]
        if g.max() >= tiles.K:
            raise InputError(f"{args.file} has label {int(g.max())}; {args.tiles} has {tiles.K}")
        img = tiles.render(g, scale=args.scale)
        what = f"{args.file} with the pictures of {args.tiles}"
    elif partial is not None:
        empty = args.empty
        if empty is None and partial.ndim == 3 and partial.shape[2] > 1:
            empty = empty_label_guess(partial)
        img = render(partial, scale=args.scale, empty=empty, legend=args.legend)
        what = f"{'x'.join(map(str, partial.shape))} grid {src.stem}"
    else:
        model = load_model(args.file, opts)
        if isinstance(model, PolyhedralModel):
            from csplab.io.meshes import write_png as write_mesh_png

            write_mesh_png(model, out)
            print(f"wrote {out}: {len(model.solids)} solids of {model.name or src.stem}, "
                  f"labels {list(model.labels)}, {model.n_polygons} polygons")  # fmt: skip
            return 0
        if isinstance(model, PolygonModel):
            from csplab.io.polygons import write_png

            write_png(model, out)
            print(f"wrote {out}: {len(model)} polygons of {model.name or src.stem}, labels "
                  f"{list(model.labels)}")  # fmt: skip
            return 0
        if isinstance(model, RuleSet):
            img = model.sheet()
            what = f"{model.K} labels of {model.meta.get('format')} tileset {model.name}"
        else:
            colors = model.meta.get("colors")
            empty = args.empty if args.empty is not None else model.meta.get("empty")
            img = render(model.labels, K=model.K, scale=args.scale, empty=empty, colors=colors,
                         objects=model_objects(model), legend=args.legend,
                         topology=model.meta.get("topology"))  # fmt: skip
            what = f"{'x'.join(map(str, model.shape))} grid {model.name}"
            if model.meta.get("topology"):
                what += f" ({model.meta['topology']})"
    if partial is not None and (unassigned := int((partial < 0).sum())):
        what += f", {unassigned} unassigned cells (drawn dark in 2D, left out in 3D)"
    img.save(out, format="PNG")
    print(f"wrote {out} ({img.width}x{img.height} px): {what}")
    return 0


def _partial_npy(src: Path) -> NDArray[np.int32] | None:
    """The labels of an ``.npy`` result grid holding unassigned cells (``-1``), else
    ``None`` (the file is read as any model file)."""
    from csplab.cli.common import load_grid
    from csplab.io.npy import MAGIC

    if not src.is_file() or src.suffix.lower() != ".npy":
        return None
    from csplab.io.common import read_bytes

    if not read_bytes(src, len(MAGIC)).startswith(MAGIC):
        return None
    g = load_grid(str(src), None)
    return g if g.size and int(g.min()) < 0 else None
