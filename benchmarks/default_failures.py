"""How often ``csplab synthesize`` with default options ends without a solution, per model.

Every built-in example (at the sizes of ``benchmarks/output_digests.py``), a few sizes that
have no solution, every model file of ``tests/io/data`` and of ``../shared/anchors-data``
(skipped when absent) is synthesized with the command's default options for each seed; a
run counts as

* ``solved``: exit 0 (the command re-checks every output with ``Problem.violations``; the
  continuous models' JSON reports the Eq. 4.1 violations of the written polygons, which
  must be 0),
* ``unsat``: exit 1 and status ``unsat`` (an exact solver's refutation),
* ``not solved``: exit 1 otherwise (the solvers gave up or the time ran out),
* ``error``: any other exit code.

The command runs in this process (``csplab.cli.main``), so the script measures whatever
``csplab`` is importable: run it once per checkout to compare two versions::

    PYTHONPATH=/path/to/old python benchmarks/default_failures.py --out before.tsv
    PYTHONPATH=/path/to/new python benchmarks/default_failures.py --out after.tsv
    python benchmarks/default_failures.py --table before.tsv after.tsv

``--seeds 1-20`` (the default) and ``--only NAME,...`` select the work.

Merrell's gadgets (the planar 3-SAT reduction of Theorem 3.3.4, ``csplab reduction
planar3sat``) have no model file: for them the script calls :func:`csplab.solvers.solve`
with the command's defaults (``catalog``, 10 restarts, and ``fallback="auto"`` where
``solve`` has it) on the incomplete model of a random formula drawn with the run's seed
(7 variables, 10 clauses; ``near``: few satisfying assignments, ``unsat``: none), and
checks the verdict against the formula's own satisfiability.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "io" / "data"
ANCHORS = ROOT.parent / "shared" / "anchors-data"
if not ANCHORS.is_dir():
    ANCHORS = Path("/work/shared/anchors-data")

#: size by the kind of built-in example (as benchmarks/output_digests.py)
SIZES = {"grid2": "20x20", "grid3": "12x12x8", "polygons": "20x20", "polyhedra": "8x8x6"}

#: extra arguments of some built-in examples
EXTRA = {"hexriver": ["--grid", "hex:odd-r"], "trifan": ["--grid", "tri"]}

#: more sizes: hard for the incomplete solver, or without a solution (fig3_1b periodic at an
#: odd size: a checkerboard cannot wrap around)
MORE = [
    ("fallible 40x40", ["fallible", "--size", "40x40"]),
    ("fig3_1b periodic 21x21", ["fig3_1b", "--size", "21x21", "--periodic"]),
    ("fig3_1b periodic 5x5", ["fig3_1b", "--size", "5x5", "--periodic"]),
]

#: model files: (name, path relative to its folder, extra arguments)
FILES = [
    ("pipes.xml", DATA / "pipes.xml", ["--size", "20x20"]),
    ("pipes.xml periodic", DATA / "pipes.xml", ["--size", "24x24", "--periodic"]),
    ("pipes3d.xml", DATA / "pipes3d.xml", ["--size", "8x8x8"]),
    ("wfc_samples.xml", DATA / "wfc_samples.xml", []),
    ("sample.png", DATA / "sample.png", ["--size", "24x24"]),
    ("hexmap.tmx", DATA / "hexmap.tmx", ["--size", "16x16"]),
    ("hex_debroglie.json", DATA / "tiled" / "hex_debroglie.json", []),
    ("tiny_debroglie.json", DATA / "tiny_debroglie.json", []),
    ("tiny_poms.json", DATA / "tiny_poms.json", []),
    ("wfc_index/within.xml", DATA / "wfc_index" / "within.xml", ["--size", "12x12"]),
    ("wfc_index/beyond.xml", DATA / "wfc_index" / "beyond.xml", ["--size", "12x12"]),
    ("tiny_polygons.json", DATA / "tiny_polygons.json", ["--size", "10x10"]),
    ("tiny.svg", DATA / "tiny.svg", ["--size", "10x10"]),
    ("tiny_mesh.obj", DATA / "tiny_mesh.obj", ["--size", "6x6x6"]),
    ("tiny.off", DATA / "tiny.off", ["--size", "6x6x6"]),
    ("tiny.stl", DATA / "tiny.stl", ["--size", "6x6x6"]),
    ("Knots3D.xml", ANCHORS / "MarkovJunior" / "Knots3D.xml", ["--size", "8x8x8"]),
    ("edged_path_constraint.json", ANCHORS / "DeBroglie" / "edged_path_constraint.json", []),
    ("pillMortal_poms.json", ANCHORS / "PunchOutModelSynthesis" / "pillMortal_poms.json", []),
    ("brutal-plum_poms.json", ANCHORS / "PunchOutModelSynthesis" / "brutal-plum_poms.json", []),
]


def builtin_kinds() -> list[tuple[str, str]]:
    """(name, kind) of every built-in example (as ``csplab info`` lists them)."""
    from csplab.examples import example_info

    found = []
    for name, text in example_info():
        kind = "grid2"
        if text.startswith("polygons:"):
            kind = "polygons"
        elif text.startswith("polyhedra:"):
            kind = "polyhedra"
        elif text.startswith("3D"):
            kind = "grid3"
        found.append((name, kind))
    return found


def cases() -> list[tuple[str, list[str]]]:
    """(label, synthesize arguments) of every model measured."""
    out: list[tuple[str, list[str]]] = []
    for name, kind in builtin_kinds():
        args = [name, "--size", SIZES[kind], *EXTRA.get(name, [])]
        if kind == "grid3":
            args += ["--boundary", "auto"]
        out.append((f"{name} {SIZES[kind]}", args))
    out += MORE
    for label, path, extra in FILES:
        if path.exists():
            out.append((label, [str(path), *extra]))
    return out


#: gadget cases: label -> literal signs of random_planar3sat
GADGETS = {"gadgets planar3sat near": "near", "gadgets planar3sat unsat": "unsat"}


def run_gadgets(signs: str, seed: int) -> tuple[str, float]:
    """The outcome of the command's defaults on the gadget model of a random formula."""
    import inspect

    from csplab.complexity.planar3sat import random_planar3sat
    from csplab.complexity.reduction import reduce_planar3sat
    from csplab.solvers import solve

    f = random_planar3sat(7, 10, rng=seed, signs=signs)
    P = reduce_planar3sat(f).problem()
    sat = len(f.models()) > 0
    kw = {"fallback": "auto"} if "fallback" in inspect.signature(solve).parameters else {}
    t0 = time.perf_counter()
    r = solve(P, "catalog", rng=seed, restarts=10, **kw)
    dt = time.perf_counter() - t0
    if r.status == "solved":
        return ("solved" if sat and P.is_solution(r.grid) else "INVALID"), dt
    if r.status == "unsat":
        return ("unsat" if not sat else "WRONG unsat"), dt
    return "not solved", dt


def is_grid(args: list[str]) -> bool:
    """Whether the model of ``args`` is a grid model (not a continuous one)."""
    import warnings

    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.examples import load_model

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return not isinstance(load_model(args[0]), PolygonModel | PolyhedralModel)


def run_one(args: list[str], seed: int, grid: bool = True) -> tuple[str, float]:
    """The outcome of one ``csplab synthesize`` (in this process) and its wall time; a
    grid model's output is written and checked again with ``csplab check`` (a continuous
    model's JSON has the checker's Eq. 4.1 violations of the output polygons)."""
    import tempfile

    from csplab.cli import main

    buf, err = io.StringIO(), io.StringIO()
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "out.npy")
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
            code = main(["synthesize", *args, "--seed", str(seed), "--json",
                         *(["--out", out] if grid else [])])  # fmt: skip
        dt = time.perf_counter() - t0
        if code == 0 and grid:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                if main(["check", args[0], out, *args[1:]]) != 0:
                    return "INVALID (csplab check)", dt
    try:
        d = json.loads(buf.getvalue().strip().splitlines()[-1])
    except (json.JSONDecodeError, IndexError):
        d = {}
    if code == 0:
        bad = d.get("violations", d.get("stats", {}).get("violations", 0))
        return ("solved" if not bad else "INVALID"), dt
    if code == 1 and d.get("status") == "unsat":
        proof = d.get("proof") or d.get("stats", {}).get("proof")
        return ("unsat" if proof else "unsat without a proof"), dt
    if code == 1:
        return "not solved", dt
    return f"error {code}: {err.getvalue().strip()[:80]}", dt


def seeds_arg(text: str) -> list[int]:
    a, _, b = text.partition("-")
    return list(range(int(a), int(b or a) + 1))


def table(paths: list[str]) -> str:
    """A markdown table of the failure counts of one or more result files."""
    runs = []
    for p in paths:
        rows = [line.rstrip("\n").split("\t") for line in open(p) if line.strip()]
        runs.append({r[0]: r for r in rows})
    names = list(dict.fromkeys(k for r in runs for k in r))
    head = "| model | " + " | ".join(Path(p).stem for p in paths) + " |"
    lines = [head, "|---" * (len(paths) + 1) + "|"]
    for n in names:
        cells = []
        for r in runs:
            row = r.get(n)
            cells.append(
                "—"
                if row is None
                else f"{row[3]} not solved, {row[2]} unsat, "
                f"{row[1]} solved" + (f", {row[4]} errors" if row[4] != "0" else "")
            )
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-20", help="seed range, e.g. 1-20")
    ap.add_argument("--only", help="comma-separated labels (or prefixes) to run")
    ap.add_argument("--out", help="also write tab-separated rows to this file")
    ap.add_argument("--table", nargs="+", metavar="TSV", help="print a table of result files")
    a = ap.parse_args()
    if a.table:
        print(table(a.table))
        return
    seeds = seeds_arg(a.seeds)
    only = a.only.split(",") if a.only else None
    out = open(a.out, "w") if a.out else None
    print("model\tsolved\tunsat\tnot_solved\terrors\tseconds\tfailing seeds")
    for label, args in [*cases(), *((g, []) for g in GADGETS)]:
        if only and not any(label.startswith(o) for o in only):
            continue
        grid = label not in GADGETS and is_grid(args)
        tally: Counter[str] = Counter()
        failing: list[str] = []
        total = 0.0
        for s in seeds:
            if label in GADGETS:
                outcome, dt = run_gadgets(GADGETS[label], s)
            else:
                outcome, dt = run_one(args, s, grid)
            total += dt
            key = outcome if outcome in ("solved", "unsat", "not solved") else "error"
            tally[key] += 1
            if key in ("not solved", "error"):
                failing.append(f"{s}" if key == "not solved" else f"{s}({outcome})")
        row = [label, str(tally["solved"]), str(tally["unsat"]), str(tally["not solved"]),
               str(tally["error"]), f"{total:.1f}", " ".join(failing)]  # fmt: skip
        print("\t".join(row), flush=True)
        if out:
            print("\t".join(row), file=out, flush=True)
    if out:
        out.close()


if __name__ == "__main__":
    main()
