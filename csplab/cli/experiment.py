"""``csplab experiment``: run a thesis experiment (or only its missing trials) and report.

``csplab experiment list`` lists the experiments; ``csplab experiment NAME --help`` shows an
experiment's options. Exit 0 when every trial of the sweep is in the store and the report
was written, 1 when trials raised errors (or, with ``--report-only``, are missing), 2 on bad
input.

Stored trials are reused; when some of them were computed by other code (another
``csplab/`` source tree or csplab version than the running one) one warning line on stderr
says how many and from which revisions, and ``--rerun-stale`` runs just those again
(``--rerun`` runs the whole sweep again).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sqlite3
import sys
from pathlib import Path
from typing import Any

from csplab.cli.common import check_output_dir, check_time_limit, key_values
from csplab.errors import InputError

# common option -> (flags, argparse kwargs)
_COMMON: dict[str, tuple[tuple[str, ...], dict[str, Any]]] = {
    "examples": (
        ("--example",),
        {"action": "append", "metavar": "MODEL", "help": "built-in example or model file "
         "(repeatable, or comma-separated)"},
    ),
    "sizes": (("--sizes",), {"help": "nx = ny values: START:STOP[:STEP] or a comma list"}),
    "size": (("--size",), {"help": "output size such as 40x40x10"}),
    "solvers": (
        ("--solver",),
        {"action": "append", "metavar": "SPEC", "help": "solver spec (repeatable, or "
         "comma-separated), e.g. catalog, blocks, sat:cadical195"},
    ),
    "seeds": (("--seeds",), {"type": int, "help": "trials (seeds) per point"}),
    "seed0": (("--seed-offset",), {"type": int, "dest": "seed0", "help": "first seed"}),
    "boundary": (("--boundary",), {"help": "auto, none, or face=label pairs like z-=1,x-=0"}),
    "periodic": (("--periodic",), {"action": "store_true", "default": None,
                                   "help": "wrap around on every axis"}),
    "order": (("--order",), {"help": "cell order of Alg. 3.1: scanline, random, "
                             "min-entropy or scan:AXES such as scan:yx"}),
    "choice": (("--choice",), {"choices": ["uniform", "weighted"], "help": "label choice"}),
    "options": (
        ("--option",),
        {"action": "append", "metavar": "[SOLVER.]KEY=VALUE", "dest": "options",
         "help": "extra solver option (repeatable; JSON values); SOLVER. limits it to one solver"},
    ),
    "time_limit": (("--time-limit",), {"type": float, "help": "seconds per trial"}),
    "constraints": (
        ("--constraints",),
        {"action": "append", "metavar": "FILE", "help": "a constraints file (repeatable): "
         "global constraints added to every trial's problem (csplab.constraints)"},
    ),
}  # fmt: skip




def description() -> str:
    from csplab.experiments import EXPERIMENTS

    return (
        "Run an experiment's missing trials into a SQLite results store and write its report "
        f"(markdown, CSV, PNG, SVG). Experiments: {', '.join(EXPERIMENTS)}. `csplab "
        "experiment NAME --help` lists an experiment's options; `csplab experiment list` "
        "describes them."
    )


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", metavar="NAME", help="experiment name, or 'list'")
    p.add_argument("rest", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)


def _experiment_parser(exp: Any) -> argparse.ArgumentParser:
    from csplab.cli import _Parser

    p = _Parser(
        prog=f"csplab experiment {exp.name}",
        description=f"{exp.title}: {exp.description}.",
    )
    g = p.add_argument_group("what to run")
    for key, (flags, kw) in _COMMON.items():
        if key in exp.uses:
            kw = dict(kw)
            kw.setdefault("dest", key)
            g.add_argument(*flags, **kw)
    exp.add_arguments(g)
    h = p.add_argument_group("how to run")
    h.add_argument("--quick", action="store_true", help="a tiny version (seconds)")
    h.add_argument("--jobs", type=int, help="local worker processes (default: CPU count)")
    h.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://host:8786")
    h.add_argument(
        "--store", help="SQLite results store (default results/csplab-experiments.sqlite)"
    )
    h.add_argument(
        "--out",
        help=f"report directory (default {exp.default_out or Path('results') / exp.name})",
    )
    h.add_argument("--report-only", action="store_true", help="run nothing; report the store")
    h.add_argument(
        "--rerun", action="store_true", help="forget this sweep's stored trials and run them again"
    )
    h.add_argument(
        "--rerun-stale",
        action="store_true",
        help="run again only the stored trials that other code computed (another csplab/ "
        "source tree or version)",
    )
    h.add_argument("--no-progress", action="store_true", help="no progress bar")
    h.add_argument("--no-figures", action="store_true", help="tables and CSVs only")
    h.add_argument("--json", action="store_true", help="print the summary as JSON")
    return p


def _split(values: list[str] | None) -> list[str] | None:
    if values is None:
        return None
    return [v.strip() for item in values for v in item.split(",") if v.strip()]


def _options(items: list[str] | None) -> dict[str, Any] | None:
    if items is None:
        return None
    return key_values(items, "--option", "KEY=VALUE or SOLVER.KEY=VALUE")


def _list() -> int:
    from csplab.experiments import EXPERIMENTS, get_experiment

    width = max(map(len, EXPERIMENTS)) + 1
    for name in EXPERIMENTS:
        exp = get_experiment(name)
        print(f"{name:<{width}} {exp.title}")
        print(f"{'':<{width}} {exp.description}")
    return 0


def run(args: argparse.Namespace) -> int:
    from csplab import experiments as ex

    if args.name == "list":
        return _list()
    exp = ex.get_experiment(args.name)
    p = _experiment_parser(exp)
    a = p.parse_args(args.rest)
    overrides: dict[str, Any] = {}
    for key in exp.uses:
        val = getattr(a, key, None)
        if key in ("examples", "solvers"):
            val = _split(val)
        elif key == "options":
            val = _options(val)
        overrides[key] = val
    for extra in set(vars(a)) - set(overrides):
        if extra in exp.defaults:
            overrides[extra] = getattr(a, extra)
    if a.jobs is not None and a.jobs < 1:
        raise InputError("--jobs must be >= 1")
    if "time_limit" in overrides:
        check_time_limit(overrides["time_limit"])
    # output paths before the work: the report folder and the store (ResultsStore checks
    # that an existing store is an intact SQLite database when it opens it)
    check_output_dir(a.out if a.out else Path(exp.default_out or Path("results") / exp.name),
                     "--out")  # fmt: skip
    store = Path(a.store) if a.store else Path(ex.DEFAULT_STORE)
    if store.is_dir():
        raise InputError(f"--store {store} is a folder, not a file")
    check_output_dir(store.parent, "--store")
    kwargs: dict[str, Any] = {}
    if a.store:
        kwargs["store"] = a.store
    try:
        summary, report = ex.run(
            exp.name, quick=a.quick, out=a.out, jobs=a.jobs, scheduler=a.scheduler,
            progress=not a.no_progress, report_only=a.report_only, rerun=a.rerun,
            rerun_stale=a.rerun_stale, figures=not a.no_figures,
            command="csplab experiment " + shlex.join([args.name, *args.rest]), **kwargs,
            **overrides,
        )  # fmt: skip
    except sqlite3.DatabaseError as broken:  # the store broke while in use: one line naming it
        from csplab.experiments.store import store_error

        raise store_error(store, broken) from None
    if a.json:
        print(
            json.dumps(
                {
                    "experiment": exp.name, "trials": summary.total, "skipped": summary.skipped,
                    "ran": summary.ran, "statuses": summary.statuses, "stale": summary.stale,
                    "errors": [f"{t.key}: {e}" for t, e in summary.errors],
                    "missing": report.missing, "files": [str(f) for f in report.files],
                    "figures": [str(f) for f in report.figures], "tables": report.tables,
                }, default=str,
            )
        )  # fmt: skip
    else:
        print(summary.line())
        for t, e in summary.errors[:5]:
            print(f"  error in {t.example} {t.size_text} {t.solver} seed {t.seed}: {e}")
        first = next(iter(report.tables.items()), None)
        if first is not None:
            from csplab.experiments.base import markdown_table

            name, rows = list(report.tables.items())[-1 if len(report.tables) > 1 else 0]
            print(f"\n{name}:\n{markdown_table(rows)}\n")
        for f in report.files + report.figures:
            print(f"wrote {f}")
        if report.missing:
            print(f"{report.missing} of {report.trials} trials are missing from the store",
                  file=sys.stderr)  # fmt: skip
    if summary.stale:  # reused trials computed by other code: say so, never silently
        print(f"csplab: warning: {summary.stale_line()}", file=sys.stderr)
    return 1 if summary.errors or report.missing else 0
