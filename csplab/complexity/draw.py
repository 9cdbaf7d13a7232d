"""Pictures of reduction grids in the style of thesis Fig. 3.7 (PIL).

Free cells are white, the enclosure dark grey, the space outside light grey, TRUE green,
FALSE red, gates blue (NOT) and yellow (OR) with their arrows drawn in. ``y`` is up.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from csplab.complexity.gadgets import (
    COLORS,
    NAMES,
    OR_BOT,
    OR_TOP,
    K,
    arrow_direction,
    label_color,
    sockets,
)

__all__ = ["draw_cell", "label_sheet", "render_reduction", "save_reduction_png"]


def draw_cell(dr: Any, x0: int, y0: int, s: int, b: int) -> None:
    """Draw label ``b`` of the reduction as an ``s``-pixel square at ``(x0, y0)`` (top-left)."""
    dr.rectangle([x0, y0, x0 + s - 1, y0 + s - 1], fill=label_color(b))
    d = arrow_direction(b)
    if d is not None and s >= 5:
        m = s / 2
        q = s * 0.32
        cx, cy = x0 + m - 0.5, y0 + m - 0.5
        tip = {"L": (-q, 0), "R": (q, 0), "U": (0, -q), "D": (0, q)}[d]
        side = (tip[1], -tip[0])
        pts = [
            (cx + tip[0], cy + tip[1]),
            (cx - tip[0] + side[0], cy - tip[1] + side[1]),
            (cx - tip[0] - side[0], cy - tip[1] - side[1]),
        ]
        dr.polygon(pts, fill=(20, 20, 20))
    elif b in (OR_TOP, OR_BOT) and s >= 5:
        dr.text((x0 + s * 0.3, y0 + s * 0.15), "OR" if s >= 14 else "", fill=(0, 0, 0))


def render_reduction(grid: ArrayLike, scale: int = 10) -> Any:
    """A PIL image of a 2D reduction grid (``-1`` = free, drawn white)."""
    from PIL import Image, ImageDraw

    g = np.asarray(grid)
    nx, ny = g.shape
    img = Image.new("RGB", (nx * scale, ny * scale), (255, 255, 255))
    dr = ImageDraw.Draw(img)
    for x in range(nx):
        for y in range(ny):
            draw_cell(dr, x * scale, (ny - 1 - y) * scale, scale, int(g[x, y]))
    return img


def save_reduction_png(grid: ArrayLike, path: str | Path, scale: int = 10) -> None:
    """Write :func:`render_reduction` to ``path``."""
    p = Path(path)
    if p.parent and not p.parent.exists():
        p.parent.mkdir(parents=True, exist_ok=True)
    render_reduction(grid, scale).save(p)


def label_sheet(scale: int = 36) -> Any:
    """A PIL image with one small picture per label: the piece in its colour, its sockets
    marked on its sides (thick dark bar = ``X``, white = ``I``, green/red = demanded value,
    blue = NOT pin, yellow = OR pin), its id and name."""
    from PIL import Image, ImageDraw

    cols = 8
    rows = (K + cols - 1) // cols
    cw, ch = scale * 3, scale * 2 + 14
    img = Image.new("RGB", (cols * cw, rows * ch), (250, 250, 250))
    dr = ImageDraw.Draw(img)
    sk = sockets()
    sock_col = {
        "X": (40, 40, 40), "I": (255, 255, 255), "T": COLORS["TRUE"], "F": COLORS["FALSE"],
        "a": (150, 150, 255), "n": COLORS["NOT"], "o": COLORS["OR"], "p": COLORS["OR"],
    }  # fmt: skip
    for b in range(K):
        r, c = divmod(b, cols)
        x0, y0 = c * cw + scale, r * ch + 4
        draw_cell(dr, x0, y0, scale, b)
        t = max(3, scale // 8)
        s = sk[b]
        dr.rectangle([x0 - t, y0, x0 - 1, y0 + scale - 1], fill=sock_col[s["L"]])
        dr.rectangle([x0 + scale, y0, x0 + scale + t - 1, y0 + scale - 1], fill=sock_col[s["R"]])
        dr.rectangle([x0, y0 - t + 1, x0 + scale - 1, y0], fill=sock_col[s["U"]])
        dr.rectangle([x0, y0 + scale, x0 + scale - 1, y0 + scale + t - 1], fill=sock_col[s["D"]])
        dr.text((c * cw + 4, y0 + scale + t + 2), f"{b} {NAMES[b]}", fill=(0, 0, 0))
    return img
