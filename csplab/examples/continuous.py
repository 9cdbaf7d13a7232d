"""Built-in continuous (polygon) examples, loadable by name with :func:`load_polygon_example`.

The examples reconstruct the small inputs of the thesis' Chapter 4 (continuous model
synthesis). Each JSON file in ``csplab/examples/continuous/`` has the keys ``"name"``,
``"description"`` (which figure it stands for, what the text pins down and what was chosen)
and ``"polygons"`` (the :class:`~csplab.continuous.model.PolygonModel` schema). The measured
properties (Alg. 3.1 success rates) are checked by ``tests/examples/test_continuous_examples.py``.

Examples
--------
>>> from csplab.examples.continuous import continuous_example_names, load_polygon_example
>>> continuous_example_names()[:2]
['triangle', 'two_objects']
>>> E = load_polygon_example("triangle")
>>> E.labels, E.bounds
((1,), (0.0, 0.0, 4.0, 3.0))
"""

from __future__ import annotations

import json
from importlib import resources

from csplab.continuous.model import PolygonModel
from csplab.errors import InputError

__all__ = [
    "CONTINUOUS_EXAMPLES",
    "continuous_example_names",
    "load_polygon_example",
]

#: name -> (file in ``csplab/examples/continuous/``, one-line description)
CONTINUOUS_EXAMPLES: dict[str, tuple[str, str]] = {
    "triangle": (
        "triangle.json",
        "Fig. 4.10/4.12: a triangle; 8 labels, 3 on a horizontal edge, 5 at an h2/h3 vertex",
    ),
    "two_objects": (
        "two_objects.json",
        "Fig. 4.11/4.14: two labels touching (a triangle standing on a slab)",
    ),
    "concave": (
        "concave.json",
        "Fig. 4.13: a box with a V notch (reflex vertex); catalog 50/50 at 40x40",
    ),
    "stacked_boxes": (
        "stacked_boxes.json",
        "Fig. 4.2: blue and purple boxes stacked, heights 5 and 2 spacings",
    ),
    "infallible": (
        "infallible.json",
        "Figs. 4.28-4.35 kind: an axis-aligned L footprint; catalog 200/200 at 40x40",
    ),
    "fallible": (
        "fallible.json",
        "a dart with a reflex vertex; catalog 0/50 at 40x40, blocks 50/50",
    ),
    "pentagon": (
        "pentagon.json",
        "a pentagon with 5 edge directions; catalog 50/50 at 40x40",
    ),
}


def continuous_example_names() -> list[str]:
    """Names of the built-in continuous examples.

    Returns
    -------
    list of str
        In the order of :data:`CONTINUOUS_EXAMPLES`.

    Examples
    --------
    >>> "fallible" in continuous_example_names()
    True
    """
    return list(CONTINUOUS_EXAMPLES)


def load_polygon_example(name: str) -> PolygonModel:
    """Load a built-in continuous example by name.

    Parameters
    ----------
    name : str
        One of :func:`continuous_example_names`.

    Returns
    -------
    PolygonModel
        The example, named ``name``; its ``meta`` holds the file's ``"description"``.

    Raises
    ------
    InputError
        If ``name`` is not a built-in continuous example (the message lists them).

    Examples
    --------
    >>> E = load_polygon_example("two_objects")
    >>> E.name, E.labels
    ('two_objects', (1, 2))
    >>> load_polygon_example("square")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: unknown continuous example 'square'; built-in continuous examples: ...
    """
    if name not in CONTINUOUS_EXAMPLES:
        raise InputError(
            f"unknown continuous example {name!r}; built-in continuous examples: "
            f"{', '.join(CONTINUOUS_EXAMPLES)}"
        )
    fname = CONTINUOUS_EXAMPLES[name][0]
    path = resources.files(__package__ or "csplab.examples").joinpath("continuous", fname)
    data = json.loads(path.read_text(encoding="utf-8"))
    return PolygonModel.from_json(data, name=name, source=f"csplab/examples/continuous/{fname}")
