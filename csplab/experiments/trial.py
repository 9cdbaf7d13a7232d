"""One trial of an experiment, and the function that runs it in a worker process.

A :class:`Trial` is plain data (picklable, JSON-describable): which example (by name or path
and by content hash), which output size, boundary and periodicity, which solver spec, which
parameters and which seed. Its :attr:`Trial.key` is a hash of all of that, so the same trial
always has the same key and a results store can tell which trials of a sweep are missing.

:func:`execute` runs a trial: it builds the :class:`~csplab.problem.Problem` (cached per
process), warms up the compiled kernels once per process, and calls the experiment's
*measure* function named by ``trial.measure`` (``"module:function"``), which returns
``{"status", "time_s", "stats"}``. The outcome is the same wherever it runs (local pool,
Dask worker, this process) because every random choice is drawn from ``rng=trial.seed``.

Examples
--------
>>> from csplab.examples import load_example
>>> E = load_example("line")
>>> t = Trial("demo", "line", E.hash(), (8, 5), "catalog", {"options": {}}, seed=1,
...           measure="csplab.experiments.trial:measure_solve")
>>> out = execute(t, E)
>>> out["status"], out["stats"]["assigned"]
('solved', 40)
>>> t.key == Trial.from_dict(t.to_dict()).key
True
"""

from __future__ import annotations

import hashlib
import importlib
import json
import socket
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.example import ExampleModel
from csplab.grids import from_example
from csplab.problem import Problem

__all__ = ["Trial", "build_problem", "execute", "grid_digest", "measure_solve", "problem_for"]


def _canon(x: Any) -> str:
    return json.dumps(x, sort_keys=True, separators=(",", ":"), default=str)


@dataclass(frozen=True)
class Trial:
    """One point of an experiment grid with one seed.

    Attributes
    ----------
    experiment : str
    example : str
        Built-in example name or model file path (for reports; the content is identified by
        ``example_hash``).
    example_hash : str
        :meth:`ExampleModel.hash` of the example.
    size : tuple of int
        Output size.
    solver : str
        Solver spec (``"catalog"``, ``"blocks"``, ``"sat:cadical195"`` ...).
    params : dict
        JSON-serialisable parameters: ``options`` (solver options), ``constraints``
        (entries of a constraints file, :mod:`csplab.constraints`, added to the problem)
        and anything the measure function reads.
    seed : int
    boundary : str
        ``"auto"``, ``"none"`` or ``"face=label,..."``.
    periodic : bool
    measure : str
        ``"module:function"`` computing the outcome.
    """

    experiment: str
    example: str
    example_hash: str
    size: tuple[int, ...]
    solver: str
    params: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    boundary: str = "none"
    periodic: bool = False
    measure: str = "csplab.experiments.trial:measure_solve"

    @property
    def key(self) -> str:
        """A hash of everything that determines the outcome (not the example's name)."""
        d = self.to_dict()
        d.pop("example")
        return hashlib.sha256(_canon(d).encode()).hexdigest()[:24]

    @property
    def size_text(self) -> str:
        return "x".join(str(s) for s in self.size)

    @property
    def options(self) -> dict[str, Any]:
        """Solver options (``params["options"]``)."""
        return dict(self.params.get("options", {}))

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["size"] = list(self.size)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Trial:
        d = dict(d)
        d["size"] = tuple(int(s) for s in d["size"])
        return cls(**d)


# ------------------------------------------------------------------------------ worker side

_PROBLEMS: OrderedDict[tuple[Any, ...], Problem] = OrderedDict()
TRIAL_LOCK = threading.Lock()  # Dask workers may run several trials in threads
_WARM = False


def parse_boundary(text: str) -> Any:
    """``"auto"``/``"none"`` or ``"z-=1,x-=0"`` -> what :func:`~csplab.grids.from_example` takes."""
    from csplab.grids import parse_boundary as parse

    return parse(text)


def build_problem(example: Any, size: tuple[int, ...], boundary: str, periodic: bool) -> Problem:
    """The problem of an example model or a tileset (:class:`~csplab.io.ruleset.RuleSet`,
    whose ``"auto"`` boundary is the file's own) at ``size``."""
    if isinstance(example, ExampleModel):
        return from_example(example, size, periodic=periodic, boundary=parse_boundary(boundary))
    return example.problem(size, periodic=periodic or None,  # type: ignore[no-any-return]
                           boundary=parse_boundary(boundary) or "none")  # fmt: skip


def problem_for(trial: Trial, example: ExampleModel) -> Problem:
    """The trial's problem, built once per process and kept in a small cache."""
    cons = trial.params.get("constraints")
    key = (trial.example_hash, trial.size, trial.boundary, trial.periodic, _canon(cons))
    with TRIAL_LOCK:
        P = _PROBLEMS.get(key)
        if P is not None:
            _PROBLEMS.move_to_end(key)
            return P
    P = build_problem(example, trial.size, trial.boundary, trial.periodic)
    if cons:  # global constraints: entries of a constraints file (csplab.constraints)
        from csplab.constraints import parse_constraints

        P = P.with_constraints(parse_constraints(cons, P, f"trial {trial.key}"))
    with TRIAL_LOCK:
        _PROBLEMS[key] = P
        while len(_PROBLEMS) > 6:
            _PROBLEMS.popitem(last=False)
    return P


def _warmup() -> None:
    global _WARM
    with TRIAL_LOCK:
        if not _WARM:
            from csplab.engine.alg31 import jit_warmup

            jit_warmup()
            _WARM = True


def resolve(path: str) -> Callable[..., dict[str, Any]]:
    """Import ``"module:function"``."""
    mod, _, fn = path.partition(":")
    f: Callable[..., dict[str, Any]] = getattr(importlib.import_module(mod), fn)
    return f


def execute(trial: Trial, example: Any) -> dict[str, Any]:
    """Run one trial; returns ``{"status", "time_s", "stats", "host"}``.

    The problem is built outside the timed part; ``time_s`` is what the measure function
    reports (normally the solver's wall time).
    """
    _warmup()
    if example.hash() != trial.example_hash:
        from csplab.errors import InputError

        raise InputError(f"example {trial.example!r} does not match the trial's example hash")
    # a grid example's problem is built here, untimed; other models (polyhedral examples of
    # continuous synthesis) are the measure function's to build and time
    from csplab.io.ruleset import RuleSet

    grid_like = isinstance(example, ExampleModel | RuleSet)
    problem = problem_for(trial, example) if grid_like else None
    t0 = time.perf_counter()
    out = resolve(trial.measure)(trial, example, problem)
    out.setdefault("time_s", time.perf_counter() - t0)
    out.setdefault("stats", {})
    out["host"] = socket.gethostname()
    return out


def grid_digest(grid: NDArray[np.integer[Any]]) -> str:
    """A short hash of a label grid (shape and labels): equal outputs have equal digests."""
    g = np.ascontiguousarray(np.asarray(grid, dtype=np.int32))
    h = hashlib.sha256(str(g.shape).encode())
    h.update(g.tobytes())
    return h.hexdigest()[:16]


def kept_stats(stats: dict[str, Any]) -> dict[str, Any]:
    """The stats of a solver worth storing: every name of the glossary
    (:data:`csplab.solvers.STATS`) whose value is a scalar or a short list (a cell)."""
    from csplab.solvers import STATS

    def small(v: Any) -> bool:
        if isinstance(v, list | tuple):
            return len(v) <= 4 and all(isinstance(x, int | float) for x in v)
        return v is None or isinstance(v, int | float | str | bool | np.integer | np.floating)

    return {k: v for k, v in stats.items() if k in STATS and small(v)}


def record(status: str, time_s: float, stats: dict[str, Any]) -> dict[str, Any]:
    """What a measure returns, as the store keeps it: the trial's status, its time in
    seconds and its stats.

    Examples
    --------
    >>> record("solved", 1, {"nodes": 3})
    {'status': 'solved', 'time_s': 1.0, 'stats': {'nodes': 3}}
    """
    return {"status": str(status), "time_s": float(time_s), "stats": stats}


def measure_solve(trial: Trial, example: ExampleModel, problem: Problem) -> dict[str, Any]:
    """The default measure: solve once with ``rng=trial.seed``; status, time, main stats and
    a digest of the output grid."""
    from csplab.solvers import solve

    restarts = int(trial.params.get("restarts", 0))
    fallback = trial.params.get("fallback")  # none unless the solver entry asks for one
    r = solve(problem, trial.solver, rng=trial.seed, restarts=restarts, fallback=fallback,
              **trial.options)  # fmt: skip
    stats = kept_stats(r.stats)
    stats["grid"] = grid_digest(r.grid)
    return record(r.status, r.time_s, stats)
