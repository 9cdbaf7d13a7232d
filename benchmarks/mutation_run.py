"""Mutation testing of the checkers, the engines and the block paths, scoped to run here.

mutmut (``pip install -e '.[test]'``) generates the mutants: its operators (numbers,
comparisons, arithmetic, ``and``/``or``, keywords, strings, arguments, ...) applied one at a
time. A whole-package ``mutmut run`` would take days on two cores, so this script mutates
only the functions that decide truth or run the engines (``TARGETS``), each against the
tests that are meant to guard it, in a copy of the work tree (the tree itself never changes),
with a time box per test run (a run that hangs counts as killed) and an optional total
budget. The report lists the score per target and every survivor with its line, so each
survivor can be killed by a new test or explained (``benchmarks/results/mutation_equivalent.md``).

Usage::

    python benchmarks/mutation_run.py                  # every target
    python benchmarks/mutation_run.py -k check3d       # targets whose name contains check3d
    python benchmarks/mutation_run.py --budget 1800 --out mutation-report.md
    python benchmarks/mutation_run.py --list           # the targets and their mutant counts

A plain ``mutmut run`` (configured in ``[tool.mutmut]`` of pyproject.toml) also works: it
mutates the checker modules in place against the tests of the checkers.
"""

from __future__ import annotations

import argparse
import ast
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUN_TIMEOUT_S = 900  # the unmutated tests' run (the mutants get 5 times its time)


@dataclass(frozen=True)
class Target:
    """Functions of one module (``Class.method`` or ``function``) and their guards."""

    name: str
    path: str
    functions: tuple[str, ...]
    tests: tuple[str, ...]
    #: environment of the test runs: ``NUMBA_DISABLE_JIT=1`` runs the ``@njit`` kernels as
    #: the Python they are written in, so a mutant of a kernel is observed without compiling
    #: every kernel of its file again (minutes per mutant); the compiled and interpreted
    #: twins are then compared as Python, which is what mutmut mutates
    env: tuple[tuple[str, str], ...] = ()


_NOJIT = (("NUMBA_DISABLE_JIT", "1"),)
#: the twins compared (kernels forced, then interpreted): statuses, grids, traces, stats
_TWINS = (
    "tests/test_interp.py::test_propagate_stops_at_a_wipe_out_of_cell_0",
    "tests/test_interp.py::test_alg31_same_as_kernels_with_labels_of_weight_0",
    "tests/test_interp.py::test_propagate_same_as_kernels_on_random_catalogs",
    "tests/test_interp.py::test_alg31_same_as_kernels_on_random_examples",
    "tests/test_interp.py::test_alg31_same_as_kernels_on_builtins",
)


TARGETS: tuple[Target, ...] = (
    Target(
        "problem.violations",
        "csplab/problem.py",
        ("Problem.violations", "Problem.is_solution", "Violations.__len__"),
        ("tests/test_problem.py",),
    ),
    Target(
        "check3d",
        "csplab/continuous/check3d.py",
        ("_samples", "_edge_pieces", "_unique_rows", "_lex_less", "_families", "violations3"),
        (
            "tests/continuous/test_check3d_samples.py",
            "tests/continuous/test_check3d_planted.py",
            "tests/continuous/test_continuous3d.py::test_3d_checker_catches_planted_defects",
        ),
    ),
    Target(
        "check",
        "csplab/continuous/check.py",
        ("neighbourhoods", "violations", "_edge_angles"),
        ("tests/continuous/test_check_planted.py", "tests/continuous/test_continuous.py"),
    ),
    Target(
        "constraints.check",
        "csplab/constraints.py",
        ("Count.check", "Separation.check", "MaxRun.check", "Symmetric.check"),
        ("tests/test_constraints.py", "tests/constraints"),
    ),
    Target(
        "blocks.tasks",
        "csplab/engine/waves.py",
        ("solve_block", "solve_compiled"),
        ("tests/engine/test_waves.py", "tests/solvers/test_blocks_failing.py"),
    ),
    Target(
        "blocks.arrays",
        "csplab/catalog.py",
        ("solve_block_arrays", "block_arrays"),
        (
            "tests/solvers/test_blocks_failing.py::test_failed_blocks_keep_their_labels_in_process",
            "tests/solvers/test_blocks_parallel.py::test_compiled_blocks_same_as_python_blocks_in_waves",
        ),
    ),
    Target(
        "alg31",
        "csplab/engine/alg31.py",
        ("run_alg31",),
        (
            "tests/engine/test_alg31.py::test_run_alg31_is_the_literal_algorithm",
            "tests/engine/test_alg31.py::test_resemblance_windows_are_3_cells_wide_by_default",
            "tests/engine/test_alg31.py::test_global_constraints_refuted_before_any_choice",
            "tests/test_kernels.py::test_alg31_in_chunks_equals_one_run",
            "tests/test_kernels.py::test_alg31_time_limit_chunks_do_not_change_the_grid",
            "tests/engine/test_waves.py",
            *_TWINS,
        ),
        _NOJIT,
    ),
    Target(
        "engine.kernels",
        "csplab/_kernels.py",
        (
            "alg31", "_propagate", "_propagate_w", "propagate", "choose_label", "entropy_of",
            "domain_size", "nth_label", "heap_update", "heap_build", "heap_pop", "_heap_up",
            "_heap_down", "_heap_swap", "ctz64", "popcount64",
        ),
        (*_TWINS, "tests/test_kernels.py::test_alg31_in_chunks_equals_one_run"),
        _NOJIT,
    ),
    Target(
        "engine.interp",
        "csplab/_interp.py",
        (
            "alg31", "_revise", "_choose", "_entropy", "propagate", "_write_back", "set_bits",
            "_ints", "_store",
        ),
        (
            *_TWINS,
            "tests/engine/test_alg31.py::test_run_alg31_is_the_literal_algorithm",
            "tests/test_interp.py::test_interpreted_work_is_counted",
        ),
        _NOJIT,
    ),
    Target(
        "blocks.kernels",
        "csplab/_kernels.py",
        ("block_catalog", "block_alg31"),
        (
            "tests/solvers/test_blocks_failing.py::test_failed_blocks_keep_their_labels_in_process",
            "tests/solvers/test_blocks_parallel.py::test_compiled_blocks_same_as_python_blocks_in_waves",
        ),
        _NOJIT,
    ),
)


def _spans(path: Path, names: tuple[str, ...]) -> list[tuple[str, int, int]]:
    """``(name, first line, last line)`` (1-based) of each named function."""
    tree = ast.parse(path.read_text())
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef):
            for f in node.body:
                if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef):
                    q = f"{node.name}.{f.name}"
                    if q in names:
                        out.append((q, f.lineno, f.end_lineno or f.lineno))
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name in names:
            if node.col_offset == 0:
                out.append((node.name, node.lineno, node.end_lineno or node.lineno))
    missing = set(names) - {n for n, _, _ in out}
    if missing:
        raise SystemExit(f"{path}: no function {sorted(missing)} (renamed? update TARGETS)")
    return out


class _NoStrings(ast.NodeTransformer):
    def visit_Constant(self, node: ast.Constant) -> ast.Constant:
        return ast.Constant("") if isinstance(node.value, str) else node

    def visit_JoinedStr(self, node: ast.JoinedStr) -> ast.AST:
        # an f-string's text parts go; its formatted values stay (a message with "XX"
        # added at an end differs from the original only in a text part)
        node.values = [v for v in node.values if not isinstance(v, ast.Constant)]
        self.generic_visit(node)
        return node


def _code(src: str) -> str | None:
    """The source's syntax tree without its strings (``None``: not Python): mutants of a
    message or a docstring only, and mutants that do not parse, are not run (the checkers'
    messages are for people, not truth)."""
    try:
        return ast.dump(_NoStrings().visit(ast.parse(src)))
    except SyntaxError:
        return None


def mutants(path: Path, names: tuple[str, ...]) -> list[tuple[object, str, str]]:
    """mutmut's mutants of the named functions: ``(mutation id, function, mutated source)``."""
    from mutmut import ALL, Context, list_mutations, mutate

    src = path.read_text()
    spans = _spans(path, names)
    base = _code(src)
    out = []
    for mid in list_mutations(Context(source=src, filename=str(path))):
        line = mid.line_number + 1
        fn = next((n for n, a, b in spans if a <= line <= b), None)
        if fn is None:
            continue
        ctx = Context(source=src, mutation_id=mid, filename=str(path))
        mutated, n = mutate(ctx)
        code = _code(mutated) if n and mutated != src else None
        if code is not None and code != base:
            out.append((mid, fn, mutated))
    assert ALL is not None
    return out


def _copy_tree(dst: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                           check=True).stdout.decode().split("\0")  # fmt: skip
    for f in files:
        if f and (ROOT / f).is_file():
            (dst / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / f, dst / f)


def _run(
    cwd: Path, tests: tuple[str, ...], timeout: float, extra: tuple[tuple[str, str], ...] = ()
) -> tuple[str, float]:
    env = {**os.environ, "PYTHONPATH": str(cwd), "HYPOTHESIS_PROFILE": "default", **dict(extra)}
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-p",
           "no:randomly", "-W", "ignore::RuntimeWarning", "--no-header", *tests]  # fmt: skip
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True,
                           timeout=timeout, check=False)  # fmt: skip
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0
    return ("survived" if r.returncode == 0 else "killed"), time.perf_counter() - t0


def _changed_line(src: str, mutated: str) -> tuple[int, str, str]:
    a, b = src.splitlines(), mutated.splitlines()
    for i, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            return i + 1, x.strip(), y.strip()
    return len(a), "", ""


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "-k", default="", help="the target of this name, or those whose name contains it"
    )
    ap.add_argument("--list", action="store_true", help="count the mutants and stop")
    ap.add_argument(
        "--functions", default="", help="only these functions of the target (comma-separated)"
    )
    ap.add_argument(
        "--sample",
        type=int,
        default=None,
        help="run this many mutants per target, drawn with a fixed seed",
    )
    ap.add_argument("--budget", type=float, default=None, help="stop after so many seconds")
    ap.add_argument("--out", default=None, help="also write the report (markdown) here")
    a = ap.parse_args(argv)
    exact = [t for t in TARGETS if t.name == a.k]
    chosen = exact or [t for t in TARGETS if a.k in t.name]
    t_start = time.perf_counter()
    lines: list[str] = ["| target | mutants | killed | timeout (hang) | survived | score |",
                        "| --- | --- | --- | --- | --- | --- |"]  # fmt: skip
    survivors: list[str] = []
    total = killed_all = 0
    with tempfile.TemporaryDirectory(prefix="csplab-mutmut-") as tmp:
        work = Path(tmp)
        _copy_tree(work)
        for t in chosen:
            path = work / t.path
            src = path.read_text()
            only = tuple(f for f in a.functions.split(",") if f)
            ms = mutants(path, tuple(f for f in t.functions if not only or f in only))
            n_all = len(ms)
            if a.sample is not None and a.sample < len(ms):
                import random

                keep = sorted(random.Random(32).sample(range(len(ms)), a.sample))
                ms = [ms[i] for i in keep]
            if a.list:
                print(f"{t.name}: {len(ms)} mutants in {', '.join(t.functions)}")
                continue
            status, dt = _run(work, t.tests, RUN_TIMEOUT_S, t.env)
            if status != "survived":
                print(f"{t.name}: its tests fail unmutated ({status}); skipped", flush=True)
                continue
            timeout = max(60.0, 5 * dt)  # a mutant 5 times slower than the tests hangs
            counts = {"killed": 0, "timeout": 0, "survived": 0}
            done = 0
            for mid, fn, mutated in ms:
                if a.budget is not None and time.perf_counter() - t_start > a.budget:
                    break
                path.write_text(mutated)
                try:
                    status, dt = _run(work, t.tests, timeout, t.env)
                finally:
                    path.write_text(src)
                counts[status] += 1
                done += 1
                if status == "survived":
                    ln, old, new = _changed_line(src, mutated)
                    survivors.append(f"- `{t.path}:{ln}` ({fn}): `{old}` -> `{new}`")
                print(f"{t.name} {done}/{len(ms)} {fn}:{mid.line_number + 1} {status} "
                      f"({dt:.1f} s)", flush=True)  # fmt: skip
            dead = counts["killed"] + counts["timeout"]
            score = f"{100 * dead / done:.1f} %" if done else "-"
            part = (
                ""
                if done == n_all
                else f" of {n_all}" + (" (sample)" if done == len(ms) else " (budget spent)")
            )
            lines.append(f"| {t.name} | {done}{part} | {counts['killed']} | {counts['timeout']} "
                         f"| {counts['survived']} | {score} |")  # fmt: skip
            total += done
            killed_all += dead
    if a.list:
        return 0
    lines.append(f"| all | {total} | | | {total - killed_all} | "
                 f"{100 * killed_all / max(total, 1):.1f} % |")  # fmt: skip
    report = "\n".join([*lines, "", "Survivors:", *(survivors or ["- none"])])
    print(report)
    if a.out:
        Path(a.out).write_text(report + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
