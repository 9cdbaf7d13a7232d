"""An independent checker of infallibility certificates (``csplab check-certificate``).

``csplab prove --certificate FILE`` writes what its verdict rests on; this module re-verifies
it from the file alone, as a DRAT checker re-verifies a SAT solver's refutation. It shares
no code with the prover (:mod:`csplab.analysis.infallible`; an import-linter contract
forbids importing it, or anything of csplab but :mod:`csplab.errors`): the frames, regions,
arc consistency and grid replay below are written again, plainly.

How the closure is checked: a state needs arc consistency only when some label that
its cell's labelled neighbours allow (a superset of the catalog) leads to no recorded
state, and at the point; the catalog is computed once per region shape (the region's
cells relative to the step's cell, which are labelled, their domains) and labels. A
certificate of up to ``_LEAN_STATES`` states (or two per step) is checked one frame and
one state at a time with Python integers (sets of cells as bit masks:
:func:`_check_lean`), where arrays would cost more in fixed overhead than in work. A
larger one is checked in arrays: every
frame is verified in one batch of boolean arrays (regions, labelled cells, recorded
keys); every state of every configuration is a row of one label array, and its
successors are looked up among the states by exact integer codes. Both make the same
checks (the tests run each planted defect through both).

Format ``csplab-certificate``, version 1 (JSON)
-----------------------------------------------
``rules``: ``labels`` (K), ``used`` (K flags: the labels a cell may take) and ``pairs``
(per axis ``d``, the pairs ``[a, b]``: ``b`` may follow ``a`` along ``+d``);
``rules_sha256``: SHA-256 of ``rules`` as compact JSON with sorted keys (a changed rule
without a new hash is rejected). ``claim`` is ``"infallible"`` or ``"fallible"``.

``rules.faces`` (optional): the file's domain rules in file order, ``[op, where, labels]``
with ``op`` one of keep / remove / force / add and ``where`` a face (``"x-"``), every cell
but a face (``"!x-"``) or every cell (``"*"``): a cell's domain is the labels in use, edited
by each rule that applies to it.

*infallible*: ``region``, ``order``, ``axes`` (outermost first), ``history``, ``back``
(optional, default 1 per axis: the region of a cell ``c`` is the box ``c - back .. c +
region - 2``, clipped) and ``configs``, one per position of a point relative to the
output's lower edges (distance ``0 .. back + history``, the last meaning "at least") and
upper edges (``0 .. region - 2``),
and -- with face rules -- whether the frame's first (``at_lower``) and last
(``at_upper``) cell on each axis lies on the output's face (always when the frame is
clipped there, both ways otherwise; without face rules, only when clipped).
Each holds ``keys[i]`` (the earlier frame cells whose labels the state before step ``i``
records) and ``states``, pairs ``[i, labels of keys[i]]``. The checker rebuilds each
frame (the cells before the point ``q = lower`` in scan order, in the box of extent
``lower + 1 + upper``, then ``q``) and verifies that

1. the configurations are exactly all of them;
2. ``keys[0]`` is empty, ``keys[i + 1] ⊆ keys[i] ∪ {i}``, and ``keys[i]`` holds every
   earlier cell of step ``i``'s region that borders a cell of that region not yet
   labelled (only those can change its catalog: a labelled cell whose region neighbours
   are all labelled agrees with them, since each label agrees with its backward
   neighbours, which border the cell being labelled);
3. the start state ``[0, []]`` is present and the set is closed: for each state at step
   ``i`` and each label of ``C_R`` at step ``i`` (arc consistency on the region of cell
   ``i``, clipped to the frame, with the recorded labels), the next state is present;
4. at the last step (the point) ``C_R`` is never empty.

Then Alg. 3.6 with these regions cannot fail in any configuration, so Alg. 3.1 never fails
(Theorem 3.3.6, the prover's docstring has the argument). With ``label_classes`` true, a
state records each label by its class -- the least label in use with the same forward
supports along the axes on which the cell's + neighbour is in the frame and not yet
labelled at that step -- and arc consistency leaves out arcs between labelled cells
(:func:`_check_closed` says why that is sound). ``dead`` (optional, with
``label_classes``): ``cap`` and ``stages`` ``[face, [[where, labels], ...]]`` of labels no
catalog of Alg. 3.1 holds at cells whose capped distances to the faces are ``where``
(each one's supports toward the face are dead at this stage or before:
:func:`_check_dead`); the checks above then run with each frame cell's dead labels out of
its domain. *fallible*: ``run`` (``shape``,
``order``, ``choices`` ``[[cell, label], ...]``, optional ``boundary``: a mapping face ->
label, or ``"auto"`` for the face rules): the checker replays
it with arc consistency on the whole grid -- the cells in scan order, each label in its
cell's catalog -- and verifies that some catalog ends empty.

Examples
--------
>>> import json
>>> cert = {"format": "csplab-certificate", "version": 1, "claim": "fallible",
...         "rules": {"labels": 2, "used": [1, 1], "pairs": [[[0, 1], [1, 0]]]}}
>>> cert["rules_sha256"] = rules_hash(cert["rules"])
>>> cert["run"] = {"shape": [3], "order": "scanline", "choices": [[[0], 0]]}
>>> check_certificate(cert)
(False, 'invalid: the run of Alg. 3.1 does not fail (every catalog non-empty at the end)')
>>> cert["rules"]["pairs"] = [[[0, 1]]]; cert["rules_sha256"] = rules_hash(cert["rules"])
>>> check_certificate(cert)[0]
True
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import json
import math
import operator
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from csplab.errors import InputError, MemoryLimitError

__all__ = ["check_certificate", "load_certificate", "rules_hash"]

FORMAT = "csplab-certificate"
VERSION = 1
_AXES = "xyzw"
# the scan order of each number of axes
_SCANLINE = [tuple(range(k)) for k in range(len(_AXES) + 1)]

Cell = tuple[int, ...]


class _Invalid(Exception):
    pass


def rules_hash(rules: Mapping[str, Any]) -> str:
    """SHA-256 of the ``rules`` object as compact JSON with sorted keys.

    Parameters
    ----------
    rules : mapping
        The certificate's ``rules`` (``labels``, ``used``, ``pairs``).

    Returns
    -------
    str
        The hex digest.

    Examples
    --------
    >>> rules_hash({"labels": 1, "used": [1], "pairs": [[[0, 0]]]})[:12]
    '2d2bbe2d9229'
    """
    return hashlib.sha256(_RULES_JSON.encode(rules).encode()).hexdigest()


# compact JSON with sorted keys, as ``json.dumps(..., sort_keys=True, separators=(",", ":"))``
_RULES_JSON = json.JSONEncoder(sort_keys=True, separators=(",", ":"))


def load_certificate(path: str | Path) -> dict[str, Any]:
    """Read a certificate file (JSON object of format ``csplab-certificate``).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    dict

    Raises
    ------
    InputError
        The file is missing, not JSON, or not a certificate of a known version.

    Examples
    --------
    >>> load_certificate("/nonexistent.json")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: /nonexistent.json: no such file
    """
    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not a JSON certificate ({type(e).__name__})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{path}: not a csplab certificate (no format {FORMAT!r})")
    if data.get("version") != VERSION:
        raise InputError(f"{path}: certificate version {data.get('version')!r} is not {VERSION}")
    return data


def check_certificate(cert: Mapping[str, Any]) -> tuple[bool, str]:
    """Re-verify a certificate without the prover's code.

    Parameters
    ----------
    cert : mapping
        A certificate as :func:`load_certificate` reads it.

    Returns
    -------
    (bool, str)
        Whether it is valid, and one line saying what was verified or the first defect.

    Examples
    --------
    >>> check_certificate({"claim": "infallible"})
    (False, 'invalid: no rules')
    """
    try:
        rules = cert.get("rules")
        if not isinstance(rules, Mapping):
            raise _Invalid("no rules")
        if rules_hash(rules) != cert.get("rules_sha256"):
            raise _Invalid("the rules do not match rules_sha256")
        fwd, bwd, used, ndim = _tables(rules)
        model = _Rules(fwd, bwd, used, ndim, _face_rules(rules.get("faces") or [], ndim, rules))
        claim = cert.get("claim")
        dead: dict[Where, int] | None = None
        if claim == "infallible" and cert.get("dead"):
            if not cert.get("label_classes"):
                raise _Invalid("dead labels are checked with label classes only")
            dead = _check_dead(cert["dead"], model)
            model = _without(model, functools.reduce(operator.and_, dead.values(), -1))
        if claim == "infallible":
            msg = _check_closed(cert, model, dead, bool(cert.get("label_classes")))
        elif claim == "fallible":
            msg = _check_run(cert, model)
        else:
            raise _Invalid(f"unknown claim {claim!r}")
    except _Invalid as e:
        return False, f"invalid: {e}"
    except (KeyError, TypeError, ValueError, IndexError, OverflowError) as e:
        return False, f"invalid: malformed certificate ({type(e).__name__}: {e})"
    return True, msg


# ----------------------------------------------------------------------------- rules


def _tables(rules: Mapping[str, Any]) -> tuple[list[list[int]], list[list[int]], int, int]:
    K = int(rules["labels"])
    flags = list(rules["used"])
    if K < 1 or len(flags) != K:
        raise _Invalid("rules: 'used' needs one flag per label")
    used = sum(1 << b for b, f in enumerate(flags) if f)
    ndim = len(rules["pairs"])
    if not 1 <= ndim <= 4:
        raise _Invalid("rules: 1 to 4 axes")
    fwd = [[0] * K for _ in range(ndim)]
    bwd = [[0] * K for _ in range(ndim)]
    for d, pairs in enumerate(rules["pairs"]):
        for a, b in pairs:
            if not (0 <= a < K and 0 <= b < K):
                raise _Invalid(f"rules: label out of range in {[a, b]}")
            if used >> a & 1 and used >> b & 1:
                fwd[d][a] |= 1 << b
                bwd[d][b] |= 1 << a
    return fwd, bwd, used, ndim


FaceRule = tuple[str, str, int]


class _Rules(NamedTuple):
    """The certificate's rules as the checks use them: per axis the forward and backward
    support bitsets of each label, the labels in use (a bitset), the axes and face rules."""

    fwd: list[list[int]]
    bwd: list[list[int]]
    used: int
    ndim: int
    faces: list[FaceRule]


def _face_rules(raw: Sequence[Any], ndim: int, rules: Mapping[str, Any]) -> list[FaceRule]:
    out = []
    for op, where, labels in raw:
        face = where[1:] if where.startswith("!") else where
        if op not in ("keep", "remove", "force", "add") or not (
            where == "*" or (len(face) == 2 and face[0] in _AXES[:ndim] and face[1] in "-+")
        ):
            raise _Invalid(f"face rule {[op, where]} is not understood")
        if any(not 0 <= b < int(rules["labels"]) for b in labels):
            raise _Invalid(f"face rule {[op, where]}: label out of range")
        out.append((str(op), str(where), sum(1 << int(b) for b in set(labels))))
    return out


# a face's bit in a set of faces: ``2d`` for the lower face of axis ``d``, ``2d + 1`` the upper
_FACE_BIT = {a + s: 1 << 2 * d + k for d, a in enumerate(_AXES) for k, s in enumerate("-+")}


def _domain(face_rules: list[FaceRule], on: int, used: int) -> int:
    """The domain of a cell lying on the faces ``on`` (:data:`_FACE_BIT`): the labels in
    use, edited by the rules."""
    dom = used
    for op, where, bits in face_rules:
        if where != "*" and (
            on & _FACE_BIT[where[1:]] if where[0] == "!" else not on & _FACE_BIT[where]
        ):
            continue
        if op == "keep":
            dom &= bits
        elif op == "remove":
            dom &= ~bits
        elif op == "force":
            dom = bits
        else:
            dom |= bits
    return dom & used


def _bits(x: int) -> Iterator[int]:
    while x:
        low = x & -x
        yield low.bit_length() - 1
        x ^= low


def _axes_of(order: str, ndim: int) -> tuple[int, ...]:
    if order == "scanline":
        return tuple(range(ndim))
    if order.startswith("scan:") and sorted(order[5:]) == sorted(_AXES[:ndim]):
        return tuple(_AXES.index(a) for a in order[5:])
    raise _Invalid(f"order {order!r} is not a scan order over {ndim} axes")


# ----------------------------------------------------------------------------- infallible


_Conf = tuple[tuple[int, ...], tuple[int, ...], tuple[bool, ...], tuple[bool, ...]]


def _positions(
    cert: Mapping[str, Any], ndim: int, face_rules: bool
) -> tuple[list[int], list[int], tuple[int, ...], list[_Conf]]:
    """The region, back and axes of an *infallible* certificate (its history checked), and its
    configurations ``(lower, upper, at_lower, at_upper)`` in file order, checked to be
    exactly the positions of a point in the region (each once)."""
    region = list(map(int, cert["region"]))
    history = list(map(int, cert["history"]))
    axes = tuple(map(int, cert["axes"]))
    if len(region) != ndim or len(history) != ndim or min(region) < 2:
        raise _Invalid("region needs at least 2 cells on every axis of the rules")
    if min(history) < 0:
        raise _Invalid("history must be non-negative")
    back = list(map(int, cert.get("back", [1] * ndim)))
    if len(back) != ndim or min(back) < 1:
        raise _Invalid("back needs a value of at least 1 on every axis")
    if _axes_of(str(cert["order"]), ndim) != axes:
        raise _Invalid("axes do not match the order")
    both = (False, True) if face_rules else (False,)

    def sides(exact: list[int]) -> set[tuple[Any, ...]]:
        # per axis the pairs (distance, edge on the face): on the face when the region is
        # clipped there (distance below ``exact``), either way at ``exact`` ("at least");
        # the distances and the flags of every position run through two products in step
        dists = [range(x + 1) if len(both) == 1 else [*range(x), x, x] for x in exact]
        flags = [[True] * x + [*both] for x in exact]
        return set(zip(itertools.product(*dists), itertools.product(*flags), strict=True))

    # the distances below which the region is clipped at the lower and the upper edges
    near_lo = [b + h for b, h in zip(back, history, strict=True)]
    near_hi = [r - 2 for r in region]
    lows, highs = sides(near_lo), sides(near_hi)
    # without at_lower / at_upper, an edge is on the face when the region is clipped there
    defaults: tuple[dict[Any, tuple[bool, ...]], ...] = ({}, {})

    def on_face(v: tuple[Any, ...], upper: int) -> tuple[bool, ...]:
        got = defaults[upper].get(v)
        if got is None:
            near = near_hi if upper else near_lo
            got = defaults[upper][v] = tuple(t < x for t, x in zip(v, near, strict=True))
        return got

    got: list[_Conf] = []
    for c in cert["configs"]:
        lo, hi = tuple(c["lower"]), tuple(c["upper"])
        a = c.get("at_lower")
        a = tuple(map(bool, a)) if a else on_face(lo, 0)
        b = c.get("at_upper")
        b = tuple(map(bool, b)) if b else on_face(hi, 1)
        got.append((lo, hi, a, b))
    want = len(lows) * len(highs)
    if (len(got) != want or len(set(got)) != want
            or not {(g[0], g[2]) for g in got} <= lows
            or not {(g[1], g[3]) for g in got} <= highs):
        raise _Invalid(f"the configurations are not the {want} positions of a point")
    return region, back, axes, got


def _check_closed(
    cert: Mapping[str, Any],
    rules: _Rules,
    dead: Mapping[Where, int] | None = None,
    classes: bool = False,
) -> str:
    """An *infallible* certificate: its configurations, frames and states (the module's
    docstring lists the checks), with each frame cell's ``dead`` labels out of its domain.

    With ``classes`` (``label_classes``), a state records each label by its class -- the
    least label in use with the same forward supports (``fwd[d]``) along the axes on which
    the cell's + neighbour lies in the frame box and is not yet labelled at that step --
    and arc consistency leaves out the arcs between two labelled cells.

    Why this suffices: inside the frame a labelled cell's - neighbours are labelled
    (scan order), so it meets unlabelled cells only along those axes; there its label
    acts only through ``fwd[d][label]`` (narrowing the neighbour, and keeping the label
    iff the neighbour's domain meets it). Arcs between labelled cells hold in every real
    run (each label agreed with its - neighbours, which its region holds). So arc
    consistency with the classes gives the catalogs of the real labels, and a real run's
    labels, mapped to their classes, stay in a closed set that holds the start state.
    The step's cell meets its labelled - neighbours along axes on which it is open, so
    their classes narrow it as their labels do.
    """
    fwd, bwd, used, ndim, face_rules = rules
    region, back, axes, got = _positions(cert, ndim, bool(face_rules))
    configs = cert["configs"]
    # shared by every configuration: frames (configurations that differ only in which
    # frame edges lie on a face have the same frame), domains and region graphs
    memo = _Memo(rules, dead or {}, int(cert["dead"]["cap"]) if dead else 0)
    nstates = sum(len(c["states"]) for c in configs)
    nsteps = sum(len(c["keys"]) for c in configs)
    if _LEAN_STATES >= 0 and nstates <= max(_LEAN_STATES, 2 * nsteps):
        nstates = _check_lean(cert, rules, region, back, axes, got, memo, classes)
        return _closed_message(cert, nstates, len(configs), region, back, classes)
    specs: list[tuple[Cell, Cell, list[list[int]]]] = []
    fid_of: dict[Any, int] = {}
    fids = []
    for c in configs:
        key = (tuple(c["lower"]), tuple(c["upper"]), tuple(map(tuple, c["keys"])))
        if key not in fid_of:
            fid_of[key] = len(specs)
            specs.append((key[0], key[1], [list(k) for k in c["keys"]]))
        fids.append(fid_of[key])
    frames = _frames(specs, region, back, axes)
    plans = _plans(frames, fids, got, used, face_rules, memo)
    maps = None
    if classes:  # per set of open axes (a bit mask), label -> class; -1 (padding) kept
        maps = np.full((1 << ndim, len(fwd[0]) + 1), -1, dtype=np.int64)
        maps[:, :-1] = _class_maps(fwd, used)
    nstates = _check_states(configs, plans, fwd, bwd, used, memo, maps)
    return _closed_message(cert, nstates, len(configs), region, back, classes)


def _closed_message(
    cert: Mapping[str, Any], nstates: int, nconf: int, region: list[int], back: list[int],
    classes: bool,
) -> str:  # fmt: skip
    rtxt = "x".join(map(str, region)) + (
        "" if set(back) == {1} else " (reaching back " + "x".join(map(str, back)) + ")"
    )
    return (
        f"valid: {nstates} states{' (labels by class)' if classes else ''} in {nconf} "
        "configurations are closed under Alg. 3.6 "
        f"with {rtxt} regions ({cert['order']}) and no catalog of a point is empty: "
        "Alg. 3.1 never fails (Theorem 3.3.6)"
    )


class _Frame(NamedTuple):
    """The frame of a configuration, its ``keys`` verified, as arrays over the ``P`` cells
    of a box holding every frame of the certificate (C order; a frame's own box, of extent
    ``ext``, sits at the origin) and its ``n`` steps (the frame's cells in scan order, the
    point last): each step's region (``box``), the cells labelled before it (``done``),
    where each cell's label sits in the step's state (``keypos``, -1: not recorded), the
    step's cell (``cell``), its labelled backward neighbours (``near_pos``: slot in the
    state, ``near_tab``: axis, or ``ndim`` for none), and where each label of the next
    state comes from (``nxt_at`` step and slot, ``nxt_from`` slot or -1: the label the
    step chooses, and ``nxt_open``: the axes, a bit mask, on which that label's cell
    has a + neighbour in the frame not yet labelled). The small graph of a step is built
    only when a state needs arc consistency (:func:`_step_graph`)."""

    ext: Cell
    n: int
    coords: Any
    keys: list[list[int]]
    cell: Any
    box: Any
    done: Any
    keypos: Any
    near_pos: Any
    near_tab: Any
    nxt_at: tuple[Any, Any]
    nxt_from: Any
    nxt_open: Any
    cells: list[Cell]
    graphs: dict[int, tuple[list[int], list[int], list[bool], bytes]]


# cells x steps x frames the frame arrays hold at once
_FRAME_CHUNK = 1 << 21


def _frames(
    specs: list[tuple[Cell, Cell, list[list[int]]]],
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
) -> list[_Frame]:
    """The frames of ``(lower, upper, keys)``, verified together, in chunks."""
    exts = np.array([[a + 1 + b for a, b in zip(lo, hi, strict=True)] for lo, hi, _ in specs])
    E = tuple(int(e) for e in exts.max(0))
    P = math.prod(E)
    per = max(1, _FRAME_CHUNK // (P * P))
    out: list[_Frame] = []
    for s in range(0, len(specs), per):
        out += _frame_chunk(specs[s : s + per], exts[s : s + per], E, region, back, axes)
    return out


def _frame_chunk(
    specs: list[tuple[Cell, Cell, list[list[int]]]],
    ext: Any,
    E: Cell,
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
) -> list[_Frame]:
    ndim, F = len(E), len(specs)
    coords = np.indices(E).reshape(ndim, -1).T  # (P, ndim), C order
    P = len(coords)
    ax = list(axes)
    # each axis' stride in a frame's scan order (outermost axis first)
    sc = np.ones((F, ndim), dtype=np.int64)
    for k in range(ndim - 2, -1, -1):
        sc[:, ax[k]] = sc[:, ax[k + 1]] * ext[:, ax[k + 1]]
    valid = (coords[None] < ext[:, None]).all(-1)
    rank = np.where(valid, (coords @ sc.T).T, P)
    lo = np.array([s[0] for s in specs])
    n = (lo * sc).sum(1) + 1  # the cells before the point in scan order, then the point
    nmax = int(n.max())
    cell = np.argsort(rank, axis=1, kind="stable")[:, :nmax]  # (F, nmax) each step's cell
    steps = np.arange(nmax)
    live = steps[None, :] < n[:, None]
    fr, rows = [], []
    slot: list[int] = []
    flat: list[int] = []
    for f, (lo_f, hi_f, keys) in enumerate(specs):
        if len(keys) != n[f] or keys[0]:
            raise _Invalid(f"{_where(lo_f, hi_f)}: keys must list {n[f]} steps, the first empty")
        lens = list(map(len, keys))
        fr.append(np.full(sum(lens), f))
        rows.append(np.repeat(np.arange(len(keys)), lens))
        slot.extend(itertools.chain.from_iterable(map(range, lens)))
        flat.extend(itertools.chain.from_iterable(keys))
    fr_a, rows_a = np.concatenate(fr), np.concatenate(rows)
    slot_a, j = np.array(slot, dtype=np.int64), _ints(flat)
    bad = (j < 0) | (j >= rows_a)
    bad[1:] |= (fr_a[1:] == fr_a[:-1]) & (rows_a[1:] == rows_a[:-1]) & (j[1:] <= j[:-1])
    if bad.any():
        t = int(np.flatnonzero(bad)[0])
        lo_f, hi_f, _ = specs[fr_a[t]]
        raise _Invalid(f"{_where(lo_f, hi_f)}: keys[{rows_a[t]}] must be sorted earlier steps")
    keypos = np.full((F, nmax, P), -1, dtype=np.int64)
    keypos[fr_a, rows_a, cell[fr_a, j]] = slot_a
    # keys[i + 1] holds only labels of keys[i] and of step i
    later = rows_a > 0
    fi, ii, ji = fr_a[later], rows_a[later] - 1, j[later]
    src = keypos[fi, ii, cell[fi, ji]]
    forgot = (ji != ii) & (src < 0)
    if forgot.any():
        t = int(np.flatnonzero(forgot)[0])
        lo_f, hi_f, _ = specs[fi[t]]
        raise _Invalid(
            f"{_where(lo_f, hi_f)}: keys[{ii[t] + 1}] records a label step {ii[t]} forgot"
        )
    # the axes on which each label of the next state has an open + neighbour (its class)
    strides = np.cumprod((1, *E[:0:-1]))[::-1]
    xj = cell[fi, ji]
    nxt_open = np.zeros(len(xj), dtype=np.int64)
    for d in range(ndim):
        inside = coords[xj, d] + 1 < ext[fi, d]
        plus = rank[fi, np.minimum(xj + strides[d], P - 1)]
        nxt_open |= (inside & (plus > ii)).astype(np.int64) << d
    # the region of each step's cell, clipped to the frame
    at = coords[cell]  # (F, nmax, ndim)
    blo = np.maximum(at - np.array(back), 0)
    bhi = np.minimum(at + np.array(region) - 2, ext[:, None, :] - 1)
    box = ((coords >= blo[:, :, None]) & (coords <= bhi[:, :, None])).all(-1) & live[:, :, None]
    done = rank[:, None, :] < steps[None, :, None]
    # a labelled cell of the region bordering one not yet labelled must be recorded
    free = (box & ~done).reshape((F, nmax, *E))
    near_free = np.zeros_like(free)
    for d in range(ndim):
        a, b = [slice(None)] * (ndim + 2), [slice(None)] * (ndim + 2)
        a[d + 2], b[d + 2] = slice(1, None), slice(None, -1)
        near_free[tuple(a)] |= free[tuple(b)]
        near_free[tuple(b)] |= free[tuple(a)]
    miss = box & done & near_free.reshape(F, nmax, P) & (keypos < 0)
    if miss.any():
        f, i, x = (int(t) for t in np.argwhere(miss)[0])
        lo_f, hi_f, _ = specs[f]
        raise _Invalid(
            f"{_where(lo_f, hi_f)}: step {i} depends on cell {coords[x].tolist()}, "
            f"not in keys[{i}]"
        )
    # the labelled backward neighbours of each step's cell in its region (a forward
    # neighbour comes later in any scan order)
    y = np.maximum(cell[:, :, None] - strides, 0)  # (F, nmax, ndim)
    ok = (at > 0) & np.take_along_axis(box & done, y, axis=2)
    near_pos = np.where(ok, np.take_along_axis(keypos, y, axis=2), 0)
    near_tab = np.where(ok, np.arange(ndim), ndim)
    nxt_from = np.where(ji == ii, -1, src)
    cut = np.searchsorted(fi, np.arange(F + 1))
    nxt_slot = slot_a[later]
    cells = [tuple(c) for c in coords.tolist()]
    out = []
    for f, (_, _, keys) in enumerate(specs):
        m, a, b = int(n[f]), cut[f], cut[f + 1]
        out.append(_Frame(
            tuple(int(e) for e in ext[f]), m, coords, keys, cell[f, :m], box[f, :m],
            done[f, :m], keypos[f, :m], near_pos[f, :m], near_tab[f, :m],
            (ii[a:b], nxt_slot[a:b]), nxt_from[a:b], nxt_open[a:b], cells, {},
        ))  # fmt: skip
    return out


def _where(lo: Sequence[int], hi: Sequence[int]) -> str:
    return f"configuration lower={list(lo)} upper={list(hi)}"


def _nxt(frame: _Frame, width: int) -> tuple[Any, Any]:
    """Per step, where each label of the next state comes from: a slot of the state,
    ``width`` (the label just chosen) or ``width + 1`` (padding); and the axes on which
    its cell is open there (``nxt_open``)."""
    out = np.full((frame.n, width), width + 1, dtype=np.int64)
    out[frame.nxt_at] = np.where(frame.nxt_from < 0, width, frame.nxt_from)
    opens = np.zeros((frame.n, width), dtype=np.int64)
    opens[frame.nxt_at] = frame.nxt_open
    return out, opens


def _step_graph(frame: _Frame, i: int) -> tuple[list[int], list[int], list[bool], bytes]:
    """Step ``i``'s region as a small graph: the slots of the state holding its labelled
    nodes' labels, its nodes (cells of ``coords`` in C order: those not yet labelled and
    those the state records), which are labelled, and its shape (the nodes relative to
    the step's cell and which are labelled: steps of one shape, in any frame, have the
    same catalogs for the same labels and domains)."""
    hit = frame.graphs.get(i)
    if hit is None:
        keep = frame.box[i] & (~frame.done[i] | (frame.keypos[i] >= 0))
        nodes = np.flatnonzero(keep)
        fixed = frame.done[i, nodes]
        rel = frame.coords[nodes] - frame.coords[frame.cell[i]]
        shape = rel.astype(np.int64).tobytes() + fixed.tobytes()
        slots = frame.keypos[i, nodes[fixed]]
        hit = (slots.tolist(), nodes.tolist(), fixed.tolist(), shape)
        frame.graphs[i] = hit
    return hit


class _Plan(NamedTuple):
    """A configuration to check: its frame (and the frame's id) and the domain of each of
    the frame's cells before arc consistency (labels in use, edited by the face rules)."""

    frame: _Frame
    fid: int
    bases: tuple[int, ...]


def _plans(
    frames: list[_Frame],
    fids: list[int],
    got: list[_Conf],
    used: int,
    face_rules: list[FaceRule],
    memo: _Memo,
) -> list[_Plan]:
    """Each configuration's frame and the domain of each of its cells: the labels in use,
    edited by the face rules of the faces it lies on, minus those dead wherever in an
    output it may lie (its distances to the frame's edges, exact on a face). The cells of
    every configuration are coded at once by their capped distances and face flags."""
    coords = frames[0].coords  # every frame's cells sit in one box
    P, ndim = coords.shape
    if not face_rules and not memo.dead:
        return [_Plan(frames[f], f, (used,) * P) for f in fids]
    cap = max(memo.cap, 1)
    radix = 4 * (cap + 1) ** 2  # per axis: distances to the lower and upper edge, flags
    lo = np.minimum(coords, cap)[None]
    out: list[_Plan] = []
    per = max(1, (1 << 20) // (P * ndim))
    for s in range(0, len(fids), per):
        part = range(s, min(s + per, len(fids)))
        ext = np.array([frames[fids[c]].ext for c in part])
        on = np.array([[got[c][2], got[c][3]] for c in part], dtype=np.int64)
        hi = np.clip(ext[:, None, :] - 1 - coords[None], 0, cap)  # outside: as on the edge
        digit = ((lo * (cap + 1) + hi) * 2 + on[:, None, 0]) * 2 + on[:, None, 1]
        inside = (coords[None] < ext[:, None, :]).all(-1)
        code = np.where(inside, digit @ radix ** np.arange(ndim), -1)
        kinds, inv = np.unique(code, return_inverse=True)
        doms = []
        for code in kinds.tolist():  # -1: a cell outside the frame
            dom = memo.domains.get(code) if code >= 0 else used
            if dom is None:
                dom = memo.domains[code] = _cell_domain(code, ndim, cap, used, face_rules, memo)
            doms.append(dom)
        table = np.array(doms, dtype=object)[inv.reshape(len(part), P)].tolist()
        out += [
            _Plan(frames[fids[c]], fids[c], tuple(row))
            for c, row in zip(part, table, strict=True)
        ]
    return out


def _cell_domain(
    code: int, ndim: int, cap: int, used: int, face_rules: list[FaceRule], memo: _Memo
) -> int:
    """The domain of a frame cell of ``code`` (per axis, little end first: its capped
    distances to the frame's lower and upper edge, and whether each edge is on the face)."""
    on, key = 0, []
    for d in range(ndim):
        code, digit = divmod(code, 4 * (cap + 1) ** 2)
        rest, at_hi = divmod(digit, 2)
        (lo, hi), at_lo = divmod(rest // 2, cap + 1), rest % 2
        on |= (at_lo and lo == 0) << 2 * d | (at_hi and hi == 0) << 2 * d + 1
        # exact on a face edge, else at least one more (a suffix lo .. cap: lo + cap + 1)
        key += [lo if at_lo else min(lo + 1, cap) + cap + 1,
                hi if at_hi else min(hi + 1, cap) + cap + 1]  # fmt: skip
    return memo.domain(on, tuple(key), used, face_rules)


class _Memo:
    """What the configurations of one certificate share."""

    def __init__(self, rules: _Rules, dead: Mapping[Where, int], cap: int = 0) -> None:
        self.dead = dead
        self.cap = cap
        self.used = rules.used
        self.tables = [*rules.fwd, *rules.bwd]
        self.unions: list[dict[int, int]] = [{} for _ in self.tables]
        self.domains: dict[int, int] = {}
        self.graphs: dict[bytes, tuple[Arcs, int]] = {}
        self.faces: dict[int, int] = {}
        self.boxes: dict[tuple[int, ...], int] = {}
        # a distance or a range of distances (``a + cap + 1``: ``a`` to ``cap``) -> the
        # farthest distance in it
        self.far = [*range(cap + 1), *[cap] * (cap + 1)]

    def domain(self, on: int, key: tuple[int, ...], used: int, face_rules: list[FaceRule]) -> int:
        """The domain of a cell on the faces ``on`` (bits ``2d``: the lower face of axis
        ``d``, ``2d + 1``: the upper) and in the box of places ``key``
        (:meth:`dead_in`): the labels in use, edited by the face rules, minus the dead."""
        dom = self.face_domain(on, used, face_rules)
        if not self.dead:
            return dom
        return dom & ~self.dead_in(key)

    def face_domain(self, on: int, used: int, face_rules: list[FaceRule]) -> int:
        """The labels in use, edited by the face rules of the faces ``on``."""
        dom = self.faces.get(on)
        if dom is None:
            dom = self.faces[on] = _domain(face_rules, on, used)
        return dom

    def dead_in(self, key: tuple[int, ...]) -> int:
        """The labels dead at every place of a box of places: per axis the distance to
        the lower and to the upper face, each ``a`` (exactly) or ``a + cap + 1`` (``a``
        to ``cap``); only labels in use."""
        got = self.boxes.get(key)
        if got is None:
            c = self.cap
            # the farthest place first: inside, few labels are dead, and none ends the AND
            far = tuple(zip(map(self.far.__getitem__, key[::2]),
                            map(self.far.__getitem__, key[1::2]), strict=True))  # fmt: skip
            got = self.dead[far] & self.used  # (labels dead everywhere are out of use)
            if not got:
                self.boxes[key] = 0
                return 0
            spans = [[v] if v <= c else range(c, v - c - 2, -1) for v in key]
            per_axis = [list(itertools.product(*spans[t : t + 2]))
                        for t in range(0, len(key), 2)]  # fmt: skip
            for k in itertools.product(*per_axis):
                got &= self.dead[k]
                if not got:
                    break
            self.boxes[key] = got
        return got


# bytes per state and label the array check holds at once, above which it refuses
_MAX_BYTES = 2 << 30


def _check_states(
    configs: Sequence[Mapping[str, Any]],
    plans: list[_Plan],
    fwd: list[list[int]],
    bwd: list[list[int]],
    used: int,
    memo: _Memo,
    maps: Any = None,
) -> int:
    """The states of every configuration, at once: present at the start, closed, never an
    empty point. A *group* is a step of a configuration; each state is a row of labels
    (padded with -1 to the widest state) in its group. ``maps`` (labels by class): per
    bit mask of open axes, label -> class, which the next state records; arcs between
    labelled cells are then left out of arc consistency."""
    K = len(fwd[0])
    ndim = len(fwd)
    width = max(len(k) for p in plans for k in p.frame.keys)
    # per group: the group of the next step (-1 at the point), the state's width, the
    # neighbours' slots and tables, the next state's slots, the domain of the step's cell
    first: list[int] = []
    nexts: list[int] = []
    widths: list[int] = []
    base: list[int] = []
    acid: list[int] = []
    npos, ntab, nxt, opens = [], [], [], []
    nxt_of: dict[int, tuple[Any, Any]] = {}
    ac_ids: dict[tuple[int, int, int], int] = {}
    base_ids: dict[tuple[int, ...], int] = {}
    ac_of: list[tuple[_Plan, int]] = []
    G = 0
    for p in plans:
        f = p.frame
        first.append(G)
        nexts.extend(range(G + 1, G + f.n))
        nexts.append(-1)
        widths.extend(len(k) for k in f.keys)
        npos.append(f.near_pos)
        ntab.append(f.near_tab)
        if p.fid not in nxt_of:
            nxt_of[p.fid] = _nxt(f, width)
        nxt.append(nxt_of[p.fid][0])
        opens.append(nxt_of[p.fid][1])
        base.extend(p.bases[x] for x in f.cell.tolist())
        bid = base_ids.setdefault(p.bases, len(base_ids))
        for i in range(f.n):
            k = (p.fid, i, bid)
            if k not in ac_ids:
                ac_ids[k] = len(ac_of)
                ac_of.append((p, i))
            acid.append(ac_ids[k])
        G += f.n
    g_next, g_width, g_acid = (np.array(v, dtype=np.int64) for v in (nexts, widths, acid))
    g_npos, g_ntab, g_nxt, g_open = (np.concatenate(v) for v in (npos, ntab, nxt, opens))
    bits = sorted(set(base))
    g_base = np.searchsorted(bits, base)
    base_rows = _unpack(bits, K)
    # the states: group, labels
    every = list(itertools.chain.from_iterable(c["states"] for c in configs))
    if set(map(len, every)) - {2}:
        raise _Invalid("a state is not a pair [step, labels]")
    steps = _ints([s[0] for s in every])
    rows_l = [s[1] for s in every]
    n_len = np.fromiter(map(len, rows_l), dtype=np.int64, count=len(rows_l))
    labels = _ints(list(itertools.chain.from_iterable(rows_l)))
    cfg = np.repeat(np.arange(len(configs)), [len(c["states"]) for c in configs])
    n_of = np.array([p.frame.n for p in plans], dtype=np.int64)
    N = len(steps)

    def where(c: int) -> str:
        return _where(configs[c]["lower"], configs[c]["upper"])

    out = np.flatnonzero((steps < 0) | (steps >= n_of[cfg]))
    if len(out):
        c = int(cfg[out[0]])
        raise _Invalid(f"{where(c)}: a state's step is not one of its {n_of[c]} steps")
    grp = np.array(first, dtype=np.int64)[cfg] + steps
    if N * (K + width) * 24 > _MAX_BYTES:
        raise MemoryLimitError(
            f"certificate: checking {N} states of {K} labels needs about "
            f"{N * (K + width) * 24 / 1e9:.1f} GB, more than {_MAX_BYTES / 1e9:.1f} GB"
        )

    def state(r: int) -> list[Any]:
        return [int(steps[r]), labs[r, : g_width[grp[r]]].tolist()]

    bad = np.flatnonzero(n_len != g_width[grp])
    if len(bad):
        r = int(bad[0])
        raise _Invalid(
            f"{where(int(cfg[r]))}: a state at step {steps[r]} does not fit keys[{steps[r]}]"
        )
    in_use = _unpack([used], K)[0]
    wrong = (labels < 0) | (labels >= K) | ~in_use[np.clip(labels, 0, K - 1)]
    if wrong.any():
        r = int(np.searchsorted(np.cumsum(n_len), np.flatnonzero(wrong)[0], side="right"))
        raise _Invalid(f"{where(int(cfg[r]))}: a state at step {steps[r]} has a label not in use")
    inrow = np.arange(width)[None, :] < n_len[:, None]
    labs = np.full((N, width), -1, dtype=np.int64)
    labs[inrow] = labels
    have = np.zeros(G, dtype=bool)
    have[grp[n_len == 0]] = True  # a state of width 0 is the empty state
    start = np.array(first, dtype=np.int64)
    if not have[start].all():
        raise _Invalid(f"{where(int(np.flatnonzero(~have[start])[0]))}: no start state")
    # the labels of each step's cell that agree with its labelled neighbours: a superset
    # of its catalog (arc consistency only removes more), enough when every one leads on
    tables = np.ones((ndim + 1, K + 1, K), dtype=bool)
    for d in range(ndim):
        tables[d, :K] = _unpack(fwd[d], K)
    fc = base_rows[g_base[grp]]
    rows = np.arange(N)
    for j in range(g_npos.shape[1]):
        fc &= tables[g_ntab[grp, j], labs[rows, g_npos[grp, j]]]
    last = g_next[grp] < 0
    st, lab = np.nonzero(fc & ~last[:, None])
    codes, next_codes = _state_codes(grp, labs, st, lab, g_next, g_nxt, K, maps, g_open)
    known = np.sort(codes)
    at = np.minimum(np.searchsorted(known, next_codes), max(N - 1, 0))
    present = known[at] == next_codes
    leads = np.zeros((N, K), dtype=bool)
    leads[st[present], lab[present]] = True
    # the rest need the catalog: arc consistency on the step's region, once per group
    # kind (frame, step, domains) and labels of the region's labelled cells
    need = np.flatnonzero(last | (fc & ~leads).any(1))
    if len(need):
        # the steps' kinds in play, merged by shape and domains of the unlabelled nodes
        kinds = np.flatnonzero(np.bincount(g_acid[grp[need]], minlength=len(ac_of)))
        gather = np.full((len(ac_of), width + 1), width)  # width: padding
        same = np.zeros(len(ac_of), dtype=np.int64)
        S = 0
        ids: dict[tuple[bytes, tuple[int, ...]], int] = {}
        for a in kinds.tolist():
            p, i = ac_of[a]
            slots, nodes, fixed, shape = _step_graph(p.frame, i)
            free = tuple(p.bases[x] for x, f in zip(nodes, fixed, strict=True) if not f)
            same[a] = ids.setdefault((shape, free), len(ids))
            gather[a, : len(slots)] = slots
            S = max(S, len(slots))
        padded = np.concatenate([labs[need], np.full((len(need), 1), -1)], axis=1)
        mk = np.take_along_axis(padded, gather[g_acid[grp[need]], : S + 1], axis=1)
        # one catalog per shape, domains and labels of the labelled nodes
        inv, which = _ranks(_row_codes(same[g_acid[grp[need]]], mk, K))
        cats: list[int] = []
        for r in which.tolist():
            p, i = ac_of[int(g_acid[grp[need[r]]])]
            slots, nodes, fixed, shape = _step_graph(p.frame, i)
            graph = memo.graphs.get(shape)
            if graph is None:
                there = [p.frame.cells[x] for x in nodes]
                here = p.frame.cells[int(p.frame.cell[i])]
                arcs = _arcs(there)
                if maps is not None:  # no arcs between labelled cells
                    arcs = [[a for a in row if not (fu and fixed[a[0]])]
                            for fu, row in zip(fixed, arcs, strict=True)]  # fmt: skip
                graph = memo.graphs[shape] = (arcs, there.index(here))
            arcs, target = graph
            it = iter(mk[r, : len(slots)].tolist())
            dom = [1 << next(it) if f else p.bases[x]
                   for f, x in zip(fixed, nodes, strict=True)]  # fmt: skip
            ac = _small_ac(dom, arcs, memo.tables, memo.unions)
            cats.append(0 if ac is None else ac[target])
        cat_rows = _unpack(cats, K)[inv]
        empty = last[need] & ~cat_rows.any(1)
        if empty.any():
            r = int(need[np.flatnonzero(empty)[0]])
            raise _Invalid(
                f"{where(int(cfg[r]))}: the point's catalog is empty in state {state(r)}"
            )
        open_ = ~last[need, None] & cat_rows & ~leads[need]
        if open_.any():
            row, b = (int(t) for t in np.argwhere(open_)[0])
            r = int(need[row])
            g = int(grp[r])
            nx = [b if s == width else labs[r, s] for s in g_nxt[g, : g_width[g + 1]].tolist()]
            if maps is not None:
                nx = [maps[m, t] for m, t in zip(g_open[g].tolist(), nx, strict=False)]
            raise _Invalid(
                f"{where(int(cfg[r]))}: not closed: state {state(r)} with label {b} leads to "
                f"{[int(steps[r]) + 1, [int(t) for t in nx]]}, which is missing"
            )
    return N


def _unpack(bitsets: list[int], K: int) -> Any:
    """Bit sets of ``K`` labels as rows of booleans."""
    nb = (K + 7) // 8
    raw = np.frombuffer(b"".join(b.to_bytes(nb, "little") for b in bitsets), dtype=np.uint8)
    return np.unpackbits(raw.reshape(-1, nb), axis=1, bitorder="little")[:, :K].astype(bool)


def _ints(values: list[Any]) -> Any:
    """``values`` as an int64 array; anything but integers is a malformed certificate."""
    out = np.array(values) if values else np.zeros(0, dtype=np.int64)
    if out.ndim != 1 or out.dtype.kind not in "iu":
        raise _Invalid("a state's step or labels are not integers")
    return out.astype(np.int64)


# the largest code of a state (group and labels) computed as a polynomial in its labels
_CODE_LIMIT = 1 << 62


def _state_codes(
    grp: Any,
    labs: Any,
    st: Any,
    lab: Any,
    g_next: Any,
    g_nxt: Any,
    K: int,
    maps: Any = None,
    g_open: Any = None,
) -> tuple[Any, Any]:
    """Exact codes of the states (``grp``, ``labs``) and of the states ``(g_next[grp[st]],
    labs[st] rearranged by g_nxt with lab chosen)`` that they lead to: equal codes for equal
    states. With ``maps``, each label of a next state is mapped by ``maps[g_open[group,
    slot]]`` (to its class). A polynomial in the labels (the padding -1 adds nothing) when
    it stays below ``_CODE_LIMIT``; else the rows are built and ranked (:func:`_row_codes`)."""
    N, width = labs.shape
    G = len(g_next)
    ext = np.concatenate([labs, np.full((N, 2), -1, dtype=np.int64)], axis=1)
    if G * (K + 1) ** width < _CODE_LIMIT:
        w = (K + 1) ** np.arange(width - 1, -1, -1, dtype=np.int64)
        gw = (K + 1) ** width
        codes = grp * gw + (labs + 1) @ w
        # the next state: its labels kept from this one, plus the chosen label's term
        nxt = np.take_along_axis(ext, g_nxt[grp], axis=1)
        if maps is not None:
            nxt = maps[g_open[grp], nxt]
            lab = maps[(g_open * (g_nxt == width)).sum(1)[grp[st]], lab]
        kept = g_next[grp] * gw + (nxt + 1) @ w
        chosen = ((g_nxt == width) * w).sum(1)
        return codes, kept[st] + (lab + 1) * chosen[grp[st]]
    e = ext[st]
    e[:, width] = lab
    cand = np.take_along_axis(e, g_nxt[grp[st]], axis=1)
    if maps is not None:
        cand = maps[g_open[grp[st]], cand]
    both = _row_codes(np.concatenate([grp, g_next[grp[st]]]), np.concatenate([labs, cand]), K)
    return both[:N], both[N:]


def _ranks(values: Any) -> tuple[Any, Any]:
    """The rank of each value among the distinct ``values`` (0, 1, ...), and the index of
    the first occurrence of each distinct value."""
    order = np.argsort(values, kind="stable")
    ordered = values[order]
    new = np.ones(len(values), dtype=bool)
    new[1:] = ordered[1:] != ordered[:-1]
    rank = np.empty(len(values), dtype=np.int64)
    rank[order] = np.cumsum(new) - 1
    return rank, order[new]


def _row_codes(group: Any, rows: Any, K: int) -> Any:
    """Exact int64 codes of ``(group, row)`` pairs (rows of labels -1 .. K - 1): equal
    codes for equal pairs, ranked again whenever the next column would overflow."""
    code = _ranks(group)[0]
    top = (1 << 62) // (K + 1)
    for k in range(rows.shape[1]):
        if len(code) and int(code.max()) >= top:
            code = _ranks(code)[0]
        code = code * (K + 1) + (rows[:, k] + 1)
    return code


Arcs = list[list[tuple[int, int]]]


def _arcs(nodes: Sequence[Cell]) -> Arcs:
    """The arcs between grid-adjacent ``nodes``: per node, ``(other node, t)`` with ``t``
    the axis ``d`` when the other is the + neighbour along ``d``, else ``ndim + d`` (the
    index of the support table in ``[*fwd, *bwd]``)."""
    pos = {x: k for k, x in enumerate(nodes)}
    arcs: Arcs = [[] for _ in nodes]
    for x, k in pos.items():
        ndim = len(x)
        for d in range(ndim):
            m = pos.get((*x[:d], x[d] + 1, *x[d + 1 :]))
            if m is not None:
                arcs[k].append((m, d))
                arcs[m].append((k, ndim + d))
    return arcs


def _small_ac(
    dom: list[int],
    arcs: Arcs,
    tables: list[list[int]],
    unions: list[dict[int, int]],
    start: Sequence[int] | None = None,
) -> list[int] | None:
    """Arc consistency (a work list of nodes) on a small graph; ``None`` on a wipe-out.
    ``tables``: ``[*fwd, *bwd]``; ``unions``: per table, the supports of a set of labels
    found so far. ``start``: the nodes whose domains changed since the domains were last
    arc consistent (default: all). ``dom`` is narrowed in place."""
    queue = list(range(len(dom))) if start is None else list(start)
    waiting = set(queue)
    while queue:
        u = queue.pop()
        waiting.discard(u)
        du = dom[u]
        for v, t in arcs[u]:
            known = unions[t]
            sup = known.get(du)
            if sup is None:
                table = tables[t]
                sup = 0
                for b in _bits(du):
                    sup |= table[b]
                known[du] = sup
            dv = dom[v]
            new = dv & sup
            if new != dv:
                if not new:
                    return None
                dom[v] = new
                if v not in waiting:
                    waiting.add(v)
                    queue.append(v)
    return dom


# ----------------------------------------------------------------------------- small certificates
#
# The same checks as _frames / _check_states, one frame and one state at a time with
# Python integers: a certificate of a few hundred states is checked faster so than
# with arrays, whose every operation costs microseconds however small.

# states up to which an infallible certificate is checked one state at a time, or up to
# twice its steps (measured: below 400 states this is the faster, from 400 to 1200 both
# take about as long, beyond, arrays win -- unless the states are spread thin over many
# configurations, about one per step, as with a 3D boundary: the arrays' per-step work
# then costs as much as the states'); negative: never
_LEAN_STATES = 1000


class _LeanFrame(NamedTuple):
    """A frame as :func:`_check_lean` uses it: its ``n`` steps, its cells in scan order
    (``coords``, every cell of the box) and ``keys``; per step, the step's region
    (``box``) and the cells not yet labelled in it (``free``), as bit masks over the scan
    ranks; the slot and support table (``fwd[d]``, ``d`` its axis) of each labelled
    backward neighbour of the step's cell in its region (``near``); the slot in this
    step's state and the class map of the axes on which the cell is open at the next step
    of each label the next state keeps (``kept``, in the next state's order); and the
    open axes (a bit mask) of the label chosen here if the next state records it (last),
    else -1 (``chosen``)."""

    n: int
    coords: list[Cell]
    keys: list[list[int]]
    box: list[int]
    free: list[int]
    near: list[list[tuple[int, list[int]]]]
    kept: list[list[tuple[int, list[int]]]]
    chosen: list[int]


def _lean_frame(
    lo: Cell, hi: Cell, keys: list[list[int]], region: list[int], back: list[int],
    axes: tuple[int, ...], fwd: list[list[int]], cls: Callable[[int], list[int]],
) -> _LeanFrame:  # fmt: skip
    """The frame of ``(lower, upper)`` with its ``keys`` verified (the checks of
    :func:`_frame_chunk`, with sets of cells as bit masks over the scan ranks); a
    neighbour's axis is given as its support table ``fwd[d]``, open axes as the class
    map ``cls`` gives for them.

    Only the axes along which the frame is at least two cells thick are looked at (along
    the others a region is the whole frame and a cell has no neighbour), and the cells a
    step depends on only when a labelled cell of its region is not recorded."""
    ndim = len(lo)
    ext = [x + 1 for x in map(operator.add, lo, hi)]
    # the axes along which the frame is 2+ cells thick, in scan order (outermost first):
    # (axis, stride in the scan, extent, support table ``fwd[d]``)
    live: list[tuple[int, int, int, list[int]]] = []
    s = n = 1
    bits = 0  # the axes of ``live``
    for d in reversed(axes):
        e = ext[d]
        n += lo[d] * s
        if e > 1:
            live.insert(0, (d, s, e, fwd[d]))
            bits |= 1 << d
        s *= e
    if len(keys) != n or keys[0]:
        raise _Invalid(f"{_where(lo, hi)}: keys must list {n} steps, the first empty")
    scanline = axes == _SCANLINE[ndim]
    if scanline:
        coords = list(itertools.product(*map(range, ext)))
    else:
        at = [axes.index(d) for d in range(ndim)]
        scan = itertools.product(*[range(ext[d]) for d in axes])
        coords = [tuple(c[k] for k in at) for c in scan]
    # keys[i]: sorted earlier steps; keys[i + 1] within keys[i] and step i
    masks = []
    for i, ks in enumerate(keys):
        m = 0
        for j in ks:
            if not ((type(j) is int or _is_int(j)) and 0 <= j < i and not m >> j):
                raise _Invalid(f"{_where(lo, hi)}: keys[{i}] must be sorted earlier steps")
            m |= 1 << j
        masks.append(m)
    for i in range(n - 1):
        if masks[i + 1] & ~(masks[i] | 1 << i):
            raise _Invalid(f"{_where(lo, hi)}: keys[{i + 1}] records a label step {i} forgot")
    # per scan rank, built an axis at a time as the ranks run (outermost axis first): the
    # step's region (the region's layers about the cell's layer, clipped, as masks over
    # the ranks: a block of ``t`` ranks per layer, repeated every ``t * e`` ranks) and the
    # axes on which the cell's + neighbour is in the frame (``opn``)
    full = (1 << s) - 1
    boxes: list[int] = []
    opn: list[int] = []
    for d, t, e, _ in live:
        r, b = region[d] - 2, back[d]
        rep = full // ((1 << t * e) - 1)
        win = [
            ((1 << (v + r + 1 if v + r < e else e) * t) - (1 << (v - b if v > b else 0) * t))
            * rep for v in range(e)
        ]  # fmt: skip
        boxes = [box & w for box in boxes for w in win] if boxes else win
        if n > 1:
            row = [1 << d] * (e - 1)
            row.append(0)
            opn = [o | p for o in opn for p in row] if opn else row
    if not live:  # a frame of one cell
        boxes, opn = [full], [0]
    del boxes[n:]
    frees = [box >> i << i for i, box in enumerate(boxes)]  # the cells not yet labelled
    # a labelled cell of the region bordering one not yet labelled must be recorded: of
    # those not recorded (``unrec``), none has a + neighbour not yet labelled in the region
    # (its - neighbours come before it in the scan)
    unrec = list(map(operator.and_, boxes, map(operator.invert, map(operator.or_, frees, masks))))
    if any(unrec):
        # per axis, its stride and the cells but its first layer
        inner = [(t, full & ~(((1 << t) - 1) * (full // ((1 << t * e) - 1))))
                 for _, t, e, _ in live]  # fmt: skip
        for i, u in enumerate(unrec):
            if u:
                free, near_free = frees[i], 0
                for t, not_first in inner:
                    near_free |= (free & not_first) >> t
                miss = u & near_free
                if miss:
                    x = coords[(miss & -miss).bit_length() - 1]
                    raise _Invalid(
                        f"{_where(lo, hi)}: step {i} depends on cell {list(x)}, not in keys[{i}]"
                    )
    # om[g]: the axes whose stride exceeds g (a label recorded g steps back has its +
    # neighbour along them not yet labelled)
    om: list[int] = []
    if n > 2:  # (else no step keeps a label)
        left = bits
        for d, t, _, _ in reversed(live):
            om += [left] * (t - len(om))
            left ^= 1 << d
        om += [0] * (n - len(om))
    if not scanline:  # the backward neighbours by axis
        live.sort()
    nears, kepts, chosens = [], [], []
    ks = keys[0]
    for i in range(n - 1):
        c = coords[i]
        # the backward neighbours (in the region: back >= 1), recorded (the miss above)
        nears.append([(ks.index(i - t), f) for d, t, _, f in live if c[d]])
        nk = keys[i + 1]
        if nk and nk[-1] == i:  # the label chosen here (keys are sorted earlier steps)
            chosens.append(opn[i])
            nk = nk[:-1]
        else:
            chosens.append(-1)
        kepts.append([(ks.index(j), cls(opn[j] & om[i - j])) for j in nk])
        ks = keys[i + 1]
    c = coords[n - 1]
    nears.append([(ks.index(n - 1 - t), f) for d, t, _, f in live if c[d]])
    kepts.append([])
    chosens.append(-1)
    return _LeanFrame(n, coords, keys, boxes, frees, nears, kepts, chosens)


def _check_lean(
    cert: Mapping[str, Any],
    rules: _Rules,
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
    got: list[_Conf],
    memo: _Memo,
    classes: bool,
) -> int:
    """The checks of :func:`_check_states` on a small certificate, a state at a time.

    A state at a step that is not the point is closed when each label of its cell that
    agrees with the labelled backward neighbours (a superset of the catalog ``C_R``)
    leads to a recorded state; only otherwise is arc consistency run on the region. At
    the point arc consistency runs unless the cell is the region's only one not yet
    labelled and labels are recorded by class: arcs between labelled cells are then left
    out, and the catalog is that superset itself (each neighbour's label supports every
    label of it, and nothing else narrows it). Configurations of one frame (they differ
    in which of its edges lie on a face) whose cells have the same domains and whose
    states are equal are the same check, made once.
    """
    fwd, _, used, ndim, face_rules = rules
    K = len(fwd[0])
    configs = cert["configs"]
    ident = list(range(K))
    # per set of open axes (a bit mask): label -> its class (every label its own without
    # classes)
    cls = _class_maps(fwd, used).__getitem__ if classes else lambda m: ident

    # per chosen label's open axes (a bit mask; -1: not recorded): its class map, and a set
    # of labels -> the set of their classes
    pick_sets: dict[int, tuple[list[int], dict[int, int] | None]] = {-1: (ident, None)}
    ac = _LeanAC(rules, memo, classes)
    cap = max(memo.cap, 1)
    plain = not face_rules and not memo.dead
    # the labels in use, and a state's labels as they are checked: every one in use
    in_use = {b for b in range(K) if used >> b & 1}
    # configurations by frame (the same frame: the same steps and keys)
    by_frame: dict[Any, list[tuple[Mapping[str, Any], _Conf]]] = {}
    for conf, g in zip(configs, got, strict=True):
        by_frame.setdefault((g[0], g[1], tuple(map(tuple, conf["keys"]))), []).append((conf, g))
    # per axis signature: its places, and their faces and farthest distances apart
    AxisKinds = tuple[list[AxisPlace], list[int], list[tuple[int, int]]]
    axis_places: dict[tuple[int, int, bool, bool, int], AxisKinds] = {}
    # a cell's domain by its faces and places along each axis (in scan order)
    cell_doms: dict[tuple[AxisPlace, ...], int] = {}
    scan_at = [axes.index(d) for d in range(ndim)]
    dead_at = memo.dead

    def cell_dom(it: tuple[AxisPlace, ...]) -> int:
        on = 0
        far: Where = ()
        for k in scan_at:
            on |= it[k][0]
            far += (it[k][2],)
        if dead_at and dead_at[far] & used:  # (else no label in use is dead in the box)
            where: tuple[int, ...] = ()
            for k in scan_at:
                where += it[k][1]
            dom = memo.domain(on, where, used, face_rules)
        else:
            dom = memo.face_domain(on, used, face_rules)
        cell_doms[it] = dom
        return dom

    # the places (capped distances to the faces, per axis) where a label in use is dead: a
    # cell elsewhere has the domain of the faces it lies on
    dead_far = set(itertools.compress(dead_at, [v & used for v in dead_at.values()]))
    face_doms: dict[int, int] = {}
    if not plain and not dead_far:  # every cell has its faces' domain: all of them alike?
        for on in range(1 << 2 * ndim):
            face_doms[on] = memo.face_domain(on, used, face_rules)
        plain = set(face_doms.values()) == {used}
    reorder = operator.itemgetter(*scan_at) if ndim > 1 else lambda t: t

    # every state a pair of an integer step and integer labels in use (all states at once)
    every = [s for c in configs for s in c["states"]]
    if set(map(type, every)) - {list, tuple} or set(map(len, every)) - {2}:
        raise _Invalid("a state is not a pair [step, labels]")
    if set(map(type, (s[0] for s in every))) - {int}:
        if any(not issubclass(t, np.integer) for t in set(type(s[0]) for s in every) - {int}):
            raise _Invalid("a state's step or labels are not integers")
    rows = [s[1] for s in every]
    if set(map(type, rows)) - {list, tuple}:
        raise _Invalid("a state's step or labels are not integers")
    flat = set(itertools.chain.from_iterable(rows))
    # numpy integers: Python ints (shifts); by the labels' types, not the set's (which keeps
    # one of 7 and np.int8(7))
    as_int = bool(set(map(type, itertools.chain.from_iterable(rows))) - {int})
    # numpy integers as steps or labels: the states as Python ints (shifts, keys)
    convert = as_int or bool(set(map(type, (s[0] for s in every))) - {int})
    if as_int or not in_use.issuperset(flat):
        for c in configs:
            lo, hi = c["lower"], c["upper"]
            _labels_in_use(c["states"], set(itertools.chain.from_iterable(
                s[1] for s in c["states"])), in_use, _where(lo, hi))  # fmt: skip
    total = len(every)
    for (lo, hi, _), members in by_frame.items():
        fr = _lean_frame(lo, hi, members[0][0]["keys"], region, back, axes, fwd, cls)
        n, coords = fr.n, fr.coords
        widths = list(map(len, fr.keys))
        # per step: the neighbours' slots and support tables (``near``); the next state's
        # kept labels as (slot, class map) pairs; the chosen label's class map and its sets
        # of classes when the next state records it (last), else ``ident`` and None
        near_of = fr.near
        keep_of = fr.kept
        for c in set(fr.chosen) - pick_sets.keys():
            pick_sets[c] = (cls(c), {})
        pick_of, sets_of = zip(*map(pick_sets.__getitem__, fr.chosen), strict=True)
        # a state at step i is recorded by its labels but the last (-> the set of last
        # labels) when step i - 1 records its chosen label, else by all its labels
        split = [False, *[c >= 0 for c in fr.chosen[:-1]]]
        last = n - 1
        exact = classes and fr.free[-1] == 1 << last
        # the states checked in this frame, by the domains of its cells: a configuration
        # with the same frame, domains and states (its positions on the faces differ) is
        # the same check, with the same outcome
        checked: dict[tuple[int, ...], list[Any]] = {}
        ext = [] if plain else [a + 1 + b for a, b in zip(lo, hi, strict=True)]
        for conf, (_, _, at_lo, at_hi) in members:
            # the domain of each cell of the frame (labels in use, face rules, dead labels)
            if plain:
                base = [used] * len(coords)
            else:
                per, faces, fars = [], [], []
                for d in axes:  # in scan order: the products below run as the cells do
                    sig = (d, ext[d], at_lo[d], at_hi[d], cap)
                    p = axis_places.get(sig)
                    if p is None:
                        q = _axis_places(*sig)
                        p = axis_places[sig] = (q, [t[0] for t in q], [t[2] for t in q])
                    per.append(p[0])
                    faces.append(p[1])
                    fars.append(p[2])
                # the faces of each cell (the axes' bits are disjoint: their sum)
                ons = list(map(sum, itertools.product(*faces)))
                for on in set(ons) - face_doms.keys():
                    face_doms[on] = memo.face_domain(on, used, face_rules)
                base = list(map(face_doms.__getitem__, ons))
                if dead_far:  # the cells that may lie where a label in use is dead
                    cells = zip(map(reorder, itertools.product(*fars)), itertools.product(*per),
                                strict=True)  # fmt: skip
                    for x, (far, it) in enumerate(cells):
                        if far in dead_far:
                            base[x] = cell_doms[it] if it in cell_doms else cell_dom(it)
            states = conf["states"]
            if len(members) > 1:
                same = checked.setdefault(tuple(base), [])
                if any(states == other for other in same):
                    continue
                same.append(states)
            if convert:
                states = [(int(i), tuple(map(int, labs))) for i, labs in states]
            # the states checked for their form and recorded: (step, labels) -> 0, or with
            # ``split``, (step, labels but the last) -> the set of last labels
            rec: dict[tuple[int, ...], int] = {}
            for i, labs in states:
                if not 0 <= i < n:
                    raise _Invalid(f"{_where(lo, hi)}: a state's step is not one of its {n} steps")
                if len(labs) != widths[i]:
                    raise _Invalid(f"{_where(lo, hi)}: a state at step {i} does not fit keys[{i}]")
                if split[i]:
                    key = (i, *labs[:-1])
                    rec[key] = rec.get(key, 0) | 1 << labs[-1]
                else:
                    rec[i, *labs] = 0
            if (0,) not in rec:
                raise _Invalid(f"{_where(lo, hi)}: no start state")
            # closed: each state's labels lead to recorded states; the point's catalog is
            # never empty. The first defect reported is the first of the point's states,
            # else the first at the latest step (in file order)
            bad: tuple[int, str] | None = None
            for i, labs in states:
                fc = base[i]
                for k, t in near_of[i]:
                    fc &= t[labs[k]]
                if i == last:
                    if fc and not exact:
                        fc = ac.catalog(fr, i, labs, base)
                    if not fc:
                        raise _Invalid(f"{_where(lo, hi)}: the point's catalog is empty in "
                                       f"state {[i, list(labs)]}")  # fmt: skip
                    continue
                if not fc:
                    continue
                # the next state's key: the kept labels by class (one or two spelled out)
                kp = keep_of[i]
                if len(kp) == 1:
                    ((k, m),) = kp
                    key = (i + 1, m[labs[k]])
                elif len(kp) == 2:
                    (k, m), (k1, m1) = kp
                    key = (i + 1, m[labs[k]], m1[labs[k1]])
                else:
                    key = (i + 1, *[m[labs[k]] for k, m in kp])
                sets = sets_of[i]
                if sets is not None:
                    pick = pick_of[i]
                    want = sets.get(fc)
                    if want is None:
                        want = 0
                        for b in _bits(fc):
                            want |= 1 << pick[b]
                        sets[fc] = want
                    avail = rec.get(key, 0)
                    if not want & ~avail:
                        continue
                    miss = 0
                    for b in _bits(fc):
                        if not avail >> pick[b] & 1:
                            miss |= 1 << b
                elif key in rec:
                    continue
                else:
                    miss = fc
                if bad is None or -i < bad[0]:
                    miss &= ac.catalog(fr, i, labs, base)
                    if miss:
                        b = (miss & -miss).bit_length() - 1
                        nx = [*key[1:], pick[b]] if sets is not None else list(key[1:])
                        state = [i, list(labs)]
                        bad = (-i, f"{_where(lo, hi)}: not closed: state {state} with label "
                                   f"{b} leads to {[i + 1, nx]}, which is missing")  # fmt: skip
            if bad is not None:
                # (every point state was checked: the point's defects come first)
                raise _Invalid(bad[1])
    return total


AxisPlace = tuple[int, tuple[int, int], tuple[int, int]]


def _axis_places(d: int, e: int, at_lo: bool, at_hi: bool, cap: int) -> list[AxisPlace]:
    """Per coordinate of a frame of extent ``e`` along axis ``d``: the faces a cell there
    lies on (bits ``2d``, ``2d + 1``), its capped distances to the faces (exact where the
    frame's edge is on the face, else ``a + cap + 1``: ``a`` or more) and the farthest
    distances among those."""
    out = []
    for v in range(e):
        lo = min(v, cap) if at_lo else min(v + 1, cap) + cap + 1
        hi = min(e - 1 - v, cap) if at_hi else min(e - v, cap) + cap + 1
        out.append((
            (at_lo and v == 0) << 2 * d | (at_hi and v == e - 1) << 2 * d + 1,
            (lo, hi),
            (lo if lo <= cap else cap, hi if hi <= cap else cap),
        ))  # fmt: skip
    return out


def _labels_in_use(states: list[Any], flat: set[Any], in_use: set[int], where: str) -> None:
    """Raise for the first label of ``states`` that is not an integer or not in use."""
    if any(not issubclass(t, np.integer) for t in set(map(type, flat)) - {int}):
        raise _Invalid("a state's step or labels are not integers")
    for s in states:
        if not in_use.issuperset(int(x) for x in s[1]):
            raise _Invalid(f"{where}: a state at step {s[0]} has a label not in use")


class _LeanAC:
    """``C_R`` of a step of a frame in a state: arc consistency on the step's region (its
    cells not yet labelled, with their domains, and its recorded ones); with ``classes``
    no arcs between labelled cells. Graphs are shared by steps of one shape (the cells
    relative to the step's cell, and which are labelled), catalogs by shape, domains and
    labels."""

    def __init__(self, rules: _Rules, memo: _Memo, classes: bool) -> None:
        self.rules, self.memo, self.classes = rules, memo, classes
        self.graphs: dict[Any, tuple[Arcs, int]] = {}
        self.catalogs: dict[Any, int] = {}

    def catalog(self, fr: _LeanFrame, i: int, labs: Sequence[int], base: list[int]) -> int:
        c = fr.coords[i]
        keys = fr.keys[i]
        box = fr.box[i]
        fixed = [(fr.coords[j], k) for k, j in enumerate(keys) if box >> j & 1]
        free = list(_bits(fr.free[i]))
        rel = [tuple(a - b for a, b in zip(x, c, strict=True)) for x, _ in fixed]
        rel.append(())  # the labelled cells, then those not yet labelled
        rel += [tuple(a - b for a, b in zip(fr.coords[j], c, strict=True)) for j in free]
        shape = tuple(rel)
        doms = tuple(base[j] for j in free)
        key = (shape, doms, tuple(labs[k] for _, k in fixed))
        cat = self.catalogs.get(key)
        if cat is not None:
            return cat
        graph = self.graphs.get(shape)
        if graph is None:
            nf = len(fixed)
            arcs = _arcs([x for x, _ in fixed] + [fr.coords[j] for j in free])
            if self.classes:
                arcs = [[a for a in row if not (u < nf and a[0] < nf)]
                        for u, row in enumerate(arcs)]  # fmt: skip
            graph = self.graphs[shape] = (arcs, nf + free.index(i))
        arcs, target = graph
        dom = [1 << labs[k] for _, k in fixed] + list(doms)
        out = _small_ac(dom, arcs, self.memo.tables, self.memo.unions)
        cat = self.catalogs[key] = 0 if out is None else out[target]
        return cat


def _is_int(x: Any) -> bool:
    return type(x) is int or isinstance(x, np.integer)


# ----------------------------------------------------------------------------- label classes


def _class_maps(fwd: list[list[int]], used: int) -> list[list[int]]:
    """Per set of axes (a bit mask ``m``: axis ``d`` when ``m >> d & 1``), label -> the least
    label in use with the same ``fwd[d]`` for every ``d`` in the set (a label out of use
    maps to itself)."""
    K = len(fwd[0])
    # each label's forward supports along the axes of the set, as nested pairs: the set
    # without its highest axis, then that axis
    rows: list[list[Any]] = [[()] * K]
    maps = []
    for m in range(1 << len(fwd)):
        if m:
            d = m.bit_length() - 1
            t, prev = fwd[d], rows[m ^ 1 << d]
            rows.append([(prev[a], t[a]) for a in range(K)])
        first: dict[Any, int] = {}
        maps.append([first.setdefault(r, a) if used >> a & 1 else a
                     for a, r in enumerate(rows[m])])  # fmt: skip
    return maps


# ----------------------------------------------------------------------------- dead labels


Where = tuple[tuple[int, ...], ...]


def _check_dead(dead: Mapping[str, Any], rules: _Rules) -> dict[Where, int]:
    """The labels dead at each ``where`` (per axis the distances to the lower and upper
    face, capped at ``cap``, which means "at least"): those the faces' domain rules
    exclude there, and those of the ``stages`` ``[face, [[where, labels], ...]]``, each
    verified: ``where`` is not on ``face``, and at every ``where`` the neighbour one cell
    nearer ``face`` may have, every label supporting one of the labels from there is dead
    -- earlier, or in this stage.

    Why no catalog of Alg. 3.1 ever holds one at such a cell: its catalogs lie inside the
    greatest arc-consistent domains before any choice, ``C_0``, where a label has a
    support in each neighbour. Take a stage label in ``C_0`` at a cell, of the first stage
    that has one, nearest the stage's face: its support in the neighbour nearer the face
    is dead earlier (so not in ``C_0``) or in this stage nearer the face -- a
    contradiction either way. So Alg. 3.1 runs the same with a cell's dead labels out of
    its domain, and the states are checked with them out.
    """
    fwd, bwd, used, ndim, face_rules = rules
    cap = int(dead["cap"])
    if not 1 <= cap <= 8:
        raise _Invalid("dead labels: cap must be 1 to 8")
    span = list(itertools.product(range(cap + 1), repeat=2))
    # the labels the face rules exclude, by the faces a place lies on (bits 2d, 2d + 1)
    excluded = [used & ~_domain(face_rules, f, used) for f in range(1 << 2 * ndim)]
    # every place, and the faces it lies on, in the same order (iterated in C)
    on = [0]
    for d in range(ndim):
        on = [f | (a == 0) << 2 * d | (b == 0) << 2 * d + 1 for f in on for a, b in span]
    known: dict[Where, int] = dict(zip(
        itertools.product(span, repeat=ndim), map(excluded.__getitem__, on), strict=True
    ))  # fmt: skip
    every = [_AXES[d] + s for d in range(ndim) for s in "-+"]
    label_bits: dict[tuple[Any, ...], int] = {}
    towards: dict[bool, dict[tuple[int, ...], list[tuple[int, int]]]] = {}
    for face, got in dead["stages"]:
        if face not in every:
            raise _Invalid(f"dead labels: {face!r} is not a face of a {ndim}D grid")
        d, minus = _AXES.index(face[0]), face[1] == "-"
        stage: dict[Where, int] = {}
        side = 0 if minus else 1
        at, bits_of = stage.get, label_bits.get
        for where, labels in got:
            k: Where = tuple(map(tuple, where))
            m = bits_of(tuple(labels))
            if m is None or k not in known or k[d][side] == 0:  # (labels seen first here)
                if k not in known or k[d][side] == 0:
                    raise _Invalid(f"dead labels: {list(where)} is not a place off {face}")
                m = 0
                for b in labels:
                    if not (isinstance(b, int) and 0 <= b < len(fwd[0]) and used >> b & 1):
                        raise _Invalid(f"dead labels: {b!r} is not a label in use")
                    m |= 1 << b
                label_bits[tuple(labels)] = m
            stage[k] = at(k, 0) | m
        table = bwd[d] if minus else fwd[d]
        sup_of: dict[int, int] = {}  # labels -> their supports toward the face
        # per distances along d, those the neighbour one cell nearer the face may have
        toward = towards.get(minus)
        if toward is None:
            toward = towards[minus] = {}
            for lo, hi in span:
                if minus:
                    los, his = ([lo - 1] if lo < cap else [cap - 1, cap]), [min(hi + 1, cap)]
                else:
                    los, his = [min(lo + 1, cap)], ([hi - 1] if hi < cap else [cap - 1, cap])
                toward[lo, hi] = list(itertools.product(los, his))
        for bits in set(stage.values()):
            sup = 0
            for b in _bits(bits):
                sup |= table[b]
            sup_of[bits] = sup
        # (a place is added to ``known`` once checked: the labels dead at a neighbour
        # are then read as before, known there or in this stage)
        for k, bits in stage.items():
            sup = sup_of[bits]
            head, tail = k[:d], k[d + 1 :]
            for p in toward[k[d]]:
                n = (*head, p, *tail)
                gone = known[n] | at(n, 0)
                if not sup & ~gone:
                    continue
                for b in _bits(bits):
                    if table[b] & ~gone:
                        raise _Invalid(
                            f"dead labels: {b} at {[list(t) for t in k]} has a support toward "
                            f"{face} that is not dead: {sorted(_bits(table[b] & ~gone))}"
                        )
            known[k] |= bits
    return known


def _without(rules: _Rules, dead: int) -> _Rules:
    """The rules with the ``dead`` labels out of use."""
    keep = rules.used & ~dead

    def cut(table: list[list[int]]) -> list[list[int]]:
        return [[row & keep if keep >> a & 1 else 0 for a, row in enumerate(t)] for t in table]

    return _Rules(cut(rules.fwd), cut(rules.bwd), keep, rules.ndim, rules.faces)


# ----------------------------------------------------------------------------- fallible


def _check_run(cert: Mapping[str, Any], rules: _Rules) -> str:
    fwd, bwd, used, ndim, face_rules = rules
    run = cert["run"]
    shape = tuple(int(s) for s in run["shape"])
    if len(shape) != ndim or any(s < 1 for s in shape):
        raise _Invalid(f"run: shape {list(shape)} does not have {ndim} positive sizes")
    axes = _axes_of(str(run.get("order", "scanline")), ndim)
    cells = sorted(
        itertools.product(*[range(s) for s in shape]), key=lambda c: tuple(c[a] for a in axes)
    )

    def faces(c: Cell) -> int:
        return sum((c[d] == 0) << 2 * d | (c[d] == shape[d] - 1) << 2 * d + 1 for d in range(ndim))

    bnd = run.get("boundary") or {}
    if bnd == "auto":  # the certificate's face rules
        rules_here = face_rules
    elif isinstance(bnd, Mapping):  # face -> label; the bottom face wins, then later faces
        every = [_AXES[d] + s for d in range(ndim) for s in "-+"]
        if any(f not in every for f in bnd):
            raise _Invalid(f"run: unknown boundary faces in {sorted(bnd)}")
        bottom = _AXES[ndim - 1] + "-"
        order = [f for f in every if f != bottom] + [bottom]
        rules_here = [("force", f, 1 << int(bnd[f])) for f in order if f in bnd]
    else:
        raise _Invalid("run: boundary must be 'auto' or map faces to labels")
    first = [_domain(rules_here, faces(c), used) for c in cells]
    if any(v == 0 for v in first):
        return "valid: Alg. 3.1 fails before its first choice (a boundary cell has no label)"
    arcs = _arcs(cells)
    tables = [*fwd, *bwd]
    unions: list[dict[int, int]] = [{} for _ in tables]
    dom = _small_ac(first, arcs, tables, unions)
    if dom is None:
        return "valid: Alg. 3.1 fails before its first choice (the grid has no solution)"
    choices = list(run["choices"])
    for k, (cell, label) in enumerate(choices):
        c = tuple(int(t) for t in cell)
        if c != cells[k]:
            raise _Invalid(f"run: choice {k + 1} is at {list(c)}, the scan visits {cells[k]}")
        if label is None:  # a run that stops at an empty catalog: it is wiped out before
            raise _Invalid(f"run: choice {k + 1} claims an empty catalog, which is not")
        if not dom[k] >> int(label) & 1:
            raise _Invalid(f"run: choice {k + 1} ({label} at {list(c)}) is not in its catalog")
        dom[k] = 1 << int(label)
        # the domains were arc consistent before: revising from the changed cell suffices
        dom = _small_ac(dom, arcs, tables, unions, start=[k])
        if dom is None:
            rest = choices[k + 1 :]  # at most the cell found empty, marked [cell, None]
            if rest and (len(rest) > 1 or rest[0][1] is not None):
                raise _Invalid(f"run: the catalog is wiped out at choice {k + 1}, not the last")
            return (
                f"valid: the run of Alg. 3.1 ({len(choices)} choices on "
                f"{'x'.join(map(str, shape))}) wipes out a catalog: fallible"
            )
    raise _Invalid("the run of Alg. 3.1 does not fail (every catalog non-empty at the end)")


def _main(argv: Sequence[str]) -> int:  # pragma: no cover - `python -m csplab.certcheck FILE`
    ok, msg = check_certificate(load_certificate(argv[0]))
    print(msg)
    return 0 if ok else 1


if __name__ == "__main__":  # pragma: no cover
    import sys

    raise SystemExit(_main(sys.argv[1:]))
