"""A failing run of Alg. 3.1 (a ``csplab witness``) replayed step by step for the page: after
each choice, what is left of the catalog C in every cell, until a cell has nothing left.

Examples
--------
>>> from csplab.examples import load_example
>>> w = {"shape": [3, 3], "order": "scan:yx", "choices": [[[0, 0], 2], [[1, 0], 0], [[2, 0], 0]]}
>>> steps = replay(load_example("fig3_5a"), w)
>>> [s["wiped"] != [] for s in steps]
[False, False, False, True]
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["replay"]


def replay(model: Any, witness: dict[str, Any]) -> list[dict[str, Any]]:
    """The catalog after every choice of ``witness`` on the model's problem of its shape.

    Parameters
    ----------
    model : ExampleModel
        The example the witness was found for.
    witness : dict
        ``shape`` and ``choices`` (``[[cell coords], label]``; a ``None`` label is the
        step that found the catalog empty).

    Returns
    -------
    list of dict
        Step 0 is the catalog before any choice (propagated), then one per choice:
        ``cell``, ``label``, ``sizes`` (labels left per cell, ``[x][y]``), ``assigned``
        (the label of each decided cell, else -1), ``wiped`` (cells with no label left)
        and ``consistent``.

    Raises
    ------
    InputError
        When the witness does not fit the model.
    """
    from csplab.catalog import assign, initial_catalog, propagate
    from csplab.errors import InputError
    from csplab.grids import from_example

    shape = tuple(int(s) for s in witness["shape"])
    P = from_example(model, shape)
    C, ok = propagate(P, initial_catalog(P))
    assigned = np.full(shape, -1, dtype=np.int64)

    def step(cell: Any, label: Any) -> dict[str, Any]:
        sizes = C.reshape(*shape, P.K).sum(axis=-1)
        return {
            "cell": cell, "label": label, "sizes": sizes.tolist(),
            "assigned": assigned.tolist(),
            "wiped": np.argwhere(sizes == 0).tolist(), "consistent": bool(ok),
        }  # fmt: skip

    steps = [step(None, None)]
    for coords, label in witness.get("choices", []):
        if label is None or not ok:
            break
        c = tuple(int(v) for v in coords)
        if len(c) != len(shape) or not 0 <= int(label) < P.K:
            raise InputError(f"witness choice {c} <- {label} does not fit the model")
        C, ok = assign(P, C, P.cell(c), int(label))
        assigned[c] = int(label)
        steps.append(step(list(c), int(label)))
    return steps
