"""Catalog gap: how often Alg. 3.1 chooses outside the exact catalog C*, and how late the
failure shows.

Alg. 3.1 picks labels from the arc-consistent catalog C, which may hold labels that no
solution has (C ≠ C*, Sec. 3.3.4, Fig. 3.5). A choice outside C* makes the partial model
impossible to complete; the algorithm notices only when a domain empties, possibly many
steps later (Fig. 3.6). For each run this experiment replays Alg. 3.1's trace against a
completability oracle (:mod:`csplab.engine.completability`): ``"sat"`` (incremental SAT,
through :func:`csplab.exact.catalog_gap`) when python-sat is installed, else ``"brute"``
(the exact depth-first search :class:`~csplab.engine.completability.SearchCompletability`;
the experiment keeps its published name):

* the **first bad step**: the first assignment after which the partial model cannot be
  completed (:func:`~csplab.engine.completability.first_inconsistent_prefix`, a binary
  search over prefixes: completability only ever turns false). Reported **1-based** (the
  step count of Alg. 3.1, like the failure step), as stored results always were;
* the **failure step**: the assignment at which Alg. 3.1 found an empty domain;
* with ``per_step``: at every step taken from a completable state, C and C* at the chosen
  cell, giving the probability that a uniform choice there is bad (|C \\ C*| / |C|).

Successful runs made no bad choice (a solution proves every prefix completable).

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("catalog_gap").trials(quick=True, examples=["line"], sizes=[4],
...                                              seeds=1)
>>> len(trials), trials[0].params["oracle"] in ("sat", "brute")
(1, True)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from csplab.deps import available
from csplab.engine.completability import (
    SearchCompletability,
    catalog_at,
    first_inconsistent_prefix,
)
from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import (
    Experiment,
    Report,
    example_names,
    group_rows,
    size_for,
    sweep_defaults,
)
from csplab.experiments.figures import new_figure, outside_legend, save_figure
from csplab.experiments.stats import median_iqr, wilson
from csplab.experiments.trial import Trial, record
from csplab.problem import Problem

__all__ = ["CatalogGap", "measure", "oracle_methods"]


def oracle_methods() -> list[str]:
    """The experiment's oracles usable here, best first: ``"sat"`` (needs python-sat) and
    ``"brute"`` (:class:`~csplab.engine.completability.SearchCompletability`)."""
    return ["sat", "brute"] if available("pysat") else ["brute"]


def measure_exact(trial: Trial, example: ExampleModel, problem: Problem) -> dict[str, Any]:
    """The same measure through :func:`csplab.exact.catalog_gap` (incremental SAT, one
    call per step only when the chosen label differs from the last witness solution)."""
    from csplab.exact import catalog_gap

    opts = trial.options
    per_step = bool(trial.params.get("per_step"))
    v: Any = catalog_gap(
        problem, rng=trial.seed, order=opts.get("order", "scanline"),
        choice=opts.get("choice", "uniform"), sizes=per_step,
    )  # fmt: skip
    st = v.stats
    status = st.get("alg31_status", "solved")
    T = int(st.get("steps_taken", 0))
    stats: dict[str, Any] = {"steps": T, "cells": problem.n, "oracle": "sat (csplab.exact)",
                             "oracle_calls": int(st.get("sat_calls", 0))}  # fmt: skip
    if status == "unsat":
        return record(status, st.get("time_s", 0.0), stats)
    first_bad: int | None = None
    if status == "failed":
        stats["fail_step"] = T
        if st.get("unsat"):
            stats["unsat_undetected"] = True
        elif v.witness is not None:
            first_bad = int(v.witness["step"]) + 1
            stats["first_bad"] = first_bad
            stats["delay"] = T - first_bad
    stats["good_steps"] = T if status == "solved" else (first_bad - 1 if first_bad else 0)
    stats["bad_choice"] = int(first_bad is not None)
    if per_step and (status == "solved" or first_bad is not None):
        upto = T if first_bad is None else first_bad
        gaps = []
        total = 0.0
        for t, e in enumerate(st["per_step"][:upto]):
            c, cs = int(e[3]), int(e[4])
            if cs < c:
                gaps.append([t + 1, c, cs])
                total += 1 - cs / c
        stats.update(gap_steps=len(gaps), expected_bad=total, checked_steps=upto, _gaps=gaps)
    stats["oracle_s"] = float(st.get("time_s", 0.0))
    return record(status, st.get("time_s", 0.0), stats)


def measure(trial: Trial, example: ExampleModel, problem: Problem) -> dict[str, Any]:
    """Run Alg. 3.1 and locate its first bad choice (see the module docstring)."""
    import time

    if trial.params.get("oracle") == "sat":
        return measure_exact(trial, example, problem)

    from csplab.solvers import solve

    r = solve(problem, "catalog", rng=trial.seed, **trial.options)
    trace = np.asarray(r.trace if r.trace is not None else np.zeros((0, 2)), dtype=np.int64)
    T = int(trace.shape[0])
    stats: dict[str, Any] = {"steps": T, "cells": problem.n}
    if r.status == "unsat":
        return record(r.status, r.time_s, stats)
    t0 = time.perf_counter()
    oracle = SearchCompletability(problem)
    first_bad: int | None = None
    if r.status == "failed":
        stats["fail_step"] = T
        if not oracle.completable([], []):
            stats["unsat_undetected"] = True  # unsatisfiable, yet C was not empty
        else:
            k = first_inconsistent_prefix(oracle, trace, full_inconsistent=True)
            assert k is not None
            first_bad = k + 1  # 1-based in the stored rows: step k + 1 of Alg. 3.1
            stats["first_bad"] = first_bad
            stats["delay"] = T - first_bad
    good_steps = T if r.status == "solved" else (first_bad - 1 if first_bad else 0)
    stats["good_steps"] = good_steps
    stats["bad_choice"] = int(first_bad is not None)
    if trial.params.get("per_step") and (r.status == "solved" or first_bad is not None):
        upto = T if first_bad is None else first_bad
        gaps: list[list[int]] = []
        total_gap = 0.0
        for t in range(upto):
            x, b = int(trace[t, 0]), int(trace[t, 1])
            cand, star = catalog_at(oracle, problem, trace[:t, 0], trace[:t, 1], x)
            if len(star) < cand.size:
                gaps.append([t + 1, int(cand.size), len(star)])
                total_gap += 1 - len(star) / cand.size
            if b not in star and first_bad is not None and t + 1 != first_bad:
                raise InputError(f"per-step C* disagrees with the binary search at step {t + 1}")
            oracle.fix([x], [b])
        stats["gap_steps"] = len(gaps)
        stats["expected_bad"] = total_gap
        stats["checked_steps"] = upto
        stats["_gaps"] = gaps
    stats["oracle"] = "brute"  # the experiment's name for the search oracle, as stored
    stats["oracle_calls"] = oracle.calls
    stats["oracle_s"] = time.perf_counter() - t0
    return record(r.status, r.time_s, stats)


class CatalogGap(Experiment):
    name = "catalog_gap"
    title = "Catalog gap: Alg. 3.1 choices outside C* and when failures show"
    description = (
        "fraction of Alg. 3.1 steps choosing outside the exact catalog C*, first bad step vs "
        "failure step, by example and size"
    )
    defaults = sweep_defaults(
        examples=["fig3_5a", "fig3_6a"], sizes="4:12:2", nz=6, seeds=100, order="scan:yx",
        boundary="none", oracle="auto", per_step=True,
    )  # fmt: skip
    quick = {"examples": ["fig3_5a"], "sizes": "4,6", "seeds": 10}
    uses = frozenset(defaults) - {"oracle", "per_step", "nz"}

    def add_arguments(self, p: Any) -> None:
        p.add_argument("--nz", type=int, help="nz for 3D examples (default 6)")
        p.add_argument("--oracle", choices=["auto", "sat", "brute"], help="completability oracle")
        p.add_argument(
            "--per-step", dest="per_step", action="store_true", default=None,
            help="compute C* at the chosen cell at every step (default on)",
        )  # fmt: skip
        p.add_argument("--no-per-step", dest="per_step", action="store_false")

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        if config["oracle"] == "auto":
            config["oracle"] = oracle_methods()[0]
        elif config["oracle"] not in oracle_methods():
            raise InputError(f"oracle {config['oracle']!r} is not available here")

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        trials: list[Trial] = []
        opts = self.solver_options(config, "catalog")
        params = {"options": opts, "oracle": config["oracle"], "per_step": bool(config["per_step"])}
        loaded, examples = self.load_examples(config)
        for spec, E in loaded:
            for s in config["sizes"]:
                size = size_for(E, int(s), int(config["nz"]))
                for seed in self.seeds(config):
                    trials.append(
                        Trial(
                            self.name, spec, E.hash(), size, "catalog", params, seed,
                            config["boundary"], bool(config["periodic"]),
                            "csplab.experiments.catalog_gap:measure",
                        )
                    )  # fmt: skip
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        names = example_names(r["example"] for r in rows)
        groups = group_rows(rows, lambda r: (names[r["example"]], r["size"]))
        table = []
        for (ex, size), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], _cells(kv[0][1]))):
            st = [r["stats"] for r in rs]
            failed = [s for s in st if "fail_step" in s]
            bad = [s for s in failed if "first_bad" in s]
            good = sum(int(s.get("good_steps", 0)) for s in st)
            nbad = sum(int(s.get("bad_choice", 0)) for s in st)
            lo, hi = wilson(nbad, good + nbad)
            delays = [s["delay"] for s in bad]
            per = [s for s in st if "checked_steps" in s]
            checked = sum(s["checked_steps"] for s in per)
            table.append(
                {
                    "example": ex, "size": size, "runs": len(rs),
                    "failed": len(failed),
                    "unsat_undetected": sum(bool(s.get("unsat_undetected")) for s in st),
                    "choice_steps": good + nbad, "bad_choices": nbad,
                    "bad_rate": nbad / (good + nbad) if good + nbad else float("nan"),
                    "bad_lo95": lo, "bad_hi95": hi,
                    "gap_step_share": (sum(s["gap_steps"] for s in per) / checked
                                       if checked else float("nan")),
                    "expected_bad_per_run": (float(np.mean([s["expected_bad"] for s in per]))
                                             if per else float("nan")),
                    "delay_median": median_iqr(delays)[0],
                    "delay_max": max(delays) if delays else float("nan"),
                    "immediate": (sum(d == 0 for d in delays) / len(delays)
                                  if delays else float("nan")),
                }
            )  # fmt: skip
        rep.tables["catalog gap"] = table
        rep.notes.append(
            "choice_steps = Alg. 3.1 steps taken from a completable partial model; "
            "bad_choices = those whose label was outside C* (at most one per run: after it "
            "nothing can be completed); bad_rate with a 95% Wilson interval. gap_step_share = "
            "share of those steps where C ≠ C* at the chosen cell; expected_bad_per_run = sum "
            "over steps of |C \\ C*| / |C| (the expected number of bad choices of a uniform "
            "choice, per run). delay = failure step − first bad step (0: the bad choice "
            "emptied a domain at once); immediate = share of bad choices with delay 0."
        )
        pts = [
            (names[r["example"]], r["size"], r["stats"]) for r in rows if "first_bad" in r["stats"]
        ]
        if pts and self.draw_figures:
            rep.figures += self._plot(pts, out)
        return rep

    def _plot(self, pts: list[tuple[str, str, dict[str, Any]]], out: Path) -> list[Path]:
        fig, axes = new_figure(1, 2, figsize=(10, 4))
        keys = [f"{e} {s}" for e, s in sorted({(e, s) for e, s, _ in pts},
                                                key=lambda k: (k[0], _cells(k[1])))]  # fmt: skip
        hi = max(st["fail_step"] for _, _, st in pts)
        for k in keys:
            sel = [st for e, s, st in pts if f"{e} {s}" == k]
            axes[0].scatter([st["first_bad"] for st in sel], [st["fail_step"] for st in sel],
                            s=12, alpha=0.7, label=k)  # fmt: skip
        axes[0].plot([1, hi], [1, hi], "k:", lw=0.8)
        axes[0].set_xlabel("first bad step (choice outside C*)")
        axes[0].set_ylabel("failure step (empty catalog)")
        axes[0].set_xscale("log")
        axes[0].set_yscale("log")
        delays = [st["delay"] for _, _, st in pts]
        top = max(delays)
        axes[1].hist(delays, bins=np.arange(-0.5, max(top, 4) + 1.5, max(1, (top + 1) // 40 or 1)),
                     color="tab:gray", rwidth=0.9)  # fmt: skip
        axes[1].set_xlabel("delay = failure step − first bad step")
        axes[1].set_ylabel("failed runs")
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        handles, labels = axes[0].get_legend_handles_labels()
        outside_legend(fig, handles=handles, labels=labels, bbox_to_anchor=(1.0, 0.95),
                       ncol=1 + len(keys) // 24)  # fmt: skip
        return save_figure(fig, out / self.name)


def _cells(size: str) -> int:
    return int(np.prod([int(v) for v in size.split("x")]))
