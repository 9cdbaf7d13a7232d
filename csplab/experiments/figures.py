"""Figures of the experiments' reports: matplotlib figures without global state, legends
outside the data, and saving as PNG and SVG with reproducible bytes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["new_figure", "outside_legend", "save_figure"]


def outside_legend(target: Any, **kwargs: Any) -> Any:
    """A legend to the right of the axes or figure ``target``, outside the data
    (``save_figure`` saves with a tight bounding box, so it is kept in the picture)."""
    kwargs.setdefault("fontsize", 8)
    kwargs.setdefault("frameon", False)
    kwargs.setdefault("loc", "upper left")
    kwargs.setdefault("bbox_to_anchor", (1.02, 1))
    kwargs.setdefault("borderaxespad", 0)
    return target.legend(**kwargs)


def new_figure(
    nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float], squeeze: bool = True
) -> tuple[Any, Any]:
    """A matplotlib figure and its axes (like ``plt.subplots``) without global state.

    The figure gets its own Agg canvas: no ``matplotlib.use``, no pyplot figure manager,
    no change to ``matplotlib.rcParams``, so plotting from a report leaves a notebook's
    or another program's backend and settings as they were.

    Parameters
    ----------
    nrows, ncols : int
        The grid of axes.
    figsize : (float, float)
        Width and height in inches.
    squeeze : bool
        As in :meth:`matplotlib.figure.Figure.subplots`.

    Returns
    -------
    (Figure, Axes or array of Axes)
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, squeeze=squeeze)


def save_figure(fig: Any, stem: Path) -> list[Path]:
    """Save a matplotlib figure as ``stem.png`` and ``stem.svg`` (reproducible bytes).

    The SVG hash salt (stable element ids) is set for these two saves only
    (``matplotlib.rc_context``); the global ``rcParams`` are left unchanged.
    """
    import matplotlib

    stem.parent.mkdir(parents=True, exist_ok=True)
    out = []
    with matplotlib.rc_context({"svg.hashsalt": "csplab"}):
        for ext, meta in (("png", {"Software": None}), ("svg", {"Date": None})):
            p = stem.with_suffix(f".{ext}")
            fig.savefig(p, dpi=130, bbox_inches="tight", metadata=meta)
            out.append(p)
    if getattr(fig.canvas, "manager", None) is not None:  # a pyplot figure: release it
        import matplotlib.pyplot as plt

        plt.close(fig)
    return out
