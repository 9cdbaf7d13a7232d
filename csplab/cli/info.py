"""``csplab info``: list the solvers (whether installed), built-in examples and file formats."""

from __future__ import annotations

import argparse
import json


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from csplab import __version__
    from csplab.baselines import BASELINES
    from csplab.constraints import solver_note
    from csplab.examples import example_info
    from csplab.io.registry import FORMATS
    from csplab.solvers import available_solvers

    solvers = available_solvers()
    examples = example_info()
    if args.json:
        formats = [f.info() for f in FORMATS.values()]
        print(
            json.dumps(
                {
                    "version": __version__,
                    "solvers": solvers,
                    "examples": dict(examples),
                    "formats": formats,
                    "baselines": {b.name: b.summary for b in BASELINES.values()},
                }
            )
        )
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
        if s.get("constraints"):
            how = f"{s['constraints']} ({solver_note(s['constraints'])})"
            print(f"  {'':<10} global constraints: {how}")
        if s.get("backends"):
            print(f"  {'':<10} backends: {', '.join(s['backends'])}")
        for o in s.get("options", []):
            vals = f" ({'|'.join(o['values'])})" if o.get("values") else ""
            print(f"  {'':<10} {o['name']}={o['default']!r}{vals}: {o['doc']}")
    print("built-in examples:")
    for name, desc in examples:
        print(f"  {name:<14} {desc}")
    print("file formats (--model-option KEY=VALUE for the loader's options):")
    for f in FORMATS.values():
        rw = "read+write" if f.readable and f.writable else ("read" if f.readable else "write")
        print(f"  {f.name:<13} {rw:<10} {' '.join(f.extensions):<15} {f.description}")
        for o in f.options:
            print(f"  {'':<13} {o.usage}: {o.help}")
    print("baselines (csplab baseline NAME MODEL --size ...):")
    for b in BASELINES.values():
        print(f"  {b.name:<10} {b.summary}")
        for bo in b.options:
            print(f"  {'':<10} --{bo.name}={bo.default!r}: {bo.help}")
    return 0
