"""``csplab info``: solvers, their dependencies, and the built-in examples."""

from __future__ import annotations

import argparse
import json
from typing import Any


def add_parser(sub: Any) -> argparse.ArgumentParser:
    p: argparse.ArgumentParser = sub.add_parser(
        "info", help="list solvers (and whether they are installed) and built-in examples"
    )
    p.add_argument("--json", action="store_true")
    return p


def run(args: argparse.Namespace) -> int:
    from csplab import __version__
    from csplab.examples import example_info
    from csplab.solvers import available_solvers

    solvers = available_solvers()
    examples = example_info()
    if args.json:
        print(json.dumps({"version": __version__, "solvers": solvers, "examples": dict(examples)}))
        return 0
    print(f"csplab {__version__}")
    print("solvers:")
    for s in solvers:
        mark = (
            "installed"
            if s.get("installed")
            else f"missing: pip install 'csplab[{s.get('extra') or s['name']}]'"
        )
        kind = "complete" if s.get("complete") else "incomplete"
        print(f"  {s['name']:<10} {kind:<10} {mark:<12} {s.get('description', s.get('error', ''))}")
        if s.get("backends"):
            print(f"  {'':<10} backends: {', '.join(s['backends'])}")
        for o in s.get("options", []):
            vals = f" ({'|'.join(o['values'])})" if o.get("values") else ""
            print(f"  {'':<10} {o['name']}={o['default']!r}{vals}: {o['doc']}")
    print("built-in examples:")
    for name, desc in examples:
        print(f"  {name:<14} {desc}")
    return 0
