"""PNG pictures of label grids (written, never read as grids: a ``.png`` read as a model is
an overlapping-model sample, :mod:`csplab.io.overlap`).

2D grids are drawn as one coloured square per cell, or with a rule set's tile pictures;
3D grids as an isometric view of the non-empty cells (:func:`csplab.render.render`).

Examples
--------
>>> import tempfile, pathlib
>>> from PIL import Image
>>> from csplab.io.common import Output
>>> with tempfile.TemporaryDirectory() as d:
...     p = pathlib.Path(d) / "g.png"
...     write_output(Output.of([[0, 1], [1, 0]]), p)
...     Image.open(p).format
'PNG'
"""

from __future__ import annotations

from pathlib import Path

from csplab.io.common import Output

__all__ = ["write_output"]


def write_output(out: Output, path: Path) -> None:
    """A PNG picture of the grid.

    The rule set's own picture (tile pictures, voxels, the overlapping model's colours) when
    ``out.model`` is a rule set, else one colour per label (3D: an isometric view).

    Parameters
    ----------
    out : Output
        The grid to write, with its model's names, meta, colours and topology.
    path : Path
        The file to write (overwritten).
    """

    import io

    from csplab.io.common import write_atomic
    from csplab.io.ruleset import RuleSet

    buf = io.BytesIO()
    if isinstance(out.model, RuleSet):
        out.model.render(out.grid, periodic=out.periodic).save(buf, format="PNG")
    else:
        from csplab.render import model_objects, render

        K = len(out.names) if out.names is not None else None
        objects = model_objects(out.model) if out.model is not None else None
        topology = out.meta.get("topology")
        img = render(out.grid, K=K, colors=out.colors, objects=objects, topology=topology)
        img.save(buf, format="PNG")
    write_atomic(path, buf.getvalue())
