"""The package stays `ruff` clean and `mypy --strict` clean (skipped when the tools are absent)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _tool(name):
    exe = Path(sys.executable).parent / name
    return str(exe) if exe.exists() else shutil.which(name)


@pytest.mark.parametrize(
    "cmd",
    [["ruff", "check", "csplab", "tests", "benchmarks", "experiments"], ["mypy"]],
    ids=["ruff", "mypy"],
)
def test_clean(cmd):
    exe = _tool(cmd[0])
    if exe is None:
        pytest.skip(f"{cmd[0]} not installed")
    args = cmd[1:2] + [a for a in cmd[2:] if (ROOT / a).exists()]
    r = subprocess.run([exe, *args], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
