"""Table 3.1: for each example, k, the output size and the computation times.

The thesis gives, per example, the size of the displayed result, the number of labels k, the
time to generate the displayed model and the time for a 40×40×10 model, using Alg. 3.1 when
it succeeds on the example and Alg. 3.4 with 10×10×10 blocks otherwise (times include the
retries). This experiment measures the same columns on any example, with ``seeds`` trials
per cell (median times), and adds one column per solver (any registered solver spec; by
default every installed one).

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("table3_1").trials(quick=True)
>>> sorted({(t.size, t.solver) for t in trials})
[((6, 6, 4), 'blocks'), ((6, 6, 4), 'catalog'), ((8, 8, 4), 'blocks'), ((8, 8, 4), 'catalog')]
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import (
    Experiment,
    Report,
    example_names,
    group_rows,
    load_examples,
    setting_of,
    sweep_defaults,
)
from csplab.experiments.figures import new_figure, outside_legend, save_figure
from csplab.experiments.stats import median_iqr
from csplab.experiments.trial import Trial
from csplab.grids import parse_shape

__all__ = ["THESIS_TABLE_3_1", "Table31"]

# Table 3.1 of the thesis (minutes): name -> (output size, k, displayed, 40x40x10)
THESIS_TABLE_3_1: dict[str, tuple[str, int, float, float]] = {
    "Parliament": ("50x50x10", 95, 4.0, 2.6),
    "Castle": ("50x50x10", 62, 0.6, 0.4),
    "Escheresque": ("60x60x10", 107, 4.3, 1.5),
    "City at Night": ("80x80x10", 120, 1.2, 0.3),
    "Canyon": ("120x60x10", 53, 1.3, 0.3),
    "Forest": ("50x50x12", 33, 0.5, 0.3),
    "Gadgets": ("30x30x10", 43, 0.3, 0.6),
    "Library": ("35x40x10", 71, 1.3, 1.3),
}

# displayed sizes of the built-in examples (chosen like the thesis' results)
DISPLAYED: dict[str, str] = {"city": "80x80x10", "castle": "50x50x10", "canal": "60x60x10"}


def installed_solvers() -> list[str]:
    """Registered solvers whose dependencies are installed, ``catalog`` and ``blocks`` first."""
    from csplab.solvers import available_solvers

    names = [s["name"] for s in available_solvers() if s.get("installed")]
    first = [n for n in ("catalog", "blocks") if n in names]
    return first + [n for n in names if n not in first]


def _shape_2d_or_3d(example: ExampleModel, text: str) -> tuple[int, ...]:
    shp = parse_shape(text)
    if example.ndim == 2 and len(shp) == 3 and shp[2] > 1:
        shp = shp[:2]
    return shp


class Table31(Experiment):
    name = "table3_1"
    title = "Table 3.1: output size, k and computation time per example"
    description = (
        "k, displayed size, time for the displayed size and for 40x40x10 (Alg. 3.1 when it "
        "succeeds, else 10x10x10 blocks), plus one column per solver"
    )
    defaults = sweep_defaults(
        examples=["city", "castle", "canal"], displayed={}, compare="40x40x10",
        solvers="installed", seeds=5, options={"blocks.block": 10}, time_limit=600.0,
    )  # fmt: skip
    quick = {
        "examples": ["castle"],
        "displayed": {"castle": "8x8x4"},
        "compare": "6x6x4",
        "solvers": ["catalog", "blocks"],
        "seeds": 1,
        "options": {"blocks.block": 4},
        "time_limit": 60.0,
    }
    uses = frozenset(defaults) - {"displayed", "compare"}

    def add_arguments(self, p: Any) -> None:
        p.add_argument(
            "--displayed",
            type=_displayed_arg,
            help="displayed size: one size for all examples or EXAMPLE=SIZE,... "
            "(default: city 80x80x10, castle 50x50x10, canal 60x60x10, else 50x50x10)",
        )
        p.add_argument("--compare", help="the common comparison size (default 40x40x10)")

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        if config["solvers"] == "installed" or config["solvers"] == ["installed"]:
            config["solvers"] = installed_solvers()
        if isinstance(config["displayed"], str):
            config["displayed"] = _displayed_arg(config["displayed"])
        parse_shape(config["compare"], what="--compare")
        for v in config["displayed"].values():
            parse_shape(v, what="--displayed")
        if not config["solvers"]:
            raise InputError("no solver to run")

    def displayed_size(self, config: dict[str, Any], spec: str, E: ExampleModel) -> tuple[int, ...]:
        d = config["displayed"]
        text = d.get(spec) or d.get(E.name) or d.get("*") or DISPLAYED.get(E.name) or "50x50x10"
        return _shape_2d_or_3d(E, text)

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        trials: list[Trial] = []
        loaded, examples = self.load_examples(config)
        for spec, E in loaded:
            sizes = dict.fromkeys(
                [self.displayed_size(config, spec, E), _shape_2d_or_3d(E, config["compare"])]
            )
            for size in sizes:
                trials += self.solver_trials(config, spec, E, size)
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        cell = group_rows(rows, lambda r: (r["example"], r["size"], setting_of(r)))
        long = []
        for (ex, size, setting), rs in sorted(cell.items()):
            ok = [r for r in rs if r["status"] == "solved"]
            med, lo, hi = median_iqr([r["time_s"] for r in rs])
            long.append(
                {
                    "example": ex, "size": size, "solver": setting, "trials": len(rs),
                    "solved": len(ok), "median_s": med, "q25_s": lo, "q75_s": hi,
                    "statuses": ",".join(sorted({r["status"] for r in rs})),
                }
            )  # fmt: skip
        wide = []
        shown: dict[str, tuple[str, str]] = {}
        exs = dict.fromkeys(r["example"] for r in rows)
        specs = dict(load_examples(list(exs))) if exs else {}
        for ex in exs:
            E = specs[ex]
            disp = "x".join(map(str, self.displayed_size(config, ex, E)))
            comp = "x".join(map(str, _shape_2d_or_3d(E, config["compare"])))
            shown[ex] = (disp, comp)
            row: dict[str, Any] = {"example": ex, "k": E.K, "output size": disp}
            cs = config["compare"]
            row["compare size"] = comp
            for label, size in (("displayed", disp), (cs, comp)):
                cat = next((x for x in long if (x["example"], x["size"], x["solver"])
                            == (ex, size, "catalog")), None)  # fmt: skip
                blk = next((x for x in long if (x["example"], x["size"], x["solver"])
                            == (ex, size, "blocks")), None)  # fmt: skip
                if cat is not None and cat["solved"] == cat["trials"]:
                    method, t = "Alg. 3.1", cat["median_s"]
                elif blk is not None:
                    method, t = "Alg. 3.4 (blocks)", blk["median_s"]
                else:
                    method, t = "–", float("nan")
                row[f"method {label}"] = method
                row[f"time {label} (s)"] = t
                if cat is not None:
                    row[f"Alg. 3.1 solved {label}"] = f"{cat['solved']}/{cat['trials']}"
            for x in long:
                if x["example"] == ex and x["size"] == comp:
                    row[f"{x['solver']} {cs} (s)"] = x["median_s"] if x["solved"] else float("nan")
                    row[f"{x['solver']} solved {cs}"] = f"{x['solved']}/{x['trials']}"
            wide.append(row)
        # a model file is named by its stem (its path stays in the configuration block)
        names = example_names(exs)
        for x in [*long, *wide]:
            x["example"] = names.get(str(x["example"]), x["example"])
        shown = {names[ex]: v for ex, v in shown.items()}
        rep.tables["per solver"] = long
        rep.tables["Table 3.1"] = wide
        rep.notes.append(
            "Times are medians over the seeds, in seconds (the thesis gives minutes, on 2009 "
            "hardware, for its own models). 'method' follows the thesis: Alg. 3.1 when it "
            "solved every seed at that size, else Alg. 3.4 with the configured blocks; times "
            "include the retries. Solver columns give the median time at the comparison size "
            "(– when no seed was solved) and how many seeds were solved."
        )
        rep.notes.append(
            "Thesis Table 3.1 (minutes): "
            + "; ".join(
                f"{k} {v[0]} k={v[1]}: {v[2]} / {v[3]}" for k, v in THESIS_TABLE_3_1.items()
            )
        )
        if long and self.draw_figures:
            rep.figures += self._plot(long, shown, out)
        return rep

    def _plot(
        self, long: list[dict[str, Any]], sizes: dict[str, tuple[str, str]], out: Path
    ) -> list[Path]:
        import numpy as np

        exs = list(sizes)
        solvers = list(dict.fromkeys(x["solver"] for x in long))
        fig, axes = new_figure(1, 2, figsize=(10, 3.8))
        w = 0.8 / max(1, len(solvers))
        for ax, which in zip(axes, (1, 0), strict=True):
            for j, s in enumerate(solvers):
                vals = []
                for ex in exs:
                    m = next((x for x in long if x["example"] == ex and x["solver"] == s
                              and x["size"] == sizes[ex][which]), None)  # fmt: skip
                    vals.append(m["median_s"] if m and m["solved"] else np.nan)
                ax.bar(np.arange(len(exs)) + j * w, vals, w, label=s)
            ticks = [f"{ex}\n{sizes[ex][which]}" for ex in exs]
            ax.set_xticks(np.arange(len(exs)) + w * (len(solvers) - 1) / 2, ticks, fontsize=8)
            ax.set_yscale("log")
            ax.set_ylabel("median time (s), solved runs only")
            ax.set_title("comparison size" if which else "displayed size", fontsize=9)
            ax.grid(alpha=0.3, axis="y")
        fig.tight_layout()
        outside_legend(axes[1])
        return save_figure(fig, out / self.name)


def _displayed_arg(text: str) -> dict[str, str]:
    if "=" not in text:
        parse_shape(text, what="--displayed")
        return {"*": text}
    out: dict[str, str] = {}
    for part in text.split(","):
        k, sep, v = part.partition("=")
        if not sep:
            raise InputError(f"--displayed {text!r}: use SIZE or EXAMPLE=SIZE,EXAMPLE=SIZE")
        parse_shape(v, what="--displayed")
        out[k.strip()] = v.strip()
    return out
