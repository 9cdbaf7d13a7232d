"""Model synthesis against the baselines of the seeds on the same examples (thesis Sec. 2.3,
5.1, Fig. 5.1/5.2; 2007 paper Fig. 5).

For each example and seed, model synthesis (``blocks``: it always returns a consistent
model) and every texture method of :mod:`csplab.baselines.texture` make an output of the
same size; each output is measured by the same checker (``Problem.violations``: the arcs it
breaks, 0 for model synthesis by construction), by the distance of its pattern statistics to
the example's (total variation between the frequencies of the distinct 2-wide sub-blocks:
0 when the output uses only the example's patterns in the same proportions), by time, and
on path examples (``loops``) by the number of dead ends (thesis Fig. 5.1).
The report's figure shows one output per method side by side for each example (a middle
slice of 3D outputs).

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("baselines").trials(quick=True)
>>> sorted({t.solver for t in trials})
['model-synthesis', 'texture:efros-leung', 'texture:graphcut']
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.example import ExampleModel
from csplab.experiments.base import Experiment, Report, group_rows
from csplab.experiments.figures import new_figure, save_figure
from csplab.experiments.measures import dead_ends, pattern_distance
from csplab.experiments.stats import median_iqr
from csplab.experiments.trial import Trial, record
from csplab.grids import parse_shape

__all__ = ["Baselines", "measure_baseline"]

METHODS = ("model-synthesis", "texture:efros-leung", "texture:graphcut")


def _make(trial: Trial, example: ExampleModel) -> NDArray[np.int32]:
    from csplab.baselines import run_baseline
    from csplab.grids import from_example
    from csplab.solvers import solve

    if trial.solver == "model-synthesis":
        P = from_example(example, trial.size)
        r = solve(P, "blocks", rng=trial.seed, block=int(trial.params.get("block", 10)))
        return np.asarray(r.grid, dtype=np.int32)
    method = trial.solver.split(":", 1)[1]
    g = run_baseline("texture", example, trial.size, rng=trial.seed, method=method,
                     **trial.params.get("options", {}).get(method, {}))  # fmt: skip
    return np.asarray(g, dtype=np.int32)


def measure_baseline(trial: Trial, example: ExampleModel, problem: Any) -> dict[str, Any]:
    """One output by one method: broken arcs, pattern distance, time."""
    import time

    t0 = time.perf_counter()
    g = _make(trial, example)
    dt = time.perf_counter() - t0
    broken = len(problem.violations(g))
    stats = {
        "violations": broken,
        "arcs": len(problem.arcs),
        "broken_fraction": broken / max(1, len(problem.arcs)),
        "pattern_tv": pattern_distance(g, np.asarray(example.labels)),
        "dead_ends": dead_ends(g, example.names) if g.ndim == 2 else None,
    }
    return record("solved", dt, stats)


class Baselines(Experiment):
    name = "baselines"
    title = "Model synthesis against texture synthesis (Fig. 5.1/5.2)"
    description = (
        "adjacency violations, pattern-statistics distance and time of model synthesis, "
        "Efros-Leung and graph-cut texture synthesis on the same examples"
    )
    defaults = {
        "examples": ["loops", "fig3_10", "fig3_6a", "line", "castle", "city"],
        "size": "40x40",
        "size3d": "24x24x8",
        "seeds": 3,
        "seed0": 0,
        "methods": list(METHODS),
        "options": {"efros-leung": {"window": 5}, "graphcut": {"patch": 6, "overlap": 2}},
    }
    quick = {
        "examples": ["loops", "castle"],
        "size": "12x12",
        "size3d": "8x8x4",
        "seeds": 1,
        "options": {"efros-leung": {"window": 3}, "graphcut": {"patch": 4, "overlap": 2}},
    }
    uses = frozenset({"examples", "seeds", "seed0"})

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        loaded, examples = self.load_examples({**config, "boundary": "none"})
        trials = []
        for spec, E in loaded:
            size = parse_shape(config["size"] if E.ndim == 2 else config["size3d"])
            for m in config["methods"]:
                for seed in self.seeds(config):
                    trials.append(Trial(self.name, spec, E.hash(), size, m,
                                        {"options": config["options"]}, seed=seed,
                                        measure=f"{__name__}:measure_baseline"))  # fmt: skip
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        cell = group_rows(rows, lambda r: (r["example"], r["size"], r["solver"]))
        table = []
        for (ex, size, m), rs in sorted(cell.items()):
            st = [r["stats"] for r in rs]
            table.append({
                "example": ex, "size": size, "method": m, "runs": len(rs),
                "broken arcs (median)": median_iqr([s["violations"] for s in st])[0],
                "broken arcs (range)": f"{min(s['violations'] for s in st)}-"
                                       f"{max(s['violations'] for s in st)}",
                "of arcs": st[0]["arcs"],
                "pattern TV (median)": median_iqr([s["pattern_tv"] for s in st])[0],
                "dead ends (median)": (median_iqr([s["dead_ends"] for s in st])[0]
                                       if st[0].get("dead_ends") is not None else "–"),
                "time s (median)": median_iqr([r["time_s"] for r in rs])[0],
            })  # fmt: skip
        rep.tables["methods"] = table
        rep.notes.append(
            "Broken arcs: adjacency constraints the output breaks (Problem.violations, the "
            "checker of every solver); model synthesis (blocks) breaks none by construction. "
            "Pattern TV: total variation distance between the output's and the example's "
            "2-wide sub-block frequencies. Dead ends (thesis Fig. 5.1): connections of path "
            "pieces that the neighbour does not return, on the path example `loops`."
        )
        if self.draw_figures and rows:
            rep.figures += self._figure(config, out)
        return rep

    def _figure(self, config: dict[str, Any], out: Path) -> list[Path]:
        from csplab.examples import load_model

        specs = list(config["examples"])
        methods = list(config["methods"])
        fig, axes = new_figure(len(specs), len(methods) + 1,
                               figsize=(2.2 * (len(methods) + 1), 2.2 * len(specs)),
                               squeeze=False)  # fmt: skip
        for i, spec in enumerate(specs):
            E = load_model(spec)
            assert isinstance(E, ExampleModel)
            size = parse_shape(config["size"] if E.ndim == 2 else config["size3d"])
            panels = [("example", np.asarray(E.labels))]
            for m in methods:
                t = Trial(self.name, spec, E.hash(), size, m, {"options": config["options"]},
                          seed=int(config["seed0"]))  # fmt: skip
                panels.append((m, np.asarray(_make(t, E))))
            for j, (title, g) in enumerate(panels):
                img = g if g.ndim == 2 else g[:, :, g.shape[2] // 2]
                ax = axes[i][j]
                ax.imshow(img.T, origin="lower", cmap="tab20", vmin=0, vmax=max(E.K - 1, 1),
                          interpolation="nearest")  # fmt: skip
                ax.set_xticks([])
                ax.set_yticks([])
                ax.set_title(f"{spec}: {title}" if j == 0 else title, fontsize=7)
        fig.tight_layout()
        return save_figure(fig, out / self.name)
