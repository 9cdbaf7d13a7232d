"""Sampling bias: label and 2×2-pattern frequencies of solver outputs vs exact uniform.

None of Merrell's algorithms samples uniformly from the consistent models; neither do SAT or
CP solvers. On strips narrow enough for transfer matrices (:class:`StripSampler`) the exact
expected frequency of every label and every 2×2 pattern under the uniform distribution on
solutions is computable. For each solver setting the experiment pools the frequencies of its
outputs (one per seed), and measures the total variation distance (TV) and Jensen-Shannon
divergence to the exact frequencies, with percentile-bootstrap 95% intervals over outputs.
The row ``uniform`` (exact uniform samples, the same number) is the noise floor: a setting
is flagged *biased* when its TV interval lies entirely above the floor's interval.

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("sampling_bias").trials(quick=True)
>>> sorted({t.solver for t in trials})
['catalog', 'exact', 'uniform']
"""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path
from typing import Any

import numpy as np

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.base import (
    Experiment,
    Report,
    example_names,
    group_rows,
    load_examples,
    setting_of,
    split_solver,
    sweep_defaults,
)
from csplab.experiments.figures import new_figure, save_figure
from csplab.experiments.measures import label_counts
from csplab.experiments.stats import jensen_shannon, total_variation
from csplab.experiments.trial import Trial, record
from csplab.experiments.uniform import StripSampler
from csplab.grids import from_example, parse_shape
from csplab.problem import Problem

__all__ = ["SamplingBias", "measure"]

_SAMPLERS: OrderedDict[tuple[Any, ...], StripSampler] = OrderedDict()


def _sampler(trial: Trial, problem: Problem) -> StripSampler:
    from csplab.experiments.trial import TRIAL_LOCK

    key = (trial.example_hash, trial.size, trial.boundary, trial.periodic)
    with TRIAL_LOCK:
        S = _SAMPLERS.get(key)
    if S is None:
        S = StripSampler(problem)
        with TRIAL_LOCK:
            _SAMPLERS[key] = S
            while len(_SAMPLERS) > 4:
                _SAMPLERS.popitem(last=False)
    return S


def _sparse_patterns(grid: np.ndarray, K: int) -> list[list[int]]:
    g = np.asarray(grid, dtype=np.int64)
    from numpy.lib.stride_tricks import sliding_window_view

    w = tuple(min(2, s) for s in g.shape)
    size = int(np.prod(w))
    codes = sliding_window_view(g, w).reshape(-1, size) @ (
        K ** np.arange(size - 1, -1, -1, dtype=np.int64)
    )
    u, c = np.unique(codes, return_counts=True)
    return [[int(a), int(b)] for a, b in zip(u, c, strict=True)]


def measure(trial: Trial, example: ExampleModel, problem: Problem) -> dict[str, Any]:
    """``exact``: the exact expected frequencies; ``uniform``: one exact uniform sample;
    any solver spec: one output. Outputs are summarised by label and 2×2-pattern counts."""
    import time

    K = problem.K
    t0 = time.perf_counter()
    if trial.solver == "exact":
        S = _sampler(trial, problem)
        if not S.satisfiable:
            return record("unsat", time.perf_counter() - t0, {})
        pf = S.pattern_frequencies(2)
        exact = {
            "log_count": S.log_count,
            "max_states": max(S.state_counts()),
            "labels": S.label_frequencies().tolist(),
            "_patterns": [[c, pf[c]] for c in sorted(pf)],
        }
        return record("solved", time.perf_counter() - t0, exact)
    if trial.solver == "uniform":
        grid = _sampler(trial, problem).sample(rng=trial.seed)
        status, elapsed = "solved", time.perf_counter() - t0
    else:
        from csplab.solvers import solve

        r = solve(problem, trial.solver, rng=trial.seed, **trial.options)
        grid, status, elapsed = r.grid, r.status, float(r.time_s)
    stats: dict[str, Any] = {}
    if status == "solved":
        stats["labels"] = label_counts(grid, K).tolist()
        stats["_patterns"] = _sparse_patterns(grid, K)
    return record(status, elapsed, stats)


class SamplingBias(Experiment):
    name = "sampling_bias"
    title = "Sampling bias: label and 2x2-pattern frequencies vs exact uniform"
    description = (
        "total variation / Jensen-Shannon distance of pooled output frequencies to the exact "
        "uniform frequencies (transfer matrices on strips), bootstrap 95% intervals"
    )
    defaults = sweep_defaults(
        omit=("order", "choice"),  # the solver entries name them
        examples=["line", "fig3_4a", "fig3_5a"], size="16x5",
        solvers=[
            "catalog", "catalog@order=scan:yx", "catalog@order=random",
            "catalog@order=min-entropy", "catalog@choice=weighted", "blocks@block=4", "sat",
            "cpsat",
        ],
        seeds=400, boundary="none", n_boot=500,
    )  # fmt: skip
    quick = {
        "examples": ["line"],
        "size": "6x3",
        "solvers": ["catalog"],
        "seeds": 8,
        "n_boot": 50,
    }
    uses = frozenset(defaults) - {"n_boot", "periodic"}

    def add_arguments(self, p: Any) -> None:
        p.add_argument("--n-boot", dest="n_boot", type=int, help="bootstrap resamples (500)")

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        from csplab.solvers import available_solvers

        if config.get("periodic"):
            raise InputError("sampling_bias needs a non-periodic strip")
        if config["size"] is None:
            raise InputError("sampling_bias needs --size (a narrow strip such as 16x5)")
        parse_shape(config["size"], what="--size")
        ok = {s["name"] for s in available_solvers() if s.get("installed")}
        keep: list[str] = []
        skipped: list[str] = []
        for e in config["solvers"]:
            spec, _ = split_solver(e)
            (keep if spec.partition(":")[0] in ok else skipped).append(e)
        config["solvers"] = keep
        config["skipped_solvers"] = skipped

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        trials: list[Trial] = []
        size = parse_shape(config["size"])
        m = "csplab.experiments.sampling_bias:measure"
        loaded, examples = self.load_examples(config)
        for spec, E in loaded:
            common = (config["boundary"], False, m)
            trials.append(Trial(self.name, spec, E.hash(), size, "exact", {}, 0, *common))
            for seed in self.seeds(config):
                trials.append(Trial(self.name, spec, E.hash(), size, "uniform", {}, seed, *common))
                for entry in config["solvers"]:
                    solver, params = self.solver_params(config, entry)
                    trials.append(
                        Trial(self.name, spec, E.hash(), size, solver, params, seed, *common)
                    )
        return trials, examples

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        by_ex = group_rows(rows, lambda r: r["example"])
        table: list[dict[str, Any]] = []
        label_rows: dict[str, dict[str, np.ndarray]] = {}
        names = example_names(by_ex)
        for spec, rs in by_ex.items():
            ex = names[spec]
            exact = next((r for r in rs if r["solver"] == "exact"), None)
            if exact is None or exact["status"] != "solved":
                rep.notes.append(f"{ex}: no exact frequencies (status "
                                 f"{exact['status'] if exact else 'missing'}).")  # fmt: skip
                continue
            ex_lab = np.asarray(exact["stats"]["labels"], dtype=float)
            ex_pat = {int(c): float(v) for c, v in exact["stats"]["_patterns"]}
            settings = group_rows((r for r in rs if r["solver"] != "exact"), setting_of)
            order = ["uniform"] + [s for s in settings if s != "uniform"]
            label_rows[ex] = {"exact": ex_lab / ex_lab.sum()}
            sampler = None
            for s in order:
                if s not in settings:
                    continue
                res = _compare(settings[s], ex_lab, ex_pat, int(config["n_boot"]))
                if s == "uniform":
                    res["verdict"] = "reference"
                elif res["outputs"] == 0:
                    res["verdict"] = "no output"
                else:
                    if sampler is None:
                        sampler = _report_sampler(settings[s][0], spec)
                    null = _null_tv(sampler, res["outputs"], ex_lab, ex_pat,
                                    int(config["n_boot"]))  # fmt: skip
                    pv = min(_pvalue(null[w], res[f"tv_{w}"]) for w in ("labels", "patterns"))
                    res["p_uniform"] = pv
                    res["verdict"] = "biased" if pv < 0.01 else "not distinguishable"
                label_rows[ex][s] = res.pop("_labels")
                table.append({"example": ex, "setting": s, **res,
                              "log_solutions": exact["stats"]["log_count"]})  # fmt: skip
        rep.tables["bias"] = table
        rep.notes.append(
            "tv = total variation distance between pooled output frequencies and the exact "
            "uniform expectation (labels; 2x2 patterns), js = Jensen-Shannon (bits); _lo/_hi "
            "= percentile-bootstrap 95% interval over outputs (TV is biased upwards at "
            "finite samples, so compare with the 'uniform' row rather than with 0). 'uniform' "
            "= the same number of exact uniform samples (the noise floor). p_uniform = Monte "
            "Carlo p-value: the share of n_boot fresh sets of as many exact uniform samples "
            "whose TV is at least as large (smaller of labels and patterns); biased = "
            "p_uniform < 0.01. "
            "log_solutions = ln(number of consistent models)."
        )
        if config.get("skipped_solvers"):
            rep.notes.append("Not installed here, skipped: " + ", ".join(config["skipped_solvers"]))
        if table and self.draw_figures:
            rep.figures += self._plot(table, label_rows, out)
        return rep

    def _plot(
        self, table: list[dict[str, Any]], labels: dict[str, dict[str, np.ndarray]], out: Path
    ) -> list[Path]:
        exs = list(dict.fromkeys(t["example"] for t in table))
        fig, axes = new_figure(len(exs), 2, figsize=(11, 3.2 * len(exs)), squeeze=False)
        for i, ex in enumerate(exs):
            ts = [t for t in table if t["example"] == ex]
            x = np.arange(len(ts))
            for j, (what, ax) in enumerate((("labels", axes[i, 0]), ("patterns", axes[i, 1]))):
                v = np.array([t[f"tv_{what}"] for t in ts])
                lo = np.array([t[f"tv_{what}_lo"] for t in ts])
                hi = np.array([t[f"tv_{what}_hi"] for t in ts])
                cols = [
                    "tab:gray" if t["setting"] == "uniform"
                    else ("tab:red" if t["verdict"] == "biased" else "tab:blue")
                    for t in ts
                ]  # fmt: skip
                ax.bar(x, v, color=cols)
                err = [np.clip(v - lo, 0, None), np.clip(hi - v, 0, None)]
                ax.errorbar(x, v, yerr=err, fmt="none", ecolor="k", capsize=3)
                ax.set_xticks(x, [t["setting"] for t in ts], rotation=30, ha="right", fontsize=7)
                ax.set_ylabel(f"TV ({'labels' if j == 0 else '2x2 patterns'})")
                ax.set_title(f"{ex}: {'label' if j == 0 else '2x2 pattern'} frequencies vs exact",
                             fontsize=9)  # fmt: skip
                ax.grid(alpha=0.3, axis="y")
        fig.tight_layout()
        return save_figure(fig, out / self.name)


def _pvalue(null: np.ndarray, value: float) -> float:
    """Monte Carlo p-value: share of null replicates at least as large as ``value``."""
    return float((1 + np.sum(null >= value)) / (1 + null.size))


def _report_sampler(row: dict[str, Any], spec: str) -> StripSampler:
    from csplab.experiments.trial import parse_boundary

    E = dict(load_examples([spec]))[spec]
    if E.hash() != row["example_hash"]:
        raise InputError(f"example {spec} changed since its trials were stored")
    size = tuple(int(v) for v in row["size"].split("x"))
    P = from_example(E, size, boundary=parse_boundary(row["boundary"]))
    return StripSampler(P)


def _null_tv(
    S: StripSampler, n: int, ex_lab: np.ndarray, ex_pat: dict[int, float], reps: int
) -> dict[str, np.ndarray]:
    """TV to the exact frequencies of ``reps`` fresh sets of ``n`` exact uniform samples."""
    from numpy.lib.stride_tricks import sliding_window_view

    K = S.problem.K
    codes = np.array(sorted(ex_pat), dtype=np.int64)
    ref_p = np.array([ex_pat[c] for c in codes])
    shape = S.problem.shape
    w = tuple(min(2, v) for v in shape)
    mult = K ** np.arange(int(np.prod(w)) - 1, -1, -1, dtype=np.int64)
    rng = np.random.default_rng(2009)
    out = {"labels": np.empty(reps), "patterns": np.empty(reps)}
    for i in range(reps):
        g = S.sample_many(n, rng).astype(np.int64)
        out["labels"][i] = total_variation(np.bincount(g.ravel(), minlength=K), ex_lab)
        win = sliding_window_view(g, (1, *w)).reshape(-1, mult.size) @ mult
        pos = np.searchsorted(codes, win)
        out["patterns"][i] = total_variation(np.bincount(pos, minlength=codes.size), ref_p)
    return out


def _compare(
    rs: list[dict[str, Any]], ex_lab: np.ndarray, ex_pat: dict[int, float], n_boot: int
) -> dict[str, Any]:
    ok = [r for r in rs if r["status"] == "solved" and "labels" in r["stats"]]
    res: dict[str, Any] = {"outputs": len(ok), "runs": len(rs)}
    nan = float("nan")
    if not ok:
        res.update({k: nan for k in ("tv_labels", "tv_labels_lo", "tv_labels_hi", "js_labels",
                                     "tv_patterns", "tv_patterns_lo", "tv_patterns_hi",
                                     "js_patterns")})  # fmt: skip
        res["_labels"] = np.full(ex_lab.shape, nan)
        return res
    codes = sorted(set(ex_pat) | {int(c) for r in ok for c, _ in r["stats"]["_patterns"]})
    pos = {c: i for i, c in enumerate(codes)}
    P = np.zeros((len(ok), len(codes)))
    L = np.array([r["stats"]["labels"] for r in ok], dtype=float)
    for i, r in enumerate(ok):
        for c, v in r["stats"]["_patterns"]:
            P[i, pos[int(c)]] = v
    ep = np.zeros(len(codes))
    for c, v in ex_pat.items():
        ep[pos[c]] = v
    rng = np.random.default_rng(12345)
    for what, M, ref in (("labels", L, ex_lab), ("patterns", P, ep)):
        est = total_variation(M.sum(axis=0), ref)
        reps = np.array([total_variation(M[rng.integers(0, len(ok), len(ok))].sum(axis=0), ref)
                         for _ in range(n_boot)])  # fmt: skip
        res[f"tv_{what}"] = est
        res[f"tv_{what}_lo"], res[f"tv_{what}_hi"] = (
            float(q) for q in np.quantile(reps, [0.025, 0.975])
        )
        res[f"js_{what}"] = jensen_shannon(M.sum(axis=0), ref)
    res["_labels"] = L.sum(axis=0) / L.sum()
    return res
