"""What the continuous checkers report: :class:`Defect` and :class:`Violations` (the 2D
checker :mod:`~csplab.continuous.check` and the 3D one :mod:`~csplab.continuous.check3d`
give the same types)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

__all__ = ["Defect", "Violations"]


@dataclass(frozen=True)
class Defect:
    """One violation: ``kind`` is ``"direction"``, ``"edge"``, ``"vertex"`` or ``"label"``."""

    kind: str
    point: tuple[float, float]
    detail: str

    def __str__(self) -> str:
        if not all(math.isfinite(c) for c in self.point):  # a defect of no one place
            return f"{self.kind}: {self.detail}"
        x, y = self.point
        return f"{self.kind} at ({x:.6g}, {y:.6g}): {self.detail}"


class Violations:
    """The defects :func:`violations` found (a sequence; empty means Eq. 4.1 holds).

    Parameters
    ----------
    defects : list of Defect
        The defects, in the order the checker found them.
    """

    def __init__(self, defects: list[Defect]) -> None:
        self.defects = defects

    def __len__(self) -> int:
        return len(self.defects)

    def __iter__(self) -> Iterator[Defect]:
        return iter(self.defects)

    def __getitem__(self, i: int) -> Defect:
        return self.defects[i]

    def __bool__(self) -> bool:
        return bool(self.defects)

    def counts(self) -> dict[str, int]:
        """The number of defects of each kind.

        Returns
        -------
        dict of str to int
            Defect kind (``"direction"``, ``"edge"``, ``"vertex"``, ``"label"``) to the
            number of such defects, sorted by kind; kinds without defects are left out.
        """
        out: dict[str, int] = {}
        for d in self.defects:
            out[d.kind] = out.get(d.kind, 0) + 1
        return dict(sorted(out.items()))

    def describe(self, limit: int = 10) -> str:
        """A summary line and the first ``limit`` defects, for people.

        Parameters
        ----------
        limit : int, default 10
            How many defects to list after the summary line.

        Returns
        -------
        str
            The summary line (the number of violations, by kind), then one indented line
            per listed defect.
        """
        c = ", ".join(f"{v} {k}" for k, v in self.counts().items())
        head = f"{len(self)} violations of Eq. 4.1" + (f" ({c})" if c else "")
        return "\n".join([head, *(f"  {d}" for d in self.defects[:limit])])
