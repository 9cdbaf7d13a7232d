"""What :class:`~csplab.continuous.model.PolygonModel` and
:class:`~csplab.continuous.polyhedra.PolyhedralModel` share: a named, labelled collection of
parts (polygons or solids) with its label set, length and ``repr``.

Examples
--------
>>> from csplab.continuous.model import PolygonModel
>>> M = PolygonModel([{"label": 2, "points": [[0, 0], [1, 0], [1, 1]]}], name="t")
>>> M.labels, len(M), M
((2,), 1, PolygonModel('t', 1 polygons, labels=[2]))
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar, Protocol


class _Labelled(Protocol):
    label: int


class PartsModel:
    """Base of the continuous models: ``parts`` names the attribute holding the parts (each
    with a ``label``), ``kind`` the model's adjective."""

    parts: ClassVar[str]
    kind: ClassVar[str]
    name: str

    def _items(self) -> Sequence[_Labelled]:
        items: Sequence[_Labelled] = getattr(self, self.parts)
        return items

    @property
    def labels(self) -> tuple[int, ...]:
        """The object labels used (sorted; 0 is implicit everywhere else)."""
        return tuple(sorted({p.label for p in self._items()}))

    def __len__(self) -> int:
        return len(self._items())

    def __repr__(self) -> str:
        nm = f"{self.name!r}, " if self.name else ""
        return f"{type(self).__name__}({nm}{len(self)} {self.parts}, labels={list(self.labels)})"
