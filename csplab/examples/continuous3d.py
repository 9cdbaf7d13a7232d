"""Built-in polyhedral examples (continuous model synthesis in 3D), loadable by name with
:func:`load_polyhedral_example`.

The examples stand for the inputs of the 2008 paper (Merrell & Manocha, "Continuous Model
Synthesis": Table 1, Fig. 1, 8-13). Each is a Wavefront OBJ file in
``csplab/examples/continuous3d/`` written by ``python -m csplab.examples.build_continuous3d``
(:mod:`csplab.examples.build_continuous3d`); its header comment says which figure it stands
for, what the paper pins down and what was chosen. Every solid is an ``o`` group with
``usemtl label_N`` (its label). That each synthesizes with ``catalog``, ``blocks`` and
``sat`` without violations is checked by ``tests/examples/test_continuous3d_examples.py``; sizes and
times against Table 1 are printed by ``benchmarks/bench_continuous3d.py``.

Examples
--------
>>> from csplab.examples.continuous3d import load_polyhedral_example, polyhedral_example_names
>>> polyhedral_example_names()[:3]
['tetrahedron', 'houses', 'skyscrapers']
>>> E = load_polyhedral_example("houses")
>>> E.name, E.labels, E.n_polygons
('houses', (1, 2), 11)
"""

from __future__ import annotations

from importlib import resources

from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.errors import InputError
from csplab.examples.continuous import CONTINUOUS_EXAMPLES, load_polygon_example

__all__ = [
    "GROUNDS",
    "POLYHEDRAL_EXAMPLES",
    "load_continuous_example",
    "load_polyhedral_example",
    "polyhedral_example_names",
]

#: name -> (file in ``csplab/examples/continuous3d/``, one-line description)
POLYHEDRAL_EXAMPLES: dict[str, tuple[str, str]] = {
    "tetrahedron": (
        "tetrahedron.obj",
        "Fig. 8/9: a corner tetrahedron, 4 polygons; its top vertex has the nine states of Fig. 9",
    ),
    "houses": (
        "houses.obj",
        "Fig. 12: a box house (label 1) under a 45-degree gable roof (label 2), 11 polygons "
        "(paper: 39)",
    ),
    "skyscrapers": (
        "skyscrapers.obj",
        "Fig. 1: a setback tower of three stacked boxes 6x6, 4x4, 2x2 (labels 1-3), 18 "
        "polygons (paper: 27)",
    ),
    "arches": (
        "arches.obj",
        "Fig. 11: a pointed arch, pillars and lintel with 45-degree haunches, 11 polygons "
        "(paper: 20)",
    ),
    "terrain": (
        "terrain.obj",
        "Fig. 10a/b: a ground slab (label 1) with a 45-degree rock frustum (label 2), 12 "
        "polygons (paper: 22)",
    ),
    "fractals": (
        "fractals.obj",
        "Fig. 10c/d: a self-similar stack of cubes 4, 2, 1 on each other's corner, 18 "
        "polygons (paper: 8)",
    ),
    "pentagons": (
        "pentagons.obj",
        "Fig. 13: a lattice-pentagon prism (label 1) with a roof slab (label 2), 14 polygons "
        "(paper: 33)",
    ),
}


#: name -> the example's ground (:func:`~csplab.continuous.csp3d.ground_faces`): the faces
#: of its bounding box past which it continues. The buildings, arches and fractals stand on
#: the bottom of their box (``z-``: they go on below it, so no output solid floats); the
#: terrain is a window onto an infinite ground slab (every face but the sky). Kept in the
#: example's ``meta["ground"]``, which :func:`~csplab.continuous.synthesis.synthesize` reads.
GROUNDS: dict[str, str] = {
    "houses": "z-",
    "skyscrapers": "z-",
    "arches": "z-",
    "terrain": "window",
    "fractals": "z-",
    "pentagons": "z-",
}


def polyhedral_example_names() -> list[str]:
    """Names of the built-in polyhedral examples.

    Returns
    -------
    list of str
        In the order of :data:`POLYHEDRAL_EXAMPLES`.

    Examples
    --------
    >>> "pentagons" in polyhedral_example_names()
    True
    """
    return list(POLYHEDRAL_EXAMPLES)


def load_polyhedral_example(name: str) -> PolyhedralModel:
    """Load a built-in polyhedral example by name.

    Parameters
    ----------
    name : str
        One of :func:`polyhedral_example_names`.

    Returns
    -------
    PolyhedralModel
        The example, named ``name``; its ``meta`` holds the one-line ``"description"``
        and, if it stands on one, its ``"ground"`` (:data:`GROUNDS`).

    Raises
    ------
    InputError
        If ``name`` is not a built-in polyhedral example (the message lists them).

    Examples
    --------
    >>> E = load_polyhedral_example("tetrahedron")
    >>> E.name, E.labels, E.n_polygons
    ('tetrahedron', (1,), 4)
    >>> load_polyhedral_example("cube")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: unknown polyhedral example 'cube'; built-in polyhedral examples: ...
    """
    from csplab.io.meshes import read_obj_model

    if name not in POLYHEDRAL_EXAMPLES:
        raise InputError(
            f"unknown polyhedral example {name!r}; built-in polyhedral examples: "
            f"{', '.join(POLYHEDRAL_EXAMPLES)}"
        )
    fname, description = POLYHEDRAL_EXAMPLES[name]
    source = f"csplab/examples/continuous3d/{fname}"
    ref = resources.files(__package__ or "csplab.examples").joinpath("continuous3d", fname)
    with resources.as_file(ref) as path:
        M = read_obj_model(path, labels="materials")
    meta = {**M.meta, "description": description}
    if name in GROUNDS:
        meta["ground"] = GROUNDS[name]
    return PolyhedralModel(M.solids, name=name, meta=meta, source=source)


def load_continuous_example(name: str) -> PolygonModel | PolyhedralModel:
    """A built-in continuous example of either dimension by name: a polygon model
    (:func:`~csplab.examples.continuous.load_polygon_example`) or a polyhedral one
    (:func:`load_polyhedral_example`).

    >>> load_continuous_example("tetrahedron").ndim, load_continuous_example("triangle").ndim
    (3, 2)
    """
    if name in POLYHEDRAL_EXAMPLES:
        return load_polyhedral_example(name)
    if name in CONTINUOUS_EXAMPLES:
        return load_polygon_example(name)
    raise InputError(
        f"unknown continuous example {name!r}; built-in continuous examples: "
        f"{', '.join([*CONTINUOUS_EXAMPLES, *POLYHEDRAL_EXAMPLES])}"
    )
