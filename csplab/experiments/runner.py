"""Run the missing trials of a sweep: in this process, a local process pool or on Dask.

:func:`run_trials` asks the store which trials are done, runs the others and writes each
outcome to the store the moment it arrives (so a killed run loses only the trials in
flight). Executors:

* ``jobs=1``: in this process (no start-up cost; used by the tests and ``--jobs 1``);
* ``jobs=N`` (default: the number of CPUs): a local :class:`~concurrent.futures.ProcessPoolExecutor`
  (spawned workers, each compiling or loading the numba kernels once);
* ``scheduler="tcp://host:8786"`` or a ``distributed.Client``: a Dask ``distributed``
  cluster (optional extra ``csplab[dask]``). Example models are scattered to the workers
  once; every worker warms up the kernels before its first trial.

Outcomes do not depend on the executor: a trial draws all its randomness from its seed.
A progress bar (tqdm, on stderr) shows trials done, the rate and the ETA.

Examples
--------
>>> import os, tempfile
>>> from csplab.examples import load_example
>>> from csplab.experiments.store import ResultsStore
>>> from csplab.experiments.trial import Trial
>>> E = load_example("line")
>>> trials = [Trial("demo", "line", E.hash(), (6, 6), "catalog", {}, seed=s) for s in range(4)]
>>> st = ResultsStore(os.path.join(tempfile.mkdtemp(), "r.sqlite"))
>>> s = run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=1, progress=False)
>>> s.ran, s.skipped, s.errors
(4, 0, [])
>>> run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=1, progress=False).skipped
4
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from collections import Counter
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from csplab.engine.pool import Workers
from csplab.errors import CsplabError, DependencyError, InputError
from csplab.example import ExampleModel
from csplab.experiments.store import ResultsStore, code_label, code_revision
from csplab.experiments.trial import Trial, execute

__all__ = ["RunSummary", "config_hash", "run_trials", "stale_counts"]


@dataclass
class RunSummary:
    """What a sweep did: how many trials it had, skipped (already stored), ran, and errors.

    ``stale`` counts the skipped trials that other code computed (see
    :meth:`~csplab.experiments.store.ResultsStore.stale`), by code revision.
    """

    experiment: str
    total: int
    skipped: int
    ran: int = 0
    errors: list[tuple[Trial, str]] = field(default_factory=list)
    statuses: dict[str, int] = field(default_factory=dict)
    time_s: float = 0.0
    executor: str = ""
    stale: dict[str, int] = field(default_factory=dict)

    def line(self) -> str:
        """One sentence, e.g. ``fig3_8: 12 trials, all 12 already stored; nothing to run``."""
        st = ", ".join(f"{k} {v}" for k, v in sorted(self.statuses.items()))
        n_stale = sum(self.stale.values())
        old = f" ({n_stale} by other code)" if n_stale else ""
        head = f"{self.experiment}: {self.total} trial{'' if self.total == 1 else 's'}"
        if self.total == 0:
            return f"{self.experiment}: no trials; nothing to run"
        every = "all " if self.total > 1 and self.skipped == self.total else ""
        stored = f"{head}, {every}{self.skipped} already stored{old}"
        if not self.ran and not self.errors and "report only" in self.executor:
            return f"{stored}; report only, nothing run"
        if not self.ran and not self.errors and self.skipped == self.total:
            return f"{stored}; nothing to run"
        return (
            f"{head}, {self.skipped} already stored{old}, {self.ran} run"
            + (f" ({st})" if st else "")
            + f" on {self.executor} in {self.time_s:.1f} s"
            + (f", {len(self.errors)} errors" if self.errors else "")
        )

    def stale_line(self) -> str:
        """One line saying which stored trials other code computed ("" when none)."""
        if not self.stale:
            return ""
        n = sum(self.stale.values())
        items = list(self.stale.items())
        parts = ", ".join(f"{v} by {k}" for k, v in items[:3])
        if len(items) > 3:
            parts += f" and {sum(v for _, v in items[3:])} by {len(items) - 3} more"
        return (
            f"{self.experiment}: {n} of the {self.skipped} stored trials of this sweep were "
            f"computed by other code ({parts}; this is {code_label(*code_revision())}); "
            "--rerun-stale runs them again, --rerun the whole sweep"
        )


def stale_counts(store: ResultsStore, experiment: str, keys: Iterable[str]) -> dict[str, int]:
    """``code label -> number`` of the stored trials among ``keys`` computed by other code
    than the running one, most frequent first."""
    found = Counter(code_label(*p) for p in store.stale(experiment, keys).values())
    return dict(found.most_common())


def config_hash(config: dict[str, Any]) -> str:
    """A short hash of a JSON-serialisable configuration."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _order(trials: Sequence[Trial]) -> list[Trial]:
    """Seeds outermost, so an interrupted sweep has covered every point about equally."""
    return sorted(trials, key=lambda t: t.seed)


def _progress(total: int, desc: str, enabled: bool) -> Any:
    from tqdm import tqdm

    tty = sys.stderr.isatty()
    return tqdm(
        total=total, desc=desc, unit="trial", disable=not enabled, file=sys.stderr,
        dynamic_ncols=True, smoothing=0.1, mininterval=0.2 if tty else 30.0,
    )  # fmt: skip


def run_trials(
    trials: Sequence[Trial],
    examples: dict[str, ExampleModel],
    store: ResultsStore,
    *,
    experiment: str,
    config: dict[str, Any] | None = None,
    jobs: int | None = None,
    scheduler: Any = None,
    progress: bool = True,
    command: str = "",
) -> RunSummary:
    """Run the trials not yet in ``store``, storing each outcome as soon as it is known.

    Parameters
    ----------
    trials : sequence of Trial
    examples : dict
        ``example_hash -> ExampleModel`` for every trial's example.
    store : ResultsStore
    experiment : str
    config : dict, optional
        The sweep's configuration (recorded with its hash in the store's ``runs`` table).
    jobs : int, optional
        Local worker processes (default: CPU count); ``1`` runs in this process.
    scheduler : str or distributed.Client, optional
        Run on a Dask cluster instead: an address such as ``tcp://host:8786``, ``"local"``
        (a local cluster of ``jobs`` processes) or a client
        (:meth:`csplab.engine.pool.Workers.dask`).
    progress : bool
        Show a progress bar on stderr.
    """
    cfg = dict(config or {})
    chash = config_hash(cfg)
    seen: set[str] = set()
    unique: list[Trial] = []
    for t in trials:
        if t.key not in seen:
            seen.add(t.key)
            unique.append(t)
    missing_ex = {t.example_hash for t in unique} - set(examples)
    if missing_ex:
        raise InputError(f"no example model given for hash(es) {sorted(missing_ex)}")
    done = store.done_keys(experiment)
    todo = _order([t for t in unique if t.key not in done])
    _check_dependencies(todo)
    summary = RunSummary(experiment, len(unique), len(unique) - len(todo))
    summary.stale = stale_counts(store, experiment, [t.key for t in unique if t.key in done])
    store.mark_abandoned(experiment)  # runs killed with SIGKILL could not say so
    run_id = store.start_run(
        experiment, cfg, chash, trials=len(unique), skipped=summary.skipped, command=command
    )
    statuses: Counter[str] = Counter()
    t0 = time.perf_counter()
    interrupted = False
    restore = _on_sigterm_interrupt()
    workers: Workers | None = None
    n = min(int(jobs or os.cpu_count() or 1), len(todo))
    if scheduler is not None and todo:
        workers = Workers.dask(scheduler, purpose="--scheduler (a Dask cluster)", local_workers=n)
        summary.executor = "dask"
    elif n > 1:
        workers = Workers.local(n, start="spawn")
        summary.executor = f"{n} local processes"
    bar = _progress(len(todo), experiment, progress)
    finished = False
    try:
        if not todo:
            summary.executor = "nothing to run"
            stream: Stream = iter(())
        elif workers is not None:
            stream = _run_on(workers, todo, examples)
        else:
            summary.executor = "this process"
            stream = _run_serial(todo, examples)
        for trial, outcome, err in stream:
            if err is not None:
                summary.errors.append((trial, err))
            else:
                assert outcome is not None
                store.add(trial, outcome, config_hash=chash)
                summary.ran += 1
                statuses[str(outcome["status"])] += 1
            bar.set_postfix_str(
                ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())), refresh=False
            )
            bar.update(1)
        finished = True
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the stored rows stay, the run is marked
        interrupted = True
        raise
    finally:
        restore()
        bar.close()
        if workers is not None:
            workers.close(kill=not finished)
        summary.statuses = dict(statuses)
        summary.time_s = time.perf_counter() - t0
        store.finish_run(
            run_id, ran=summary.ran, errors=len(summary.errors), interrupted=interrupted
        )
    return summary


def _on_sigterm_interrupt() -> Any:
    """Handle SIGTERM (what ``timeout`` and batch schedulers send) like Ctrl-C until the
    returned function is called: it raises :class:`KeyboardInterrupt` in the main thread, so
    the pool is shut down, its workers killed and the run marked as interrupted."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def handler(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt(f"signal {signum}")

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except (ValueError, OSError):  # not supported here
        return lambda: None
    return lambda: signal.signal(signal.SIGTERM, previous)


def _check_dependencies(todo: Sequence[Trial]) -> None:
    """One line, before anything runs, when a solver of the trials to run needs a package
    that is not installed (:class:`DependencyError`) or is given an option it does not
    declare or a bad value (:class:`InputError`, e.g. ``catalog@order=zigzag`` or
    ``--option time_limit=0``). An unknown solver is left to its trials, which report it."""
    from csplab.solvers import get_solver

    seen: set[str] = set()
    for t in todo:
        key = f"{t.solver}|{sorted(t.options.items(), key=str)!r}"
        if key in seen:
            continue
        seen.add(key)
        try:
            cls, backend = get_solver(t.solver)
        except DependencyError:
            raise
        except CsplabError:
            continue
        cls.validate(t.options, backend)


Stream = Iterator[tuple[Trial, dict[str, Any] | None, str | None]]


def _describe(e: BaseException) -> str:
    msg = str(e).strip().splitlines()
    return f"{type(e).__name__}: {msg[0] if msg else ''}"


def _run_serial(todo: Sequence[Trial], examples: dict[str, ExampleModel]) -> Stream:
    for t in todo:
        try:
            out = execute(t, examples[t.example_hash])
        except Exception as e:  # a trial's failure must not stop the sweep
            yield t, None, _describe(e)
        else:
            yield t, out, None


def _run_on(workers: Workers, todo: Sequence[Trial], examples: dict[str, ExampleModel]) -> Stream:
    """The trials on worker processes, at most four per worker in flight, as they finish;
    an interruption cancels what is queued and kills the workers."""
    shared = {h: workers.share(examples[h]) for h in sorted({t.example_hash for t in todo})}
    pending: dict[Any, Trial] = {}
    it = iter(todo)

    def feed() -> None:
        while len(pending) < 4 * workers.size:
            t = next(it, None)
            if t is None:
                return
            key = f"csplab-{t.experiment}-{t.key}"
            pending[workers.submit(execute, t, shared[t.example_hash], key=key)] = t

    try:
        feed()
        while pending:
            for fut in workers.wait(list(pending), first=True):
                t = pending.pop(fut)
                e = fut.exception()
                if e is not None:
                    yield t, None, _describe(e)
                else:
                    yield t, fut.result(), None
            feed()
    except BaseException:
        workers.cancel(list(pending))
        workers.close(kill=True)
        raise
