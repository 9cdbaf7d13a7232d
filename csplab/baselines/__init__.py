"""Baselines the seeds compare model synthesis against, runnable on the same inputs.

Each baseline declares itself once in :data:`BASELINES` (name, summary, options, function);
``csplab baseline NAME MODEL --size ... --out FILE`` and ``csplab info`` are derived from
the declaration. A grid baseline returns an ordinary label grid, so ``csplab check`` counts
the adjacency constraints it breaks (model synthesis breaks none by construction).

To add one: write ``csplab/baselines/NAME.py`` with a function ``f(example, size, *, rng,
**options) -> grid``, add a :class:`Baseline` entry to :data:`BASELINES` with its options,
and a test under ``tests/baselines/``.

Examples
--------
>>> from csplab.examples import load_example
>>> g = run_baseline("texture", load_example("fig3_10"), (8, 8), rng=0, window=3)
>>> g.shape
(8, 8)
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from csplab.errors import InputError

__all__ = ["BASELINES", "Baseline", "BaselineOption", "run_baseline"]


@dataclass(frozen=True)
class BaselineOption:
    """One option of a baseline: its name (``--name`` on the command line), type, default
    and help."""

    name: str
    type: type
    default: Any
    help: str


@dataclass(frozen=True)
class Baseline:
    """A declared baseline: ``function`` is ``"module:function"``."""

    name: str
    summary: str
    function: str
    options: tuple[BaselineOption, ...] = ()
    gives: str = "grid"
    #: ``"module:function"`` of ``f(example, size, **options) -> bytes``: the peak memory,
    #: estimated from the sizes before the work (``None``: small by construction)
    memory: str | None = None
    #: what the refusal of a too-large estimate tells the user to change
    memory_hint: str = "use a smaller --size"

    def resolve(self) -> Callable[..., Any]:
        mod, _, fn = self.function.partition(":")
        f: Callable[..., Any] = getattr(importlib.import_module(mod), fn)
        return f


#: every baseline, declared once
BASELINES: dict[str, Baseline] = {
    "texture": Baseline(
        "texture",
        "texture synthesis of label grids (2D and 3D): Efros & Leung 1999 non-parametric "
        "sampling (a label drawn among the causal-neighbourhood matches within (1 + eps) of "
        "the best) or Kwatra et al. 2003 graph-cut patches (minimum-cut seams, PyMaxflow)",
        "csplab.baselines.texture:texture",
        (
            BaselineOption("method", str, "efros-leung", "efros-leung or graphcut"),
            BaselineOption("window", int, 5, "efros-leung: odd neighbourhood width in cells"),
            BaselineOption("patch", int, 8, "graphcut: patch width in cells"),
            BaselineOption("overlap", int, 3, "graphcut: overlap of neighbouring patches"),
            BaselineOption("eps", float, 0.1, "candidates within (1 + eps) of the best match"),
        ),
        memory="csplab.baselines.texture:texture_memory",
        memory_hint="use a smaller --size, --window (efros-leung) or --patch (graphcut)",
    ),
    "geometry": Baseline(
        "geometry",
        "Lagae et al. 2004 geometry synthesis: a signed distance field of the example's "
        "closed mesh, best-first block matching in a search tree of block pyramids, the "
        "zero level set as a closed mesh (marching cubes)",
        "csplab.baselines.geometry:geometry",
        (
            BaselineOption("resolution", int, 24, "field samples along the example's longest side"),
            BaselineOption("block", int, 8, "block side in samples (a power of 2)"),
            BaselineOption("levels", int, 1, "1: single resolution; more: multiresolution"),
        ),
        gives="mesh",
    ),
    "retarget": Baseline(
        "retarget",
        "Wu et al. 3D model retargeting with offset statistics: voxels, dominant offsets of "
        "matched surface features, expansion moves over translated copies (PyMaxflow), a "
        "closed mesh; --offsets all is the conventional MRF of every translation",
        "csplab.baselines.retarget:retarget",
        (
            BaselineOption("resolution", int, 24, "voxels along the example's longest side"),
            BaselineOption("offsets", str, "sparse", "sparse (principal offsets) or all"),
            BaselineOption("regular", int, 2, "offsets all: translations this many voxels apart"),
        ),
        gives="mesh",
    ),
}


def run_baseline(
    name: str,
    example: Any,
    size: Sequence[int],
    *,
    rng: Any = None,
    memory_limit: float | None = None,
    **options: Any,
) -> Any:
    """Run the baseline ``name`` on ``example`` at ``size`` with its ``options``: a label
    grid (``gives="grid"``) or a ``trimesh.Trimesh`` (``gives="mesh"``). A baseline that
    declares its :attr:`Baseline.memory` is refused before the work
    (:class:`~csplab.errors.MemoryLimitError`, one line) when its estimate exceeds
    ``memory_limit`` GB (default :func:`csplab.limits.memory_budget`)."""
    b = BASELINES.get(name)
    if b is None:
        raise InputError(f"unknown baseline {name!r}; baselines: {', '.join(BASELINES)}")
    known = {o.name for o in b.options}
    bad = set(options) - known
    if bad:
        raise InputError(
            f"baseline {name!r} has no option(s) {', '.join(sorted(bad))}; "
            f"it has {', '.join(sorted(known)) or 'none'}"
        )
    if b.memory is not None:
        from csplab.limits import check_memory, memory_budget

        mod, _, fn = b.memory.partition(":")
        need = float(getattr(importlib.import_module(mod), fn)(example, size, **options))
        check_memory(
            need,
            f"baseline {name} at {'x'.join(map(str, size))}",
            b.memory_hint,
            budget=memory_budget(memory_limit),
        )
    return b.resolve()(example, size, rng=rng, **options)
