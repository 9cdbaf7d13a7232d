"""``csplab serve``: a local web page to see, explore and edit models (pannable world, 3D viewer).

Serve a web page on http://HOST:PORT/ (see :mod:`csplab.web`) to choose a built-in example
or a model file in the current directory, a solver and its options; pan and zoom an endless
world (chunks load as the view moves), paint edits that are re-synthesized locally (undo,
download in any output format), look at 3D results in a three.js viewer, follow long runs
and see the infallibility verdict, a witness replayed step by step and the UNSAT core of a
refused edit. Binds 127.0.0.1 unless --host says otherwise; reads only files under the
current directory. Needs the web extra: pip install 'csplab[web]'.

Exit codes: 0 the server stopped, 2 bad input.
"""

from __future__ import annotations

import argparse
import sys

from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", metavar="MODEL", nargs="?", help="the model the page opens with")
    p.add_argument("--port", type=int, default=8000, help="TCP port (default 8000)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1: this machine only)")  # fmt: skip


def run(args: argparse.Namespace) -> int:
    from csplab.deps import require
    from csplab.web import serve

    if not 0 < args.port < 65536:
        raise InputError(f"--port must be 1..65535, not {args.port}")
    for module in ("starlette", "uvicorn"):  # before the banner: one line when missing
        require(module, "web", "csplab serve")
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"csplab: warning: serving on {args.host}: other machines can reach the page",
              file=sys.stderr)  # fmt: skip
    serve(".", host=args.host, port=args.port, model=args.model, banner=True)
    return 0
