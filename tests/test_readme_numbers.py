"""Issue 30 row 24: every measured figure the README quotes names what regenerates it
(``benchmarks/readme_numbers.py``; its rerun of the quoted commands is the script's
slow part, the paragraph check runs here)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
try:
    import readme_numbers as rn
finally:
    sys.path.pop(0)


def test_every_measured_paragraph_names_its_script() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    bad = [line for line in rn.check_sources(text) if not line.startswith("ok")]
    assert not bad, bad


def test_the_check_notices_a_paragraph_without_its_source() -> None:
    text = "Intro.\n\nTime to a valid 40×40×10 model: 0.06 s.\n\nNext paragraph names " \
           "benchmarks/bench_solvers.py.\n"  # fmt: skip
    lines = rn.check_sources(text)
    assert any(ln.startswith("NO SOURCE") and "40×40×10" in ln for ln in lines), lines
    assert any(ln.startswith("MISSING") for ln in lines)


def test_the_counts_of_a_quoted_output_are_read() -> None:
    quoted = ("prints `solved: triangle 40x30 spacings of 1 (3 edge directions, 14581 "
              "vertices, 32640 edges, K=8) with catalog in 0.277 s, seed 1`, then `887 "
              "polygons`")  # fmt: skip
    assert rn._numbers(quoted) == {"vertices": "14581", "edges": "32640", "K": "8",
                                   "polygons": "887"}  # fmt: skip
