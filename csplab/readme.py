"""README tables generated from the declarations (one truth per concept).

Sections of ``README.md`` between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` are
produced by the functions in :data:`SECTIONS`; ``python -m csplab.readme --write`` rewrites
them, ``python -m csplab.readme`` (the test suite) fails when one is stale.

Examples
--------
>>> from csplab.readme import render
>>> render("solvers").splitlines()[0]
'| name | algorithm | complete | global constraints | options | notes |'
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
from pathlib import Path

__all__ = ["SECTIONS", "render", "stale_sections", "update"]

# section name -> "module:function" returning the markdown
SECTIONS: dict[str, str] = {
    "solvers": "csplab.solvers:markdown_table",
    "formats": "csplab.io.registry:markdown_table",
}


def render(name: str) -> str:
    """The markdown of section ``name``."""
    modname, fn = SECTIONS[name].split(":")
    return str(getattr(importlib.import_module(modname), fn)()).strip()


def _pattern(name: str) -> re.Pattern[str]:
    return re.compile(rf"(<!-- {name}:begin -->\n)(.*?)(<!-- {name}:end -->)", re.S)


def update(text: str) -> str:
    """``text`` with every section regenerated."""
    for name in SECTIONS:
        body = render(name) + "\n"

        def fill(m: re.Match[str], body: str = body) -> str:
            return m.group(1) + body + m.group(3)

        text = _pattern(name).sub(fill, text)
    return text


def stale_sections(text: str) -> list[str]:
    """Sections that are missing or differ from their declarations."""
    out = []
    for name in SECTIONS:
        m = _pattern(name).search(text)
        if m is None or m.group(2).strip() != render(name):
            out.append(name)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m csplab.readme", description=__doc__)
    p.add_argument("path", nargs="?", default="README.md")
    p.add_argument("--write", action="store_true", help="rewrite the generated sections")
    args = p.parse_args(argv)
    path = Path(args.path)
    text = path.read_text(encoding="utf-8")
    if args.write:
        path.write_text(update(text), encoding="utf-8")
        return 0
    stale = stale_sections(text)
    for name in stale:
        print(f"{path}: section {name!r} is stale; run python -m csplab.readme --write")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
