"""Theorem 5.2.4: a linear-bounded automaton simulated by a 2D model-consistency problem.

An :class:`LBA` is deterministic: states, an input alphabet, a tape alphabet, a start,
an accept and a reject state, and transitions ``(state, symbol) -> (state, symbol, move)``
with ``move`` in ``L``/``R``/``S``. The tape is ``< w >``; the end markers may not be
overwritten or passed, and the head starts on the first input symbol (on ``>`` for the
empty word). A missing transition rejects.

:func:`lba_problem` builds the thesis' construction: the model is ``|w| + 2`` cells wide,
row 1 (the top row) holds the input with the start state, and every row below is the next
configuration. Labels are the tape symbols ``s``, head labels ``(s, q)`` and, for moves,
*departure* labels ``(s, q^r)``/``(s, q^l)`` and *arrival* labels ``(t, q^r')``/
``(t, q^l')``; a move takes two rows (Eq. 5.1–5.4)::

    < (d,q1) a  b >      head in q1 reads d, moves right into q2
    < (d,q2^r) (a,q2^r') b >
    < d (a,q2)  b >

``T_y`` lets each label have exactly the label the automaton's next step puts below it
(a plain symbol: itself or an arrival; a departure: the plain symbol; an arrival: the head
label); ``T_x`` ties each departure to an arrival on the correct side. The accept state
repeats downwards, the reject state has nothing below it. With ``rows`` larger than the
number of rows the computation needs (:attr:`LBA.max_steps` bounds it for every input of
a length), the model with the input on row 1 is consistent iff the automaton accepts.

Two automata are built in (:data:`BUILTIN`): ``anbncn`` for ``{a^n b^n c^n : n >= 1}``
and ``ww`` for ``{w w : w in {a, b}*}``, both not context-free.

Examples
--------
>>> M = load_lba("anbncn")
>>> M.accepts("aabbcc"), M.accepts("aabbc")
(True, False)
>>> lba_consistent(M, "aabbcc").holds, lba_consistent(M, "abcabc").holds
(True, False)
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab import grids
from csplab.errors import FormatError, InputError
from csplab.problem import Problem
from csplab.result import Verdict

__all__ = [
    "BUILTIN",
    "LANGUAGES",
    "LBA",
    "LBAConstruction",
    "all_words",
    "build_construction",
    "lba_consistent",
    "lba_problem",
    "load_lba",
    "parse_lba",
]

LEFT, RIGHT = "<", ">"
MOVES = ("L", "R", "S")

BUILTIN: dict[str, str] = {
    "anbncn": """\
# {a^n b^n c^n : n >= 1}: mark one a (X), the first b after it (Y) and the first c after
# that (Z), go back, repeat; when the next unmarked cell is a Y, only Y and Z may remain.
name: anbncn
input: a b c
tape: a b c X Y Z
start: q0
accept: acc
reject: rej
max_steps: 10 4 2
q0 a -> qb X R
q0 Y -> qcheck Y R
qb a -> qb a R
qb Y -> qb Y R
qb b -> qc Y R
qc b -> qc b R
qc Z -> qc Z R
qc c -> qback Z L
qback a -> qback a L
qback b -> qback b L
qback Y -> qback Y L
qback Z -> qback Z L
qback X -> q0 X R
qcheck Y -> qcheck Y R
qcheck Z -> qcheck Z R
qcheck > -> acc > S
""",
    "ww": """\
# {w w : w in {a, b}*}: mark the first half (A, B) and the second half (P, Q) from both
# ends inwards, then compare them symbol by symbol (X: compared, Y: matched).
name: ww
input: a b
tape: a b A B P Q X Y
start: m0
accept: acc
reject: rej
max_steps: 12 6 3
m0 > -> acc > S
m0 a -> m1 A R
m0 b -> m1 B R
m0 P -> c0 P L
m0 Q -> c0 Q L
m1 a -> m1 a R
m1 b -> m1 b R
m1 P -> m2 P L
m1 Q -> m2 Q L
m1 > -> m2 > L
m2 a -> m3 P L
m2 b -> m3 Q L
m3 a -> m3 a L
m3 b -> m3 b L
m3 A -> m0 A R
m3 B -> m0 B R
c0 A -> c0 A L
c0 B -> c0 B L
c0 < -> c1 < R
c1 X -> c1 X R
c1 A -> ca X R
c1 B -> cb X R
c1 Y -> acc Y S
ca A -> ca A R
ca B -> ca B R
ca Y -> ca Y R
ca P -> cback Y L
cb A -> cb A R
cb B -> cb B R
cb Y -> cb Y R
cb Q -> cback Y L
cback A -> cback A L
cback B -> cback B L
cback Y -> cback Y L
cback X -> c1 X R
""",
}

#: reference membership for the built-in automata (used by the tests and the experiment)
LANGUAGES: dict[str, Any] = {
    "anbncn": lambda w: (len(w) % 3 == 0 and len(w) > 0
                         and w == "a" * (len(w) // 3) + "b" * (len(w) // 3) + "c" * (len(w) // 3)),
    "ww": lambda w: len(w) % 2 == 0 and w[: len(w) // 2] == w[len(w) // 2 :],
}  # fmt: skip


@dataclass(frozen=True)
class LBA:
    """A deterministic linear-bounded automaton (see the module docstring)."""

    name: str
    input_alphabet: tuple[str, ...]
    tape_alphabet: tuple[str, ...]
    states: tuple[str, ...]
    start: str
    accept: str
    reject: str
    delta: dict[tuple[str, str], tuple[str, str, str]] = field(hash=False)
    max_steps: tuple[int, ...] = (0,)

    def __post_init__(self) -> None:
        syms = set(self.tape_alphabet) | {LEFT, RIGHT}
        if not set(self.input_alphabet) <= set(self.tape_alphabet):
            raise InputError("the input alphabet must be part of the tape alphabet")
        if LEFT in self.tape_alphabet or RIGHT in self.tape_alphabet:
            raise InputError("'<' and '>' are the end markers, not tape symbols")
        for s in (self.start, self.accept, self.reject):
            if s not in self.states:
                raise InputError(f"state {s!r} is not declared")
        for (q, s), (q2, s2, mv) in self.delta.items():
            where = f"transition {q} {s} -> {q2} {s2} {mv}"
            if q not in self.states or q2 not in self.states:
                raise InputError(f"{where}: unknown state")
            if s not in syms or s2 not in syms:
                raise InputError(f"{where}: unknown symbol")
            if mv not in MOVES:
                raise InputError(f"{where}: move must be L, R or S")
            if q in (self.accept, self.reject):
                raise InputError(f"{where}: halting states have no transitions")
            if s in (LEFT, RIGHT) and s2 != s:
                raise InputError(f"{where}: the end markers may not be overwritten")
            if s2 not in (LEFT, RIGHT) and s in (LEFT, RIGHT):
                raise InputError(f"{where}: the end markers may not be overwritten")
            if (s == LEFT and mv == "L") or (s == RIGHT and mv == "R"):
                raise InputError(f"{where}: the head may not pass an end marker")

    @property
    def symbols(self) -> tuple[str, ...]:
        """Tape symbols with the end markers."""
        return (LEFT, *self.tape_alphabet, RIGHT)

    @functools.cached_property
    def construction(self) -> LBAConstruction:
        """Theorem 5.2.4's labels and matrices for this automaton, built once.

        The cache lives on the automaton it describes (so it dies with it and cannot be
        confused with another object); :func:`dataclasses.replace` gives a fresh one.
        """
        return build_construction(self)

    def step_bound(self, n: int) -> int:
        """The declared bound on the number of steps for inputs of length ``n``."""
        return sum(c * n**i for i, c in enumerate(self.max_steps))

    def check_word(self, word: str) -> list[str]:
        w = list(word)
        bad = [s for s in w if s not in self.input_alphabet]
        if bad:
            raise InputError(f"input {word!r} uses {bad[0]!r}, not in the input alphabet "
                             f"{' '.join(self.input_alphabet)}")  # fmt: skip
        return w

    def run(self, word: str, max_steps: int | None = None) -> dict[str, Any]:
        """Simulate directly. Returns ``accepted``, ``steps``, ``moves`` (head moves, which
        take two rows in the model), ``rows`` (the model rows the computation fills) and
        the configurations ``(state, head, tape)``."""
        tape = [LEFT, *self.check_word(word), RIGHT]
        q, h = self.start, 1
        confs = [(q, h, "".join(tape))]
        steps = moves = 0
        limit = self.step_bound(len(word)) if max_steps is None else max_steps
        while q not in (self.accept, self.reject):
            if steps >= limit:
                raise InputError(
                    f"LBA {self.name} did not halt on {word!r} within {limit} steps "
                    "(max_steps is too small, or the automaton loops)"
                )
            t = self.delta.get((q, tape[h]))
            if t is None:
                q = self.reject
            else:
                q, tape[h], mv = t
                if mv != "S":
                    moves += 1
                    h += 1 if mv == "R" else -1
            steps += 1
            confs.append((q, h, "".join(tape)))
        return {
            "accepted": q == self.accept,
            "steps": steps,
            "moves": moves,
            "rows": 1 + steps + moves,
            "configurations": confs,
        }

    def accepts(self, word: str) -> bool:
        return bool(self.run(word)["accepted"])


def parse_lba(text: str, path: str = "<lba>") -> LBA:
    """Read the text format of :data:`BUILTIN`: ``key: value`` lines (``name``, ``input``,
    ``tape``, ``start``, ``accept``, ``reject``, ``max_steps`` = coefficients ``c0 c1 c2 ..``
    of the step bound ``c0 + c1 n + c2 n^2 + ..``) and transitions ``q s -> q2 s2 MOVE``;
    ``#`` starts a comment."""
    keys: dict[str, str] = {}
    delta: dict[tuple[str, str], tuple[str, str, str]] = {}
    order: list[str] = []
    for i, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if "->" in line:
            lhs, _, rhs = line.partition("->")
            a, b = lhs.split(), rhs.split()
            if len(a) != 2 or len(b) != 3:
                raise FormatError("a transition is 'state symbol -> state symbol L|R|S'",
                                  path=path, line=i)  # fmt: skip
            if (a[0], a[1]) in delta:
                raise FormatError(f"second transition for {a[0]} {a[1]} (the automaton must "
                                  "be deterministic)", path=path, line=i)  # fmt: skip
            delta[(a[0], a[1])] = (b[0], b[1], b[2].upper())
            for s in (a[0], b[0]):
                if s not in order:
                    order.append(s)
            continue
        k, sep, v = line.partition(":")
        if not sep:
            raise FormatError(f"cannot read {line!r}", path=path, line=i)
        keys[k.strip()] = v.strip()
    need = ["input", "tape", "start", "accept", "reject"]
    miss = [k for k in need if k not in keys]
    if miss:
        raise FormatError(f"missing {', '.join(miss)}", path=path)
    states = [keys["start"], *[s for s in order if s != keys["start"]]]
    for s in (keys["accept"], keys["reject"]):
        if s not in states:
            states.append(s)
    try:
        steps = tuple(int(v) for v in keys.get("max_steps", "0 0 0").split())
    except ValueError:
        raise FormatError("max_steps must be integer coefficients", path=path) from None
    try:
        return LBA(
            name=keys.get("name", Path(path).stem),
            input_alphabet=tuple(keys["input"].split()),
            tape_alphabet=tuple(keys["tape"].split()),
            states=tuple(states),
            start=keys["start"],
            accept=keys["accept"],
            reject=keys["reject"],
            delta=delta,
            max_steps=steps,
        )
    except InputError as e:
        raise FormatError(str(e), path=path) from None


def load_lba(spec: str) -> LBA:
    """A built-in automaton by name (``anbncn``, ``ww``) or a spec file."""
    if spec in BUILTIN:
        return parse_lba(BUILTIN[spec], spec)
    p = Path(spec)
    if not p.exists():
        raise InputError(f"{spec!r} is neither a built-in LBA ({', '.join(BUILTIN)}) nor a file")
    return parse_lba(p.read_text(encoding="utf-8"), str(p))


# ----------------------------------------------------------------------------- construction


@dataclass
class LBAConstruction:
    """Labels and transition matrices of Theorem 5.2.4 for one automaton.

    ``T[0]`` is ``T_x`` (``b`` right of ``a``), ``T[1]`` is ``T_y`` (``b`` above ``a``:
    rows go down in time, so ``T[1][s, a]`` means ``s`` may be directly below ``a``).
    """

    lba: LBA
    names: tuple[str, ...]
    index: dict[tuple[str, str, str], int]
    T: NDArray[np.bool_]

    @property
    def K(self) -> int:
        return len(self.names)

    def head(self, symbol: str, state: str) -> int:
        return self.index[(symbol, state, "")]

    def decode_row(self, row: NDArray[np.integer[Any]]) -> tuple[str | None, int | None, str]:
        """``(state, head position, tape)`` of one model row (state ``None`` when the row
        holds a move in progress)."""
        tape, state, head = [], None, None
        for i, b in enumerate(row.tolist()):
            s, q, kind = self.key[b]
            tape.append(s)
            if q and kind == "":
                state, head = q, i
        return state, head, "".join(tape)

    @property
    def key(self) -> list[tuple[str, str, str]]:
        out: list[tuple[str, str, str]] = [("", "", "")] * self.K
        for k, i in self.index.items():
            out[i] = k
        return out


def build_construction(lba: LBA) -> LBAConstruction:
    """The label set and ``T_x``, ``T_y`` of Theorem 5.2.4 (Eq. 5.1–5.4) for ``lba``."""
    syms = lba.symbols
    r_targets = sorted({q for (q, _, m) in lba.delta.values() if m == "R"})
    l_targets = sorted({q for (q, _, m) in lba.delta.values() if m == "L"})
    keys: list[tuple[str, str, str]] = [(s, "", "") for s in syms]
    keys += [(s, q, "") for q in lba.states for s in syms]
    dep = sorted({(s2, q2, m) for (q2, s2, m) in lba.delta.values() if m != "S"})
    keys += [(s, q, m.lower()) for s, q, m in dep]  # departures: kind "r" / "l"
    # arrivals; nothing arrives on '<' from its left or on '>' from its right (the model's
    # border has no neighbour there to pair with, so such labels would be unconstrained)
    keys += [(s, q, "r'") for q in r_targets for s in syms if s != LEFT]
    keys += [(s, q, "l'") for q in l_targets for s in syms if s != RIGHT]
    index = {k: i for i, k in enumerate(keys)}
    K = len(keys)

    def name(k: tuple[str, str, str]) -> str:
        s, q, kind = k
        if not q:
            return s
        sup = {"": "", "r": "^r", "l": "^l", "r'": "^r'", "l'": "^l'"}[kind]
        return f"({s},{q}{sup})"

    below = np.zeros((K, K), dtype=bool)  # below[a, s]: s may be directly below a
    for k, i in index.items():
        s, q, kind = k
        if not q:  # Eq. 5.4: a plain symbol, or an arrival on it
            below[i, index[k]] = True
            for q2 in r_targets:
                if (s, q2, "r'") in index:
                    below[i, index[(s, q2, "r'")]] = True
            for q2 in l_targets:
                if (s, q2, "l'") in index:
                    below[i, index[(s, q2, "l'")]] = True
        elif kind == "":
            if q == lba.accept:
                below[i, i] = True
            elif q == lba.reject:
                pass  # nothing below the reject state
            else:
                t = lba.delta.get((q, s))
                if t is not None:
                    q2, s2, mv = t
                    below[i, index[(s2, q2, "" if mv == "S" else mv.lower())]] = True
        elif kind in ("r", "l"):  # Eq. 5.1
            below[i, index[(s, "", "")]] = True
        else:  # Eq. 5.2
            below[i, index[(s, q, "")]] = True
    # T_x: departures and arrivals pair up (Eq. 5.3); everything else is free horizontally
    right_pin: list[Any] = [None] * K
    left_pin: list[Any] = [None] * K
    for (_, q, kind), i in index.items():
        if kind == "r":
            right_pin[i] = ("r", q)
        elif kind == "r'":
            left_pin[i] = ("r", q)
        elif kind == "l":
            left_pin[i] = ("l", q)
        elif kind == "l'":
            right_pin[i] = ("l", q)
    Tx = np.array([[right_pin[a] == left_pin[b] for b in range(K)] for a in range(K)])
    T = np.stack([Tx, below.T])
    return LBAConstruction(lba, tuple(name(k) for k in keys), index, T)


def lba_problem(lba: LBA, word: str, rows: int | None = None) -> tuple[Problem, LBAConstruction]:
    """The incomplete model of Theorem 5.2.4: ``|word| + 2`` wide, ``rows`` high (default
    ``2 max_steps(|word|) + 2``), row 1 (the top, ``y = rows - 1``) fixed to
    ``< (w1, q0) w2 .. >``, everything else free."""
    w = lba.check_word(word)
    con = lba.construction
    H = 2 * lba.step_bound(len(w)) + 2 if rows is None else int(rows)
    if H < 1:
        raise InputError("rows must be positive")
    W = len(w) + 2
    tape = [LEFT, *w, RIGHT]
    fixed = np.full((W, H), -1, dtype=np.int64)
    for x, s in enumerate(tape):
        fixed[x, H - 1] = con.index[(s, lba.start, "")] if x == 1 else con.index[(s, "", "")]
    P = grids.grid(
        (W, H), con.T, fixed=fixed, names=con.names, name=f"lba:{lba.name}:{word}",
        meta={"lba": lba.name, "input": word},
    )  # fmt: skip
    return P, con


def lba_consistent(lba: LBA, word: str, rows: int | None = None) -> Verdict:
    """Is the model with ``word`` on row 1 consistent? Decided by arc consistency (the
    rows are forced one by one) with the SAT completion as a fallback when arc consistency
    leaves a choice. ``witness`` is the completed grid; ``stats`` says what decided."""
    from csplab.catalog import Propagator

    P, _con = lba_problem(lba, word, rows)
    eng = Propagator(P)
    stats: dict[str, Any] = {"shape": P.shape, "labels": P.K}
    if not eng.ok:
        stats["decided_by"] = "arc consistency"
        return Verdict(False, None, stats, f"{word!r}: inconsistent (the automaton rejects)")
    C = eng.catalog()
    if (C.sum(axis=1) == 1).all():
        g = C.argmax(axis=1).astype(np.int32).reshape(P.shape)
        stats["decided_by"] = "arc consistency"
        ok = P.is_solution(g)
        return Verdict(ok, g if ok else None, stats,
                       f"{word!r}: {'consistent' if ok else 'inconsistent'}")  # fmt: skip
    from csplab.complexity import complete_model

    r = complete_model(P)
    stats["decided_by"] = "sat"
    ok = r.status == "solved"
    return Verdict(ok, r.grid if ok else None, stats,
                   f"{word!r}: {'consistent' if ok else 'inconsistent'}")  # fmt: skip


def all_words(alphabet: tuple[str, ...], max_len: int) -> list[str]:
    """Every word over ``alphabet`` of length ``0 .. max_len``."""
    return ["".join(t) for n in range(max_len + 1) for t in itertools.product(alphabet, repeat=n)]
