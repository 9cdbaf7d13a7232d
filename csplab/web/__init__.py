"""``csplab serve``: a local web page to see, explore and edit models.

The page (:mod:`csplab.web.app`, Starlette served by uvicorn) lets a user pick a built-in
example or a model file under the served directory, a solver and its options (the form is
built from the solvers' declarations, as the command line is), pan and zoom an endless
world (:class:`csplab.World`) whose chunks load as the view moves, paint edits that are
re-synthesized locally (:mod:`csplab.web.worlds`) and undone, look at 3D results in a
three.js viewer (``.glb``; :mod:`csplab.web.glb`), follow long runs (server-sent events)
and see analyses: the infallibility verdict, a witness replayed step by step
(:mod:`csplab.web.replay`) and the UNSAT core of a refused edit.

Safe by default (:mod:`csplab.web.safety`): it binds 127.0.0.1, reads only files under the
served directory (no path or symlink escapes), limits request size, output size and run
time, refuses cross-site edits, and answers a bad request with one line, never a trace.
three.js is vendored from its npm package under ``static/vendor/three`` (MIT, its
``LICENSE`` beside it): the page works offline.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["serve"]


def serve(root: str | Path = ".", *, host: str = "127.0.0.1", port: int = 8000,
          model: str | None = None, banner: bool = False) -> None:  # fmt: skip
    """Run the server until interrupted.

    Parameters
    ----------
    root : str or Path
        The served directory (only files under it are read).
    host : str
        The address to bind (default the local machine only).
    port : int
        The TCP port.
    model : str, optional
        The model the page selects first.
    banner : bool
        Print one line on stderr saying where the page is, once the app is made.

    Raises
    ------
    InputError
        When ``model`` is neither a built-in example nor a file under ``root``.
    DependencyError
        When Starlette or uvicorn (the ``web`` extra) is not installed.
    """
    from csplab.deps import require

    require("starlette", "web", "csplab serve")
    uvicorn = require("uvicorn", "web", "csplab serve")
    from csplab.web.app import create_app

    app = create_app(root, start_model=model)
    if banner:
        import sys

        print(f"csplab: serving {Path(root).resolve()} on http://{host}:{port}/ (Ctrl-C "
              "stops)", file=sys.stderr, flush=True)  # fmt: skip
    uvicorn.run(app, host=host, port=port, log_level="warning")
