"""`Result` (what a solver returns) and `Verdict` (what an analysis tool returns).

Examples
--------
>>> import numpy as np
>>> r = Result("solved", np.zeros((2, 2), dtype=np.int32), "catalog", seed=1, time_s=0.01)
>>> r.ok, r.to_dict()["status"]
(True, 'solved')
>>> Verdict(True, stats={"states": 12}).holds
True
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from csplab.problem import Problem

__all__ = ["STATUSES", "Result", "Status", "Verdict"]

Status = Literal["solved", "failed", "unsat", "timeout"]
STATUSES: tuple[str, ...] = ("solved", "failed", "unsat", "timeout")


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.floating):
        return float(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    return x


@dataclass
class Result:
    """Outcome of one solver run.

    The parameters are kept as attributes of the same names.

    Parameters
    ----------
    status : {"solved", "failed", "unsat", "timeout"}
        ``solved``: ``grid`` is a solution (checked with :meth:`Problem.violations`).
        ``failed``: an incomplete algorithm gave up (this says nothing about
        satisfiability). ``unsat``: proven unsatisfiable. ``timeout``: the time limit hit.
    grid : int32 array of the problem's shape
        The labels (``-1`` for cells left unassigned).
    solver : str
        The solver spec used, e.g. ``"catalog"`` or ``"sat:cadical195"``.
    seed : int or None
        Reproduces the run with ``rng=seed``.
    time_s : float
        Wall time in seconds.
    stats : dict
        Solver-specific, JSON-serialisable figures.
    trace : int array ``(steps, 2)`` or None
        ``(cell, label)`` per assignment for the catalog algorithms.
    problem : Problem or None
        The solved problem, for rendering (label names, model, periodicity, topology).
    """

    status: Status
    grid: NDArray[np.int32]
    solver: str
    seed: int | None = None
    time_s: float = 0.0
    stats: dict[str, Any] = field(default_factory=dict)
    trace: NDArray[np.int64] | None = field(default=None, repr=False)
    problem: Problem | None = field(default=None, repr=False, compare=False)

    @property
    def ok(self) -> bool:
        """Whether the run solved the problem (``status == "solved"``)."""
        return self.status == "solved"

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable summary (without the grid).

        Returns
        -------
        dict
            ``status``, ``solver``, ``seed``, ``time_s`` (rounded to microseconds),
            ``shape`` (the grid's) and ``stats`` (numpy values made plain).
        """
        return {
            "status": self.status,
            "solver": self.solver,
            "seed": self.seed,
            "time_s": round(float(self.time_s), 6),
            "shape": list(self.grid.shape),
            "stats": _jsonable(self.stats),
        }

    def to_json(self) -> str:
        """The summary :meth:`to_dict` as a JSON string.

        Returns
        -------
        str
            One line of JSON.
        """
        return json.dumps(self.to_dict())

    def __repr__(self) -> str:
        return (
            f"Result(status={self.status!r}, solver={self.solver!r}, seed={self.seed}, "
            f"shape={tuple(self.grid.shape)}, time_s={self.time_s:.3f})"
        )

    def _repr_png_(self) -> bytes:
        from csplab.render import render_png_bytes

        names = self.problem.names if self.problem is not None else None
        model = self.problem.meta.get("model") if self.problem is not None else None
        per = self.problem.meta.get("periodic", False) if self.problem is not None else False
        topo = self.problem.meta.get("topology") if self.problem is not None else None
        return render_png_bytes(self.grid, names=names, model=model, periodic=bool(np.all(per)),
                                topology=topo)  # fmt: skip


@dataclass
class Verdict:
    """Outcome of an analysis tool.

    The parameters are kept as attributes of the same names; a verdict is true iff
    ``holds`` is ``True``.

    Parameters
    ----------
    holds : bool or None
        ``True``: the property was proven. ``False``: refuted (see ``witness``).
        ``None``: undecided (a bound was reached).
    witness : object
        A counterexample or certificate, tool-specific.
    stats : dict
        Figures (states enumerated, time ...).
    message : str
        One-line human summary.
    """

    holds: bool | None
    witness: Any = None
    stats: dict[str, Any] = field(default_factory=dict)
    message: str = ""

    def __bool__(self) -> bool:
        return bool(self.holds)

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form of the verdict.

        Returns
        -------
        dict
            ``holds``, ``message``, ``stats`` and ``witness`` (plain data when the witness
            is a dict, sequence or array, else its ``repr``).
        """
        w = self.witness
        return {
            "holds": self.holds,
            "message": self.message,
            "stats": _jsonable(self.stats),
            "witness": _jsonable(w) if isinstance(w, dict | list | tuple | np.ndarray) else repr(w),
        }
