"""Built-in continuous (polygon) examples, loadable by name with :func:`load_polygon_example`.

The examples reconstruct the small inputs of the thesis' Chapter 4 (continuous model
synthesis). Each JSON file in ``csplab/examples/continuous/`` has the keys ``"name"``,
``"description"`` (which figure it stands for, what the text pins down and what was chosen)
and ``"polygons"`` (the :class:`~csplab.continuous.model.PolygonModel` schema). The measured
properties (Alg. 3.1 success rates) are checked by ``tests/examples/test_continuous_examples.py``.

Examples
--------
>>> from csplab.examples.continuous import CONTINUOUS_EXAMPLES, load_polygon_example
>>> list(CONTINUOUS_EXAMPLES)[:2]
['triangle', 'two_objects']
>>> E = load_polygon_example("triangle")
>>> E.labels, E.bounds
((1,), (0.0, 0.0, 4.0, 3.0))
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from importlib import resources
from importlib.resources.abc import Traversable

from csplab.continuous.model import PolygonModel
from csplab.errors import InputError

__all__ = [
    "CONTINUOUS_EXAMPLES",
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


def example_file(
    table: Mapping[str, tuple[str, str]], folder: str, kind: str, name: str
) -> tuple[Traversable, str]:
    """The packaged file of the built-in continuous example ``name`` of ``table`` (a table
    name -> (file, description) of ``csplab/examples/FOLDER/``) and its source path.

    The one lookup of :func:`load_polygon_example` and
    :func:`~csplab.examples.continuous3d.load_polyhedral_example`.

    Parameters
    ----------
    table : mapping of str to (str, str)
        :data:`CONTINUOUS_EXAMPLES` or :data:`~csplab.examples.continuous3d.POLYHEDRAL_EXAMPLES`.
    folder : str
        The folder of ``csplab/examples/`` that holds the table's files.
    kind : str
        What the table holds, for the message (``"continuous"``, ``"polyhedral"``).
    name : str
        The example's name.

    Returns
    -------
    file : Traversable
        The packaged file (:func:`importlib.resources.as_file` gives a path).
    source : str
        ``csplab/examples/FOLDER/FILE``, for messages.

    Raises
    ------
    InputError
        If ``name`` is not in ``table`` (the message lists the table's names).

    Examples
    --------
    >>> example_file(CONTINUOUS_EXAMPLES, "continuous", "continuous", "triangle")[1]
    'csplab/examples/continuous/triangle.json'
    """
    if name not in table:
        raise InputError(
            f"unknown {kind} example {name!r}; built-in {kind} examples: {', '.join(table)}"
        )
    fname = table[name][0]
    ref = resources.files("csplab.examples").joinpath(folder, fname)
    return ref, f"csplab/examples/{folder}/{fname}"


def load_polygon_example(name: str) -> PolygonModel:
    """Load a built-in continuous example by name.

    Parameters
    ----------
    name : str
        A key of :data:`CONTINUOUS_EXAMPLES`.

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
    ref, source = example_file(CONTINUOUS_EXAMPLES, "continuous", "continuous", name)
    data = json.loads(ref.read_text(encoding="utf-8"))
    return PolygonModel.from_json(data, name=name, source=source)
