"""Fig. 3.8: the success rate of Alg. 3.1 as the model grows.

For each example model and each ``nx = ny`` in ``sizes`` (``nz`` fixed, 10 by default, for
3D examples), run the solver with seeds ``seed0 … seed0 + seeds - 1`` and count how often it
returns a solution. The report gives the rate with its 95% Wilson interval per point, one
curve per example (and per solver when several are compared: ``catalog``, ``blocks``,
``perfect``, ``backtrack`` … any registered solver spec), and the median time.

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("fig3_8").trials(quick=True)
>>> len(trials), sorted({t.size for t in trials})[:2]
(12, [(4, 4), (4, 4, 4)])
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import (
    Experiment,
    Report,
    example_names,
    setting_of,
    size_for,
    sweep_defaults,
)
from csplab.experiments.figures import new_figure, outside_legend, save_figure
from csplab.experiments.stats import median_iqr, wilson
from csplab.experiments.trial import Trial

__all__ = ["Fig38"]


class Fig38(Experiment):
    name = "fig3_8"
    title = "Fig. 3.8: success rate of Alg. 3.1 versus model size"
    description = (
        "success rate (95% Wilson intervals) vs nx = ny, nz fixed, one curve per example and solver"
    )
    defaults = sweep_defaults(
        examples=["city", "castle", "canal"], sizes="5:50:5", nz=10, solvers=["catalog"],
        seeds=100, constraints=None,
    )  # fmt: skip
    quick = {
        "examples": ["castle", "line"],
        "sizes": "4,8",
        "nz": 4,
        "seeds": 3,
    }
    uses = frozenset(defaults)
    tilesets = True

    def add_arguments(self, p: Any) -> None:
        p.add_argument("--nz", type=int, help="nz for 3D examples (default 10)")

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        if int(config["nz"]) < 1:
            raise InputError("--nz must be >= 1")

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        trials: list[Trial] = []
        loaded, examples = self.load_examples(config)
        for spec, E in loaded:
            for s in config["sizes"]:
                size = size_for(E, int(s), int(config["nz"]))
                trials += self.solver_trials(config, spec, E, size)
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        groups: dict[tuple[str, str, int], list[dict[str, Any]]] = defaultdict(list)
        sizes: dict[tuple[str, str, int], str] = {}
        names = example_names(r["example"] for r in rows)
        for r in rows:
            nx = int(r["size"].split("x")[0])
            key = (names[r["example"]], setting_of(r), nx)
            groups[key].append(r)
            sizes[key] = r["size"]
        table = []
        for (ex, solver, nx), rs in sorted(
            groups.items(), key=lambda kv: (kv[0][0], kv[0][1], kv[0][2])
        ):
            k = sum(r["status"] == "solved" for r in rs)
            lo, hi = wilson(k, len(rs))
            med, _, _ = median_iqr([r["time_s"] for r in rs])
            table.append(
                {
                    "example": ex, "solver": solver, "nx": nx, "size": sizes[(ex, solver, nx)],
                    "trials": len(rs), "solved": k, "rate": k / len(rs), "lo95": lo,
                    "hi95": hi, "median_s": med,
                }
            )  # fmt: skip
        rep.tables["success rate"] = table
        # the figure as a table: one row per size, one column per curve
        curves = sorted({(t["example"], t["solver"]) for t in table})
        wide: dict[int, dict[str, Any]] = {}
        for t in table:
            label = t["example"] if len(config["solvers"]) == 1 else f"{t['example']}/{t['solver']}"
            row = wide.setdefault(t["nx"], {"nx": t["nx"]})
            row[label] = f"{t['rate']:.2f} [{t['lo95']:.2f}, {t['hi95']:.2f}] ({t['trials']})"
        rep.tables["figure as table"] = [wide[k] for k in sorted(wide)]
        if table and self.draw_figures:
            rep.figures += self._plot(table, curves, config, out)
        rep.notes.append(
            "Success = the solver returned a consistent model (status `solved`); intervals "
            "are 95% Wilson score intervals; the count of trials is in parentheses."
        )
        return rep

    def _plot(
        self,
        table: list[dict[str, Any]],
        curves: list[tuple[str, str]],
        config: dict[str, Any],
        out: Path,
    ) -> list[Path]:
        fig, ax = new_figure(figsize=(6.4, 4.2))
        solvers = sorted({c[1] for c in curves})
        styles = ["-", "--", ":", "-."]
        markers = "osd^v<>"
        for i, (ex, solver) in enumerate(curves):
            pts = [t for t in table if t["example"] == ex and t["solver"] == solver]
            x = [t["nx"] for t in pts]
            y = [t["rate"] for t in pts]
            err = [[t["rate"] - t["lo95"] for t in pts], [t["hi95"] - t["rate"] for t in pts]]
            exs = {c[0] for c in curves}
            label = ex if len(solvers) == 1 else solver if len(exs) == 1 else f"{ex} ({solver})"
            ax.errorbar(
                x, y, yerr=err, label=label, capsize=3, marker=markers[i % len(markers)],
                linestyle=styles[solvers.index(solver) % len(styles)], linewidth=1.4,
                markersize=4,
            )  # fmt: skip
        ax.set_xlabel("nx = ny" + (f"  (nz = {config['nz']} for 3D models)"))
        ax.set_ylabel("success rate")
        ax.set_ylim(-0.03, 1.03)
        ax.grid(alpha=0.3)
        outside_legend(ax)
        n = min(t["trials"] for t in table)
        what = solvers[0] if len(solvers) == 1 else "each solver"
        one = {c[0] for c in curves}
        ax.set_title(
            f"Success rate of {what}{' on ' + next(iter(one)) if len(one) == 1 else ''}\n"
            f"(order {config['order']} unless stated, boundary {config['boundary']}, "
            f"≥{n} trials per point, 95% Wilson intervals)",
            fontsize=9,
        )
        return save_figure(fig, out / self.name)
