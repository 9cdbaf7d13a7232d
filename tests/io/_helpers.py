"""Shared paths and solver lists for the format tests."""

from pathlib import Path

import pytest

import csplab

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
