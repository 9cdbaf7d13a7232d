"""Small polyhedral solids for the 3D tests."""

from __future__ import annotations


def box(label: int, lo: list[int], hi: list[int]) -> dict[str, object]:
    """An axis-aligned box ``lo``-``hi`` as a solid mapping, faces outward."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
         [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]  # fmt: skip
    f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]]
    return {"label": label, "vertices": v, "faces": f}
