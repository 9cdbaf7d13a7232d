"""`RuleSet`: adjacency rules read from a tileset file, ready to become a :class:`Problem`.

A tileset (WaveFunctionCollapse, POMS, DeBroglie, MarkovJunior) does not hold an example
grid but the rules themselves: ``K`` labels (tiles in their orientations) with names and
weights, transition matrices ``T[d, a, b]`` ("``b`` may be the ``+1`` neighbour of ``a``
along axis ``d``", the same meaning as :meth:`ExampleModel.transitions`), optional tile
pictures, a default output size and periodicity, and the domain restrictions the file
states (boundary conditions, tiles removed or forced in regions). :meth:`RuleSet.problem`
turns it into a :class:`~csplab.problem.Problem` of any size.

Domain restrictions are applied in file order with the files' meaning: ``keep`` and
``remove`` intersect the domains, ``force`` sets them (overriding earlier restrictions on
those cells, as POMS does), ``add`` puts labels back. Every restriction becomes one
:class:`~csplab.problem.Unary` of the problem (boundary conditions of kind ``"boundary"``),
so analysis tools can name the one that makes a problem unsatisfiable.

Examples
--------
>>> import numpy as np
>>> T = np.ones((2, 2, 2), dtype=bool); T[:, 1, 1] = False      # no two 1s side by side
>>> rs = RuleSet(T, names=["sea", "isle"], shape=(4, 3),
...              boundary_ops=[DomainOp("force", np.array([True, False]), face="y-")])
>>> P = rs.problem()
>>> P.shape, P.names, [u.key for u in P.unary]
((4, 3), ('sea', 'isle'), ['y-'])
>>> rs.problem((5, 5), boundary="none").unary
()
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import grids
from csplab.errors import InputError
from csplab.grids import parse_shape
from csplab.problem import AXIS_NAMES, Problem, Unary

if TYPE_CHECKING:
    from PIL import Image

    from csplab.io.symmetry import Group

__all__ = ["DomainOp", "RuleSet"]

OpKind = Literal["keep", "remove", "force", "add"]


@dataclass(frozen=True, eq=False)
class DomainOp:
    """One domain restriction a rule-set file states, applied when a problem is built.

    Parameters
    ----------
    op : {"keep", "remove", "force", "add"}
        ``keep``: only ``labels`` stay allowed; ``remove``: ``labels`` are removed;
        ``force``: the domain becomes ``labels`` (overriding earlier restrictions);
        ``add``: ``labels`` become allowed again.
    labels : bool array ``(K,)``
    face : str, optional
        ``"x-"``, ``"y+"``, ...: the outer layer of cells on that face.
    region : sequence of ``(start, stop)`` per axis, optional
        A box of cells; ``None`` is open, negative numbers count from the end. Missing
        axes (and ``region=None`` without ``face``) mean the whole axis.
    flip : sequence of bool, optional
        Axes along which ``region`` counts from the other end (files whose ``y`` points
        down, as in images).
    kind : {"boundary", "domain", "fixed"}
        The kind of the :class:`~csplab.problem.Unary` it becomes.
    key : str
        Names it in reports (default: the face or ``op``).
    """

    op: OpKind
    labels: NDArray[np.bool_]
    face: str | None = None
    region: Sequence[tuple[int | None, int | None]] | None = None
    flip: Sequence[bool] = ()
    kind: Literal["boundary", "domain", "fixed"] = "domain"
    key: str = ""

    def cells(self, shape: tuple[int, ...]) -> NDArray[np.int64]:
        """Flat indices of the cells it applies to in a grid of ``shape``."""
        idx = np.arange(math.prod(shape), dtype=np.int64).reshape(shape)
        for d, f in enumerate(self.flip[: len(shape)]):
            if f:
                idx = np.flip(idx, axis=d)
        sl: list[slice | int] = [slice(None)] * len(shape)
        if self.face is not None:
            d = AXIS_NAMES.index(self.face[0])
            if d >= len(shape):
                return np.zeros(0, dtype=np.int64)
            sl[d] = 0 if self.face[1] == "-" else shape[d] - 1
        elif self.region is not None:
            for d, (a, b) in enumerate(self.region[: len(shape)]):
                sl[d] = slice(a, b)
        return idx[tuple(sl)].ravel()


def _face_ok(face: str, ndim: int) -> bool:
    return len(face) == 2 and face[0] in AXIS_NAMES[:ndim] and face[1] in "-+"


class RuleSet:
    """Labels, adjacency rules and pictures read from a tileset file.

    Parameters
    ----------
    relations : bool array ``(ndim, K, K)``
        ``relations[d, a, b]``: ``b`` may be the ``+1`` neighbour of ``a`` along axis ``d``.
    names, weights : optional
        One name / non-negative weight per label (default ``"0", "1", ...`` and ones).
    name : str
    shape : tuple of int, optional
        The file's output size (used when :meth:`problem` gets no shape).
    periodic : bool or sequence of bool
        The file's periodicity.
    boundary_ops, constraint_ops : sequence of DomainOp
        Boundary conditions (dropped by ``boundary="none"``) and other restrictions (always
        applied).
    constraints : sequence of mapping
        Global constraints the file states, as entries of csplab's constraints file
        (:mod:`csplab.constraints`), added to every problem built (for its size).
    images : uint8 array ``(K, h, w, 4)``, optional
        One RGBA picture per label, rows top to bottom as in an image file.
    colors : uint8 array ``(K, 3)``, optional
        One colour per label for pictures without tile images.
    empty : int, optional
        The empty-space label, left out of 3D pictures and exports.
    voxels : uint8 array ``(K, s, s, s)``, optional
        3D tile pictures: colour indices into ``voxel_palette`` (0 = empty), composited by
        :meth:`render` and :meth:`expand_voxels`.
    voxel_palette : uint8 array ``(256, 3)``, optional
    symmetry : (Group, perm), optional
        The symmetry group and its action on the labels, ``perm[g, label]`` (for
        :meth:`closure_violations`).
    meta : mapping
        Provenance: ``format``, ``source``, ``warnings`` and format-specific data.
    topology : str, optional
        The grid (:mod:`csplab.topology`, e.g. ``hex:odd-r``); ``relations`` then hold one
        matrix per relation of that grid (default: square, one per axis).
    """

    def __init__(
        self,
        relations: ArrayLike,
        *,
        names: Sequence[str] | None = None,
        weights: ArrayLike | None = None,
        name: str = "",
        shape: Sequence[int] | None = None,
        periodic: bool | Sequence[bool] = False,
        boundary_ops: Sequence[DomainOp] = (),
        constraint_ops: Sequence[DomainOp] = (),
        constraints: Sequence[Mapping[str, Any]] = (),
        images: ArrayLike | None = None,
        colors: ArrayLike | None = None,
        empty: int | None = None,
        voxels: ArrayLike | None = None,
        voxel_palette: ArrayLike | None = None,
        symmetry: tuple[Group, NDArray[np.int64]] | None = None,
        meta: Mapping[str, Any] | None = None,
        topology: str | None = None,
    ) -> None:
        from csplab.topology import Topology

        topo = Topology.parse(topology)
        self.topology = topo.name
        T = np.array(relations, dtype=bool)
        self._ndim = int(T.shape[0]) if T.ndim == 3 else 0
        if not topo.square:  # one matrix per relation of the grid (csplab.topology)
            self._ndim = len(shape) if shape is not None else 2
            want = len(topo.relation_names(self._ndim))
            if T.ndim != 3 or T.shape[0] != want:
                raise InputError(f"a {topo.name} rule set needs {want} relations")
        if T.ndim != 3 or T.shape[1] != T.shape[2] or not 1 <= T.shape[0] <= 4 or T.shape[1] < 1:
            raise InputError(f"relations must have shape (ndim, K, K), got {T.shape}")
        T.setflags(write=False)
        self.relations: NDArray[np.bool_] = T
        K = self.K
        self.names: tuple[str, ...] = (
            tuple(str(s) for s in names) if names is not None else tuple(map(str, range(K)))
        )
        if len(self.names) != K:
            raise InputError(f"{len(self.names)} names for {K} labels")
        w = np.ones(K) if weights is None else np.array(weights, dtype=np.float64).reshape(-1)
        if w.shape != (K,) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InputError(f"weights must be {K} finite non-negative numbers")
        w.setflags(write=False)
        self.weights: NDArray[np.float64] = w
        self.name = name
        self.shape: tuple[int, ...] | None = None if shape is None else tuple(map(int, shape))
        if self.shape is not None and len(self.shape) != self.ndim:
            raise InputError(f"default shape {self.shape} does not have {self.ndim} axes")
        self.periodic = periodic
        for op in (*boundary_ops, *constraint_ops):
            if op.labels.shape != (K,):
                raise InputError(f"restriction {op.key or op.op} needs {K} label flags")
            if op.face is not None and not _face_ok(op.face, self.ndim):
                raise InputError(f"unknown face {op.face!r}")
        self.boundary_ops: tuple[DomainOp, ...] = tuple(boundary_ops)
        self.constraint_ops: tuple[DomainOp, ...] = tuple(constraint_ops)
        self.constraints: tuple[Mapping[str, Any], ...] = tuple(constraints)
        self.images: NDArray[np.uint8] | None = None
        if images is not None:
            im = np.asarray(images, dtype=np.uint8)
            if im.ndim != 4 or im.shape[0] != K or im.shape[3] != 4:
                raise InputError(f"images must have shape ({K}, h, w, 4), got {im.shape}")
            self.images = im
        self.colors: NDArray[np.uint8] | None = None
        if colors is not None:
            c = np.asarray(colors, dtype=np.uint8)
            if c.shape != (K, 3):
                raise InputError(f"colors must have shape ({K}, 3), got {c.shape}")
            self.colors = c
        if empty is not None and not 0 <= empty < K:
            raise InputError(f"empty label {empty} is outside 0..{K - 1}")
        self.empty = empty
        self.voxels: NDArray[np.uint8] | None = None
        self.voxel_palette: NDArray[np.uint8] | None = None
        if voxels is not None:
            vx = np.asarray(voxels, dtype=np.uint8)
            if vx.ndim != 4 or vx.shape[0] != K:
                raise InputError(f"voxels must have shape ({K}, s, s, s), got {vx.shape}")
            pal = np.asarray(voxel_palette if voxel_palette is not None else _gray(), np.uint8)
            if pal.shape != (256, 3):
                raise InputError(f"voxel_palette must have shape (256, 3), got {pal.shape}")
            self.voxels, self.voxel_palette = vx, pal
        self.symmetry = symmetry
        self.meta: dict[str, Any] = dict(meta or {})
        self.meta.setdefault("warnings", [])

    # ------------------------------------------------------------------ basics
    def hash(self) -> str:
        """A stable content hash (relations, names, weights, size, periodicity, the file's
        restrictions and constraints) for result stores, like :meth:`ExampleModel.hash`."""
        import hashlib
        import json

        h = hashlib.sha256()
        h.update(str((self.relations.shape, self.shape, self.periodic)).encode())
        h.update(np.packbits(self.relations).tobytes())
        h.update("\0".join(self.names).encode())
        h.update(self.weights.tobytes())
        for op in (*self.boundary_ops, *self.constraint_ops):
            h.update(str((op.op, op.face, op.region, tuple(op.flip), op.kind)).encode())
            h.update(np.packbits(op.labels).tobytes())
        h.update(json.dumps(list(self.constraints), sort_keys=True, default=str).encode())
        return h.hexdigest()[:16]

    def background(self) -> list[int]:
        """Labels that count as 'nothing built': the file's empty label, else the labels its
        boundary conditions force on every face, else labels named ``empty ...``, else 0."""
        if self.empty is not None:
            return [self.empty]
        forced = [op.labels for op in self.boundary_ops if op.op == "force"]
        if forced:
            common = np.logical_and.reduce(forced)
            if common.any():
                return np.flatnonzero(common).tolist()
        named = [b for b, nm in enumerate(self.names) if nm.split(" ")[0].lower() == "empty"]
        return named or [0]

    @property
    def K(self) -> int:
        """Number of labels."""
        return int(self.relations.shape[1])

    @property
    def ndim(self) -> int:
        return self._ndim

    @property
    def warnings(self) -> list[str]:
        """Things the loader could not represent exactly (unsupported constraints ...)."""
        w: list[str] = self.meta["warnings"]
        return w

    def transitions(self) -> NDArray[np.bool_]:
        """``T[d, a, b]``, as :meth:`ExampleModel.transitions`."""
        return self.relations

    def label_name(self, b: int) -> str:
        return self.names[b] if 0 <= b < self.K else str(b)

    def __repr__(self) -> str:
        nm = f"{self.name!r}, " if self.name else ""
        fmt = self.meta.get("format", "?")
        return f"RuleSet({nm}format={fmt}, ndim={self.ndim}, K={self.K}, shape={self.shape})"

    def closure_violations(self, limit: int = 100) -> list[str]:
        """Rules whose image under the tileset's symmetry group is missing (empty when the
        rule set is closed under the group, or when the file has no symmetry group)."""
        if self.symmetry is None:
            return []
        from csplab.io.symmetry import closure_violations

        G, perm = self.symmetry
        out = []
        for axis, a, b, g in closure_violations(G, perm, self.relations, limit):
            out.append(
                f"{self.names[a]!r} then {self.names[b]!r} along +{AXIS_NAMES[axis]}: "
                f"its image under {G.name(g)!r} is missing"
            )
        return out

    # ------------------------------------------------------------------ problems
    def problem(
        self,
        shape: Sequence[int] | str | None = None,
        *,
        periodic: bool | Sequence[bool] | None = None,
        boundary: Mapping[str, int] | Literal["auto", "none"] | None = "auto",
        fixed: ArrayLike | Mapping[Sequence[int], int] | None = None,
        mask: ArrayLike | None = None,
    ) -> Problem:
        """The synthesis problem on a grid of ``shape`` (default: the file's size).

        Parameters
        ----------
        shape : sequence of int or str, optional
        periodic : bool or sequence of bool, optional
            Default: the file's setting. Boundary conditions of the file are not applied
            on periodic axes (there is no outside).
        boundary : "auto" (default), "none", None or mapping face -> label
            ``"auto"``: the file's boundary conditions; ``"none"`` or ``None``: none (as in
            :func:`~csplab.grids.from_example`, where ``None`` also means none); a mapping puts
            one label on each named face. The file's other restrictions are always applied.
        fixed, mask :
            As in :func:`~csplab.grids.grid`.
        """
        if shape is None:
            if self.shape is None:
                raise InputError(f"{self.name or 'this rule set'} has no default size: give one")
            shp = self.shape
        else:
            shp = parse_shape(shape) if isinstance(shape, str) else tuple(int(s) for s in shape)
        if len(shp) != self.ndim:
            if len(shp) > self.ndim and all(s == 1 for s in shp[self.ndim :]):
                shp = shp[: self.ndim]
            else:
                raise InputError(
                    f"size {'x'.join(map(str, shp))} has {len(shp)} axes; "
                    f"{self.name or 'the rule set'} is {self.ndim}-D"
                )
        parse_shape(shp)
        per = self.periodic if periodic is None else periodic
        per_t = (bool(per),) * self.ndim if isinstance(per, bool | np.bool_) else tuple(per)
        if len(per_t) != self.ndim:
            raise InputError(f"periodic needs {self.ndim} flags")
        mapping = None
        if isinstance(boundary, Mapping):
            mapping = dict(boundary)
            ops = list(self.constraint_ops)
        elif boundary == "auto":
            ops = [
                op
                for op in self.boundary_ops
                if op.face is None or not per_t[AXIS_NAMES.index(op.face[0])]
            ] + list(self.constraint_ops)
        elif boundary in (None, "none"):
            ops = list(self.constraint_ops)
        else:
            raise InputError(
                f"boundary must be None, 'auto', 'none' or a mapping, not {boundary!r}"
            )
        meta = {
            "format": self.meta.get("format"),
            "source": self.meta.get("source"),
            "rule_set": self.name,
            "model": self,  # lets Result._repr_png_ draw the tiles
        }
        P = grids.grid(
            shp,
            self.relations,
            topology=self.topology,
            periodic=per_t,
            fixed=fixed,
            boundary=mapping,
            mask=mask,
            weights=self.weights,
            names=self.names,
            name=self.name,
            meta=meta,
        )
        unary = self._unaries(ops, shp)
        if unary:
            P = P.with_unary(unary)
        if self.constraints:
            from csplab.constraints import parse_constraints

            P = P.with_constraints(
                parse_constraints(list(self.constraints), P, self.meta.get("source") or self.name)
            )
        return P

    def _unaries(self, ops: Sequence[DomainOp], shp: tuple[int, ...]) -> list[Unary]:
        """File-order semantics of ``ops`` as one Unary each (later ``force``/``add``
        ops edit the earlier ones on their cells, so their intersection is exact)."""
        items: list[list[Any]] = []  # [kind, key, cells, allowed]
        for i, op in enumerate(ops):
            cells = op.cells(shp)
            if cells.size == 0:
                continue
            key = op.key or op.face or f"{op.op}[{i}]"
            if op.op in ("force", "add"):
                for it in items:
                    hit = np.isin(it[2], cells)
                    if op.op == "force":
                        it[2], it[3] = it[2][~hit], it[3][~hit]
                    else:
                        it[3][hit] |= op.labels
            if op.op == "add":
                continue
            allowed = op.labels if op.op in ("keep", "force") else ~op.labels
            items.append([op.kind, key, cells, np.tile(allowed, (cells.size, 1))])
        out = []
        for kind, key, cells, allowed in items:
            keep = ~allowed.all(axis=1)
            if keep.any():
                out.append(Unary(kind, key, cells[keep].copy(), allowed[keep].copy()))
        return out

    # ------------------------------------------------------------------ pictures
    def label_colors(self) -> NDArray[np.uint8]:
        """One RGB colour per label (the file's, else the mean tile colour, else csplab's
        palette, one colour per tile: orientations share it)."""
        from csplab.render import label_objects, object_colors

        if self.colors is not None:
            return self.colors
        if self.images is not None:
            im = self.images.astype(np.float64)
            a = im[..., 3:4] / 255.0
            tot = np.maximum(a.sum(axis=(1, 2)), 1e-9)
            mean = np.clip((im[..., :3] * a).sum(axis=(1, 2)) / tot, 0, 255)
            return np.asarray(mean, dtype=np.uint8)
        return object_colors(label_objects(self.K, names=self.names))

    def expand_voxels(self, grid: ArrayLike) -> NDArray[np.uint8]:
        """A 3D label grid with every cell replaced by its tile's voxels (colour indices,
        0 = empty; unassigned cells are empty)."""
        if self.voxels is None:
            raise InputError(f"{self.name or 'this rule set'} has no voxel tiles")
        g = np.asarray(grid, dtype=np.int64)
        if g.ndim != 3:
            raise InputError(f"voxel tiles need a 3D grid, got shape {g.shape}")
        ext = np.concatenate([self.voxels, np.zeros((1, *self.voxels.shape[1:]), np.uint8)])
        v = ext[np.where((g >= 0) & (g < self.K), g, self.K)]  # (nx, ny, nz, sx, sy, sz)
        nx, ny, nz, sx, sy, sz = v.shape
        return np.ascontiguousarray(
            v.transpose(0, 3, 1, 4, 2, 5).reshape(nx * sx, ny * sy, nz * sz)
        )

    def render(
        self, grid: ArrayLike, *, scale: int | None = None, periodic: bool | None = None
    ) -> Image.Image:
        """A picture of a label grid: tile images composited in 2D when the file has them,
        else one colour per label (3D: isometric, the empty label left out). ``periodic``
        is used by models whose pictures depend on it (the overlapping model)."""
        from csplab.render import render

        g = np.asarray(grid)
        if self.topology != "square" and g.ndim == 2:
            return render(g, K=self.K, colors=self.label_colors(), scale=scale,
                          topology=self.topology)  # fmt: skip
        if self.images is not None and g.ndim == 2:
            return render(g, tiles=self.images, scale=scale)
        if self.voxels is not None and g.ndim == 3 and g.size * self.voxels[0].size <= 2_000_000:
            assert self.voxel_palette is not None
            return render(
                self.expand_voxels(g), K=256, colors=self.voxel_palette, empty=0, scale=scale
            )
        return render(g, K=self.K, colors=self.label_colors(), empty=self.empty, scale=scale)

    def sheet(self, columns: int | None = None) -> Image.Image:
        """All labels side by side with their names (what ``csplab show`` draws)."""
        from PIL import Image as PILImage
        from PIL import ImageDraw

        K = self.K
        cols = columns or max(1, min(K, 8))
        rows = -(-K // cols)
        if self.images is not None:
            tiles = self.images
        else:
            c = self.label_colors()
            tiles = np.concatenate(
                [np.repeat(np.repeat(c[:, None, None, :], 16, 1), 16, 2),
                 np.full((K, 16, 16, 1), 255, np.uint8)], axis=3)  # fmt: skip
        h, w = tiles.shape[1:3]
        s = max(1, 48 // max(h, w))
        cw, ch = max(w * s, 90) + 8, h * s + 22
        img = PILImage.new("RGB", (cols * cw, rows * ch), (255, 255, 255))
        draw = ImageDraw.Draw(img)
        for b in range(K):
            x0, y0 = (b % cols) * cw + 4, (b // cols) * ch + 4
            t = PILImage.fromarray(np.repeat(np.repeat(tiles[b], s, 0), s, 1), "RGBA")
            img.paste(t, (x0, y0), t)
            draw.rectangle((x0 - 1, y0 - 1, x0 + w * s, y0 + h * s), outline=(160, 160, 160))
            draw.text((x0, y0 + h * s + 2), self.names[b][:16], fill=(0, 0, 0))
        return img

    def _repr_png_(self) -> bytes:
        buf = io.BytesIO()
        self.sheet().save(buf, format="PNG")
        return buf.getvalue()


def _gray() -> NDArray[np.uint8]:
    from csplab.render import palette

    p = palette(256)
    p[0] = 0
    return p
