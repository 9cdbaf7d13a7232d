"""Built-in example models, loadable by name with :func:`load_example`; :func:`load_model`
takes the name of any built-in example (grid, polygons, polyhedra) or a model file.

The 2D examples reconstruct the thesis' small figures (each file documents which figure it
stands for and which property it has; where the text does not pin the exact grid, the file
says so and the tests check the stated property). The 3D examples are csplab's own.

Examples
--------
>>> from csplab.examples import load_example, example_names
>>> "line" in example_names()
True
>>> load_example("fig3_1b").labels[:, :, ].tolist()
[[0, 1, 0], [1, 0, 1], [0, 1, 0]]
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel

if TYPE_CHECKING:
    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.io.ruleset import RuleSet

__all__ = ["ALIASES", "EXAMPLES", "example_info", "example_names", "load_example", "load_model"]

# name -> (file, one-line description); aliases below
EXAMPLES: dict[str, tuple[str, str]] = {
    "fig3_1a": ("fig3_1a_empty.grid", "E0, Fig. 3.1(a): all empty space; one solution"),
    "fig3_1b": ("fig3_1b_checkerboard.grid", "E1, Fig. 3.1(b): checkerboard; two solutions"),
    "line": ("fig3_1c_line.grid", "Fig. 3.1(c)/3.12: a line in empty space; infallible"),
    "fig3_1d": ("fig3_1d_unique.grid", "E3, Fig. 3.1(d): no repeated label; no larger model"),
    "fig3_4a": ("fig3_4a_column.grid", "Fig. 3.4(a)/3.9: a column; infallible, 3x2 not 2x2 proof"),
    "fig3_5a": ("fig3_5a_fallible.grid", "E_F, Fig. 3.5(a): a 2 forces a 6; fallible, C != C*"),
    "fig3_15": ("fig3_15_infallible.grid", "E_I, Fig. 3.15: fig3_5a, enclosed 0 -> 9; infallible"),
    "fig3_6a": ("fig3_6a_pairs.grid", "E_F, Fig. 3.6(a): 2s in pairs; fallible, detected late"),
    "fig3_16": ("fig3_16_pairs.grid", "E_I, Fig. 3.16: fig3_6a + labels >= 10; infallible"),
    "fig3_10": ("fig3_10_rectangle.grid", "Fig. 3.10(a): a rectangle; small blocks grow it thin"),
    "loops": ("loops.grid", "csplab's own: closed loops of connecting path pieces (Fig. 5.1)"),
    "pillar": ("pillar.grid", "3D, 2007 paper Fig. 2: base, shaft, capital; no levitation"),
    "city": ("city3d.grid", "3D, csplab's own: a city block, K=119; Alg. 3.1 never failed"),
    "castle": ("castle3d.grid", "3D, csplab's own: castle walls, towers, K=63; fails often"),
    "canal": ("canal3d.grid", "3D, csplab's own: canal town, bridges, K=80; fails seldom"),
    "hexriver": ("hexriver.grid", "hexagonal (hex:odd-r), csplab's own: a river with banks"),
    "trifan": ("trifan.grid", "triangular (tri), csplab's own: rosettes of six triangles"),
}
ALIASES: dict[str, str] = {
    "E0": "fig3_1a",
    "empty": "fig3_1a",
    "E1": "fig3_1b",
    "checkerboard": "fig3_1b",
    "fig3_1c": "line",
    "fig3_12": "line",
    "E3": "fig3_1d",
    "fig3_9": "fig3_4a",
    "pairs": "fig3_6a",
    "rectangle": "fig3_10",
}


def example_names() -> list[str]:
    """Names of the built-in grid examples.

    Returns
    -------
    list of str
        The names :func:`load_example` takes (without the aliases), in catalogue order.
    """
    return list(EXAMPLES)


def example_info() -> list[tuple[str, str]]:
    """``(name, description)`` of every built-in example: grids, then polygon models and
    polyhedral models (continuous model synthesis, :mod:`csplab.examples.continuous`,
    :mod:`csplab.examples.continuous3d`)."""
    from csplab.examples.continuous import CONTINUOUS_EXAMPLES
    from csplab.examples.continuous3d import POLYHEDRAL_EXAMPLES

    grids = [(k, v[1]) for k, v in EXAMPLES.items()]
    polys = [(k, f"polygons: {v[1]}") for k, v in CONTINUOUS_EXAMPLES.items()]
    return grids + polys + [(k, f"polyhedra: {v[1]}") for k, v in POLYHEDRAL_EXAMPLES.items()]


def load_example(name: str) -> ExampleModel:
    """Load a built-in grid example by name.

    Parameters
    ----------
    name : str
        A name of :func:`example_names` or an alias such as ``"E1"`` or ``"checkerboard"``.

    Returns
    -------
    ExampleModel
        The example, named by its canonical name.

    Raises
    ------
    InputError
        When ``name`` is neither a built-in example nor an alias (the message lists them).
    """
    key = ALIASES.get(name, name)
    if key not in EXAMPLES:
        raise InputError(f"unknown example {name!r}; built-in examples: {', '.join(EXAMPLES)}")
    from csplab.io.gridtext import parse_grid

    fname = EXAMPLES[key][0]
    text = resources.files(__package__).joinpath(fname).read_text(encoding="utf-8")
    ex = parse_grid(text, path=f"csplab/examples/{fname}", name=key)
    return ex


def load_model(
    spec: str | Path, options: dict[str, Any] | None = None
) -> ExampleModel | RuleSet | PolygonModel | PolyhedralModel:
    """A built-in example name (``csplab info`` lists them) or a model file path (any
    format of :func:`csplab.io.read_model`, with its loader ``options``).

    An existing file wins over a built-in name; a name that is neither raises.

    Examples
    --------
    >>> load_model("line").shape
    (4, 3)
    >>> load_model("line", {"N": 2})
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: model options apply to model files only, not to the built-in \
example 'line'
    """
    from csplab.io import read_model

    p = Path(spec)
    if p.exists():
        return read_model(p, **(options or {}))
    text = str(spec)
    builtin: Callable[[str], ExampleModel | PolygonModel | PolyhedralModel] | None = None
    if text in EXAMPLES or text in ALIASES:
        builtin = load_example
    else:  # csplab.continuous (shapely, scipy) only for the continuous examples
        from csplab.examples.continuous import CONTINUOUS_EXAMPLES, load_polygon_example
        from csplab.examples.continuous3d import POLYHEDRAL_EXAMPLES, load_polyhedral_example

        if text in CONTINUOUS_EXAMPLES:
            builtin = load_polygon_example
        elif text in POLYHEDRAL_EXAMPLES:
            builtin = load_polyhedral_example
    if builtin is not None:
        if options:
            raise InputError(
                f"model options apply to model files only, not to the built-in example {text!r}"
            )
        return builtin(text)
    if p.suffix or "/" in text or "\\" in text:
        raise FormatError("no such file", path=text)
    raise InputError(
        f"{text!r} is neither a model file nor a built-in example "
        f"({', '.join([*EXAMPLES, *CONTINUOUS_EXAMPLES, *POLYHEDRAL_EXAMPLES])}); "
        "see `csplab info`"
    )
