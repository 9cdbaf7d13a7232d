"""glTF (``.glb``) of what the page shows in 3D: a voxel model in its tile colours, or the
solids of a continuous model.

A voxel grid is written by the one voxel mesher of csplab (:func:`csplab.io.write_labels`
to ``.obj``: faces between filled and empty cells only, one material per label in the
label colours, ``y`` up) and converted to binary glTF by trimesh; a polyhedral model is
written by :func:`csplab.io.meshes.write_glb`.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.deps import require

__all__ = ["grid_glb", "solids_glb"]


def grid_glb(grid: NDArray[np.int32], model: Any = None) -> bytes:
    """Binary glTF of a 3D label grid: one mesh per label colour, the empty label left out.

    Parameters
    ----------
    grid : int32 array ``[x, y, z]``
        The labels (``z`` up).
    model : ExampleModel or RuleSet, optional
        Supplies the label colours (an example's: one colour per object, as
        :func:`csplab.render.render` draws it), the empty label and voxel tiles.

    Returns
    -------
    bytes
        The ``.glb`` file.

    Raises
    ------
    DependencyError
        When trimesh (the ``mesh`` extra) is not installed.

    Examples
    --------
    >>> g = np.zeros((2, 1, 2), dtype=np.int32); g[0, 0, 0] = 1
    >>> grid_glb(g)[:4]
    b'glTF'
    >>> grid_glb(np.zeros((2, 2, 2), dtype=np.int32))[:4]  # nothing but empty space
    b'glTF'
    """
    tm = require("trimesh", "mesh", "writing glTF")
    from csplab.io import write_labels
    from csplab.io.obj import write_obj
    from csplab.render import model_objects, object_colors

    with tempfile.TemporaryDirectory(prefix="csplab-glb-") as d:
        obj = Path(d) / "model.obj"
        objects = model_objects(model) if model is not None else None
        if objects is not None and not hasattr(model, "label_colors") \
                and model.meta.get("colors") is None:  # fmt: skip
            # labels of one object (a house's walls, roofs ...) in one colour, as pictures
            write_obj(grid, obj, colors=object_colors(objects), names=model.names)
        else:
            write_labels(grid, obj, model=model, periodic=False)
        scene = tm.load(str(obj), force="scene", process=False)
        if not scene.geometry:  # all empty space: the empty scene of the solids' writer
            from csplab.continuous.polyhedra import PolyhedralModel

            return solids_glb(PolyhedralModel([]))
        return bytes(scene.export(file_type="glb"))


def solids_glb(model: Any) -> bytes:
    """Binary glTF of a polyhedral model (:func:`csplab.io.meshes.write_glb`).

    Parameters
    ----------
    model : PolyhedralModel
        The solids.

    Returns
    -------
    bytes
        The ``.glb`` file.
    """
    from csplab.io.meshes import write_glb

    with tempfile.TemporaryDirectory(prefix="csplab-glb-") as d:
        p = Path(d) / "model.glb"
        write_glb(model, p)
        return p.read_bytes()
