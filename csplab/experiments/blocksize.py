"""Sec. 3.3.6 / Fig. 3.10: the block-size trade-off of Alg. 3.4.

For each example (at one output size) and each block size ``m`` from 1 to the full model,
run Alg. 3.4 (solver ``blocks``, block ``m × m (× min(m, nz))``) over the seeds, plus Alg. 3.1
(solver ``catalog``) on the same problem as the reference. Per block size the report gives:

* block acceptance rate (blocks kept / blocks tried), per-attempt success rate and retries;
* wall time;
* final consistency (must be 100%: Alg. 3.4 never leaves an inconsistent model);
* expressiveness: fraction of non-empty cells, the largest connected non-empty object (cells
  and bounding box), and the distinct 3×3 (3×3×3 in 3D) patterns of the outputs, compared
  with the patterns of Alg. 3.1's successful outputs (how many of them this block size never
  builds).

With the single rectangle of Fig. 3.10 (example ``fig3_10``), small blocks can only build
rectangles less than a block high: the largest object's smaller side stays below ``m``.

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("blocksize").trials(quick=True)
>>> sorted({t.options.get("block", (0,))[0] for t in trials if t.solver == "blocks"})
[2, 3, 4, 12]
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import (
    Experiment,
    Report,
    background_labels,
    example_names,
    group_rows,
    load_examples,
    sweep_defaults,
)
from csplab.experiments.figures import new_figure, outside_legend, save_figure
from csplab.experiments.measures import (
    objects,
    pack_grid,
    pack_hashes,
    pattern_hashes,
    unpack_grid,
    unpack_hashes,
)
from csplab.experiments.stats import median_iqr, wilson
from csplab.experiments.trial import Trial, grid_digest, record
from csplab.grids import parse_shape
from csplab.problem import Problem

__all__ = ["BlockSize", "measure"]


def default_size(example: ExampleModel) -> tuple[int, ...]:
    """30×30 for 2D examples, 40×40×10 for 3D ones."""
    if example.ndim == 3 and example.shape[2] > 1:
        return (40, 40, 10)
    return (30, 30) if example.ndim == 2 else (30, 30, 1)


def block_shape(m: int, size: tuple[int, ...]) -> tuple[int, ...]:
    """``m`` along every axis, capped at the model size."""
    return tuple(min(m, s) for s in size)


def measure(trial: Trial, example: ExampleModel, problem: Problem) -> dict[str, Any]:
    """Solve once; record consistency, block statistics and expressiveness measures."""
    from csplab.solvers import solve

    r = solve(problem, trial.solver, rng=trial.seed, **trial.options)
    complete = bool(np.all(r.grid >= 0))
    viol = len(problem.violations(r.grid))
    stats: dict[str, Any] = {
        "consistent": bool(complete and viol == 0),
        "final_violations": viol,
        "grid": grid_digest(r.grid),
    }
    for k in ("blocks_tried", "blocks_accepted", "retries", "acceptance_rate", "assigned"):
        if k in r.stats:
            stats[k] = r.stats[k]
    if stats["consistent"]:
        stats.update(objects(r.grid, trial.params["background"]))
        h = pattern_hashes(r.grid, int(trial.params.get("window", 3)))
        stats["patterns"] = int(h.size)
        stats["_patterns"] = pack_hashes(h)
    stats["_grid"] = pack_grid(r.grid)
    return record(r.status, r.time_s, stats)


class BlockSize(Experiment):
    name = "blocksize"
    title = "Sec. 3.3.6, Fig. 3.10: block-size trade-off of Alg. 3.4"
    description = (
        "acceptance, retries, time, consistency and expressiveness (largest object, "
        "non-empty cells, distinct 3x3(x3) patterns vs Alg. 3.1) for block sizes 1..full"
    )
    defaults = sweep_defaults(
        examples=["fig3_10", "castle"], size=None,
        blocks=[1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, "full"], retries=20, seeds=20, window=3,
    )  # fmt: skip
    quick = {
        "examples": ["fig3_10"],
        "size": "12x12",
        "blocks": [2, 3, 4, "full"],
        "seeds": 3,
    }
    uses = frozenset(defaults) - {"blocks", "retries", "window"}

    def add_arguments(self, p: Any) -> None:
        p.add_argument(
            "--blocks", type=_blocks_arg, help="block sizes, e.g. 1,2,4,8,full (default 1..20,full)"
        )
        p.add_argument("--retries", type=int, help="retries per block (default 20)")
        p.add_argument("--window", type=int, help="pattern window (default 3)")

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        config["blocks"] = _blocks_arg(config["blocks"])
        if int(config["retries"]) < 0 or int(config["window"]) < 1:
            raise InputError("--retries must be >= 0 and --window >= 1")

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        trials: list[Trial] = []
        loaded, examples = self.load_examples(config)
        for spec, E in loaded:
            size = parse_shape(config["size"]) if config["size"] else default_size(E)
            common = {"background": background_labels(E), "window": int(config["window"])}
            shapes: dict[tuple[int, ...], None] = {}
            for m in config["blocks"]:
                shapes.setdefault(size if m == "full" else block_shape(int(m), size), None)
            for seed in self.seeds(config):
                for shp in shapes:
                    opts = self.solver_options(config, "blocks")
                    opts.update(block=list(shp), retries=int(config["retries"]))
                    trials.append(
                        Trial(
                            self.name, spec, E.hash(), size, "blocks",
                            {"options": opts, **common}, seed, config["boundary"],
                            bool(config["periodic"]), "csplab.experiments.blocksize:measure",
                        )
                    )  # fmt: skip
                opts = self.solver_options(config, "catalog")
                trials.append(
                    Trial(
                        self.name, spec, E.hash(), size, "catalog", {"options": opts, **common},
                        seed, config["boundary"], bool(config["periodic"]),
                        "csplab.experiments.blocksize:measure",
                    )
                )  # fmt: skip
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        by_ex = group_rows(rows, lambda r: r["example"])
        names = example_names(by_ex)
        table: list[dict[str, Any]] = []
        for spec, rs in by_ex.items():
            ex = names[spec]
            ref = [r for r in rs if r["solver"] == "catalog"]
            blocks = [r for r in rs if r["solver"] == "blocks"]
            groups = group_rows(blocks, lambda r: int(r["params"]["options"]["block"][0]))
            size = [int(v) for v in rs[0]["size"].split("x")]
            whole = [r for r in rs if r["solver"] == "blocks" and _is_full(r, size)]
            # Alg. 3.1's outputs: its successful runs, and the accepted whole-model blocks
            # of Alg. 3.4 (each is a successful Alg. 3.1 run, after retries)
            ref_ok = [r for r in ref if r["stats"].get("consistent")]
            ref_ok += [r for r in whole if r["stats"].get("blocks_accepted", 0) > 0]
            ref_pat = _union(ref_ok)
            for m in sorted(groups):
                full = _is_full(groups[m][0], size)
                table.append(_row(ex, f"blocks m={m}" + (" (full)" if full else ""), m,
                                  groups[m], ref_pat))  # fmt: skip
            if ref:
                table.append(_row(ex, "Alg. 3.1 (catalog)", max(size), ref, ref_pat))
            rep.notes.append(
                f"{ex}: the Alg. 3.1 reference holds {len(ref_ok)} outputs "
                f"({len(ref_pat)} distinct patterns)."
            )
        rep.tables["block size"] = table
        rep.notes.append(
            "m = block side (capped at the model size; 'full' = the whole model, which is "
            "Alg. 3.1 with retries). accept = blocks kept / blocks tried; per-attempt = "
            "blocks kept / attempts; consistent = outputs with zero violations. Object "
            "measures over consistent outputs: nonempty = fraction of cells that are not "
            "empty space/ground, largest = cells of the largest connected non-empty object "
            "(mean, max), thin side = smaller horizontal side of its bounding box (max). "
            "patterns = distinct 3x3(x3) sub-blocks per output (mean); union = over all "
            "seeds; a31_missed = patterns of Alg. 3.1's outputs (its successful runs and the "
            "accepted whole-model blocks) that this setting never produced."
        )
        if table and self.draw_figures:
            rep.figures += self._plot(table, out)
            rep.figures += self._montage(rows, config, out, names)
        return rep

    def _plot(self, table: list[dict[str, Any]], out: Path) -> list[Path]:
        exs = list(dict.fromkeys(t["example"] for t in table))
        from matplotlib.lines import Line2D

        fig, axes = new_figure(2, 2, figsize=(9, 6.4))
        handles: list[Any] = []
        for ex in exs:
            pts = [t for t in table if t["example"] == ex and t["setting"].startswith("blocks")]
            ref = [t for t in table if t["example"] == ex and not t["setting"].startswith("blocks")]
            m = [t["m"] for t in pts]
            (line,) = axes[0, 0].plot(m, [t["accept"] for t in pts], "o-", label=ex)
            handles.append(Line2D([], [], color=line.get_color(), marker="o", label=ex))
            axes[0, 0].plot(m, [t["per_attempt"] for t in pts], "x:", color=line.get_color())
            axes[0, 1].plot(m, [t["median_s"] for t in pts], "o-", color=line.get_color(), label=ex)
            axes[1, 0].plot(m, [t["largest_rel"] for t in pts], "o-", color=line.get_color(),
                            label=f"{ex} largest object")  # fmt: skip
            axes[1, 0].plot(m, [t["nonempty"] for t in pts], "s--", color=line.get_color(),
                            label=f"{ex} non-empty cells")  # fmt: skip
            cov = [1 - t["a31_missed"] / t["a31_patterns"] if t["a31_patterns"] else np.nan
                   for t in pts]  # fmt: skip
            axes[1, 1].plot(m, cov, "o-", color=line.get_color(), label=ex)
            if ref and ref[0]["nonempty"] == ref[0]["nonempty"]:
                axes[1, 0].axhline(ref[0]["largest_rel"], color=line.get_color(), lw=0.8, ls=":")
        axes[0, 0].set_title("block acceptance (o) and per-attempt success (x)", fontsize=9)
        axes[0, 1].set_title("median wall time (s)", fontsize=9)
        axes[0, 1].set_yscale("log")
        axes[1, 0].set_title(
            "largest object / model cells, non-empty fraction (dotted: Alg. 3.1)", fontsize=9
        )
        axes[1, 1].set_title("share of Alg. 3.1's 3x3(x3) patterns produced", fontsize=9)
        for ax in axes.ravel():
            ax.set_xscale("log", base=2)
            ax.set_xlabel("block side m")
            ax.grid(alpha=0.3)
        grey = "0.35"
        handles += [
            Line2D([], [], color=grey, marker="o", ls="-", label="acceptance; largest object"),
            Line2D([], [], color=grey, marker="x", ls=":", label="per-attempt success"),
            Line2D([], [], color=grey, marker="s", ls="--", label="non-empty cells"),
            Line2D([], [], color=grey, lw=0.8, ls=":", label="Alg. 3.1 largest object"),
        ]
        fig.tight_layout()
        # outside the panels, so no legend covers a curve
        outside_legend(fig, handles=handles, bbox_to_anchor=(1.0, 0.97))
        return save_figure(fig, out / self.name)

    def _montage(
        self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path, names: dict[str, str]
    ) -> list[Path]:
        """Outputs of the first seed at a few block sizes (re-run from their seeds)."""
        from csplab.experiments.trial import Trial, problem_for
        from csplab.render import render
        from csplab.solvers import solve

        seed0 = int(config["seed0"])
        first = [r for r in rows if r["seed"] == seed0 and r["solver"] == "blocks"]
        exs = {
            spec: E for spec, E in load_examples(list(dict.fromkeys(r["example"] for r in first)))
        }
        panels: list[tuple[str, Any]] = []
        for ex, E in exs.items():
            rs = sorted((r for r in first if r["example"] == ex),
                        key=lambda r: r["params"]["options"]["block"][0])  # fmt: skip
            pick = (
                rs if len(rs) <= 5 else [rs[i] for i in np.linspace(0, len(rs) - 1, 5).astype(int)]
            )
            for r in pick:
                size = tuple(int(s) for s in r["size"].split("x"))
                if "_grid" in r["stats"]:
                    grid = unpack_grid(r["stats"]["_grid"])
                else:  # stored without its grid: re-run it from its seed
                    t = Trial(self.name, ex, r["example_hash"], size, "blocks", r["params"],
                              r["seed"], r["boundary"], r["periodic"])  # fmt: skip
                    P = problem_for(t, E)
                    grid = solve(P, "blocks", rng=r["seed"], **r["params"]["options"]).grid
                if grid_digest(grid) != r["stats"].get("grid"):
                    raise InputError(
                        f"re-running {names[ex]} seed {r['seed']} did not reproduce the stored grid"
                    )
                m = r["params"]["options"]["block"][0]
                bg = r["params"]["background"]
                panels.append(
                    (f"{names[ex]}, m={m}", render(grid, K=E.K, empty=bg[0] if bg else None))
                )
        if not panels:
            return []
        cols = min(5, len(panels))
        nrow = (len(panels) + cols - 1) // cols
        fig, axes = new_figure(nrow, cols, figsize=(2.6 * cols, 2.7 * nrow), squeeze=False)
        for ax in axes.ravel():
            ax.axis("off")
        for ax, (title, img) in zip(axes.ravel(), panels, strict=False):
            ax.imshow(np.asarray(img), interpolation="nearest")
            ax.set_title(title, fontsize=8)
        fig.suptitle(f"Alg. 3.4 outputs, seed {seed0}", fontsize=9)
        fig.tight_layout()
        return save_figure(fig, out / f"{self.name}_outputs")


def _blocks_arg(value: Any) -> list[int | str]:
    items = value.split(",") if isinstance(value, str) else list(value)
    out: list[int | str] = []
    for it in items:
        s = str(it).strip().lower()
        if s == "full":
            out.append("full")
            continue
        try:
            m = int(s)
        except ValueError:
            raise InputError(f"block size {it!r} must be a positive integer or 'full'") from None
        if m < 1:
            raise InputError(f"block size {m} must be >= 1")
        out.append(m)
    if not out:
        raise InputError("give at least one block size")
    return out


def _is_full(row: dict[str, Any], size: list[int]) -> bool:
    return [int(v) for v in row["params"]["options"]["block"]] == size


def _union(rs: list[dict[str, Any]]) -> set[int]:
    u: set[int] = set()
    for r in rs:
        p = r["stats"].get("_patterns")
        if p:
            u.update(int(v) for v in unpack_hashes(p))
    return u


def _row(
    ex: str, setting: str, m: int, rs: list[dict[str, Any]], ref_pat: set[int]
) -> dict[str, Any]:
    ok = [r for r in rs if r["stats"].get("consistent")]
    st = [r["stats"] for r in ok]
    tried = sum(r["stats"].get("blocks_tried", 1) for r in rs)
    kept = sum(r["stats"].get("blocks_accepted", int(r["status"] == "solved")) for r in rs)
    retries = sum(r["stats"].get("retries", 0) for r in rs)
    n_cells = int(np.prod([int(s) for s in rs[0]["size"].split("x")]))
    pats = _union(ok)
    lo, _ = wilson(len(ok), len(rs))
    largest = [s.get("largest_object", 0) for s in st]
    thin = [min(s["largest_extent"][:2]) if s.get("largest_extent") else 0 for s in st]
    return {
        "example": ex,
        "setting": setting,
        "m": m,
        "trials": len(rs),
        "consistent": len(ok) / len(rs),
        "cons_lo95": lo,
        "accept": kept / tried if tried else float("nan"),
        "per_attempt": kept / (tried + retries) if tried + retries else float("nan"),
        "retries": retries / len(rs),
        "median_s": median_iqr([r["time_s"] for r in rs])[0],
        "nonempty": float(np.mean([s.get("nonempty_fraction", 0) for s in st]))
        if st
        else float("nan"),
        "largest": float(np.mean(largest)) if st else float("nan"),
        "largest_max": max(largest) if st else 0,
        "largest_rel": float(np.mean(largest)) / n_cells if st else float("nan"),
        "thin_side_max": max(thin) if st else 0,
        "patterns": float(np.mean([s.get("patterns", 0) for s in st])) if st else float("nan"),
        "union": len(pats),
        "a31_patterns": len(ref_pat),
        "a31_missed": len(ref_pat - pats),
    }
