"""Apply each hand mutation of issue 32, one at a time, and run the tests that must kill it.

Every mutation below once passed the whole suite: a sampling of the 3D checker removed, a
block that failed every retry handing back its partial labels, the Efros-Leung baseline
matching loosely or not at all, the SAT oracle accepting models with several labels in a
cell; or survived ``benchmarks/mutation_run.py`` until a test was written for it (the 3D
checker's sampling of edges and of the example's triangles, a block's deadline, the
interpreted engine's wipe-out at cell 0 and entropy of tiny weights, the cell
Alg. 3.1 names when a global constraint's root pruning ends in a wipe-out). The script copies
the tracked files of the work tree to a temporary directory (the work tree itself is never
changed), checks that the killing tests pass there
unmutated, then applies each mutation (an exact text replacement, which must match once)
and runs its tests: a mutation is *killed* when they fail.

Usage::

    python benchmarks/hand_mutations.py            # every mutation
    python benchmarks/hand_mutations.py -k check3d # those whose id contains "check3d"
    python benchmarks/hand_mutations.py --list

The exit status is 0 when every mutation selected was killed. Each run stops at its first
failing test (``-x``) and has a time box (``--timeout``, default 300 s; a run that does not
answer in time has hung and counts as killed, marked so). numba's on-disk cache of the copy
is kept between runs: a mutated file gets a modification time of its own (so its kernels
and bytecode are compiled afresh, never taken from the cache of the unmutated file or of
another mutant) and gets its original
time back with its original text (so the unmutated kernels' cache stays valid). ``--out``
also writes the report to a file.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT_S = 300.0  # a test run that takes longer has hung: the mutation is killed


@dataclass(frozen=True)
class Mutation:
    """One hand mutation: replace ``old`` (which occurs once in ``path``) by ``new``."""

    id: str
    path: str
    old: str
    new: str
    tests: tuple[str, ...]
    what: str


MUTATIONS: tuple[Mutation, ...] = (
    Mutation(
        "check3d-no-edge-pieces",
        "csplab/continuous/check3d.py",
        "out.append(_edge_pieces(edges[:, 0], edges[:, 1], verts))",
        "out.append(np.zeros((0, 3)))",
        ("tests/continuous/test_check3d_planted.py::test_crossing_bars_only_edge_pieces_see",),
        "the output's edge pieces are not sampled",
    ),
    Mutation(
        "check3d-no-triangle-centres",
        "csplab/continuous/check3d.py",
        "        out.append(tri.mean(axis=1))\n        # every edge once",
        "        # every edge once",
        (
            "tests/continuous/test_check3d_planted.py"
            "::test_a_box_on_part_of_a_triangle_only_triangle_centres_see",
        ),
        "the output's triangle centres are not sampled",
    ),
    Mutation(
        "check3d-no-vertices",
        "csplab/continuous/check3d.py",
        "    out = [verts]\n",
        "    out = [verts[:0]]\n",
        (
            "tests/continuous/test_check3d_planted.py::test_cubes_meeting_at_a_corner_only_vertices_see",
        ),
        "the models' vertices are not sampled",
    ),
    Mutation(
        "check2d-no-overlap-by-shapes",
        "csplab/continuous/check.py",
        "            if both.area > 1e-12 * scale * scale:",
        "            if False:",
        ("tests/continuous/test_check_planted.py",),
        "the 2D checker looks for overlapping labels at ring nodes only",
    ),
    Mutation(
        "blocks-compiled-partial-labels",
        "csplab/catalog.py",
        "return (lgrid if ok else None), int(counters[2]), int(counters[3])",
        "return lgrid, int(counters[2]), int(counters[3])",
        ("tests/solvers/test_blocks_failing.py",),
        "a compiled block task returns its partial labels after failing every retry",
    ),
    Mutation(
        "blocks-interpreted-partial-labels",
        "csplab/engine/waves.py",
        "    return BlockOutcome(block, None, status, retry_count, revisions)",
        "    return BlockOutcome(block, r.grid.reshape(-1), status, retry_count, revisions)",
        ("tests/solvers/test_blocks_failing.py",),
        "an interpreted block task returns its partial labels after failing every retry",
    ),
    Mutation(
        "alg31-label-draws-reversed",
        "csplab/engine/alg31.py",
        "    ustream = rng.random(n)\n    noise",
        "    ustream = 1.0 - rng.random(n)\n    noise",
        ("tests/engine/test_alg31.py::test_run_alg31_is_the_literal_algorithm",),
        "the compiled Alg. 3.1 draws its labels from the other end of the catalog",
    ),
    Mutation(
        "alg31-root-constraint-wipe-out-unnamed",
        "csplab/engine/alg31.py",
        'stats["fail_cell"] = list(problem.coords(got)) if got >= 0 else None',
        'stats["fail_cell"] = None',
        (
            "tests/engine/test_alg31.py"
            "::test_a_global_constraint_pruning_left_to_arc_consistency_names_the_wiped_cell",
        ),
        "a root pruned by a global constraint then wiped by arc consistency names no cell",
    ),
    Mutation(
        "check3d-example-sampled-as-output-at-dense-2",
        "csplab/continuous/check3d.py",
        "    if dense <= 1:\n",
        "    if dense <= 2:\n",
        ("tests/continuous/test_check3d_samples.py",),
        "the example gets the output's sampling when dense=2 (the mutation_run survivor)",
    ),
    Mutation(
        "check3d-first-edge-of-each-triangle-unsampled",
        "csplab/continuous/check3d.py",
        "ab = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]]",
        "ab = np.concatenate([tri[:, [0, 2]], tri[:, [1, 2]]",
        ("tests/continuous/test_check3d_samples.py",),
        "an edge that is the first edge of both its triangles is not sampled",
    ),
    Mutation(
        "check3d-example-grid-off-the-triangles",
        "csplab/continuous/check3d.py",
        "u, w = i / dense, j / dense",
        "u, w = i * dense, j / dense",
        ("tests/continuous/test_check3d_samples.py",),
        "the example's grid of points lies off its triangles",
    ),
    Mutation(
        "blocks-deadline-a-second-per-attempt",
        "csplab/engine/waves.py",
        "max(0.0, deadline - time.perf_counter())",
        "max(1.0, deadline - time.perf_counter())",
        ("tests/engine/test_waves.py",),
        "a block's attempt gets a second of its own after the deadline (the deadline gap)",
    ),
    Mutation(
        "interp-wipe-out-of-cell-0-goes-on",
        "csplab/_interp.py",
        "        if wiped >= 0:\n            break\n",
        "        if wiped >= 1:\n            break\n",
        ("tests/test_interp.py::test_propagate_stops_at_a_wipe_out_of_cell_0",),
        "the interpreted propagation goes on after cell 0 is wiped out",
    ),
    Mutation(
        "interp-tiny-weights-entropy",
        "csplab/_interp.py",
        "    return math.log(s) - sl / s\n",
        "    return math.log(s) + sl / s\n",
        ("tests/test_interp.py::test_alg31_same_as_kernels_with_labels_of_weight_0",),
        "the interpreted entropy of a domain of tiny weights has the wrong sign",
    ),
    Mutation(
        "efros-leung-threshold-10",
        "csplab/baselines/texture.py",
        "cand = np.flatnonzero(dist <= best * (1.0 + eps))",
        "cand = np.flatnonzero(dist <= best * 10)",
        ("tests/baselines/test_texture_guarded.py",),
        "Efros-Leung keeps candidates within 10 times the best distance, not 1 + eps",
    ),
    Mutation(
        "efros-leung-random-position",
        "csplab/baselines/texture.py",
        "out[cell] = ex_lab[int(cand[gen.integers(len(cand))])]",
        "out[cell] = ex_lab[int(gen.integers(len(ex_lab)))]",
        ("tests/baselines/test_texture_guarded.py",),
        "Efros-Leung copies the label of a random example position",
    ),
    Mutation(
        "graphcut-seam-half-cost",
        "csplab/baselines/texture.py",
        "w[tuple(a)] = diff[tuple(a)] + diff[tuple(b)] + 1e-6",
        "w[tuple(a)] = diff[tuple(a)] + 1e-6",
        ("tests/baselines/test_texture_guarded.py",),
        "a graph-cut seam is priced by one side's mismatch only",
    ),
    Mutation(
        "geometry-search-farthest-first",
        "csplab/baselines/geometry.py",
        "dist = ((content - pyr[lvl + 1][None, :]) ** 2).mean(axis=1)",
        "dist = -((content - pyr[lvl + 1][None, :]) ** 2).mean(axis=1)",
        ("tests/baselines/test_geometry.py::test_a_block_of_the_source_finds_an_identical_block",),
        "the block search pops the farthest node first",
    ),
    Mutation(
        "sat-lazy-amo-never-refined",
        "csplab/engine/sat.py",
        "                if multi.size == 0:\n",
        "                if True:\n",
        ("tests/solvers/test_conformance_amo.py",),
        "the SAT oracle accepts a model with several labels in a cell (lazy at-most-one)",
    ),
    Mutation(
        "cnf-amo-skips-two-label-cells",
        "csplab/cnf.py",
        "    cand = cand[size[cand] >= 2]\n",
        "    cand = cand[size[cand] >= 3]\n",
        ("tests/solvers/test_conformance_amo.py",),
        "eager at-most-one clauses leave out the cells with two labels",
    ),
)


def _copy_tree(dst: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                           check=True).stdout.decode().split("\0")  # fmt: skip
    for f in files:
        if not f or not (ROOT / f).is_file():
            continue
        (dst / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dst / f)
    # tests not yet committed (a work tree in progress) come along too
    for f in (ROOT / "tests").rglob("*.py"):
        t = dst / f.relative_to(ROOT)
        if not t.exists():
            t.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(f, t)


def _pytest(cwd: Path, tests: tuple[str, ...], timeout: float) -> tuple[bool, float, str]:
    env = {**os.environ, "PYTHONPATH": str(cwd)}
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
           "-p", "no:randomly", *tests]  # fmt: skip
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False,
                           timeout=timeout)  # fmt: skip
    except subprocess.TimeoutExpired:
        return False, time.perf_counter() - t0, f"no answer in {timeout:.0f} s (a hang)"
    lines = r.stdout.strip().splitlines() or [""]
    failed = [ln.split()[1] for ln in lines if ln.startswith(("FAILED ", "ERROR "))]
    tail = lines[-1] if not failed else f"{lines[-1]}: {', '.join(failed)}"
    if r.returncode not in (0, 1):  # not a test failure: an error of the run itself
        tail = f"exit {r.returncode}: " + " | ".join(
            (r.stdout + r.stderr).strip().splitlines()[-3:]
        )
    return r.returncode == 0, time.perf_counter() - t0, tail


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-k", default="", help="only mutations whose id contains this")
    ap.add_argument("--list", action="store_true", help="list the mutations and stop")
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S,
                    help="seconds a test run may take before it counts as a hang")  # fmt: skip
    ap.add_argument("--out", default=None, help="also write the report here")
    a = ap.parse_args(argv)
    chosen = [m for m in MUTATIONS if a.k in m.id]
    if a.list:
        for m in chosen:
            print(f"{m.id}: {m.what} ({m.path}) <- {', '.join(m.tests)}")
        return 0
    killed = 0
    report: list[str] = []

    def say(line: str) -> None:
        print(line, flush=True)
        report.append(line)

    t_all = time.perf_counter()
    baseline: dict[tuple[str, ...], tuple[bool, float, str]] = {}
    with tempfile.TemporaryDirectory(prefix="csplab-mut-") as tmp:
        work = Path(tmp)
        _copy_tree(work)
        for m in chosen:
            src = work / m.path
            text = src.read_text()
            if text.count(m.old) != 1:
                say(f"{m.id}: STALE (the text to mutate occurs {text.count(m.old)} times)")
                continue
            if m.tests not in baseline:  # each set of tests once, unmutated
                baseline[m.tests] = _pytest(work, m.tests, a.timeout)
            ok, dt, tail = baseline[m.tests]
            if not ok:
                say(f"{m.id}: BROKEN (the tests fail unmutated: {tail})")
                continue
            stamp = src.stat().st_mtime_ns
            src.write_text(text.replace(m.old, m.new))
            # a time of its own (one per mutation: two mutants of one file may have the same
            # size), so neither Python's bytecode cache nor numba's takes another's code
            own = stamp + (1 + MUTATIONS.index(m)) * 7_000_000_000
            os.utime(src, ns=(own, own))
            try:
                ok, dt, tail = _pytest(work, m.tests, a.timeout)
            finally:
                src.write_text(text)
                os.utime(src, ns=(stamp, stamp))
            status = "survived" if ok else "killed"
            killed += not ok
            say(f"{m.id}: {status} in {dt:.0f} s by {' '.join(m.tests)} [{tail}]")
    say(f"{killed} of {len(chosen)} hand mutations killed "
        f"({time.perf_counter() - t_all:.0f} s in all)")  # fmt: skip
    if a.out:
        Path(a.out).write_text("\n".join(report) + "\n")
    return 0 if killed == len(chosen) else 1


if __name__ == "__main__":
    sys.exit(main())
