"""The Starlette application of ``csplab serve``: the page, its JSON API and the files.

Routes (every ``/api`` answer is JSON; an error is ``{"error": "one line"}`` with status
400, 403, 404 or 413, never a stack trace):

* ``GET /`` the page; ``/static/...`` its scripts and the vendored three.js;
* ``GET /api/meta``: built-in examples, model files under the served directory, the
  solvers' declarations (the form is built from them), the output formats, the limits;
* ``POST /api/world``: open an endless world; ``GET /api/world/ID/chunk/I/J.png`` a chunk
  drawn with the label colours (or the tileset's pictures); ``POST .../edit``,
  ``POST .../undo``; ``GET .../download?region=X0:X1,Y0:Y1&format=.png`` any output
  format; ``GET .../model.glb?region=...`` a 3D world's region for the viewer;
* ``POST /api/run``: ``synthesize``, ``world`` (a region, e.g. of a 3D world for the viewer),
  ``prove`` or ``witness`` as the command line runs them;
  ``GET /api/run/ID/events`` its progress (server-sent events), ``GET /api/run/ID`` its
  result, ``.../result.png``, ``.../result.glb``, ``.../download?format=`` and
  ``.../replay`` (a witness step by step, the catalog emptying).
"""

from __future__ import annotations

import asyncio
import itertools
import json
import math
import re
import tempfile
import threading
from collections.abc import AsyncIterator, Awaitable, Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import CsplabError, InputError
from csplab.web.jobs import Jobs
from csplab.web.safety import Limits, Refused, cross_site, inside
from csplab.web.worlds import BRUSHES, WorldSession

if TYPE_CHECKING:  # Starlette is the web extra: imported when an app is made
    from starlette.applications import Starlette
    from starlette.requests import Request
    from starlette.responses import JSONResponse, Response

__all__ = ["STATIC", "create_app"]

STATIC = Path(__file__).parent / "static"
_MODEL_SUFFIXES = (".grid", ".txt", ".xml", ".json", ".vox", ".png", ".tmx", ".obj", ".off",
                   ".stl", ".svg")  # fmt: skip
_NAME = re.compile(r"^[A-Za-z0-9_.\-/ ]{1,200}$")


def _error(status: int, message: str) -> JSONResponse:
    from starlette.responses import JSONResponse

    return JSONResponse({"error": message}, status_code=status)


def _hex(colors: NDArray[np.uint8]) -> list[str]:
    return ["#" + "".join(f"{int(v):02x}" for v in c) for c in colors]


def label_colors(model: Any, K: int) -> NDArray[np.uint8]:
    """The colour of each label on the page: the model's own, else csplab's palette (one
    distinct colour per label, so the map tells every label apart)."""
    from csplab.render import palette

    own = getattr(model, "label_colors", None)
    if callable(own):
        return np.asarray(own(), dtype=np.uint8).reshape(-1, 3)[:K]
    if hasattr(model, "meta") and model.meta.get("colors") is not None:
        return np.asarray(model.meta["colors"], dtype=np.uint8).reshape(-1, 3)[:K]
    return palette(K)


class _State:
    def __init__(self, root: Path, limits: Limits) -> None:
        self.root = root.resolve()
        self.limits = limits
        self.worlds: dict[str, WorldSession] = {}
        self.colors: dict[str, NDArray[np.uint8]] = {}
        self.jobs = Jobs(limits.jobs)
        self.lock = threading.Lock()
        self.n = 0

    def model_spec(self, name: Any) -> str:
        """A built-in example name, or the path of a model file under the root."""
        from csplab.examples import ALIASES, example_info

        if not isinstance(name, str) or not _NAME.match(name):
            raise InputError(f"model must be a built-in example or a file name, not {name!r}")
        if name in ALIASES or name in {n for n, _ in example_info()}:
            return name
        p = inside(self.root, name)
        if not p.is_file():
            raise InputError(f"{name}: no such model file in the served directory")
        return str(p)


def _int(body: dict[str, Any], key: str, default: int | None = None, lo: int | None = None,
         hi: int | None = None) -> int:  # fmt: skip
    v = body.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int):
        raise InputError(f"{key} must be an integer, not {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(f"{key} must be in {lo}..{hi}, not {v}")
    return v


def _shape(text: Any, what: str, limit: int) -> tuple[int, ...]:
    from csplab.grids import parse_shape

    if not isinstance(text, str):
        raise InputError(f"{what} must be a size such as 16x16, not {text!r}")
    s = parse_shape(text, what=what)
    if math.prod(s) > limit:
        raise InputError(f"{what} {text} has {math.prod(s)} cells, more than the limit {limit}")
    return tuple(s)


def _region(req: Request, limit: int) -> tuple[tuple[int, int], tuple[int, int]]:
    from csplab.cli.world import parse_region

    xs, ys = parse_region(req.query_params.get("region", ""))
    n = (xs[1] - xs[0]) * (ys[1] - ys[0])
    if n > limit:
        raise InputError(f"region of {n} cells is more than the limit {limit}")
    return xs, ys


def _download(grid: NDArray[np.int32], model: Any, fmt: str, name: str) -> Response:
    from starlette.responses import Response

    from csplab.io import write_labels
    from csplab.io.registry import output_extensions

    if fmt not in output_extensions():
        raise InputError(f"format must be one of {', '.join(output_extensions())}, not {fmt!r}")
    with tempfile.TemporaryDirectory(prefix="csplab-dl-") as d:
        p = Path(d) / f"{name}{fmt}"
        write_labels(grid, p, model=model, periodic=False)
        data = p.read_bytes()
    head = {"content-disposition": f'attachment; filename="{name}{fmt}"'}
    return Response(data, media_type="application/octet-stream", headers=head)


def create_app(
    root: str | Path = ".", limits: Limits | None = None, *, start_model: str | None = None
) -> Starlette:
    """The application serving ``root`` (only files under it are read).

    Parameters
    ----------
    root : str or Path
        The served directory.
    limits : Limits, optional
        Request, output and run-time limits (default :class:`~csplab.web.safety.Limits`).
    start_model : str, optional
        The model the page selects first (a built-in name or a file under ``root``).

    Raises
    ------
    InputError
        When ``start_model`` is neither.
    DependencyError
        When Starlette (the ``web`` extra) is not installed.

    Returns
    -------
    Starlette
        The ASGI application (``uvicorn.run(app)``, or Starlette's ``TestClient``).

    Examples
    --------
    >>> from starlette.testclient import TestClient
    >>> c = TestClient(create_app("."))
    >>> c.get("/api/meta").status_code
    200
    >>> c.get("/api/world/nope/chunk/0/0.png").json()
    {'error': 'no world nope (open one first)'}
    """
    from csplab.deps import require

    require("starlette", "web", "csplab serve")
    from starlette.applications import Starlette
    from starlette.exceptions import HTTPException
    from starlette.responses import FileResponse, JSONResponse, Response, StreamingResponse
    from starlette.routing import Mount, Route
    from starlette.staticfiles import StaticFiles

    st = _State(Path(root), limits or Limits())
    if start_model is not None:  # a bad name fails now, in one line, not on the page
        spec = st.model_spec(start_model)
        if Path(spec).is_absolute():
            start_model = str(Path(spec).relative_to(st.root))
    L = st.limits

    def world_of(req: Request) -> WorldSession:
        wid = req.path_params["wid"]
        w = st.worlds.get(wid)
        if w is None:
            raise HTTPException(404, f"no world {wid} (open one first)")
        return w

    async def body_of(req: Request) -> dict[str, Any]:
        why = cross_site({k.lower(): v for k, v in req.headers.items()},
                         req.headers.get("host", ""))  # fmt: skip
        if why:
            raise Refused(why)
        raw = b""
        async for part in req.stream():
            raw += part
            if len(raw) > L.body_bytes:
                raise HTTPException(413, f"request body over {L.body_bytes} bytes")
        try:
            data = json.loads(raw or b"{}")
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError("the request body is not JSON") from None
        if not isinstance(data, dict):
            raise InputError("the request body must be a JSON object")
        return data

    async def page(req: Request) -> Response:
        return FileResponse(STATIC / "index.html")

    async def meta(req: Request) -> Response:
        from csplab.examples import example_info
        from csplab.io.registry import output_extensions
        from csplab.solvers import available_solvers

        files: list[str] = []
        for p in sorted(itertools.islice(st.root.rglob("*"), 5000)):  # a huge folder: bounded
            if len(files) >= 200:
                break
            if p.suffix.lower() in _MODEL_SUFFIXES and p.is_file():
                try:
                    rel = str(inside(st.root, str(p.relative_to(st.root))).relative_to(st.root))
                except (Refused, ValueError):
                    continue  # a symlink out of the served directory
                if not any(part.startswith(".") for part in Path(rel).parts):
                    files.append(rel)
        return JSONResponse({
            "examples": [{"name": n, "description": d} for n, d in example_info()],
            "files": files,
            "solvers": json.loads(json.dumps(available_solvers(), default=str)),
            "formats": output_extensions(),
            "brushes": list(BRUSHES), "start": start_model,
            "limits": {"cells": L.cells, "edit_cells": L.edit_cells, "seconds": L.seconds,
                       "body_bytes": L.body_bytes},
        })  # fmt: skip

    # -- worlds -------------------------------------------------------------------------
    async def world_new(req: Request) -> Response:
        from csplab.solvers import solver_class

        body = await body_of(req)
        spec = st.model_spec(body.get("model"))
        chunk = _shape(body.get("chunk", "16x16"), "chunk", 64 * 64 * 16)
        alg31 = solver_class("catalog")  # a world's blocks run Alg. 3.1: its declared options
        opts = {}
        for key in ("order", "choice"):
            v = body.get(key)
            o = alg31.option(key)
            if v not in (None, "") and o is not None:
                opts[key] = o.check(str(v), "catalog")
            if opts.get(key) == "auto":  # the catalog solver's, by its problem's constraints
                raise InputError("a world's order is one of the Alg. 3.1 orders, not auto")
        seed = _int(body, "seed", 0, 0, 2**62)

        def build() -> WorldSession:
            return WorldSession(spec, seed=seed, chunk=chunk, margin=6, **opts)

        w = await asyncio.to_thread(build)
        with st.lock:
            st.n += 1
            wid = f"w{st.n}"
            st.worlds[wid] = w
            while len(st.worlds) > 8:
                st.worlds.pop(next(iter(st.worlds)))
        K = w.world.K
        cols = label_colors(w.model, K)
        st.colors[wid] = cols
        return JSONResponse({
            "id": wid, "chunk": list(w.world.chunk_shape), "ndim": w.world.ndim, "K": K,
            "names": [w.model.label_name(b) if hasattr(w.model, "label_name") else str(b)
                      for b in range(K)],
            "colors": _hex(cols), "empty": w.empty, "scale": 8, "seed": seed,
            "tiles": hasattr(w.model, "render"), "order": w.world.order,
            "choice": w.world.choice, "dropped": w.world.dropped,
        })  # fmt: skip

    async def chunk_png(req: Request) -> Response:
        from csplab.render import render

        w = world_of(req)
        try:
            i, j = int(req.path_params["i"]), int(req.path_params["j"])
        except ValueError:
            raise InputError("chunk coordinates must be integers") from None
        if w.world.ndim != 2:
            raise InputError("a 3D world has no map: open its region in the 3D viewer")
        g = await asyncio.to_thread(w.chunk, i, j)
        if hasattr(w.model, "render"):
            img = w.model.render(g, periodic=False)
        else:
            img = render(g, K=w.world.K, colors=st.colors[req.path_params["wid"]], scale=8)
        buf = __import__("io").BytesIO()
        img.save(buf, format="PNG")
        return Response(buf.getvalue(), media_type="image/png",
                        headers={"cache-control": "no-store"})  # fmt: skip

    async def edit(req: Request) -> Response:
        w = world_of(req)
        body = await body_of(req)
        x0, x1 = _int(body, "x0"), _int(body, "x1")
        y0, y1 = _int(body, "y0"), _int(body, "y1")
        brush = body.get("brush")
        label = body.get("label")
        if brush not in BRUSHES:
            raise InputError(f"brush must be one of {', '.join(BRUSHES)}, not {brush!r}")
        lab = _int(body, "label", None, 0, w.world.K - 1) if brush == "label" else None
        del label
        cells = body.get("cells")  # a freehand stroke; default the whole rectangle
        if cells is not None:
            if not isinstance(cells, list) or not 0 < len(cells) <= L.edit_cells or not all(
                isinstance(c, list) and len(c) == 2 and all(type(v) is int for v in c)
                for c in cells
            ):
                raise InputError(f"cells must be 1..{L.edit_cells} [x, y] integer pairs")
            cells = [(int(x), int(y)) for x, y in cells]
        out = await asyncio.to_thread(
            w.edit, str(brush), (x0, x1), (y0, y1), label=lab, cells=cells,
            limit=L.edit_cells, time_limit=min(30.0, L.seconds),
        )  # fmt: skip
        out["edits"] = len(w.patches)
        return JSONResponse(json.loads(json.dumps(out)))

    async def undo(req: Request) -> Response:
        w = world_of(req)
        await body_of(req)
        touched = w.undo()
        return JSONResponse({"touched": touched, "edits": len(w.patches)})

    async def world_download(req: Request) -> Response:
        w = world_of(req)
        xs, ys = _region(req, L.cells)
        g = await asyncio.to_thread(w.region, xs, ys)
        fmt = req.query_params.get("format", ".png")
        return await asyncio.to_thread(_download, g, w.model, fmt, "world")

    async def world_glb(req: Request) -> Response:
        from csplab.web.glb import grid_glb

        w = world_of(req)
        xs, ys = _region(req, L.cells)
        g = await asyncio.to_thread(w.region, xs, ys)
        data = await asyncio.to_thread(grid_glb, g, w.model)
        return Response(data, media_type="model/gltf-binary")

    # -- runs ---------------------------------------------------------------------------
    async def run_new(req: Request) -> Response:
        from csplab.cli.common import load_model
        from csplab.solvers import solver_class, solver_names

        body = await body_of(req)
        command = body.get("command", "synthesize")
        spec = st.model_spec(body.get("model"))
        seconds = float(min(L.seconds, max(1, _int(body, "time_limit", 30, 1, 3600))))
        seed = _int(body, "seed", 0, 0, 2**62)
        model = await asyncio.to_thread(load_model, spec)
        kind = type(model).__name__
        info: dict[str, Any] = {"model": body.get("model"), "kind": kind}
        if command == "synthesize":
            size = _shape(body.get("size", "16x16"), "size", L.cells)
            solver = body.get("solver", "catalog")
            if solver not in solver_names():
                raise InputError(f"solver must be one of {', '.join(solver_names())}")
            argv = ["synthesize", spec, "--size", "x".join(map(str, size)), "--solver",
                    str(solver), "--seed", str(seed), "--time-limit", str(seconds),
                    "--json"]  # fmt: skip
            cls = solver_class(str(solver))
            options = body.get("options") or {}
            if not isinstance(options, dict):
                raise InputError("options must be an object of solver options")
            for k, v in options.items():
                if cls.option(str(k)) is None or k in ("progress", "time_limit"):
                    raise InputError(f"solver {solver} has no option {k!r}")
                if v not in (None, ""):
                    argv += ["--option", f"{k}={v}"]
            cons = body.get("constraints")
            if cons:
                argv += ["--constraints", str(inside(st.root, str(cons)))]
                info["constraints"] = cons
            boundary = body.get("boundary", "auto" if len(size) == 3 else None)
            if boundary not in (None, "", "auto", "none"):
                raise InputError("boundary must be auto or none")
            if boundary:
                argv += ["--boundary", str(boundary)]
            out = {"PolyhedralModel": "result.obj", "PolygonModel": "result.json"}.get(
                kind, "result.npy")
            argv += ["--out", "{OUT}/" + out]
            info.update(size=list(size), out=out, solver=solver)
        elif command == "world":  # a region of an endless world, as `csplab world` makes it
            chunk = _shape(body.get("chunk", "16x16x10"), "chunk", L.cells)
            region = body.get("region", f"0:{2 * chunk[0]},0:{2 * chunk[1]}")
            from csplab.cli.world import parse_region

            xs, ys = parse_region(str(region))
            n = (xs[1] - xs[0]) * (ys[1] - ys[0]) * math.prod(chunk[2:])
            if n > L.cells * 16:
                raise InputError(f"region of {n} cells is more than the limit {L.cells * 16}")
            argv = ["world", spec, "--chunk", "x".join(map(str, chunk)), "--seed", str(seed),
                    f"--region={xs[0]}:{xs[1]},{ys[0]}:{ys[1]}", "--out", "{OUT}/result.npy",
                    "--json"]  # fmt: skip
            info.update(size=[xs[1] - xs[0], ys[1] - ys[0], *chunk[2:]], out="result.npy")
        elif command in ("prove", "witness"):
            argv = [command, spec, "--json"]
            if command == "witness":  # prove is bounded by its state budget (--max-states)
                argv += ["--time-limit", str(seconds)]
            order = body.get("order") or "scanline"
            if not isinstance(order, str) or not re.fullmatch(r"[a-z:\-]{1,20}", order):
                raise InputError(f"order must be an order such as scanline, not {order!r}")
            argv += ["--order", order]
            if command == "witness":
                ms = body.get("max_size")
                if ms:
                    _shape(ms, "max_size", 12 * 12)
                    argv += ["--max-size", str(ms)]
            info["order"] = order
        else:
            raise InputError("command must be synthesize, world, prove or witness")
        job = st.jobs.start(str(command), argv, info)
        return JSONResponse({"id": job.id})

    def job_of(req: Request) -> Any:
        job = st.jobs.get(req.path_params["jid"])
        if job is None:
            raise HTTPException(404, f"no run {req.path_params['jid']}")
        return job

    async def run_events(req: Request) -> Response:
        job = job_of(req)

        async def stream() -> AsyncIterator[str]:
            sent = 0
            deadline = asyncio.get_running_loop().time() + L.seconds + 60
            while True:
                while sent < len(job.events):
                    yield f"data: {json.dumps(job.events[sent])}\n\n"
                    sent += 1
                if job.finished and sent >= len(job.events):
                    yield "event: end\ndata: {}\n\n"
                    return
                if asyncio.get_running_loop().time() > deadline or await req.is_disconnected():
                    return
                await asyncio.sleep(0.15)

        return StreamingResponse(stream(), media_type="text/event-stream",
                                 headers={"cache-control": "no-store"})  # fmt: skip

    async def run_get(req: Request) -> Response:
        job = job_of(req)
        from csplab.io.registry import output_extensions

        kind = job.info.get("kind")
        gives: Any = kind if kind in ("PolygonModel", "PolyhedralModel") else None
        return JSONResponse(json.loads(json.dumps({
            "id": job.id, "state": job.state, "command": job.argv[0], "info": job.info,
            "result": job.result, "error": job.error, "code": job.code,
            "formats": output_extensions(gives=gives),
        }, default=str)))  # fmt: skip

    def job_grid(job: Any) -> tuple[NDArray[np.int32], Any]:
        from csplab.cli.common import load_model

        if not job.finished or job.state != "done":
            raise InputError(f"run {job.id} has no result ({job.state})")
        p = job.folder / "result.npy"
        if not p.exists():
            raise InputError(f"run {job.id} has no label grid")
        model: Any = load_model(job.argv[1])
        return np.load(p, allow_pickle=False).astype(np.int32), model

    def job_solids(job: Any) -> Any:
        """A continuous run's output, read back from the file the command wrote."""
        from csplab.io import read_model

        for name in ("result.json", "result.obj"):
            if job.state == "done" and (job.folder / name).exists():
                return read_model(job.folder / name)
        return None

    def write_solids(model: Any, fmt: str) -> bytes:
        from csplab.io.registry import output_format

        with tempfile.TemporaryDirectory(prefix="csplab-dl-") as d:
            p = Path(d) / f"result{fmt}"
            gives: Any = type(model).__name__
            output_format(p, gives=gives).write(model, p)
            return p.read_bytes()

    async def run_png(req: Request) -> Response:
        from csplab.render import render_png_bytes

        job = job_of(req)
        solids = await asyncio.to_thread(job_solids, job)
        if solids is not None:
            data = await asyncio.to_thread(write_solids, solids, ".png")
            return Response(data, media_type="image/png")
        g, model = await asyncio.to_thread(job_grid, job)
        names: Any = getattr(model, "names", None)
        data = await asyncio.to_thread(render_png_bytes, g, names=names, model=model)
        return Response(data, media_type="image/png")

    async def run_glb(req: Request) -> Response:
        from csplab.web.glb import grid_glb, solids_glb

        job = job_of(req)
        solids = await asyncio.to_thread(job_solids, job)
        if solids is not None and solids.ndim == 3:
            data = await asyncio.to_thread(solids_glb, solids)
        else:
            g, model = await asyncio.to_thread(job_grid, job)
            if g.ndim != 3:
                raise InputError("a 2D result has no 3D view")
            data = await asyncio.to_thread(grid_glb, g, model)
        if len(data) > L.output_bytes:
            raise HTTPException(413, f"the model is {len(data)} bytes, over the limit")
        return Response(data, media_type="model/gltf-binary")

    async def run_download(req: Request) -> Response:
        from csplab.io.registry import output_extensions

        job = job_of(req)
        fmt = req.query_params.get("format", ".png")
        solids = await asyncio.to_thread(job_solids, job)
        if solids is None:
            g, model = await asyncio.to_thread(job_grid, job)
            return await asyncio.to_thread(_download, g, model, fmt, "result")
        kinds = output_extensions(gives=job.info["kind"])
        if fmt not in kinds:
            raise InputError(f"format must be one of {', '.join(kinds)}, not {fmt!r}")
        data = await asyncio.to_thread(write_solids, solids, fmt)
        head = {"content-disposition": f'attachment; filename="result{fmt}"'}
        return Response(data, media_type="application/octet-stream", headers=head)

    def job_problem(job: Any) -> tuple[Any, NDArray[np.int32]]:
        from csplab.cli import build_parser
        from csplab.cli.common import problem_from_args

        g, model = job_grid(job)
        if job.argv[0] != "synthesize":
            raise InputError(f"run {job.id} is not a synthesis")
        args = build_parser(only="synthesize").parse_args(job.argv)
        return problem_from_args(args, model), g

    async def run_constraints(req: Request) -> Response:
        from csplab.web.overlay import constraint_rows

        job = job_of(req)
        P, g = await asyncio.to_thread(job_problem, job)
        return JSONResponse({"constraints": constraint_rows(P, g)})

    async def run_constraints_png(req: Request) -> Response:
        from csplab.render import render_png_bytes
        from csplab.web.overlay import highlight

        job = job_of(req)
        P, g = await asyncio.to_thread(job_problem, job)
        if g.ndim != 2:
            raise InputError("constraints are drawn on 2D results")
        _, model = await asyncio.to_thread(job_grid, job)
        png = await asyncio.to_thread(render_png_bytes, g, names=getattr(model, "names", None),
                                      model=model)  # fmt: skip
        data = await asyncio.to_thread(highlight, png, P, g)
        return Response(data, media_type="image/png")

    async def run_replay(req: Request) -> Response:
        from csplab.cli.common import load_model
        from csplab.web.replay import replay

        job = job_of(req)
        if job.argv[0] != "witness" or job.state != "done" or job.result is None:
            raise InputError(f"run {job.id} is not a finished witness search")
        w = job.result.get("witness")
        if not isinstance(w, dict):
            raise InputError("the search found no failing run to replay")
        model: Any = await asyncio.to_thread(load_model, job.argv[1])
        steps = await asyncio.to_thread(replay, model, w)
        K = int(getattr(model, "K", 0) or len(model.names or ()))
        return JSONResponse({"witness": w, "steps": steps,
                             "colors": _hex(label_colors(model, K))})  # fmt: skip

    async def on_error(req: Request, exc: Exception) -> Response:
        if isinstance(exc, HTTPException):
            return _error(exc.status_code, str(exc.detail))
        if isinstance(exc, Refused):
            return _error(403, str(exc))
        if isinstance(exc, CsplabError | ValueError):
            from csplab.cli.common import readable

            lines = readable(str(exc)).strip().splitlines()
            return _error(400, lines[0] if lines else type(exc).__name__)
        import traceback

        traceback.print_exception(exc)
        return _error(500, f"internal error ({type(exc).__name__}); the server log has details")

    async def limit_body(req: Request, call_next: Callable[[Request], Awaitable[Response]]
                         ) -> Response:  # fmt: skip
        n = req.headers.get("content-length")
        if n is not None and (not n.isdigit() or int(n) > L.body_bytes):
            return _error(413, f"request body over {L.body_bytes} bytes")
        if len(str(req.url)) > 4096:
            return _error(414, "request line too long")
        return await call_next(req)

    from starlette.middleware import Middleware
    from starlette.middleware.base import BaseHTTPMiddleware

    routes = [
        Route("/", page),
        Route("/api/meta", meta),
        Route("/api/world", world_new, methods=["POST"]),
        Route("/api/world/{wid}/chunk/{i}/{j}.png", chunk_png),
        Route("/api/world/{wid}/edit", edit, methods=["POST"]),
        Route("/api/world/{wid}/undo", undo, methods=["POST"]),
        Route("/api/world/{wid}/download", world_download),
        Route("/api/world/{wid}/model.glb", world_glb),
        Route("/api/run", run_new, methods=["POST"]),
        Route("/api/run/{jid}", run_get),
        Route("/api/run/{jid}/events", run_events),
        Route("/api/run/{jid}/result.png", run_png),
        Route("/api/run/{jid}/result.glb", run_glb),
        Route("/api/run/{jid}/download", run_download),
        Route("/api/run/{jid}/replay", run_replay),
        Route("/api/run/{jid}/constraints", run_constraints),
        Route("/api/run/{jid}/constraints.png", run_constraints_png),
        Mount("/static", StaticFiles(directory=STATIC, follow_symlink=False), name="static"),
    ]
    handlers: dict[Any, Any] = {HTTPException: on_error, CsplabError: on_error,
                                ValueError: on_error, Exception: on_error}  # fmt: skip
    app = Starlette(routes=routes, exception_handlers=handlers,
                    middleware=[Middleware(BaseHTTPMiddleware, dispatch=limit_body)])  # fmt: skip
    app.state.csplab = st
    return app
