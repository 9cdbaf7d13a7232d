"""Digests of one seeded output of every built-in example, through the command line.

Run before and after a change that should not alter outputs (a refactoring); the two lists
must be equal line for line::

    python benchmarks/output_digests.py > before.txt   # on the old commit
    python benchmarks/output_digests.py > after.txt    # on the new one
    diff before.txt after.txt

Each line: example, size, the SHA-256 of the output file, and the command's exit code; the
3D grid examples have a second line, ``blocks``: the same command with ``--solver blocks
--block 6`` (modify in blocks, its compiled sweep).
"""

from __future__ import annotations

import hashlib
import subprocess
import sys
import tempfile
from pathlib import Path

#: size and output extension by the kind of example (see ``csplab info``)
SIZES = {"grid2": ("20x20", ".npy"), "grid3": ("12x12x8", ".npy"),
         "polygons": ("20x20", ".json"), "polyhedra": ("8x8x6", ".obj")}


def kinds() -> list[tuple[str, str]]:
    """(name, kind) of every built-in example, read from ``csplab info``."""
    out = subprocess.run([sys.executable, "-m", "csplab", "info"], capture_output=True,
                         text=True, check=True).stdout
    rows = out.split("built-in examples:", 1)[1].split("file formats", 1)[0].splitlines()
    found = []
    for row in rows:
        parts = row.split(None, 1)
        if len(parts) < 2:
            continue
        name, text = parts
        if text.startswith("polygons:"):
            found.append((name, "polygons"))
        elif text.startswith("polyhedra:"):
            found.append((name, "polyhedra"))
        elif text.startswith("3D"):
            found.append((name, "grid3"))
        else:
            found.append((name, "grid2"))
    return found


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind in kinds():
            size, ext = SIZES[kind]
            out = Path(tmp) / f"{name}{ext}"
            cmd = [sys.executable, "-m", "csplab", "synthesize", name, "--size", size,
                   "--seed", "1", "--out", str(out)]
            if kind == "grid3":
                cmd += ["--boundary", "auto"]
            if name == "hexriver":
                cmd += ["--grid", "hex:odd-r"]
            if name == "trifan":
                cmd += ["--grid", "tri"]
            runs = [("", cmd)]
            if kind == "grid3":  # modify in blocks too (its compiled sweep: many blocks)
                runs.append(("blocks", [*cmd, "--solver", "blocks", "--block", "6"]))
            for solver, argv in runs:
                out.unlink(missing_ok=True)
                rc = subprocess.run(argv, capture_output=True, text=True).returncode
                digest = hashlib.sha256(out.read_bytes()).hexdigest()[:16] if out.exists() else "-"
                print(f"{name:14s} {size:8s} {digest} exit={rc}{' ' + solver if solver else ''}",
                      flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
