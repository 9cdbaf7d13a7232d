"""An independent checker of infallibility certificates (``csplab check-certificate``).

``csplab prove --certificate FILE`` writes what its verdict rests on; this module re-verifies
it from the file alone, as a DRAT checker re-verifies a SAT solver's refutation. It shares
no code with the prover (:mod:`csplab.analysis.infallible`; an import-linter contract
forbids importing it, or anything of csplab but :mod:`csplab.errors`): the frames, regions,
arc consistency and grid replay below are written again, plainly.

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
(:func:`_check_classes` says why that is sound). ``dead`` (optional, with
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

import hashlib
import itertools
import json
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from csplab.errors import InputError

__all__ = ["check_certificate", "load_certificate", "rules_hash"]

FORMAT = "csplab-certificate"
VERSION = 1
_AXES = "xyzw"

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
    return hashlib.sha256(
        json.dumps(rules, sort_keys=True, separators=(",", ":")).encode()
    ).hexdigest()


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
            everywhere = -1
            for bits in dead.values():
                everywhere &= bits
            model = _without(model, everywhere)
        if claim == "infallible" and cert.get("label_classes"):
            msg = _check_classes(cert, model, dead)
        elif claim == "infallible":
            msg = _check_closed(cert, model)
        elif claim == "fallible":
            msg = _check_run(cert, model)
        else:
            raise _Invalid(f"unknown claim {claim!r}")
    except _Invalid as e:
        return False, f"invalid: {e}"
    except (KeyError, TypeError, ValueError, IndexError) as e:
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


def _domain(face_rules: list[FaceRule], faces: set[str], used: int) -> int:
    """The domain of a cell lying on ``faces``: the labels in use, edited by the rules."""
    dom = used
    for op, where, bits in face_rules:
        if where != "*" and (where[1:] in faces if where[0] == "!" else where not in faces):
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


def _check_closed(cert: Mapping[str, Any], rules: _Rules) -> str:
    fwd, bwd, used, ndim, face_rules = rules
    region = [int(t) for t in cert["region"]]
    history = [int(t) for t in cert["history"]]
    axes = tuple(int(a) for a in cert["axes"])
    if len(region) != ndim or len(history) != ndim or any(r < 2 for r in region):
        raise _Invalid("region needs at least 2 cells on every axis of the rules")
    if any(h < 0 for h in history):
        raise _Invalid("history must be non-negative")
    back = [int(t) for t in cert.get("back", [1] * ndim)]
    if len(back) != ndim or any(b < 1 for b in back):
        raise _Invalid("back needs a value of at least 1 on every axis")
    if _axes_of(str(cert["order"]), ndim) != axes:
        raise _Invalid("axes do not match the order")
    both = (False, True) if face_rules else (False,)
    want = set()
    for lo in itertools.product(*[range(1 + b + h) for b, h in zip(back, history, strict=True)]):
        for hi in itertools.product(*[range(r - 1) for r in region]):
            at_lo = [(True,) if lo[d] < back[d] + history[d] else both for d in range(ndim)]
            at_hi = [(True,) if hi[d] < region[d] - 2 else both for d in range(ndim)]
            for a in itertools.product(*at_lo):
                for b in itertools.product(*at_hi):
                    want.add((lo, hi, a, b))
    configs = cert["configs"]
    got = [
        (
            tuple(c["lower"]), tuple(c["upper"]),
            tuple(bool(t) for t in c.get("at_lower", [])) or tuple(
                lo < b + h for lo, b, h in zip(c["lower"], back, history, strict=True)),
            tuple(bool(t) for t in c.get("at_upper", [])) or tuple(
                hi < r - 2 for hi, r in zip(c["upper"], region, strict=True)),
        )
        for c in configs
    ]  # fmt: skip
    if len(got) != len(set(got)) or set(got) != want:
        raise _Invalid(f"the configurations are not the {len(want)} positions of a point")
    nstates = 0
    # shared by every configuration: support sets, frames (configurations that differ only
    # in which frame edges lie on a face have the same frame) and catalogs
    memo = _Memo()
    for c, (_, _, a, b) in zip(configs, got, strict=True):
        nstates += _check_config(c, region, back, axes, fwd, bwd, used, face_rules, a, b, memo)
    rtxt = "x".join(map(str, region)) + (
        "" if set(back) == {1} else " (reaching back " + "x".join(map(str, back)) + ")"
    )
    return (
        f"valid: {nstates} states in {len(configs)} configurations are closed under Alg. 3.6 "
        f"with {rtxt} regions ({cert['order']}) and no catalog of a point is empty: "
        "Alg. 3.1 never fails (Theorem 3.3.6)"
    )


def _check_config(
    conf: Mapping[str, Any],
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
    fwd: list[list[int]],
    bwd: list[list[int]],
    used: int,
    face_rules: list[FaceRule],
    at_lo: tuple[bool, ...],
    at_hi: tuple[bool, ...],
    memo: _Memo,
) -> int:
    lo, hi = tuple(conf["lower"]), tuple(conf["upper"])
    ext = tuple(a + 1 + b for a, b in zip(lo, hi, strict=True))
    keys = [list(k) for k in conf["keys"]]
    where = f"configuration lower={list(lo)} upper={list(hi)}"
    fkey = (lo, hi, tuple(map(tuple, keys)))
    frame = memo.frames.get(fkey)
    if frame is None:
        frame = memo.frames[fkey] = (
            len(memo.frames),
            _frame_graphs(lo, hi, ext, keys, region, back, axes, where),
        )
    gid, graphs = frame

    def base(x: Cell) -> int:
        on = frozenset(
            {_AXES[d] + "-" for d in range(len(x)) if at_lo[d] and x[d] == 0}
            | {_AXES[d] + "+" for d in range(len(x)) if at_hi[d] and x[d] == ext[d] - 1}
        )
        dom = memo.domains.get(on)
        if dom is None:
            dom = memo.domains[on] = _domain(face_rules, set(on), used)
        return dom

    bases = [tuple(base(x) for x in g[3]) for g in graphs]
    return _check_states(conf, keys, graphs, bases, gid, fwd, bwd, used, memo, where)


class _Memo:
    """What the configurations of one certificate share."""

    def __init__(self) -> None:
        self.union: dict[tuple[int, int, int], int] = {}
        self.frames: dict[Any, tuple[int, list[_Graph]]] = {}
        self.domains: dict[frozenset[str], int] = {}
        self.catalogs: dict[Any, list[int]] = {}


_Graph = tuple[list[int], list[list[tuple[int, int, bool]]], int, list[Cell]]


def _frame_graphs(
    lo: Cell,
    hi: Cell,
    ext: Cell,
    keys: list[list[int]],
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
    where: str,
) -> list[_Graph]:
    """The frame of a configuration, its ``keys`` verified, as one small graph per step."""

    def order_key(c: Cell) -> Cell:
        return tuple(c[a] for a in axes)

    cells = sorted(itertools.product(*[range(e) for e in ext]), key=order_key)
    cells = [c for c in cells if order_key(c) < order_key(lo)] + [lo]
    index = {c: i for i, c in enumerate(cells)}
    n = len(cells)
    if len(keys) != n or keys[0]:
        raise _Invalid(f"{where}: keys must list {n} steps, the first empty")
    boxes: list[list[Cell]] = []
    for i, c in enumerate(cells):
        if keys[i] != sorted(set(keys[i])) or any(not 0 <= j < i for j in keys[i]):
            raise _Invalid(f"{where}: keys[{i}] must be sorted earlier steps")
        if i + 1 < n and not set(keys[i + 1]) <= set(keys[i]) | {i}:
            raise _Invalid(f"{where}: keys[{i + 1}] records a label step {i} forgot")
        box = list(itertools.product(*[
            range(max(0, c[d] - back[d]), min(ext[d] - 1, c[d] + region[d] - 2) + 1)
            for d in range(len(c))
        ]))  # fmt: skip
        inbox = set(box)
        labelled = {x for x in box if x in index and index[x] < i}
        for x in labelled:
            near = ((*x[:d], x[d] + s, *x[d + 1 :]) for d in range(len(x)) for s in (-1, 1))
            if any(y in inbox and y not in labelled for y in near) and index[x] not in keys[i]:
                raise _Invalid(f"{where}: step {i} depends on cell {list(x)}, not in keys[{i}]")
        boxes.append(box)
    return [_graph(boxes[i], index, i, keys[i], cells[i]) for i in range(n)]


def _check_states(
    conf: Mapping[str, Any],
    keys: list[list[int]],
    graphs: list[_Graph],
    bases: list[tuple[int, ...]],
    gid: int,
    fwd: list[list[int]],
    bwd: list[list[int]],
    used: int,
    memo: _Memo,
    where: str,
) -> int:
    """The states of a configuration: present at the start, closed, never an empty point."""
    n = len(graphs)
    by_step: list[set[tuple[int, ...]]] = [set() for _ in range(n)]
    try:
        for i, labs in conf["states"]:
            by_step[i if i >= 0 else n].add(tuple(labs))
    except (IndexError, TypeError):
        raise _Invalid(f"{where}: a state's step is not one of its {n} steps") from None
    in_use = set(_bits(used))
    for i, group in enumerate(by_step):
        if any(len(t) != len(keys[i]) for t in group):
            raise _Invalid(f"{where}: a state at step {i} does not fit keys[{i}]")
        labels = set(itertools.chain.from_iterable(group))
        if not labels <= in_use:
            raise _Invalid(f"{where}: a state at step {i} has a label not in use")
    if () not in by_step[0]:
        raise _Invalid(f"{where}: no start state")
    for i in range(n):
        src, arcs, target, _ = graphs[i]
        pos = {j: k for k, j in enumerate(keys[i])}
        # where each fixed node's label, and each label of the next state, sits in a state
        src_at = [pos[j] for j in src if j >= 0]
        nxt_at = [-1 if j == i else pos[j] for j in keys[i + 1]] if i + 1 < n else []
        later = by_step[i + 1] if i + 1 < n else set()
        cats = memo.catalogs
        here = (gid, i, bases[i])
        # the labels of cell i that agree with its labelled neighbours: a superset of its
        # catalog (arc consistency only removes more), enough when every one leads on
        near = [(pos[src[v]], bwd[d] if plus else fwd[d]) for v, d, plus in arcs[target]
                if src[v] >= 0]  # fmt: skip
        base_t = bases[i][target]
        for labs in by_step[i]:
            if i < n - 1:
                fc = base_t
                for k, table in near:
                    fc &= table[labs[k]]
                if all(
                    tuple([b if k < 0 else labs[k] for k in nxt_at]) in later for b in _bits(fc)
                ):
                    continue
            mk = tuple([labs[k] for k in src_at])
            cat = cats.get((here, mk))
            if cat is None:
                it = iter(mk)
                dom = [b0 if j < 0 else 1 << next(it) for j, b0 in zip(src, bases[i], strict=True)]
                out = _small_ac(dom, arcs, fwd, bwd, memo.union)
                cat = cats[(here, mk)] = [] if out is None else list(_bits(out[target]))
            if i == n - 1:
                if not cat:
                    raise _Invalid(
                        f"{where}: the point's catalog is empty in state {[i, list(labs)]}"
                    )
                continue
            for b in cat:
                nxt = tuple([b if k < 0 else labs[k] for k in nxt_at])
                if nxt not in later:
                    raise _Invalid(
                        f"{where}: not closed: state {[i, list(labs)]} with label {b} leads to "
                        f"{[i + 1, list(nxt)]}, which is missing"
                    )
    return sum(len(s) for s in by_step)


def _graph(
    box: list[Cell], index: Mapping[Cell, int], i: int, key: Sequence[int], cell: Cell
) -> tuple[list[int], list[list[tuple[int, int, bool]]], int, list[Cell]]:
    """The region of step ``i`` as a small graph: its unlabelled cells (``src`` -1) and its
    labelled cells whose label the state records (``src`` = their step); arcs
    ``(node, axis, node is the + neighbour)``; the node of cell ``i``; the nodes' cells."""
    known = set(key)
    nodes = [x for x in box if not (x in index and index[x] < i) or index[x] in known]
    src = [index[x] if x in index and index[x] < i else -1 for x in nodes]
    return src, _arcs(nodes), nodes.index(cell), nodes


def _arcs(nodes: Sequence[Cell]) -> list[list[tuple[int, int, bool]]]:
    """The arcs between grid-adjacent ``nodes``: per node, ``(other node, axis, other is the
    + neighbour)``."""
    pos = {x: k for k, x in enumerate(nodes)}
    arcs: list[list[tuple[int, int, bool]]] = [[] for _ in nodes]
    for x, k in pos.items():
        for d in range(len(x)):
            m = pos.get((*x[:d], x[d] + 1, *x[d + 1 :]))
            if m is not None:
                arcs[k].append((m, d, True))
                arcs[m].append((k, d, False))
    return arcs


def _small_ac(
    dom: list[int],
    arcs: list[list[tuple[int, int, bool]]],
    fwd: list[list[int]],
    bwd: list[list[int]],
    union: dict[tuple[int, int, int], int],
    start: Sequence[int] | None = None,
) -> list[int] | None:
    """Arc consistency (a work list of nodes) on a small graph; ``None`` on a wipe-out.
    ``start``: the nodes whose domains changed since the domains were last arc consistent
    (default: all)."""
    queue = list(range(len(dom))) if start is None else list(start)
    waiting = [False] * len(dom)
    for u in queue:
        waiting[u] = True
    while queue:
        u = queue.pop()
        waiting[u] = False
        du = dom[u]
        for v, d, plus in arcs[u]:
            ukey = (d if plus else -1 - d, du, 0)
            sup = union.get(ukey)
            if sup is None:
                table = fwd[d] if plus else bwd[d]
                sup = 0
                for b in _bits(du):
                    sup |= table[b]
                union[ukey] = sup
            new = dom[v] & sup
            if new != dom[v]:
                if new == 0:
                    return None
                dom[v] = new
                if not waiting[v]:
                    waiting[v] = True
                    queue.append(v)
    return dom


# ----------------------------------------------------------------------------- infallible,
# labels recorded by their class


def _check_classes(
    cert: Mapping[str, Any], rules: _Rules, dead: Mapping[Where, int] | None = None
) -> str:
    """An *infallible* certificate with ``label_classes``: as above, except that a state
    records each label by its class -- the least label in use with the same forward
    supports (``fwd[d]``) along the axes on which the cell's + neighbour lies in the frame
    box and is not yet labelled at that step -- and arc consistency leaves out the arcs
    between two labelled cells.

    Why this suffices: inside the frame a labelled cell's - neighbours are labelled
    (scan order), so it meets unlabelled cells only along those axes; there its label
    acts only through ``fwd[d][label]`` (narrowing the neighbour, and keeping the label
    iff the neighbour's domain meets it). Arcs between labelled cells hold in every real
    run (each label agreed with its - neighbours, which its region holds). So arc
    consistency with the classes gives the catalogs of the real labels, and a real run's
    labels, mapped to their classes, stay in a closed set that holds the start state.
    """
    ndim, face_rules = rules.ndim, rules.faces
    region = [int(t) for t in cert["region"]]
    history = [int(t) for t in cert["history"]]
    back = [int(t) for t in cert.get("back", [1] * ndim)]
    axes = tuple(int(a) for a in cert["axes"])
    if len(region) != ndim or len(history) != ndim or len(back) != ndim:
        raise _Invalid("region, history and back need a value on every axis of the rules")
    if any(r < 2 for r in region) or any(h < 0 for h in history) or any(b < 1 for b in back):
        raise _Invalid("region needs >= 2, history >= 0 and back >= 1 on every axis")
    if _axes_of(str(cert["order"]), ndim) != axes:
        raise _Invalid("axes do not match the order")
    both = (False, True) if face_rules else (False,)
    want = set()
    for lo in itertools.product(*[range(1 + b + h) for b, h in zip(back, history, strict=True)]):
        for hi in itertools.product(*[range(r - 1) for r in region]):
            at_lo = [(True,) if lo[d] < back[d] + history[d] else both for d in range(ndim)]
            at_hi = [(True,) if hi[d] < region[d] - 2 else both for d in range(ndim)]
            for a in itertools.product(*at_lo):
                for b in itertools.product(*at_hi):
                    want.add((lo, hi, a, b))
    got = [
        (tuple(c["lower"]), tuple(c["upper"]), tuple(bool(t) for t in c["at_lower"]),
         tuple(bool(t) for t in c["at_upper"]))
        for c in cert["configs"]
    ]  # fmt: skip
    if len(got) != len(set(got)) or set(got) != want:
        raise _Invalid(f"the configurations are not the {len(want)} positions of a point")
    canon: dict[frozenset[int], list[int]] = {}
    nstates = 0
    for conf, (lo, hi, on_lo, on_hi) in zip(cert["configs"], got, strict=True):
        nstates += _check_class_config(
            conf, lo, hi, on_lo, on_hi, region, back, axes, rules, canon, dead or {}
        )
    return (
        f"valid: {nstates} states (labels by class) in {len(got)} configurations are closed "
        f"under Alg. 3.6 with {'x'.join(map(str, region))} regions ({cert['order']}) and no "
        "catalog of a point is empty: Alg. 3.1 never fails (Theorem 3.3.6)"
    )


def _class_of(fwd: list[list[int]], used: int, ax: frozenset[int]) -> list[int]:
    """Label -> the least label in use with the same ``fwd[d]`` for every ``d`` in ``ax``."""
    first: dict[tuple[int, ...], int] = {}
    return [
        first.setdefault(tuple(fwd[d][a] for d in sorted(ax)), a) if used >> a & 1 else a
        for a in range(len(fwd[0]))
    ]


def _check_class_config(
    conf: Mapping[str, Any],
    lo: Cell,
    hi: Cell,
    at_lo: tuple[bool, ...],
    at_hi: tuple[bool, ...],
    region: list[int],
    back: list[int],
    axes: tuple[int, ...],
    rules: _Rules,
    canon: dict[frozenset[int], list[int]],
    dead: Mapping[Where, int],
) -> int:
    fwd, bwd, used, ndim, face_rules = rules
    where = f"configuration lower={list(lo)} upper={list(hi)}"
    ext = tuple(a + 1 + b for a, b in zip(lo, hi, strict=True))

    def okey(c: Cell) -> Cell:
        return tuple(c[a] for a in axes)

    cells = [c for c in itertools.product(*[range(e) for e in ext]) if okey(c) < okey(lo)]
    cells = [*sorted(cells, key=okey), lo]
    index = {c: i for i, c in enumerate(cells)}
    n = len(cells)
    keys = [[int(j) for j in k] for k in conf["keys"]]
    if len(keys) != n or keys[0]:
        raise _Invalid(f"{where}: keys must list {n} steps, the first empty")

    cap = max((v for k in dead for a in k for v in a), default=0)
    doms: dict[Cell, int] = {}

    def face_dom(x: Cell) -> int:
        if x in doms:
            return doms[x]
        on = {_AXES[d] + "-" for d in range(ndim) if at_lo[d] and x[d] == 0}
        on |= {_AXES[d] + "+" for d in range(ndim) if at_hi[d] and x[d] == ext[d] - 1}
        dom = _domain(face_rules, on, used)
        if dead:  # minus the labels dead wherever in an output this cell may lie
            per_axis = []
            for d in range(ndim):
                lo_d, hi_d = x[d], ext[d] - 1 - x[d]  # distances, exact on a face edge
                los = [min(lo_d, cap)] if at_lo[d] else range(min(lo_d + 1, cap), cap + 1)
                his = [min(hi_d, cap)] if at_hi[d] else range(min(hi_d + 1, cap), cap + 1)
                per_axis.append([(a, b) for a in los for b in his])
            alive = 0
            for k in itertools.product(*per_axis):
                alive |= ~dead[k]
            dom &= alive
        doms[x] = dom
        return dom

    def classes(j: int, i: int) -> list[int]:
        """Label of step j -> its class at step i (axes whose + neighbour is open)."""
        x = cells[j]
        ax = frozenset(
            d for d in range(ndim)
            if x[d] + 1 < ext[d] and index.get((*x[:d], x[d] + 1, *x[d + 1 :]), n) >= i
        )  # fmt: skip
        if ax not in canon:
            canon[ax] = _class_of(fwd, used, ax)
        return canon[ax]

    steps = []
    for i, c in enumerate(cells):
        if keys[i] != sorted(set(keys[i])) or any(not 0 <= j < i for j in keys[i]):
            raise _Invalid(f"{where}: keys[{i}] must be sorted earlier steps")
        if i + 1 < n and not set(keys[i + 1]) <= set(keys[i]) | {i}:
            raise _Invalid(f"{where}: keys[{i + 1}] records a label step {i} forgot")
        box = list(itertools.product(*[
            range(max(0, c[d] - back[d]), min(ext[d] - 1, c[d] + region[d] - 2) + 1)
            for d in range(ndim)
        ]))  # fmt: skip
        labelled = {x for x in box if index.get(x, n) < i}
        nodes = [x for x in box if x not in labelled or index[x] in keys[i]]
        inbox = set(box)
        for x in labelled:
            near = ((*x[:d], x[d] + s, *x[d + 1 :]) for d in range(ndim) for s in (-1, 1))
            if any(y in inbox and y not in labelled for y in near) and index[x] not in keys[i]:
                raise _Invalid(f"{where}: step {i} depends on cell {list(x)}, not in keys[{i}]")
        arcs = [
            [(v, d, plus) for v, d, plus in row if not (x in labelled and nodes[v] in labelled)]
            for x, row in zip(nodes, _arcs(nodes), strict=True)
        ]
        pos = {j: k for k, j in enumerate(keys[i])}
        src = [pos[index[x]] if x in labelled else -1 for x in nodes]
        base = [face_dom(x) for x in nodes]
        nxt = (
            [(-1 if j == i else pos[j], classes(j, i + 1)) for j in keys[i + 1]]
            if i + 1 < n else []
        )  # fmt: skip
        steps.append((src, arcs, nodes.index(c), base, nxt))
    by_step: list[set[tuple[int, ...]]] = [set() for _ in range(n)]
    for i, labs in conf["states"]:
        if not 0 <= i < n or len(labs) != len(keys[i]):
            raise _Invalid(f"{where}: state {[i, labs]} does not fit keys[{i}]")
        if any(not (0 <= b < len(fwd[0]) and used >> b & 1) for b in labs):
            raise _Invalid(f"{where}: state {[i, labs]} has a label not in use")
        by_step[i].add(tuple(labs))
    if () not in by_step[0]:
        raise _Invalid(f"{where}: no start state")
    union: dict[tuple[int, int, int], int] = {}
    for i, (src, arcs, target, base, nxt) in enumerate(steps):
        later = by_step[i + 1] if i + 1 < n else set()
        cats: dict[tuple[int, ...], int] = {}
        for labs in by_step[i]:
            mk = tuple([labs[k] for k in src if k >= 0])
            cat = cats.get(mk)
            if cat is None:
                dom = [b0 if k < 0 else 1 << labs[k] for k, b0 in zip(src, base, strict=True)]
                out = _small_ac(dom, arcs, fwd, bwd, union)
                cat = cats[mk] = 0 if out is None else out[target]
            if i == n - 1:
                if not cat:
                    raise _Invalid(f"{where}: the point's catalog is empty in {[i, list(labs)]}")
                continue
            for b in _bits(cat):
                new = tuple([m[b if k < 0 else labs[k]] for k, m in nxt])
                if new not in later:
                    raise _Invalid(
                        f"{where}: not closed: state {[i, list(labs)]} with label {b} leads to "
                        f"{[i + 1, list(new)]}, which is missing"
                    )
    return sum(len(s) for s in by_step)


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
    known: dict[Where, int] = {}
    for k in itertools.product(span, repeat=ndim):
        on = {_AXES[d] + "-" for d in range(ndim) if k[d][0] == 0}
        on |= {_AXES[d] + "+" for d in range(ndim) if k[d][1] == 0}
        known[k] = used & ~_domain(face_rules, on, used)
    every = [_AXES[d] + s for d in range(ndim) for s in "-+"]
    for face, got in dead["stages"]:
        if face not in every:
            raise _Invalid(f"dead labels: {face!r} is not a face of a {ndim}D grid")
        d, minus = _AXES.index(face[0]), face[1] == "-"
        stage: dict[Where, int] = {}
        for where, labels in got:
            k = tuple((int(a), int(b)) for a, b in where)
            if k not in known or k[d][0 if minus else 1] == 0:
                raise _Invalid(f"dead labels: {list(where)} is not a place off {face}")
            for b in labels:
                if not (isinstance(b, int) and 0 <= b < len(fwd[0]) and used >> b & 1):
                    raise _Invalid(f"dead labels: {b!r} is not a label in use")
                stage[k] = stage.get(k, 0) | 1 << b
        table = bwd[d] if minus else fwd[d]
        for k, bits in stage.items():
            lo, hi = k[d]
            if minus:
                los, his = ([lo - 1] if lo < cap else [cap - 1, cap]), [min(hi + 1, cap)]
            else:
                los, his = [min(lo + 1, cap)], ([hi - 1] if hi < cap else [cap - 1, cap])
            for a, c in itertools.product(los, his):
                n = (*k[:d], (a, c), *k[d + 1 :])
                gone = known[n] | stage.get(n, 0)
                for b in _bits(bits):
                    if table[b] & ~gone:
                        raise _Invalid(
                            f"dead labels: {b} at {[list(t) for t in k]} has a support toward "
                            f"{face} that is not dead: {sorted(_bits(table[b] & ~gone))}"
                        )
        for k, bits in stage.items():
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

    def faces(c: Cell) -> set[str]:
        on = {_AXES[d] + "-" for d in range(ndim) if c[d] == 0}
        return on | {_AXES[d] + "+" for d in range(ndim) if c[d] == shape[d] - 1}

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
    union: dict[tuple[int, int, int], int] = {}
    dom = _small_ac(first, arcs, fwd, bwd, union)
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
        dom = _small_ac(dom, arcs, fwd, bwd, union, start=[k])
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
