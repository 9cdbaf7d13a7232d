"""``csplab show --legend``."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image


def test_show_legend(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from csplab.cli import main

    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert main(["show", "city", "--out", str(a)]) == 0
    assert main(["show", "city", "--out", str(b), "--legend"]) == 0
    capsys.readouterr()
    with Image.open(a) as ia, Image.open(b) as ib:
        assert ib.width > ia.width
