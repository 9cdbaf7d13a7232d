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
        mark = "installed" if s.get("installed") else "missing: " + ", ".join(s.get("requires", []))
        kind = "complete" if s.get("complete") else "incomplete"
        print(f"  {s['name']:<10} {kind:<10} {mark:<12} {s.get('description', s.get('error', ''))}")
        if s.get("backends"):
            print(f"  {'':<10} backends: {', '.join(s['backends'])}")
    print("built-in examples:")
    for name, desc in examples:
        print(f"  {name:<14} {desc}")
    return 0
