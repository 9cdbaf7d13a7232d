"""User-defined constraints of continuous model synthesis in 3D (thesis Sec. 4.6).

Three kinds, read from the constraints file shared with the grid constraints
(``{"constraints": [...]}``; labels by id or by name where the model names them):

``{"type": "dimensional", "labels": [2], "normals": ["z", [1, 1, 0]]}``
    Sec. 4.6.1, Fig. 4.25: objects of these labels never pass through a plane of these
    families, so they are exactly one plane spacing thick along each normal (a road of
    fixed width, a storey of fixed height). Enforced by removing every vertex and edge state
    in which such a label lies on both sides of such a plane: a domain restriction, so
    **every solver enforces it exactly**.
``{"type": "large-scale", "voxel": [4, 4, 4], "allowed": {"2": [[0, 0, 0], [1, 0, 0]]}}``
    Sec. 4.6.3, Fig. 4.26: a coarse grid of voxels (``voxel`` plane spacings each, from the
    region's corner) and, per label, the voxels where it may appear (labels not listed are
    free; empty space always is). A state is removed when one of its sectors lies in a
    voxel where its label is not allowed: a domain restriction, **exact for every solver**.
``{"type": "connected", "labels": [1]}``
    Sec. 4.6.2: the objects of each of these labels form exactly one connected group
    (closures meeting at least at a point; an output without the label breaks it: there is
    no group, like the thesis' single seed grown into a road network). The thesis grows
    objects from a seed; csplab makes it one global constraint on the CSP's problem, the
    grid solvers' :class:`~csplab.constraints.Connected` over the variables that touch the
    label (:meth:`~csplab.continuous.csp3d.ContinuousCSP3.connected`): **exact** in ``sat``,
    ``cpsat`` and ``asp``, propagated by ``catalog``, ``backtrack`` and the other
    propagating solvers, checked (a breach is ``failed``, so ``restarts`` retry) by the rest.

:func:`csplab.continuous.check3d.user_violations3` checks all three on the output solids
alone (the truth, as :func:`~csplab.continuous.check3d.violations3` is for Eq. 4.1): a solid
of a dimensional label spanning more than one plane spacing along the normal; a solid of a
large-scale label meeting a voxel where it is not allowed (volume of the intersection,
manifold3d); the solids of a connected label in more than one group (solids sharing a vertex
are joined).

Examples
--------
>>> c = parse_user_constraints({"constraints": [{"type": "dimensional", "labels": [1],
...     "normals": ["z"]}]}, source="c.json")
>>> c.dimensional
((1, (0, 0, 1)),)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.lattice import primitive3
from csplab.continuous.space import States3
from csplab.errors import InputError

__all__ = [
    "KINDS3",
    "UserConstraints3",
    "parse_user_constraints",
    "read_user_constraints",
]

#: the constraint types of polyhedral models, and what the solvers do with each
KINDS3: dict[str, str] = {
    "dimensional": "exact for every solver (vertex and edge states removed)",
    "large-scale": "exact for every solver (vertex and edge states removed)",
    "connected": "a global constraint (csplab.constraints.Connected): exact in sat, cpsat and "
    "asp, propagated or checked by the others",
}
_AXES = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}


@dataclass(frozen=True)
class UserConstraints3:
    """Parsed constraints (labels are model labels, normals primitive integer vectors)."""

    dimensional: tuple[tuple[int, tuple[int, int, int]], ...] = ()
    voxel: tuple[int, int, int] | None = None
    allowed: tuple[tuple[int, frozenset[tuple[int, int, int]]], ...] = ()
    connected: tuple[int, ...] = ()
    source: str = "<constraints>"

    def __bool__(self) -> bool:
        return bool(self.dimensional or self.allowed or self.connected)

    def merged(self, other: UserConstraints3) -> UserConstraints3:
        """Both sets of constraints (``--constraints`` given twice)."""
        if self.voxel and other.voxel and self.voxel != other.voxel and other.allowed:
            raise InputError(
                f"{other.source}: large-scale voxels {list(other.voxel)} differ from "
                f"{list(self.voxel)} in {self.source}"
            )
        return UserConstraints3(
            self.dimensional + other.dimensional,
            self.voxel or other.voxel,
            self.allowed + other.allowed,
            tuple(dict.fromkeys(self.connected + other.connected)),
            self.source,
        )


def _labels(raw: Any, where: str, names: Mapping[str, int]) -> list[int]:
    if not isinstance(raw, list) or not raw:
        raise InputError(f'{where}: "labels" must be a non-empty list')
    out = []
    for x in raw:
        if isinstance(x, bool):
            raise InputError(f"{where}: label {x!r} is not a label")
        if isinstance(x, int) and x >= 1:
            out.append(int(x))
        elif isinstance(x, str) and x in names:
            out.append(int(names[x]))
        elif isinstance(x, str) and x.isdigit() and int(x) >= 1:
            out.append(int(x))
        else:
            raise InputError(f"{where}: label {x!r} is not an object label (an id >= 1 or a name)")
    return out


def parse_user_constraints(
    data: Any, *, source: str = "<constraints>", names: Mapping[str, int] | None = None
) -> UserConstraints3:
    """Constraints from the parsed JSON ``data`` (see the module docstring); ``names``
    maps label names to ids. Bad entries raise one :class:`InputError` line naming
    ``source`` and the entry."""
    names = dict(names or {})
    if not isinstance(data, Mapping) or not isinstance(data.get("constraints"), list):
        raise InputError(f'{source}: expected {{"constraints": [...]}}')
    dim: list[tuple[int, tuple[int, int, int]]] = []
    voxel: tuple[int, int, int] | None = None
    allowed: list[tuple[int, frozenset[tuple[int, int, int]]]] = []
    conn: list[int] = []
    for i, c in enumerate(data["constraints"]):
        where = f"{source}: constraint {i}"
        if not isinstance(c, Mapping) or "type" not in c:
            raise InputError(f'{where}: expected an object with a "type"')
        kind = c["type"]
        if kind not in KINDS3:
            raise InputError(
                f"{where}: type {kind!r} does not apply to polyhedral models "
                f"(these take {', '.join(KINDS3)})"
            )
        if kind == "dimensional":
            labs = _labels(c.get("labels"), where, names)
            normals = c.get("normals", ["x", "y", "z"])
            if not isinstance(normals, list) or not normals:
                raise InputError(f'{where}: "normals" must be a non-empty list')
            for n in normals:
                if isinstance(n, str) and n in _AXES:
                    vec = _AXES[n]
                elif (isinstance(n, list) and len(n) == 3
                      and all(isinstance(x, int) and not isinstance(x, bool) for x in n)
                      and any(n)):  # fmt: skip
                    vec = primitive3(n)
                else:
                    raise InputError(f"{where}: normal {n!r} is not x, y, z or [a, b, c] integers")
                dim += [(b, vec) for b in labs]
        elif kind == "large-scale":
            v = c.get("voxel")
            if isinstance(v, int) and not isinstance(v, bool):
                v = [v, v, v]
            if (not isinstance(v, list) or len(v) != 3
                    or not all(isinstance(x, int) and not isinstance(x, bool) and x >= 1
                               for x in v)):  # fmt: skip
                raise InputError(f'{where}: "voxel" must be a positive integer or three of them')
            if voxel is not None and tuple(v) != voxel:
                raise InputError(f"{where}: a second large-scale voxel size {v}")
            voxel = (int(v[0]), int(v[1]), int(v[2]))
            al = c.get("allowed")
            if not isinstance(al, Mapping) or not al:
                raise InputError(f'{where}: "allowed" must map labels to voxel lists')
            for lab, cells in al.items():
                (b,) = _labels([lab], where, names)
                if not isinstance(cells, list) or not all(
                    isinstance(x, list) and len(x) == 3
                    and all(isinstance(y, int) and not isinstance(y, bool) for y in x)
                    for x in cells
                ):  # fmt: skip
                    raise InputError(f"{where}: voxels of label {lab} must be [[i, j, k], ...]")
                allowed.append((b, frozenset((int(x), int(y), int(z)) for x, y, z in cells)))
        else:
            conn += _labels(c.get("labels"), where, names)
    return UserConstraints3(tuple(dim), voxel, tuple(allowed), tuple(dict.fromkeys(conn)), source)


def read_user_constraints(
    path: str | Path, names: Mapping[str, int] | None = None
) -> UserConstraints3:
    """:func:`parse_user_constraints` of a JSON file."""
    from csplab.io.common import read_json_file

    p = Path(path)
    data = read_json_file(p)  # the same checks as every JSON reader (size, nesting depth)
    return parse_user_constraints(data, source=str(p), names=names)


# ----------------------------------------------------------------------------- enforcing
def allowed_states(csp: States3, c: UserConstraints3) -> NDArray[np.bool_]:
    """``(n_variables, K)``: the domain of ``csp.problem`` with the dimensional and
    large-scale constraints applied (a state is removed when it breaks one)."""
    A = csp.arrangement
    signs, dirs = A.cells
    index = {b: i for i, b in enumerate(csp.labels)}
    for b, _ in (*c.dimensional, *c.allowed):
        if b not in index:
            raise InputError(f"{c.source}: label {b} does not occur in the example")
    fam_of = {tuple(int(x) for x in n): f for f, n in enumerate(A.normals.tolist())}
    dim: list[tuple[int, int]] = []
    for b, n in c.dimensional:
        if n not in fam_of:
            raise InputError(
                f"{c.source}: the normal {list(n)} is not a plane family of the example "
                f"({', '.join(str(list(x)) for x in A.normals.tolist())})"
            )
        dim.append((index[b], fam_of[n]))
    dom = np.array(csp.problem.domains, dtype=bool, copy=True)
    kinds = (
        (csp.vertex_type, csp.vtypes, csp.var_vertex, A.vertex_positions(), csp.vertex_outside),
        (csp.edge_type, csp.etypes, csp.var_edge, A.edge_positions(), csp.edge_outside),
    )
    # large-scale: per label, a boolean voxel grid
    grids: list[tuple[int, NDArray[np.bool_]]] = []
    if c.allowed and c.voxel is not None:
        shape = tuple(-(-s // v) for s, v in zip(A.size, c.voxel, strict=True))
        for b, cells in c.allowed:
            g = np.zeros(shape, dtype=bool)
            for x, y, z in cells:
                if all(0 <= q < s for q, s in zip((x, y, z), shape, strict=True)):
                    g[x, y, z] = True
            grids.append((index[b], g))
    vox = np.array(c.voxel or (1, 1, 1), dtype=np.float64)
    eps = 1e-3 / (A.D * float(np.abs(A.normals).sum(axis=1).max()))
    for types, tlist, var, pos, outside in kinds:
        for t, (fams, states, gid) in enumerate(tlist):
            sel = np.flatnonzero(types == t)
            if not sel.size or not states:
                continue
            S = np.array(states, dtype=np.int64)  # (n_states, n_groups)
            bad = np.zeros(len(S), dtype=bool)
            for bi, f in dim:
                if f not in set(fams.tolist()):
                    continue
                # only inside the region: past its side (a ground below) is no part of it
                inside = np.asarray(outside[t]) == -1
                plus = np.unique(gid[signs[:, f] > 0])
                minus = np.unique(gid[signs[:, f] < 0])
                plus, minus = plus[inside[plus]], minus[inside[minus]]
                bad |= (S[:, plus] == bi).any(axis=1) & (S[:, minus] == bi).any(axis=1)
            rows = np.ones((len(sel), 1), dtype=bool) & ~bad[None, :]
            if grids:
                ng = S.shape[1]
                rep = np.array([int(np.flatnonzero(gid == k)[0]) for k in range(ng)])
                q = pos[sel][:, None, :] + eps * dirs[rep][None, :, :]  # (n, ng, 3)
                cell = np.floor(q / vox).astype(np.int64)
                inside = ((q > 0) & (q < np.array(A.size))).all(axis=2)
                ok_rows = np.ones((len(sel), len(S)), dtype=bool)
                for bi, g in grids:
                    cl = np.clip(cell, 0, np.array(g.shape) - 1)
                    okv = g[cl[..., 0], cl[..., 1], cl[..., 2]] | ~inside  # (n, ng)
                    has = S == bi  # (n_states, ng)
                    # a state is out when a group with label bi sits in a forbidden voxel
                    forbidden = (~okv).astype(np.int64) @ has.T.astype(np.int64) > 0
                    ok_rows &= ~forbidden
                rows = rows & ok_rows
            k = S.shape[0]
            dom[var[sel], :k] &= rows
    return dom
