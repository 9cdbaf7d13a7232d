"""Experiment ``constraints``: success rate and time of each solver with global constraints.

Examples may be tilesets: the default is the WFC pipes tileset and the DeBroglie road
tileset of the test data (run from the repository's root), the built-in path example
``loops`` and the 3D ``city``. For each, the constraints are *one connected structure*:
every cell that is not background (:func:`~csplab.experiments.base.background_labels`: the
empty space and ground of ``boundary="auto"``, else the most frequent label; a tileset's
empty or border label) belongs to one connected component
(:class:`~csplab.constraints.Connected`), and *a bounded amount of it*: between ``lo`` and
``hi`` of the cells are non-background (:class:`~csplab.constraints.Count`, default 5% and
30%); a tileset's own constraints (the road tileset's path) hold as well. ``--constraints
FILE`` replaces the generated ones by the file's. Each solver runs once per seed
(``catalog@restarts=20`` retries, as WaveFunctionCollapse does); a trial succeeds when the
solver returns a grid that :meth:`~csplab.problem.Problem.violations` accepts, so the
exact solvers show what the constraints cost and the others how often they get there. The
report is :class:`~csplab.experiments.fig3_8.Fig38`'s: rate with 95% Wilson intervals and
median time per size, and a figure.

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("constraints").trials(quick=True)
>>> sorted({c["type"] for c in trials[0].params["constraints"]})
['connected', 'count']
"""

from __future__ import annotations

from typing import Any

import numpy as np

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import background_labels
from csplab.experiments.fig3_8 import Fig38

__all__ = ["ConstraintsExperiment"]


class ConstraintsExperiment(Fig38):
    name = "constraints"
    title = "Global constraints: success rate and time per solver"
    description = (
        "success rate (95% Wilson) and median time vs nx = ny with a connectivity and a count "
        "constraint, one curve per example and solver"
    )
    defaults = {
        **Fig38.defaults,
        "examples": [
            "tests/io/data/pipes.xml",
            "tests/io/data/tiny_debroglie.json",
            "loops",
            "city",
        ],
        "sizes": "8,12,16",
        "nz": 6,
        "solvers": [
            "sat",
            "cpsat",
            "asp",
            "backtrack",
            "catalog@restarts=20",
            "blocks@sweeps=4,restarts=3",
        ],
        "seeds": 4,
        "time_limit": 10.0,
        "fraction": [0.05, 0.30],
    }
    quick = {
        "examples": ["loops", "city"],
        "sizes": "6",
        "nz": 4,
        "seeds": 2,
        "solvers": ["sat", "catalog@restarts=5"],
    }
    uses = frozenset(defaults) - {"fraction"}

    def add_arguments(self, p: Any) -> None:
        super().add_arguments(p)
        p.add_argument("--fraction", type=float, nargs=2, metavar=("LO", "HI"),
                       help="the count constraint: fractions of non-background cells "
                       "(default 0.05 0.30)")  # fmt: skip

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        lo, hi = (float(f) for f in config["fraction"])
        if not 0 <= lo <= hi <= 1:
            raise InputError("--fraction needs 0 <= LO <= HI <= 1")

    def constraint_entries(
        self, config: dict[str, Any], example: ExampleModel, size: tuple[int, ...]
    ) -> list[dict[str, Any]]:
        if config.get("constraints"):
            return super().constraint_entries(config, example, size)
        bg = set(background_labels(example))
        fg = [b for b in range(example.K) if b not in bg]
        if not fg:
            raise InputError(f"{example.name}: every label is background; nothing to connect")
        n = int(np.prod(size))
        lo, hi = (float(f) for f in config["fraction"])
        return [
            {"type": "connected", "labels": fg},
            {"type": "count", "labels": fg, "min": int(np.ceil(lo * n)), "max": int(hi * n)},
        ]
