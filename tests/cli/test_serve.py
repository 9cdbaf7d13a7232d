"""``csplab serve``: the command starts the page (and its vendored three.js) on 127.0.0.1;
bad input is one line and exit 2 before anything is served."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
ROOT = Path(__file__).resolve().parents[2]


def _csplab(args: list[str], cwd: Path, **kw: object) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "csplab", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **kw)  # type: ignore[call-overload]  # fmt: skip


@pytest.mark.parametrize(("args", "says"), [
    (["--port", "0"], "--port must be 1..65535, not 0"),
    (["nothere.grid"], "nothere.grid: no such model file in the served directory"),
    (["../secret.grid"], "'../secret.grid' is outside the served directory"),
])  # fmt: skip
def test_bad_input_is_one_line(args: list[str], says: str, tmp_path: Path) -> None:
    p = _csplab(["serve", *args], tmp_path)
    _, err = p.communicate(timeout=120)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert p.returncode == 2 and lines == [f"csplab: error: {says}"], err


def test_serve_starts_the_page_on_localhost(tmp_path: Path) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    (tmp_path / "mine.grid").write_text((ROOT / "csplab/examples/fig3_4a_column.grid").read_text())
    p = _csplab(["serve", "mine.grid", "--port", str(port)], tmp_path)
    try:
        base = f"http://127.0.0.1:{port}"
        for _ in range(300):
            try:
                page = urllib.request.urlopen(base + "/", timeout=2).read().decode()
                break
            except OSError:
                time.sleep(0.1)
        else:
            raise AssertionError("the server did not start")
        assert "<title>csplab</title>" in page and "vendor/three" in page
        js = urllib.request.urlopen(base + "/static/vendor/three/build/three.module.js").read()
        assert b"REVISION" in js
        meta = urllib.request.urlopen(base + "/api/meta").read().decode()
        assert '"start":"mine.grid"' in meta and '"mine.grid"' in meta
    finally:
        p.terminate()
        _, err = p.communicate(timeout=30)
    assert f"serving {tmp_path.resolve()} on http://127.0.0.1:{port}/" in err
