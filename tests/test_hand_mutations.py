"""The hand mutations of issue 32, each killed by its tests (slow: several minutes).

``benchmarks/hand_mutations.py`` copies the work tree, applies each mutation (a sampling of
the 3D checker removed, a failed block handing back partial labels, Efros-Leung matching
loosely or not at all, a graph-cut seam priced wrongly, the SAT oracle without
at-most-one) and runs the tests that guard it; every mutation must make them fail."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_mutations_listed() -> None:
    """The script knows its mutations and each names an existing test file."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import hand_mutations as hm
    finally:
        sys.path.pop(0)
    assert len(hm.MUTATIONS) >= 9
    for m in hm.MUTATIONS:
        assert (ROOT / m.path).read_text().count(m.old) == 1, m.id  # not stale
        for t in m.tests:
            assert (ROOT / t.split("::")[0]).exists(), (m.id, t)


@pytest.mark.slow
def test_every_hand_mutation_is_killed() -> None:
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "hand_mutations.py")],
                       capture_output=True, text=True, check=False)  # fmt: skip
    assert r.returncode == 0, r.stdout + r.stderr
