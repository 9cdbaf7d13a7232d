"""The ``csplab`` command line.

Each subcommand lives in its own module, which declares ``add_arguments(parser)`` and
``run(args) -> int``; its docstring is its help, one text: the first line (the command's
name in double backquotes, a colon, what it does) is the one-line help of ``csplab --help``,
the whole docstring (what it does, its exit codes) the description of ``csplab NAME --help``.
A ``HELP`` string, a ``DESCRIPTION`` string (``RAW_DESCRIPTION = True`` keeps its layout) or
a ``description()`` function (a text computed when the parser is built) replaces them.
``EXIT_AT_ONCE = True`` declares a command that leaves nothing to clean up once ``run``
returns (its output written atomically, its worker pools closed): the console script then
ends the process at once, without the interpreter's teardown (:func:`main`).
:data:`COMMANDS` maps names to modules, and :func:`build_parser` builds every subparser the
same way. Exit codes: 0 success, 1 the algorithm failed / the problem is unsatisfiable / a
check found problems, 2 bad input (one line on stderr, no traceback).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings
from collections.abc import Sequence
from types import ModuleType
from typing import Any, NoReturn

from csplab.cli.common import readable
from csplab.errors import CsplabError
from csplab.limits import memory_limit

__all__ = ["COMMANDS", "main"]

# name -> module (one line per command)
COMMANDS: dict[str, str] = {
    "synthesize": "csplab.cli.synthesize",
    "check": "csplab.cli.check",
    "info": "csplab.cli.info",
    "explain": "csplab.cli.explain",
    "catalog-gap": "csplab.cli.catalog_gap",
    "show": "csplab.cli.show",
    "prove": "csplab.cli.prove",
    "check-certificate": "csplab.cli.check_certificate",
    "witness": "csplab.cli.witness",
    "refine": "csplab.cli.refine",
    "reduction": "csplab.cli.reduction",
    "count": "csplab.cli.count",
    "experiment": "csplab.cli.experiment",
    "baseline": "csplab.cli.baseline",
    "world": "csplab.cli.world",
    "serve": "csplab.cli.serve",
}


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        """One line, as every bad input (no usage text: ``--help`` has it)."""
        print(f"csplab: error: {message} (see `{self.prog} --help`)", file=sys.stderr)
        raise SystemExit(2)


_NEGATIVE = re.compile(r"-[0-9.]")


def _attach_negative_values(words: list[str]) -> list[str]:
    """``--size -5x5x5`` as ``--size=-5x5x5``: argparse would take ``-5x5x5`` for an option
    and print a usage text; attached, the value reaches the option's own check (one line
    naming the flag and the value).

    Examples
    --------
    >>> _attach_negative_values(["synthesize", "x", "--size", "-5x5x5", "--seed", "1"])
    ['synthesize', 'x', '--size=-5x5x5', '--seed', '1']
    """
    out: list[str] = []
    i = 0
    while i < len(words):
        w = words[i]
        nxt = words[i + 1] if i + 1 < len(words) else None
        if w.startswith("--") and "=" not in w and nxt is not None and _NEGATIVE.match(nxt):
            out.append(f"{w}={nxt}")
            i += 2
            continue
        out.append(w)
        i += 1
    return out


_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")


_SUMMARY = re.compile(r"``csplab [\w-]+``: (.*?)\.?$")


def _summary(mod: ModuleType) -> str:
    r"""A command's one-line help: ``HELP``, else its docstring's first line, after the name
    it starts with (as in "``csplab NAME``: what it does.").

    Examples
    --------
    >>> import types
    >>> _summary(types.ModuleType("m", "``csplab m``: do ``x`` once.\n\nMore."))
    'do `x` once'
    """
    if hasattr(mod, "HELP"):
        return str(mod.HELP)
    first = (mod.__doc__ or "").strip().partition("\n")[0]
    m = _SUMMARY.match(first)
    return (m.group(1) if m else first).replace("``", "`")


def _description(mod: ModuleType) -> tuple[str | None, bool]:
    r"""A command's ``--help`` text and whether its layout is kept: ``description()``, else
    ``DESCRIPTION``, else the module docstring with its reST markup made plain.

    Examples
    --------
    >>> import types
    >>> m = types.ModuleType("m", "``csplab m``: see :func:`~csplab.solve`.\n\nExit 0.")
    >>> _description(m)
    ('`csplab m`: see `csplab.solve`.\n\nExit 0.', True)
    """
    if hasattr(mod, "description"):
        return mod.description(), False
    if hasattr(mod, "DESCRIPTION"):
        return mod.DESCRIPTION, bool(getattr(mod, "RAW_DESCRIPTION", False))
    if not mod.__doc__:
        return None, False
    return _ROLE.sub(r"`\1`", mod.__doc__.strip()).replace("``", "`"), True


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command; with ``only``, that command's parser in full and the
    others as bare names (their modules are not imported: a faster start)."""
    from csplab import __version__

    parser = _Parser(
        prog="csplab",
        description="Example-based model synthesis as constraint programming (Merrell 2009).",
    )
    parser.add_argument("--version", action="version", version=f"csplab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name, modname in COMMANDS.items():
        if only is not None and name != only:
            sub.add_parser(name)
            continue
        mod = importlib.import_module(modname)
        desc, raw = _description(mod)
        p = sub.add_parser(
            name,
            help=_summary(mod),
            description=desc or _summary(mod),
            formatter_class=argparse.RawDescriptionHelpFormatter if raw else argparse.HelpFormatter,
        )
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run, _exit_at_once=bool(getattr(mod, "EXIT_AT_ONCE", False)))
    return parser


def _show_warning(message: Warning | str, category: type[Warning], *args: object,
                  **kwargs: object) -> None:  # fmt: skip
    print(f"csplab: warning: {readable(str(message).strip().splitlines()[0])}", file=sys.stderr)


# commands that run csplab's numba kernels (the first run compiles them: one line on stderr)
_KERNEL_COMMANDS = frozenset(COMMANDS) - {"info", "show", "check", "check-certificate", "serve"}


_ANNOUNCING = [False, False]  # hook installed, listener registered


def _compiling_notice(module: str) -> None:
    """The :func:`csplab._jit.on_load` hook of the console script: once csplab's kernels
    are numba dispatchers, listen for numba compiling one of them (numba's
    ``numba:compile`` event fires on a cache miss only, never for machine code loaded from
    its cache) and print one line on stderr before the first such compilation. Small
    models, which the interpreted engine solves, and paths that need no uncached kernel
    (``--solver sat`` with its kernels cached, whatever Alg. 3.1's cache holds) print
    nothing."""
    if _ANNOUNCING[1] or not module.startswith("csplab"):
        return
    from numba.core import event

    _ANNOUNCING[1] = True
    event.register("numba:compile", _compile_listener())  # type: ignore[no-untyped-call]


def _compile_listener() -> Any:
    """A numba event listener printing :data:`~csplab.cli.common.COMPILING` on stderr when
    numba starts compiling a function of csplab (once per listener)."""
    from numba.core import event

    from csplab.cli.common import COMPILING

    class Notice(event.Listener):
        printed = False

        def on_start(self, ev: Any) -> None:
            data = ev.data if isinstance(ev.data, dict) else {}
            func = getattr(data.get("dispatcher"), "py_func", None)
            if not self.printed and str(getattr(func, "__module__", "")).startswith("csplab"):
                self.printed = True
                print(f"csplab: {COMPILING}", file=sys.stderr, flush=True)

        def on_end(self, ev: Any) -> None:
            pass

    return Notice()


def _announce_compiling() -> None:
    if not _ANNOUNCING[0]:
        from csplab import _jit

        _ANNOUNCING[0] = True
        _jit.on_load(_compiling_notice)


def _exit_at_once(code: int) -> NoReturn:
    """Flush stdout and stderr, then end the process with ``code`` (no teardown)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (BrokenPipeError, ValueError):  # a closed pipe or stream: nothing to write
            pass
    os._exit(code)


def main(argv: Sequence[str] | None = None, *, announce: bool | None = None) -> int:
    """Entry point of the ``csplab`` console script.

    ``announce`` (default: only for the console script itself, ``argv is None``) prints one
    line on stderr before numba's one-time compilation of a kernel (numba compiles one
    only when its cache lacks it).

    The console script (``argv is None``) of a command declaring ``EXIT_AT_ONCE`` ends the
    process with the command's exit code as soon as it returns, skipping the interpreter's
    teardown (freeing every object and module, a native SAT solver's destructor): 0.2 s of
    CPU after ``synthesize castle --size 40x40x10 --solver sat``. Callers passing ``argv``
    (tests, scripts) get the code returned as always.
    """
    words = _attach_negative_values(list(sys.argv[1:] if argv is None else argv))
    first = next((w for w in words if not w.startswith("-")), None)
    plain = first in COMMANDS and words and words[0] == first
    parser = build_parser(only=first if plain else None)
    args = parser.parse_args(words)
    if announce is None:
        announce = argv is None
    if announce and args.command in _KERNEL_COMMANDS:
        _announce_compiling()
    try:
        with warnings.catch_warnings():  # library warnings: one line each, no source line
            warnings.showwarning = _show_warning
            # --memory-limit reaches every estimate, the readers' included (not only the
            # ones a command passes it to)
            with memory_limit(getattr(args, "memory_limit", None)):
                code: int = args._run(args)
        if argv is None and getattr(args, "_exit_at_once", False):
            _exit_at_once(code)
        return code
    except CsplabError as e:
        msg = readable(str(e)).strip().splitlines()
        print(f"csplab: error: {msg[0] if msg else type(e).__name__}", file=sys.stderr)
        for extra in msg[1:6]:
            print(f"  {extra}", file=sys.stderr)
        return 2
    except MemoryError:  # an allocation the estimate did not foresee
        print("csplab: error: out of memory (try a smaller --size)", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("csplab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
