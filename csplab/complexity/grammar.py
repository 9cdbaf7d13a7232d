"""Theorems 5.2.1 and 5.2.3: consistent models and formal languages.

**Theorem 5.2.1** (some example models have no context-free grammar for their consistent
models). :func:`abc_example` builds an example model (our reconstruction of Fig. 5.5, whose
picture is missing from the thesis text) whose consistent models, inside empty space, can
only contain rows ``a^i b^i c^i``: above ``a^i b^j`` stands a triangle whose left half rests
on the ``a``s and right half on the ``b``s; each triangle row is one cell shorter at both
ends, and the two halves may only end together (the top row is ``UE VE``), so ``i = j``;
below ``b^j c^k`` a mirrored triangle forces ``j = k``. Labels: ``a b c`` (the row), ``UE
U1 U | V V1 VE`` (upper triangle: left edge, the cell under the next row's edge, interior;
mirrored on the right) and ``PE P1 P | Q Q1 QE`` (lower triangle). Intersected with the
regular language ``0* a+ b+ c+ 0*`` and mapped to the row strings, the consistent models
give ``{a^i b^i c^i}``, which is not context-free; context-free languages are closed under
both operations, so no context-free grammar generates the consistent models.
:func:`abc_rows_ok` is the check applied to every enumerated model.

**Theorem 5.2.3** (a 1D example gives a regular grammar). :class:`RegularGrammar` has one
non-terminal ``A_b`` per label with ``A_b -> b`` and ``A_b -> b A_c`` iff ``T[b, c]``, and a
start symbol ``S`` with the right-hand sides of every ``A_b``.

Examples
--------
>>> from csplab import ExampleModel
>>> G = RegularGrammar.from_example(ExampleModel([0, 0, 1, 2, 0]))
>>> print(G.to_text().splitlines()[1])
A_0 -> 0 | 0 A_0 | 0 A_1
>>> sorted(G.generate(3)[3])[:3]
[(0, 0, 0), (0, 0, 1), (0, 1, 2)]
>>> E = abc_example()
>>> E.shape, E.K
((14, 11), 16)
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError
from csplab.example import ExampleModel

__all__ = ["ABC_NAMES", "RegularGrammar", "abc_example", "abc_figure", "abc_rows_ok"]

ABC_NAMES = (
    "0", "a", "b", "c", "UE", "U1", "U", "V", "V1", "VE", "PE", "P1", "P", "Q", "Q1", "QE",
)  # fmt: skip
_ID = {n: i for i, n in enumerate(ABC_NAMES)}


def abc_figure(i: int) -> NDArray[np.int32]:
    """One figure with the row ``a^i b^i c^i`` and its two triangles, inside a one-cell
    margin of empty space: shape ``(3i + 2, 2i + 3)``, indexed ``[x, y]``."""
    if i < 1:
        raise InputError("i must be at least 1")
    g = np.zeros((3 * i + 2, 2 * i + 3), dtype=np.int32)
    yb = i + 1
    for x in range(1, i + 1):
        g[x, yb] = _ID["a"]
        g[x + i, yb] = _ID["b"]
        g[x + 2 * i, yb] = _ID["c"]
    for k in range(i):
        y = yb + 1 + k  # upper triangle over a^i b^i
        for x in range(1 + k, i + 1):
            g[x, y] = _ID["UE" if x == 1 + k else "U1" if x == 2 + k else "U"]
        for x in range(i + 1, 2 * i - k + 1):
            g[x, y] = _ID["VE" if x == 2 * i - k else "V1" if x == 2 * i - k - 1 else "V"]
        y = yb - 1 - k  # lower triangle under b^i c^i
        for x in range(i + 1 + k, 2 * i + 1):
            g[x, y] = _ID["PE" if x == i + 1 + k else "P1" if x == i + 2 + k else "P"]
        for x in range(2 * i + 1, 3 * i - k + 1):
            g[x, y] = _ID["QE" if x == 3 * i - k else "Q1" if x == 3 * i - k - 1 else "Q"]
    return g


def abc_example(i: int = 4) -> ExampleModel:
    """The Theorem 5.2.1 example: :func:`abc_figure` for ``i = 4`` (the smallest figure in
    which every adjacency of the construction occurs)."""
    return ExampleModel(abc_figure(i), names=ABC_NAMES, name="abc")


def abc_rows_ok(grid: NDArray[np.integer[Any]]) -> list[int]:
    """The ``i`` of every maximal run of row labels ``a``/``b``/``c`` in ``grid``; raises
    ``ValueError`` naming the row when a run is not of the form ``a^i b^i c^i``."""
    g = np.asarray(grid)
    out = []
    letters = {1: "a", 2: "b", 3: "c"}
    for y in range(g.shape[1]):
        row = "".join(letters.get(int(b), ".") for b in g[:, y])
        for run in re.findall(r"[abc]+", row):
            m = re.fullmatch(r"(a+)(b+)(c+)", run)
            if not m or not len(m.group(1)) == len(m.group(2)) == len(m.group(3)):
                raise ValueError(f"row y={y} holds {run!r}, not a^i b^i c^i")
            out.append(len(m.group(1)))
    return out


@dataclass(frozen=True)
class RegularGrammar:
    """A right-linear grammar over labels: ``rules[A]`` lists right-hand sides
    ``(terminal, next non-terminal or None)``; ``start`` is ``"S"``."""

    K: int
    rules: dict[str, tuple[tuple[int, str | None], ...]]
    start: str = "S"

    @classmethod
    def from_example(cls, example: ExampleModel) -> RegularGrammar:
        """Theorem 5.2.3's grammar for a 1D example (Eq. 3.2's ``T_x``)."""
        if example.ndim != 1:
            raise InputError(f"Theorem 5.2.3 needs a 1D example, got shape {example.shape}")
        T = example.transitions()[0]
        K = example.K
        # as csplab.grids.from_example: labels absent from E never occur in a model
        present = np.flatnonzero(example.counts() > 0).tolist()
        rules: dict[str, tuple[tuple[int, str | None], ...]] = {}
        for b in present:
            rhs: list[tuple[int, str | None]] = [(b, None)]
            rhs += [(b, f"A_{c}") for c in range(K) if T[b, c]]
            rules[f"A_{b}"] = tuple(rhs)
        rules["S"] = tuple(r for b in present for r in rules[f"A_{b}"])
        return cls(K, {"S": rules["S"], **{k: v for k, v in rules.items() if k != "S"}})

    def to_text(self) -> str:
        """The rules, one non-terminal per line."""
        lines = []
        for A, rhs in self.rules.items():
            alts = [f"{t}" if n is None else f"{t} {n}" for t, n in rhs]
            lines.append(f"{A} -> " + " | ".join(alts))
        return "\n".join(lines)

    def generate(self, max_len: int) -> dict[int, set[tuple[int, ...]]]:
        """Every terminal string of length ``1 .. max_len``, by expanding derivations."""
        out: dict[int, set[tuple[int, ...]]] = {n: set() for n in range(1, max_len + 1)}
        frontier: list[tuple[tuple[int, ...], str]] = [((), self.start)]
        while frontier:
            nxt: list[tuple[tuple[int, ...], str]] = []
            for prefix, A in frontier:
                for t, B in self.rules[A]:
                    s = (*prefix, t)
                    if B is None:
                        out[len(s)].add(s)
                    elif len(s) < max_len:
                        nxt.append((s, B))
            frontier = nxt
        return out

    def count(self, max_len: int) -> dict[int, int]:
        """The number of derivations of each length (the grammar is unambiguous: the
        non-terminal after a terminal ``b`` is always ``A_b``, so this counts strings)."""
        ways: dict[str, int] = {self.start: 1}
        out: dict[int, int] = {}
        for n in range(1, max_len + 1):
            done = 0
            nxt: dict[str, int] = {}
            for A, w in ways.items():
                for _, B in self.rules[A]:
                    if B is None:
                        done += w
                    else:
                        nxt[B] = nxt.get(B, 0) + w
            out[n] = done
            ways = nxt
        return out

    def accepts(self, word: Iterable[int]) -> bool:
        """Is ``word`` generated (a left-to-right run of the grammar as an automaton)?"""
        cur = {self.start}
        w = list(word)
        if not w:
            return False
        for j, t in enumerate(w):
            last = j == len(w) - 1
            nxt: set[str] = set()
            for A in cur:
                for tt, B in self.rules[A]:
                    if tt != t:
                        continue
                    if last and B is None:
                        return True
                    if B is not None:
                        nxt.add(B)
            cur = nxt
        return False
