"""Where every measured number in README.md comes from, and the quoted outputs rerun.

README.md quotes two kinds of measured numbers:

- the output of its example commands (``prints `solved: triangle 40x30 ... 14581 vertices
  ...```): this script reruns each command (:data:`QUOTED`) in a fresh folder and compares
  every count the README quotes (vertices, edges, K, polygons, solids, violations) with the
  run, printing "matches" or both numbers; times are printed beside the README's (they
  depend on the machine and are not compared);
- figures of benchmarks, experiments and audits: each paragraph that quotes them
  (:data:`SOURCES`, a phrase of the paragraph) must name the script or command that
  regenerates them in the same paragraph; the script checks that it does and that the
  script exists (``tests/test_readme_numbers.py`` runs this check in the suite).

Usage::

    python benchmarks/readme_numbers.py            # both checks (the commands take ~1 min)
    python benchmarks/readme_numbers.py --sources  # only the paragraph check

The exit status is 0 when every count matches and every paragraph names its source.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

#: (the command as the README shows it, a phrase that starts its quoted output)
QUOTED: tuple[tuple[str, str], ...] = (
    ("csplab synthesize triangle --size 40x30 --seed 1 --out triangle.svg",
     "prints `solved: triangle 40x30"),
    ("csplab synthesize houses --size 20x20x8 --seed 1 --out houses.obj",
     "prints `solved: houses 20x20x8"),
)  # fmt: skip

#: (a phrase of a README paragraph quoting measured figures, what regenerates them: a
#: ``benchmarks/`` or ``experiments/`` script path, or a ``csplab`` command)
SOURCES: tuple[tuple[str, str], ...] = (
    ("Time to a valid 40×40×10 model", "benchmarks/bench_solvers.py"),
    ("pays for writing 1.3–6 million clauses", "benchmarks/bench_solvers.py"),
    ("Efros-Leung breaks 67–103 of 12,864 arcs", "csplab experiment baselines"),
    ("0.17 s instead of 0.58 s", "benchmarks/bench_startup.py"),
    ("29 of 29 killed", "benchmarks/mutation_run.py"),
    ("each of its 20 mutations is killed", "benchmarks/hand_mutations.py"),
    ("<!-- audit:begin -->", "benchmarks/audit_cli.py"),
    ("5–30% of the cells built", "csplab experiment constraints"),
    ("finds a 2×5×4 witness", "csplab witness castle"),
    ("prints `solved: triangle 40x30", "benchmarks/readme_numbers.py"),
    ("prints `solved: houses 20x20x8", "benchmarks/readme_numbers.py"),
)

_COUNTS = (
    ("vertices", r"(\d+) vertices"),
    ("edges", r"(\d+)\s+edges"),
    ("K", r"K=(\d+)"),
    ("polygons", r"(\d+) polygons"),
    ("solids", r"(\d+) solids"),
    ("violations", r"violations=(\d+)"),
)
_TIMES = r"(catalog in|csp|solve|geometry|check) ([\d.]+) s"


def paragraph(text: str, phrase: str) -> str:
    """The README paragraph (text between blank lines) that contains ``phrase``; a table
    or a generated section counts with the prose just before it."""
    i = text.find(phrase)
    if i < 0:
        return ""
    a = text.rfind("\n\n", 0, max(i - 1, 0))
    a = text.rfind("\n\n", 0, a) if text[a + 2 : i].lstrip().startswith(("|", "<!--")) else a
    b = text.find("\n\n", i)
    return text[a + 2 if a >= 0 else 0 : b if b >= 0 else len(text)]


def check_sources(text: str) -> list[str]:
    """One line per entry of :data:`SOURCES`: ``ok`` or what is wrong."""
    out = []
    for phrase, source in SOURCES:
        par = paragraph(text, phrase)
        path = source if "/" in source else None
        if not par:
            out.append(f"MISSING  {phrase!r} is no longer in README.md (update SOURCES)")
        elif source not in par and Path(source).name not in par:
            out.append(f"NO SOURCE  the paragraph with {phrase!r} does not name {source}")
        elif path is not None and not (ROOT / path).exists():
            out.append(f"NO SCRIPT  {path} does not exist")
        else:
            out.append(f"ok  {phrase!r} <- {source}")
    return out


def _numbers(s: str) -> dict[str, str]:
    got = {}
    for name, rx in _COUNTS:
        m = re.search(rx, s)
        if m:
            got[name] = m.group(1)
    return got


def rerun(text: str) -> tuple[list[str], bool]:
    """Run each :data:`QUOTED` command; compare its counts with the README's."""
    lines, ok = [], True
    for cmd, phrase in QUOTED:
        i = text.find(phrase)
        quoted = text[i : text.find("\n\n", i)] if i >= 0 else ""
        quoted = re.sub(r"\s+", " ", quoted)
        want = _numbers(quoted)
        with tempfile.TemporaryDirectory() as tmp:
            env = {**os.environ, "PYTHONPATH": str(ROOT)}
            t0 = time.perf_counter()
            r = subprocess.run([sys.executable, "-m", "csplab", *cmd.split()[1:]], cwd=tmp,
                               env=env, capture_output=True, text=True, check=False)  # fmt: skip
            dt = time.perf_counter() - t0
        got = _numbers(r.stdout)
        lines.append(f"$ {cmd}   (exit {r.returncode}, {dt:.1f} s)")
        if not want:
            lines.append(f"  the README has no quoted output starting {phrase!r}")
            ok = False
        for name in want:
            same = want[name] == got.get(name)
            ok &= same
            verdict = "matches" if same else f"DIFFERS: the run gives {got.get(name)}"
            lines.append(f"  {name}: README {want[name]}, {verdict}")
        t_readme = dict(re.findall(_TIMES, quoted))
        t_run = dict(re.findall(_TIMES, r.stdout))
        for k, v in t_readme.items():
            lines.append(f"  time {k}: README {v} s, this run {t_run.get(k, '-')} s "
                         "(machine-dependent, not compared)")  # fmt: skip
    return lines, ok


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    text = README.read_text(encoding="utf-8")
    src = check_sources(text)
    print("README paragraphs with measured figures and what regenerates them:")
    print("\n".join(src))
    ok = all(s.startswith("ok") for s in src)
    if "--sources" not in args:
        print("\nThe README's quoted outputs, rerun:")
        lines, same = rerun(text)
        print("\n".join(lines))
        ok &= same
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
