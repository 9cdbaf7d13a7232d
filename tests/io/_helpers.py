"""Shared paths, format samples and solver lists for the format tests."""

import functools
import tempfile
from pathlib import Path

import numpy as np
import pytest

import csplab
from csplab.io import model_format
from csplab.io.common import Output
from csplab.io.registry import FORMATS

DATA = Path(__file__).resolve().parent / "data"
ANCHORS = Path(__file__).resolve().parents[3] / "shared" / "anchors-data"
if not ANCHORS.exists():
    ANCHORS = Path("/work/shared/anchors-data")


def anchor(rel: str) -> Path:
    """A file of the shared external test data, or skip the test."""
    p = ANCHORS / rel
    if not p.is_file():
        pytest.skip(f"external test data {rel} not present")
    return p


def installed_solvers() -> list[str]:
    return [s["name"] for s in csplab.available_solvers() if s.get("installed")]


@functools.cache
def format_sample(name: str) -> tuple[str, bytes]:
    """A small file of format ``name``, as (file name, content): the smallest file of
    ``DATA`` detected as ``name``, else a 3x3x2 grid written by the format's own writer."""
    fmt = FORMATS[name]
    found = sorted(
        (p for p in DATA.iterdir() if p.is_file() and model_format(p) == name),
        key=lambda p: p.stat().st_size,
    )
    if found:
        return found[0].name, found[0].read_bytes()
    if fmt.writable:
        grid = np.arange(18, dtype=np.int32).reshape(3, 3, 2) % 3
        with tempfile.TemporaryDirectory() as d:
            p = Path(d) / f"sample{fmt.extensions[0]}"
            fmt.write(Output.of(grid, names=["air", "ground", "wall"]), p)
            return p.name, p.read_bytes()
    pytest.fail(f"no sample of the {name} format: add a small file to {DATA}")


def copy_companions(folder: Path) -> None:
    """Copy the folders that sample files refer to (``samples/``, ``tilesets/``: the files
    a WFC samples list names) from ``DATA`` into ``folder``."""
    import shutil

    for sub in ("samples", "tilesets"):
        if (DATA / sub).is_dir() and not (folder / sub).exists():
            shutil.copytree(DATA / sub, folder / sub)
