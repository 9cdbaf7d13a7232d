"""Infallibility table: verdict, method, time and certificate size for every grid model.

For every built-in grid example, the repository's tileset test files and every rule set of
the anchor data (``--example`` overrides), at the thesis' boundaries (``none``; ``auto`` =
ground and empty space, for examples: a tileset has its file's own) and in Alg. 3.1's scan
order (``scanline``; the 2D thesis figures also in their own ``scan:yx``), one trial runs
:func:`~csplab.analysis.decide.decide_infallibility` within ``time_limit`` and then
checks what the verdict rests on, with code that shares nothing with the prover:

* the certificate is re-verified by :mod:`csplab.certcheck` (closed state set, or the
  failing run replayed) and the check is timed against the decision. Like is compared
  with like: the decision is timed from the model in memory to the certificate object
  (:func:`~csplab.analysis.decide.decide_infallibility`, every region tried and every
  failure search included; loading the model file and writing the JSON are not), the
  check from the certificate object, as JSON decoding gives it, to the verdict
  (:func:`~csplab.certcheck.check_certificate`, turning its lists into arrays included;
  reading the file and decoding the JSON are not, and are reported apart as ``json s``).
  Neither side counts process start-up. The ratio compares the CPU time of the two sides
  (one thread each, in the same process): on a loaded machine a check of a few
  milliseconds that loses the processor for a time slice would otherwise count the wait;
  the wall-clock times are in the table beside. Each side is timed as the best of up to
  3 runs, run again only while its runs have taken under 1 s in all (:func:`_best`: a
  single run of a few milliseconds is noise -- a code path's first call in a worker pays
  one-time warm-ups, a garbage collection of the worker's whole heap falls on whichever
  side is allocating when it is due); a longer decision runs once;
* a **proved** model gets ``runs`` (default 100000, the issue's target) seeded runs of
  Alg. 3.1 (:func:`random_runs`: the ``catalog`` solver's engine, the same order, each
  output problem built once) over a fixed mix of outputs from 2x2 to 40x40 (2D) or 2x2x2
  to 40x40x10 (3D) (:data:`RUN_MIX`); every solved output is checked by
  :meth:`Problem.violations`. One failure or invalid output is a contradiction (a bug),
  reported with its size and seed and replayed;
* a **refuted** model's witness is replayed by :func:`~csplab.analysis.witness.replay`
  (Alg. 3.1's engine): a witness that does not replay is a contradiction;
* *any order*: seeded min-entropy runs (WFC's order) look for a failure
  (:func:`~csplab.analysis.witness.find_failure`); a proof for every order is not attempted.

Models outside the proof's scope (hexagonal or triangular grids, periodic files, global
constraints, continuous models) get one row saying why. The report prints the issue's
targets: at least 90 % decided, 0 contradictions, checks in at most 1/10 of the decision
time, the thesis' hand-decided 2D figures in seconds.

Examples
--------
>>> from csplab.experiments import get_experiment
>>> trials = get_experiment("infallibility").trials(quick=True)
>>> sorted({(t.example, t.params["boundary"], t.params["order"]) for t in trials})[:2]
[('fig3_4a', 'auto', 'scan:yx'), ('fig3_4a', 'auto', 'scanline')]
"""

from __future__ import annotations

import json
import math
import os
import statistics
import time
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from csplab.errors import CsplabError, InputError
from csplab.example import ExampleModel
from csplab.experiments.base import Experiment, Report, load_examples, sweep_defaults
from csplab.experiments.trial import Trial, record
from csplab.problem import Problem

__all__ = ["RUN_MIX", "Infallibility", "anchor_rule_sets", "measure", "random_runs", "run_schedule"]

# the 2D figures the thesis decides by hand (Sec. 3.3.4, 3.3.7, 3.3.8), in its scan order
HAND_DECIDED = ("fig3_5a", "fig3_6a", "fig3_15", "fig3_16")
THESIS_2D = ("fig3_1a", "fig3_1b", "line", "fig3_1d", "fig3_4a", *HAND_DECIDED, "fig3_10")


def anchor_rule_sets(root: Path | None = None) -> list[str]:
    """The rule sets of the anchor data (``../shared/anchors-data`` from the working
    directory or from the repository, or two levels up), sorted; empty when absent.

    Examples
    --------
    >>> isinstance(anchor_rule_sets(Path("/nonexistent")), list)
    True
    """
    repo = Path(__file__).resolve().parents[2]
    roots = [root] if root is not None else [
        Path("..") / "shared" / "anchors-data",
        repo.parent / "shared" / "anchors-data",
        repo.parents[1] / "shared" / "anchors-data",  # a worktree one level deeper
    ]  # fmt: skip
    for r in roots:
        if r.is_dir():
            files = [p for p in r.rglob("*") if p.suffix in (".json", ".xml") and p.is_file()]
            return sorted(os.path.relpath(p) for p in files)
    return []


# the repository's own tileset test files (WFC simple tiled 2D and 3D, POMS, DeBroglie)
OWN_TILESETS = ("pipes.xml", "pipes3d.xml", "tiny_poms.json", "tiny_debroglie.json")


def _default_examples() -> list[str]:
    from csplab.examples import example_info

    data = Path(__file__).resolve().parents[2] / "tests" / "io" / "data"
    own = [os.path.relpath(data / f) for f in OWN_TILESETS if (data / f).is_file()]
    return [name for name, _ in example_info()] + own + anchor_rule_sets()


class Infallibility(Experiment):
    name = "infallibility"
    title = "Infallibility of the built-in and anchor-data models (thesis Sec. 3.3.7)"
    description = (
        "prove or refute that Alg. 3.1 never fails, per model, boundary and scan order, with "
        "certificates re-checked independently and random runs as a cross-check"
    )
    defaults = sweep_defaults(
        omit=("sizes", "size", "solvers", "seeds", "choice", "options", "periodic", "order",
              "constraints"),
        examples=[], boundary="none,auto", time_limit=600.0, runs=100_000, runs_limit=600.0,
        any_order_s=20.0,
    )  # fmt: skip
    quick: ClassVar[dict[str, Any]] = {
        "examples": ["fig3_4a"],
        "time_limit": 20.0,
        "runs": 200,
        "runs_limit": 10.0,
        "any_order_s": 2.0,
    }
    uses = frozenset({"examples", "boundary", "time_limit", "seed0"})
    tilesets = True
    default_out = str(Path("papers") / "merrell-2009-thesis")

    def add_arguments(self, p: Any) -> None:
        p.add_argument("--runs", type=int, help="random Alg. 3.1 runs per proved model, "
                       f"over a fixed mix of sizes (default and target {RUNS_TARGET})")  # fmt: skip
        p.add_argument("--runs-limit", type=float, dest="runs_limit",
                       help="CPU seconds for a model's random runs, a safety; "
                       "runs cut short are reported short of the target")  # fmt: skip
        p.add_argument("--any-order-s", type=float, dest="any_order_s",
                       help="seconds of min-entropy runs per model (0: skip)")  # fmt: skip

    def validate(self, config: dict[str, Any]) -> None:
        super().validate(config)
        if not config["examples"]:
            config["examples"] = _default_examples()
        b = config["boundary"]
        config["boundary"] = b.split(",") if isinstance(b, str) else list(b)
        bad = [x for x in config["boundary"] if x not in ("none", "auto")]
        if bad:
            raise InputError(f"boundary: none and/or auto, not {bad}")
        if not (config["time_limit"] and config["time_limit"] > 0):
            raise InputError("time_limit must be a positive number of seconds")
        if int(config["runs"]) < 0:
            raise InputError("runs must be >= 0")

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, Any]]:
        from csplab.examples import EXAMPLES

        trials: list[Trial] = []
        models: dict[str, Any] = {}
        for spec in config["examples"]:
            try:
                ((_, E),) = load_examples([spec], tilesets=True)
            except CsplabError:  # a continuous model: one row in the report
                continue
            models[E.hash()] = E
            is_example = isinstance(E, ExampleModel)
            bounds = config["boundary"] if is_example else ["file"]
            orders = ["scanline"]
            if is_example and E.ndim == 2 and (spec in THESIS_2D or spec not in EXAMPLES):
                orders.append("scan:yx")
            for bnd in bounds:
                for order in orders:
                    params = {
                        "order": order, "boundary": bnd,
                        "time_limit": float(config["time_limit"]),
                        "runs": int(config["runs"]), "runs_limit": float(config["runs_limit"]),
                        "any_order_s": float(config["any_order_s"]),
                    }  # fmt: skip
                    trials.append(Trial(
                        self.name, spec, E.hash(), (2,) * max(E.ndim, 1), "decide", params,
                        int(config.get("seed0", 0)), "none", False,
                        "csplab.experiments.infallibility:measure",
                    ))  # fmt: skip
        return trials, models

    def report(self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path) -> Report:
        rep = Report(self.name, self.title, config)
        table = []
        key = {spec: i for i, spec in enumerate(config["examples"])}
        rows = sorted(
            rows,
            key=lambda r: (key.get(r["example"], len(key)), r["example"],
                           r["params"]["boundary"], r["params"]["order"]),
        )  # fmt: skip
        for r in rows:
            s = r["stats"]
            is_file = s.get("tileset", False)
            table.append({
                "model": Path(r["example"]).name if "/" in r["example"] else r["example"],
                "dims": s.get("dims", ""),
                "K": s.get("K", ""),
                "boundary": "file's own" if is_file else r["params"]["boundary"],
                "order": r["params"]["order"],
                "verdict": s.get("verdict", r["status"]),
                "method": s.get("method", ""),
                "time s": _num(s.get("decide_s")),
                "certificate": s.get("certificate", ""),
                "check s": _num(s.get("check_s"), 3),
                "json s": _num(s.get("json_s"), 3),
                "check/time": _num(s.get("check_ratio"), 3),
                "cross-check": s.get("crosscheck", ""),
                "any order (min-entropy)": s.get("any_order", ""),
            })  # fmt: skip
        seen = {r["example"] for r in rows}
        by_hash = {r["example_hash"]: r for r in rows}
        for spec in config["examples"]:
            if spec in seen:
                continue
            try:
                ((_, m),) = load_examples([spec], tilesets=True)
            except CsplabError:
                m = None
            twin = by_hash.get(m.hash()) if m is not None else None
            if twin is not None:  # the same rules: the same trials (keys ignore the name)
                table.append({"model": Path(spec).name, "verdict": twin["stats"].get("verdict"),
                              "method": f"the same rules as {Path(twin['example']).name}: "
                              "see its rows"})  # fmt: skip
            else:
                table.append({"model": spec, "verdict": "n/a",
                              "method": "a continuous model: no grid, no Alg. 3.1"})  # fmt: skip
        rep.tables["verdicts"] = table
        rep.notes += _targets(rows)
        rep.notes.append(
            "Reading and soundness of the proofs: [infallibility_reading.md]"
            "(infallibility_reading.md). `proved`: Alg. 3.6 with the region in `method` cannot "
            "fail (Theorem 3.3.6; a region reaching `back` cells before its point still holds "
            "the point's backward neighbours); `refuted`: a failing run of Alg. 3.1 "
            "(certificate = the run, replayed); `undecided`: neither within the time limit. "
            "Times are wall-clock seconds on a shared 2-core machine (noisy). `check/time`: "
            "the independent check of the certificate over the decision's time, like with "
            "like: the decision from the model in memory to the certificate object (every "
            "region tried and every failure search included), the check from the decoded "
            "certificate to the verdict (its lists turned into arrays included); neither "
            "counts start-up, reading or writing files; the ratio is of CPU seconds (one "
            "thread each, the same process), the times shown are wall clock; each side is "
            "the best of up to 3 runs while they take under 1 s in all (a single run of "
            "milliseconds is noise: first-call warm-ups, garbage collections), a longer "
            "decision runs once. `json s`: decoding the certificate's JSON text, apart."
        )
        return rep


def _num(x: Any, digits: int = 2) -> str:
    if not isinstance(x, int | float) or not math.isfinite(x):
        return ""
    return f"{x:.{digits}f}" if x < 1000 else f"{x:.0f}"


def _targets(rows: list[dict[str, Any]]) -> list[str]:
    """The issue's targets, measured: each with "meets" or the shortfall."""
    applicable = [r for r in rows if r["stats"].get("verdict") in ("proved", "refuted",
                                                                    "undecided")]  # fmt: skip
    decided = [r for r in applicable if r["stats"]["verdict"] != "undecided"]
    contra = [r for r in rows if r["stats"].get("contradiction")]
    ratios = [r["stats"]["check_ratio"] for r in decided
              if isinstance(r["stats"].get("check_ratio"), int | float)]  # fmt: skip
    hand = [r for r in rows if r["example"] in HAND_DECIDED and r["params"]["order"] == "scan:yx"
            and r["params"]["boundary"] == "none"]  # fmt: skip
    out = []
    if applicable:
        pct = 100 * len(decided) / len(applicable)
        out.append(
            f"Target ≥ 90 % decided: {len(decided)} of {len(applicable)} model settings in "
            f"the proof's scope ({pct:.0f} %): " + ("meets" if pct >= 90 else
                                                   f"shortfall {90 - pct:.0f} points")
        )  # fmt: skip
        slow = [r for r in applicable if (r["stats"].get("decide_s") or 0) > 600]
        out.append(f"Target ≤ 10 min per model on one core: {len(slow)} over: "
                   + ("meets" if not slow else "shortfall"))  # fmt: skip
    out.append(
        f"Target 0 contradictions between verdicts and runs: {len(contra)}: "
        + ("meets" if not contra else "SHORTFALL (bugs): " + "; ".join(
            f"{r['example']} {r['params']['boundary']}: {r['stats']['contradiction']}"
            for r in contra))
    )  # fmt: skip
    if ratios:
        over = sum(x > 0.1 for x in ratios)
        out.append(
            "Target check ≤ 1/10 of the decision time (CPU): "
            f"median {statistics.median(ratios):.3f}, max {max(ratios):.3f}; "
            f"{len(ratios) - over} of {len(ratios)} within: "
            + ("meets" if not over else f"shortfall on {over}")
        )  # fmt: skip
    if hand:
        worst = max(float(r["stats"].get("decide_s") or 0) for r in hand)
        done = all(r["stats"].get("verdict") in ("proved", "refuted") for r in hand)
        out.append(
            f"Target: Figs. 3.5, 3.6, 3.15, 3.16 (scan:yx, no boundary) decided in seconds: "
            f"{'all decided' if done else 'not all decided'}, slowest {worst:.2f} s: "
            + ("meets" if done and worst < 10 else "shortfall")
        )  # fmt: skip
    proved = [r for r in rows if r["stats"].get("verdict") == "proved"]
    if proved:
        counts = [int(r["stats"].get("runs_done") or 0) for r in proved]
        met = [r for r in proved if r["stats"].get("runs_target") == "meets"]
        cpu = sum(float(r["stats"].get("runs_cpu_s") or 0) for r in proved)
        slowest = max(float(r["stats"].get("runs_cpu_s") or 0) for r in proved)
        out.append(
            f"Target ≥ {RUNS_TARGET} random Alg. 3.1 runs per proved model with 0 failures "
            "(outputs 2x2 to 40x40, 2x2x2 to 40x40x10, in the fixed mix of `RUN_MIX`; every "
            f"solved output checked by `Problem.violations`): {len(met)} of {len(proved)} "
            f"proved settings meet; fewest runs {min(counts)}, {sum(counts)} runs in all, "
            f"{cpu:.1f} s CPU (slowest setting {slowest:.1f} s): "
            + ("meets" if len(met) == len(proved) else
               f"shortfall on {len(proved) - len(met)} (see `cross-check`)")
        )  # fmt: skip
    return out


def measure(trial: Trial, example: Any, problem: Problem | None) -> dict[str, Any]:
    """Decide one model setting and check the verdict (see the module docstring)."""
    from csplab.analysis.decide import decide_infallibility
    from csplab.certcheck import check_certificate

    order = str(trial.params["order"])
    is_example = isinstance(example, ExampleModel)
    boundary = str(trial.params["boundary"]) if is_example else None
    stats: dict[str, Any] = {"tileset": not is_example}
    try:
        stats["dims"] = "x".join(map(str, example.shape)) if example.shape else f"{example.ndim}D"
        stats["K"] = int(example.K) if is_example else int(example.transitions().shape[1])
        (decide_s, decide_cpu), v = _best(lambda: decide_infallibility(
            example, order=order, boundary=None if boundary == "none" else boundary,
            time_limit=float(trial.params["time_limit"]), rng=trial.seed, certificate=True,
        ))  # fmt: skip
    except InputError as e:
        stats.update(verdict="n/a", method=str(e).split(": ", 1)[-1])
        return record("n/a", 0.0, stats)
    verdict = {True: "proved", False: "refuted", None: "undecided"}[v.holds]
    stats.update(verdict=verdict, method=v.stats.get("method", ""), decide_s=decide_s,
                 decide_cpu_s=decide_cpu)  # fmt: skip
    if v.holds is None:
        stats["method"] = f"{len(v.stats.get('attempts', []))} regions tried; {v.message}"
    wit = v.witness if isinstance(v.witness, dict) else {}
    cert = wit.get("certificate")
    if cert is not None:
        text = json.dumps(cert)
        t1 = time.perf_counter()
        decoded = json.loads(text)
        stats["json_s"] = time.perf_counter() - t1
        (stats["check_s"], stats["check_cpu_s"]), (ok, msg) = _best(
            lambda: check_certificate(decoded)
        )
        # the work of each side: CPU seconds of this process (both run on one thread here)
        stats["check_ratio"] = stats["check_cpu_s"] / max(decide_cpu, 1e-9)
        nstates = sum(len(c["states"]) for c in cert.get("configs", []))
        size = f"{len(text) / 1e6:.2f} MB" if len(text) > 1e5 else f"{len(text) / 1e3:.1f} kB"
        stats["certificate"] = (
            f"{nstates} states, {size}" if cert["claim"] == "infallible"
            else f"run of {len(cert['run']['choices'])} choices on "
                 f"{'x'.join(map(str, cert['run']['shape']))}, {size}"
        )  # fmt: skip
        if not ok:
            stats["contradiction"] = f"certificate rejected: {msg}"
    if v.holds is True:
        _runs(example, order, boundary, trial, stats)
    elif v.holds is False:
        from csplab.analysis.witness import replay

        rp = replay(example, wit["alg31"])
        stats["crosscheck"] = "witness replays" if rp.holds else "witness does NOT replay"
        if not rp.holds:
            stats["contradiction"] = f"the witness does not replay: {rp.message}"
    _any_order(example, boundary, trial, stats)
    return record("ok", decide_s, stats)


def _best(run: Any, budget: float = 1.0, times: int = 3) -> tuple[tuple[float, float], Any]:
    """The shortest wall-clock and CPU seconds of ``run()`` over up to ``times`` runs, run
    again only while they have taken under ``budget`` s in all; and the first run's result.

    A single run of a few milliseconds is noise: the first call of a code path in a
    worker pays one-time warm-ups (lazy imports, first calls), and a garbage collection of
    the whole heap falls on whichever side allocates when it is due. Both sides are timed
    alike; a decision over ``budget`` s runs once (the runs are seeded: the same result).
    """
    out, spent, wall, cpu = None, 0.0, math.inf, math.inf
    for k in range(times):
        t0, c0 = time.perf_counter(), time.process_time()
        got = run()
        dt, dc = time.perf_counter() - t0, time.process_time() - c0
        out = got if k == 0 else out
        wall, cpu, spent = min(wall, dt), min(cpu, dc), spent + dt
        if spent >= budget:
            break
    return (wall, cpu), out


# The fixed mix of output sizes of the random runs (per 100 runs, for 1D, 2D and 3D): many
# small outputs, where every cell is near a border, and a share of large ones, where a run
# makes the most choices; a few flat shapes so that each axis is scanned both long and short.
# Run ``i`` of a trial has the size ``run_schedule(ndim)[i % 100]`` and the seed
# ``trial.seed * 1_000_003 + i``; any prefix of the schedule holds every size about in
# proportion, so runs cut short by ``runs_limit`` (CPU seconds) still cover them all.
RUN_MIX: dict[int, tuple[tuple[tuple[int, ...], int], ...]] = {
    1: (((2,), 8), ((3,), 8), ((4,), 8), ((5,), 8), ((6,), 8), ((8,), 10), ((12,), 10),
        ((16,), 10), ((24,), 15), ((40,), 15)),
    2: (((2, 2), 8), ((3, 3), 8), ((2, 5), 4), ((5, 2), 4), ((4, 4), 8), ((5, 5), 8),
        ((3, 8), 4), ((8, 3), 4), ((6, 6), 8), ((8, 8), 10), ((12, 12), 10), ((16, 16), 10),
        ((24, 24), 7), ((40, 40), 7)),
    3: (((2, 2, 2), 8), ((3, 3, 3), 8), ((2, 3, 5), 4), ((5, 3, 2), 4), ((4, 4, 4), 8),
        ((5, 5, 5), 8), ((3, 7, 4), 4), ((7, 3, 4), 4), ((6, 6, 6), 8), ((8, 8, 10), 10),
        ((12, 12, 10), 10), ((16, 16, 10), 10), ((24, 24, 10), 9), ((40, 40, 10), 5)),
}  # fmt: skip
RUNS_TARGET = 100_000  # the cross-check: random runs per proved model, 0 failures


def run_schedule(ndim: int) -> list[tuple[int, ...]]:
    """The 100 output sizes of one cycle of the random runs (:data:`RUN_MIX`), interleaved:
    size ``s`` of weight ``w`` takes the slots at ``(j + 1/2) / w``, ``j < w``.

    Parameters
    ----------
    ndim : int
        1, 2 or 3.

    Returns
    -------
    list of tuple of int

    Raises
    ------
    InputError
        For another number of dimensions.

    Examples
    --------
    >>> sch = run_schedule(2)
    >>> len(sch), sch.count((40, 40)), sch[:3]
    (100, 7, [(8, 8), (12, 12), (16, 16)])
    """
    mix = RUN_MIX.get(ndim)
    if mix is None:
        raise InputError(f"random runs: outputs of 1, 2 or 3 dimensions, not {ndim}")
    slots = [((j + 0.5) / w, i, s) for i, (s, w) in enumerate(mix) for j in range(w)]
    return [s for _, _, s in sorted(slots)]


def random_runs(
    example: Any, order: str, boundary: str | None, *, runs: int, seed: int,
    time_limit: float, keep: int = 3,
) -> dict[str, Any]:  # fmt: skip
    """Seeded runs of Alg. 3.1 (:func:`~csplab.engine.alg31.run_alg31`, the ``catalog``
    solver's engine) over the sizes of :func:`run_schedule`, each output problem built once.

    Run ``i`` has the seed ``seed + i`` and the size ``run_schedule(ndim)[i % 100]``; it
    repeats alone with ``solve(P, "catalog", rng=seed + i, order=order)``. A run that does
    not solve is a failure: the first ``keep`` are kept as witnesses (size, seed, choices)
    and replayed by :func:`~csplab.analysis.witness.replay`. A solved output is checked by
    :meth:`Problem.violations`, which shares no code with the engine: a violation is
    ``invalid``. Stops after ``runs`` runs or ``time_limit`` CPU seconds of the calling
    thread (a wall-clock limit would cut a run short on a loaded machine, or with more
    workers than cores, that fits on one core).

    Parameters
    ----------
    example : ExampleModel or RuleSet
    order : str
        A scan order of Alg. 3.1 (``scanline``, ``scan:yx`` ...).
    boundary : {None, "none", "auto"}
        ``"auto"``: ground and empty space (a tileset always has its file's own).
    runs : int
        How many runs.
    seed : int
        The seed of run 0.
    time_limit : float
        CPU seconds (this thread, building the problems included) after which no run
        starts.
    keep : int
        Failures kept as witnesses.

    Returns
    -------
    dict
        ``runs_done``, ``runs_per_size`` (``"2x2": count``, in the order of
        :data:`RUN_MIX`), ``failed``,
        ``invalid``, ``failures`` (the kept witnesses with ``replays``), ``runs_s`` (wall
        clock) and ``runs_cpu_s`` (CPU of this thread), building the problems included, and
        ``cut`` (whether the time limit stopped the runs).

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> out = random_runs(load_example("line"), "scanline", None, runs=30, seed=0,
    ...                   time_limit=60)
    >>> out["runs_done"], out["failed"], out["invalid"], out["runs_per_size"]["2x2"]
    (30, 0, 0, 3)
    """
    from csplab.analysis.witness import model_problem, replay
    from csplab.engine.alg31 import run_alg31
    from csplab.grids import parse_boundary

    t0, c0 = time.perf_counter(), time.thread_time()
    deadline = c0 + float(time_limit)
    bnd = "auto" if (boundary == "auto" or not isinstance(example, ExampleModel)) else None
    schedule = run_schedule(example.ndim)
    problems = {s: model_problem(example, s, None if bnd is None else parse_boundary(bnd))
                for s, _ in RUN_MIX[example.ndim]}  # fmt: skip
    per = dict.fromkeys(problems, 0)
    failures: list[dict[str, Any]] = []
    failed = invalid = done = 0
    cut = False
    while done < runs:
        if time.thread_time() >= deadline:
            cut = True
            break
        s = schedule[done % len(schedule)]
        P, sd = problems[s], seed + done
        r = run_alg31(P, np.random.default_rng(sd), order=order)
        done += 1
        per[s] += 1
        if r.status == "solved":
            if len(P.violations(r.grid)):
                invalid += 1
                if len(failures) < keep:
                    failures.append({"shape": list(s), "seed": sd, "kind": "invalid"})
            continue
        failed += 1
        if len(failures) < keep:
            tr = r.trace if r.trace is not None else np.zeros((0, 2), dtype=np.int64)
            w: dict[str, Any] = {"shape": list(s), "order": order, "seed": sd}
            if bnd is not None:
                w["boundary"] = bnd
            w["kind"] = r.status
            w["choices"] = [[list(P.coords(int(c))), int(b)] for c, b in tr.tolist()]
            w["replays"] = bool(replay(example, w).holds)
            failures.append(w)
    return {
        "runs_done": done,
        "runs_per_size": {_fmt(s): k for s, k in per.items() if k},
        "failed": failed, "invalid": invalid, "failures": failures, "cut": cut,
        "runs_s": time.perf_counter() - t0, "runs_cpu_s": time.thread_time() - c0,
    }  # fmt: skip


def _fmt(shape: tuple[int, ...] | list[int]) -> str:
    return "x".join(map(str, shape))


def _runs(example: Any, order: str, boundary: str | None, trial: Trial,
          stats: dict[str, Any]) -> None:  # fmt: skip
    """The random-run cross-check of a proved model (:func:`random_runs`, seeds from
    ``trial.seed``): every failure, and every invalid output, is a contradiction."""
    want = int(trial.params["runs"])
    out = random_runs(example, order, boundary, runs=want, seed=trial.seed * 1_000_003,
                      time_limit=float(trial.params["runs_limit"]))  # fmt: skip
    done, per = out["runs_done"], out["runs_per_size"]
    failures = [{k: v for k, v in f.items() if k != "choices"} for f in out["failures"]]
    stats.update(runs_done=done, runs_per_size=per, runs_failed=out["failed"],
                 runs_invalid=out["invalid"], runs_failures=failures, runs_s=out["runs_s"],
                 runs_cpu_s=out["runs_cpu_s"])  # fmt: skip
    bad = out["failed"] + out["invalid"]
    sizes = list(per)
    span = f"{len(sizes)} sizes {sizes[0]}..{max(sizes, key=_cells)}" if sizes else "no sizes"
    met = done >= RUNS_TARGET and not bad
    verdict = "meets" if met else (
        f"short: {done} of {RUNS_TARGET}" + (" (runs_limit)" if out["cut"] else "")
        if not bad else "FAILS")  # fmt: skip
    stats["runs_target"] = "meets" if met else "short" if not bad else "fails"
    stats["crosscheck"] = (
        f"{done} runs ({span}), {out['failed']} failed, {out['invalid']} invalid, "
        f"{out['runs_cpu_s']:.1f} s CPU: {verdict}"
    )
    if bad:
        f = out["failures"][0]
        how = "an invalid grid" if f["kind"] == "invalid" else f["kind"]
        rp = "" if f["kind"] == "invalid" else (
            ", replays" if f["replays"] else ", does NOT replay")  # fmt: skip
        stats["contradiction"] = (
            f"Alg. 3.1 {how} on {_fmt(f['shape'])} (seed {f['seed']}, order {order}{rp}) "
            f"although proved infallible; {out['failed']} failed, {out['invalid']} invalid "
            f"of {done} runs"
        )


def _cells(size: str) -> tuple[int, str]:
    return math.prod(int(t) for t in size.split("x")), size


def _any_order(example: Any, boundary: str | None, trial: Trial,
               stats: dict[str, Any]) -> None:  # fmt: skip
    from csplab.analysis.witness import find_failure

    budget = float(trial.params.get("any_order_s") or 0)
    if budget <= 0:
        return
    try:
        ff = find_failure(
            example, order="min-entropy", rng=trial.seed, time_limit=budget, exact=False,
            boundary="auto" if boundary == "auto" else None,
            max_size=(40,) if example.ndim == 1 else (12, 12) if example.ndim == 2 else None,
        )  # fmt: skip
    except CsplabError as e:
        stats["any_order"] = f"n/a ({e})"
        return
    if ff.holds is False and ff.witness is not None:
        w = ff.witness
        stats["any_order"] = f"fallible: fails on {'x'.join(map(str, w['shape']))}"
    else:
        stats["any_order"] = f"no failure in {ff.stats.get('random_runs', 0)} runs (not a proof)"
