"""The README's commands, as a new user runs them (issue 30): every command line in its
shell blocks (``` fences without a language) and every try-it of the formats table, in
order, from the repository root.

The default suite checks that each command parses (the subcommand and every flag exist, the
files it names from the repository are there); ``-m slow`` runs them all, in order, in a
scratch copy of the repository's layout (``csplab``, ``tests`` linked), with the shared test
data at ``../shared/anchors-data`` when it is there (commands on it are skipped otherwise).
Usage synopses (``MODEL``, ``[--flag]``, ``...``) are not commands and are left out.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
SHARED = ROOT.parent / "shared" / "anchors-data"
if not SHARED.is_dir():
    SHARED = Path("/work/shared/anchors-data")
_SYNOPSIS = re.compile(r"\b[A-Z][A-Z_]{2,}\b|\[|\.\.\.|\||path/to/|scheduler:8786")
#: commands that take minutes or set up a new environment: run only with -m slow
_SLOW = ("pip install", "experiment", "run_all.py", "benchmarks/", "--jobs")


def _shell_blocks() -> list[str]:
    out, inside, lang = [], False, ""
    for line in README.splitlines():
        if line.startswith("```"):
            inside, lang = (not inside), line[3:].strip()
            continue
        if inside and not lang:
            out.append(line)
    return out


def commands() -> list[str]:
    """The README's runnable command lines, in order (comments cut, ``\\`` joined)."""
    lines, joined = _shell_blocks(), []
    buf = ""
    for ln in lines:
        buf += ln.rstrip("\\").strip() + " " if ln.endswith("\\") else ln.strip()
        if not ln.endswith("\\"):
            joined.append(buf)
            buf = ""
    table = README.split("<!-- formats:begin -->", 1)[1].split("<!-- formats:end -->")[0]
    for row in table.splitlines()[2:]:
        cell = row.rstrip(" |").rsplit("|", 1)[-1].strip().strip("`")
        joined.append(cell.replace("\\|", "|"))
    out = []
    for c in joined:
        c = c.split("  #")[0].split(" # ")[0].strip()
        if not c.startswith(("csplab ", "python ", "python3 ")) or c == "csplab info":
            if c != "csplab info":
                continue
        if _SYNOPSIS.search(c.replace(".[test]", "").replace("'.[", "'")):
            continue
        if c not in out:
            out.append(c)
    return out


def _parts(cmd: str) -> list[list[str]]:
    return [shlex.split(p) for p in cmd.split("&&")]


def test_the_readme_has_commands():
    cmds = commands()
    assert len(cmds) >= 15, cmds
    assert any("synthesize triangle" in c for c in cmds)


@pytest.mark.parametrize("cmd", commands())
def test_every_readme_command_parses(cmd):
    """The subcommand and its flags exist; the repository files it names are there."""
    from csplab.cli import build_parser

    for words in _parts(cmd):
        if words[0] != "csplab":
            continue
        build_parser().parse_args(words[1:])  # SystemExit(2) on an unknown flag
        for w in words[1:]:
            if "/" in w and not w.startswith(("../", "-")) and "=" not in w:
                assert (ROOT / w).exists(), (cmd, w)


@pytest.mark.slow
def test_readme_commands_run_in_order(tmp_path):
    repo = tmp_path / "repo"
    repo.mkdir()
    for name in ("csplab", "tests", "experiments", "benchmarks", "pyproject.toml"):
        (repo / name).symlink_to(ROOT / name)
    if SHARED.is_dir():
        (tmp_path / "shared").mkdir()
        (tmp_path / "shared" / "anchors-data").symlink_to(SHARED)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    failures = []
    for cmd in commands():
        if any(s in cmd for s in _SLOW):
            continue
        if "../shared/" in cmd and not SHARED.is_dir():
            continue
        for words in _parts(cmd):
            argv = [sys.executable, "-m", "csplab", *words[1:]] if words[0] == "csplab" else [
                sys.executable, *words[1:]]  # fmt: skip
            p = subprocess.run(argv, cwd=repo, env=env, capture_output=True, text=True,
                               timeout=600)  # fmt: skip
            if p.returncode != 0:
                failures.append((cmd, p.returncode, (p.stderr or p.stdout).strip()[-300:]))
                break
    assert not failures, failures
