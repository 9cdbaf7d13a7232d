"""Experiments that reproduce the thesis' figures and tables and compare solvers.

Each experiment is a grid of trials (example × size × solver × parameters × seed) run by
:func:`~csplab.experiments.runner.run_trials` into a SQLite
:class:`~csplab.experiments.store.ResultsStore`, then summarised by its report (tables as
markdown and CSV, figures as PNG and SVG). Re-running the same sweep runs only the trials
missing from the store. ``csplab experiment NAME`` is the command line; :func:`run` the
Python entry point.

========================  ============================================================
``fig3_8``                success rate of Alg. 3.1 vs model size (Fig. 3.8)
``blocksize``             Alg. 3.4 block-size trade-off (Sec. 3.3.6, Fig. 3.10)
``table3_1``              k, output size and times per example and solver (Table 3.1)
``catalog_gap``           Alg. 3.1 choices outside the exact catalog C*
``sampling_bias``         label / 2×2-pattern frequencies vs exact uniform sampling
``table1_continuous``     continuous 3D: Table 1, Figs. 1, 10-13 of the 2008 paper
``baselines``             model synthesis against texture synthesis (Fig. 5.1/5.2)
``infallibility``         proved / refuted / undecided per model, with certificates
========================  ============================================================

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> d = Path(tempfile.mkdtemp())
>>> summary, report = run("fig3_8", quick=True, store=d / "r.sqlite", out=d, jobs=1,
...                       progress=False, examples=["line"], seeds=2)
>>> summary.ran, report.tables["success rate"][0]["rate"]
(4, 1.0)
>>> run("fig3_8", quick=True, store=d / "r.sqlite", out=d, jobs=1, progress=False,
...     examples=["line"], seeds=2)[0].skipped
4
"""

from __future__ import annotations

import importlib
import os
from pathlib import Path
from typing import Any

from csplab.errors import InputError
from csplab.experiments.base import Experiment, Report, provenance_note
from csplab.experiments.runner import RunSummary, config_hash, run_trials, stale_counts
from csplab.experiments.store import ResultsStore

__all__ = [
    "EXPERIMENTS",
    "Experiment",
    "Report",
    "ResultsStore",
    "RunSummary",
    "get_experiment",
    "run",
]

# name -> "module:Class"
EXPERIMENTS: dict[str, str] = {
    "fig3_8": "csplab.experiments.fig3_8:Fig38",
    "blocksize": "csplab.experiments.blocksize:BlockSize",
    "table3_1": "csplab.experiments.table3_1:Table31",
    "catalog_gap": "csplab.experiments.catalog_gap:CatalogGap",
    "sampling_bias": "csplab.experiments.sampling_bias:SamplingBias",
    "table1_continuous": "csplab.experiments.table1_continuous:Table1Continuous",
    "baselines": "csplab.experiments.baselines:Baselines",
    "constraints": "csplab.experiments.constraints:ConstraintsExperiment",
    "infallibility": "csplab.experiments.infallibility:Infallibility",
}
ALIASES: dict[str, str] = {"fig3_10": "blocksize", "table3.1": "table3_1", "fig3.8": "fig3_8"}

DEFAULT_STORE = Path("results") / "csplab-experiments.sqlite"


def get_experiment(name: str) -> Experiment:
    """The experiment registered under ``name`` (or an alias such as ``fig3_10``)."""
    key = ALIASES.get(name, name)
    target = EXPERIMENTS.get(key)
    if target is None:
        raise InputError(f"unknown experiment {name!r}; experiments: {', '.join(EXPERIMENTS)}")
    mod, _, cls = target.partition(":")
    exp: Experiment = getattr(importlib.import_module(mod), cls)()
    return exp


def run(
    name: str,
    *,
    quick: bool = False,
    store: str | os.PathLike[str] = DEFAULT_STORE,
    out: str | os.PathLike[str] | None = None,
    jobs: int | None = None,
    scheduler: Any = None,
    progress: bool = True,
    report_only: bool = False,
    rerun: bool = False,
    rerun_stale: bool = False,
    figures: bool = True,
    command: str = "",
    **overrides: Any,
) -> tuple[RunSummary, Report]:
    """Run (the missing trials of) an experiment and write its report.

    Parameters
    ----------
    name : str
        An experiment name (see :data:`EXPERIMENTS`).
    quick : bool
        The tiny configuration used by the tests.
    store : path
        The SQLite results store (default ``results/csplab-experiments.sqlite``).
    out : path, optional
        Report directory (default ``results/NAME``, or the experiment's ``default_out``):
        ``NAME.md``, one CSV per table,
        ``NAME_trials.csv.gz`` (every trial), PNG and SVG.
    jobs, scheduler, progress
        See :func:`~csplab.experiments.runner.run_trials`.
    report_only : bool
        Do not run anything; report what the store holds.
    rerun : bool
        Forget this sweep's stored trials first and run them all again (after a fix to a
        measure, say).
    rerun_stale : bool
        Forget and run again only this sweep's stored trials that other code computed
        (another ``csplab/`` source tree or csplab version; see
        :meth:`~csplab.experiments.store.ResultsStore.stale`). Without it such trials are
        reused and counted in ``summary.stale``.
    figures : bool
        Draw the figures (PNG and SVG); tables and CSVs are always written.
    **overrides
        Configuration values (``examples=``, ``sizes=``, ``seeds=`` …).
    """
    exp = get_experiment(name)
    exp.draw_figures = figures
    config = exp.make_config(quick=quick, **overrides)
    trials, examples = exp.build(config)
    outdir = Path(out) if out is not None else Path(exp.default_out or Path("results") / exp.name)
    with ResultsStore(store) as st:
        if rerun and not report_only:
            st.delete(exp.name, [t.key for t in trials])
        elif rerun_stale and not report_only:
            st.delete(exp.name, list(st.stale(exp.name, [t.key for t in trials])))
        if report_only:
            done = st.done_keys(exp.name)
            summary = RunSummary(exp.name, len(trials), sum(t.key in done for t in trials))
            summary.executor = "nothing (report only)"
            summary.stale = stale_counts(st, exp.name, [t.key for t in trials if t.key in done])
        else:
            summary = run_trials(
                trials, examples, st, experiment=exp.name, config=config, jobs=jobs,
                scheduler=scheduler, progress=progress, command=command,
            )  # fmt: skip
        keys = {t.key for t in trials}
        rows = st.rows(exp.name, keys)
        report = exp.report(rows, config, outdir)
        note = provenance_note(rows)
        if note:
            report.notes.append(note)
        report.trials = len(keys)
        report.missing = len(keys) - len(rows)
        raw = outdir / f"{exp.name}_trials.csv.gz"
        st.export_csv(raw, exp.name, keys)
        report.files.append(raw)
    report.config = {**config, "config_hash": config_hash(config)}
    report.write(outdir, exp.name)
    return summary, report
