"""The label set of the Theorem 3.3.4 reduction (thesis Fig. 3.7), given directly.

Every label is a square piece with a *socket* on each side; two pieces may be neighbours
(``T_x[a, b]``: ``b`` right of ``a``; ``T_y[a, b]``: ``b`` above ``a``) iff the touching
sockets are compatible. Sockets:

=====  =========================================================  ==================
name   meaning                                                    compatible with
=====  =========================================================  ==================
``X``  outside: the back of a wall, a gate body                   ``X``
``I``  inside face of the enclosure, or a side of an arrow that   ``T``, ``F``, ``a``
       may see either value
``T``  TRUE fill                                                  ``T``, ``I``
``F``  FALSE fill                                                 ``F``, ``I``
``a``  the side of a NOT arrow that faces the enclosure           ``I``
``n``  NOT gate pin                                               ``n``
``o``  OR gate pin                                                ``o``
=====  =========================================================  ==================

The labels (pictures: :func:`csplab.complexity.draw.label_sheet`, drawn by ``csplab reduction
planar3sat --labels``; in the ASCII pictures ``#`` is enclosure, ``.`` a wire cell, ``T``/``F``
the demanded value):

* ``wall`` (0): all sides ``X``; the space outside the wires and the outer corner of a bend.
* ``TRUE`` (1) and ``FALSE`` (2): the fill of a wire, all sides ``T`` or ``F``, so TRUE and
  FALSE never touch and a connected wire is all TRUE or all FALSE.
* ``enc[s]`` (3–17), for every non-empty set ``s`` of sides among ``L R D U``: enclosure
  whose sides in ``s`` touch a wire (socket ``I``) and the others ``X``. ``enc[D]`` is the
  top of a horizontal wire, ``enc[U]`` the bottom, ``enc[L]``/``enc[R]`` the sides of a
  vertical wire; two sides give the inner corner of a bent wire (``enc[RD]``) or a wall
  between two parallel wires (``enc[LR]``); the fan-out of a variable into its legs is a
  horizontal wire with ``enc[U]``/``enc[D]`` pieces cut by the legs. Because ``I`` only
  accepts fill or arrows, a free cell next to the enclosure can only hold ``TRUE``,
  ``FALSE`` or a gate arrow.
* ``NOT`` (18) and its two arrows ``NOT-dn`` (19: TRUE below, FALSE above) and ``NOT-up``
  (20: FALSE below, TRUE above): ``NOT`` sits in the left wall of a vertical wire and only
  accepts an arrow on its right; the arrow cuts the wire and swaps the values below and
  above it::

      # T #        # F #
      N ↓ #        N ↑ #
      # F #        # T #

* ``OR-top`` (21) sits above the junction of a clause above the variable line; the
  junction then holds one of ``OR<`` (23), ``ORv`` (24), ``OR>`` (25), each demanding
  TRUE in its arrow's direction and accepting either value on the other two wires.
  ``OR-bot`` (22) with ``OR<'`` (26), ``OR^'`` (27), ``OR>'`` (28) is the mirror image for
  clauses below the line::

      # O #        . O .
      . v .   ->   . v .   with TRUE below the junction (the middle leg)
      # . #        # T #

Examples
--------
>>> T = transitions()
>>> T.shape
(2, 29, 29)
>>> bool(T[0, TRUE, TRUE]), bool(T[0, TRUE, FALSE]), bool(T[1, FALSE, TRUE])
(True, False, False)
>>> [NAMES[b] for b in np.flatnonzero(T[0, NOT])]       # what may follow NOT on the right
['NOT-dn', 'NOT-up']
>>> [NAMES[b] for b in np.flatnonzero(T[1, :, OR_TOP])]  # what may sit below OR-top
['OR<', 'ORv', 'OR>']
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ARROW_BOT",
    "ARROW_TOP",
    "FALSE",
    "NAMES",
    "NOT",
    "NOT_DN",
    "NOT_UP",
    "OR_BOT",
    "OR_TOP",
    "SIDES",
    "TRUE",
    "WALL",
    "K",
    "enclosure",
    "sockets",
    "transitions",
]

SIDES = "LRDU"  # left, right, down, up
WALL, TRUE, FALSE = 0, 1, 2
_ENC0 = 3
NOT, NOT_DN, NOT_UP = 18, 19, 20
OR_TOP, OR_BOT = 21, 22
#: arrows under OR-top: demand TRUE to the left, below, to the right
ARROW_TOP = (23, 24, 25)
#: arrows over OR-bot: demand TRUE to the left, above, to the right
ARROW_BOT = (26, 27, 28)
K = 29

_COMPAT = {
    frozenset("X"), frozenset("T"), frozenset("F"), frozenset("IT"), frozenset("IF"),
    frozenset("Ia"), frozenset("n"), frozenset("o"), frozenset("p"),
}  # fmt: skip


def _enc_name(mask: int) -> str:
    return "enc[" + "".join(s for i, s in enumerate(SIDES) if mask >> i & 1) + "]"


def enclosure(sides: str) -> int:
    """The enclosure label whose sides ``sides`` (a subset of ``"LRDU"``) touch a wire;
    ``""`` gives ``wall``.

    >>> NAMES[enclosure("DR")]
    'enc[RD]'
    """
    mask = 0
    for s in sides:
        mask |= 1 << SIDES.index(s)
    return WALL if mask == 0 else _ENC0 + mask - 1


def sockets() -> list[dict[str, str]]:
    """The four side sockets of every label, ``{"L": .., "R": .., "D": .., "U": ..}``."""
    out: list[dict[str, str]] = [dict.fromkeys(SIDES, "X") for _ in range(K)]
    out[TRUE] = dict.fromkeys(SIDES, "T")
    out[FALSE] = dict.fromkeys(SIDES, "F")
    for mask in range(1, 16):
        out[_ENC0 + mask - 1] = {s: ("I" if mask >> i & 1 else "X") for i, s in enumerate(SIDES)}
    out[NOT] = {"L": "X", "R": "n", "D": "X", "U": "X"}
    out[NOT_DN] = {"L": "n", "R": "a", "D": "T", "U": "F"}
    out[NOT_UP] = {"L": "n", "R": "a", "D": "F", "U": "T"}
    out[OR_TOP] = {"L": "X", "R": "X", "D": "o", "U": "X"}
    out[OR_BOT] = {"L": "X", "R": "X", "D": "X", "U": "p"}
    demand = ("L", "D", "R")
    for lab, d in zip(ARROW_TOP, demand, strict=True):
        out[lab] = {"L": "I", "R": "I", "D": "I", "U": "o"}
        out[lab][d] = "T"
    for lab, d in zip(ARROW_BOT, ("L", "U", "R"), strict=True):
        out[lab] = {"L": "I", "R": "I", "D": "p", "U": "I"}
        out[lab][d] = "T"
    return out


NAMES: tuple[str, ...] = (
    "wall", "TRUE", "FALSE", *(_enc_name(m) for m in range(1, 16)), "NOT", "NOT-dn", "NOT-up",
    "OR-top", "OR-bot", "OR<", "ORv", "OR>", "OR<'", "OR^'", "OR>'",
)  # fmt: skip


def transitions() -> NDArray[np.bool_]:
    """``T[d, a, b]`` for ``d = 0`` (x, ``b`` right of ``a``) and ``d = 1`` (y, ``b`` above
    ``a``): the touching sockets must be compatible."""
    sk = sockets()
    T = np.zeros((2, K, K), dtype=bool)
    for a in range(K):
        for b in range(K):
            T[0, a, b] = frozenset(sk[a]["R"] + sk[b]["L"]) in _COMPAT
            T[1, a, b] = frozenset(sk[a]["U"] + sk[b]["D"]) in _COMPAT
    return T


# ----------------------------------------------------------------------------- pictures

COLORS: dict[str, tuple[int, int, int]] = {
    "free": (255, 255, 255),
    "wall": (205, 205, 205),
    "enc": (90, 90, 90),
    "TRUE": (60, 170, 75),
    "FALSE": (215, 60, 50),
    "NOT": (40, 90, 200),
    "OR": (235, 190, 40),
    "arrow": (20, 20, 20),
}


def label_color(b: int) -> tuple[int, int, int]:
    """The picture colour of label ``b`` (Fig. 3.7: TRUE green, FALSE red)."""
    if b < 0:
        return COLORS["free"]
    if b == WALL:
        return COLORS["wall"]
    if b == TRUE:
        return COLORS["TRUE"]
    if b == FALSE:
        return COLORS["FALSE"]
    if b < NOT:
        return COLORS["enc"]
    if b in (NOT, NOT_DN, NOT_UP):
        return (120, 160, 240) if b != NOT else COLORS["NOT"]
    if b in (OR_TOP, OR_BOT):
        return COLORS["OR"]
    return (250, 225, 120)


def arrow_direction(b: int) -> str | None:
    """``"L"``, ``"R"``, ``"D"`` or ``"U"`` for arrow labels, else ``None``."""
    return {
        NOT_DN: "D", NOT_UP: "U", ARROW_TOP[0]: "L", ARROW_TOP[1]: "D", ARROW_TOP[2]: "R",
        ARROW_BOT[0]: "L", ARROW_BOT[1]: "U", ARROW_BOT[2]: "R",
    }.get(b)  # fmt: skip
