"""The page in a real browser (Debian's chromium with chromium-driver, through Selenium):
load it, pan the world and compare the drawn chunks with ``World.chunk`` pixel by pixel,
paint an edit and check exactly the expected chunks changed, open a 3D result and check
the canvas draws the model in its colours, and try path-escape and oversized requests.

One server and one browser for the module; skipped when chromium, chromium-driver or
Selenium is missing (``.ci/run`` installs them).
"""

from __future__ import annotations

import shutil
import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

pytest.importorskip("starlette")
uvicorn = pytest.importorskip("uvicorn")
webdriver = pytest.importorskip("selenium.webdriver")

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
if not (CHROMIUM and DRIVER):
    pytest.skip("no chromium and chromium-driver here", allow_module_level=True)

from csplab.render import palette  # noqa: E402
from csplab.web.app import create_app  # noqa: E402
from csplab.world import World  # noqa: E402


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    root = tmp_path_factory.mktemp("served")
    port = _free_port()
    cfg = uvicorn.Config(create_app(root), host="127.0.0.1", port=port, log_level="warning")
    srv = uvicorn.Server(cfg)
    t = threading.Thread(target=srv.run, daemon=True)
    t.start()
    for _ in range(200):
        if srv.started:
            break
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}"
    srv.should_exit = True
    t.join(10)


def browser(width: int = 1100, height: int = 760) -> Any:
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    o = Options()
    for a in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
              f"--window-size={width},{height}", "--use-gl=angle", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--force-device-scale-factor=1"]:  # fmt: skip
        o.add_argument(a)
    o.binary_location = CHROMIUM
    return webdriver.Chrome(options=o, service=Service(DRIVER))


@pytest.fixture(scope="module")
def page(server: str) -> Iterator[Any]:
    d = browser()
    d.get(server + "/")
    wait(d, "return !!(window.csplab && window.csplab.ready)")
    yield d
    d.quit()


def wait(d: Any, script: str, timeout: float = 60.0) -> Any:
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        v = d.execute_script(script)
        if v:
            return v
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for: {script}")


def select(d: Any, id_: str, value: str) -> None:
    d.execute_script(f"const e = document.getElementById('{id_}'); e.value = {value!r}; "
                     "e.dispatchEvent(new Event('change'));")  # fmt: skip


def fill(d: Any, id_: str, value: str) -> None:
    el = d.find_element("id", id_)
    el.clear()
    el.send_keys(value)


_RECTS = """
const S = window.csplab, c = document.getElementById('map'), [X, Y] = S.world.chunk;
const out = [];
const i0 = Math.floor(S.view.cx / X), j0 = Math.floor(S.view.cy / Y);
for (let i = i0 - 8; i <= i0 + 8; i++) for (let j = j0 - 8; j <= j0 + 8; j++) {
  const [x, y, w, h] = S.chunkRect(i, j);
  if (x >= 0 && y >= 0 && x + w <= c.width && y + h <= c.height) out.push([i, j, x, y, w, h]);
}
return out;
"""


def canvas(d: Any, id_: str = "map") -> np.ndarray:
    """The canvas' pixels (RGB), read once as a PNG."""
    import base64
    import io

    from PIL import Image

    url = d.execute_script(f"return document.getElementById('{id_}').toDataURL('image/png')")
    png = base64.b64decode(url.split(",", 1)[1])
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def chunk_pixels(d: Any) -> dict[tuple[int, int], np.ndarray]:
    """The pixels of every chunk drawn wholly inside the map."""
    img = canvas(d)
    return {(i, j): img[y : y + h, x : x + w] for i, j, x, y, w, h in d.execute_script(_RECTS)}


def loaded(d: Any) -> None:
    wait(d, "const S = window.csplab; S.drawMap(); return [...S.chunks.values()].every(e => e.ok)")


def test_pan_the_world_and_compare_chunks_with_world_chunk(page: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    select(page, "model", "loops")
    fill(page, "seed", "4")
    fill(page, "chunk", "16x16")
    page.find_element("id", "open-world").click()
    wait(page, "return window.csplab.world && window.csplab.world.id")
    loaded(page)
    start = page.execute_script("return [window.csplab.view.cx, window.csplab.view.cy]")
    canvas = page.find_element("id", "map")
    ActionChains(page).move_to_element(canvas).click_and_hold().move_by_offset(-300, 170) \
        .release().perform()  # fmt: skip
    cx, cy = page.execute_script("return [window.csplab.view.cx, window.csplab.view.cy]")
    assert (cx - start[0], cy - start[1]) == pytest.approx((300 / 8, 170 / 8), abs=0.3)
    loaded(page)
    ref = World("loops", seed=4, chunk=(16, 16))
    cols = palette(ref.K)
    drawn = chunk_pixels(page)
    assert len(drawn) >= 6
    for (i, j), got in drawn.items():
        want = cols[ref.chunk(i, j)]  # [x, y] -> pixels, y up, 8 px per cell
        img = np.repeat(np.repeat(np.transpose(want, (1, 0, 2))[::-1], 8, 0), 8, 1)
        assert (got == img).all(), (i, j)


def test_paint_an_edit_then_exactly_the_expected_chunks_change(page: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    if not page.execute_script("return !!(window.csplab.world)"):
        pytest.skip("the pan test opens the world")
    loaded(page)
    before = chunk_pixels(page)
    chunks = set(before)
    select(page, "tool", "brush")
    select(page, "brush", "label")
    select(page, "label", "1")
    canvas = page.find_element("id", "map")
    ActionChains(page).move_to_element(canvas).click_and_hold().move_by_offset(0, 0) \
        .release().perform()  # fmt: skip
    edit = wait(page, "return window.csplab.lastEdit")
    assert edit["status"] == "solved", edit
    loaded(page)
    after = chunk_pixels(page)
    differ = {c for c in chunks if not (before[c] == after[c]).all()}
    assert differ == {tuple(c) for c in edit["changed"]} & chunks
    assert differ and differ <= {tuple(c) for c in edit["touched"]}
    page.find_element("id", "undo").click()
    wait(page, "return window.csplab.lastUndo")
    loaded(page)
    again = chunk_pixels(page)
    for c in chunks:
        assert (again[c] == before[c]).all(), c
    select(page, "tool", "pan")


def test_a_3d_result_is_drawn_in_the_model_colours(page: Any) -> None:
    page.find_element("id", "flat").click()  # unlit: the canvas shows the material colours
    select(page, "model", "castle")
    fill(page, "size", "8x8x6")
    fill(page, "seed", "1")
    select(page, "solver", "catalog")
    page.find_element("id", "synthesize").click()
    wait(page, "return window.csplab.glbReady", timeout=120)
    time.sleep(0.3)
    img = canvas(page, "viewer")
    bg = np.array([0x20, 0x28, 0x30])
    fg = img[(np.abs(img.astype(int) - bg).sum(axis=-1) > 6)]
    assert len(fg) > 0.02 * img.shape[0] * img.shape[1]
    cols = page.execute_script("return window.csplab.meshColors()")
    want = np.array([[int(c[k : k + 2], 16) for k in (1, 3, 5)] for c in cols])
    near = np.abs(fg[:, None, :].astype(int) - want[None]).max(axis=-1).min(axis=1) <= 3
    assert near.mean() > 0.98, near.mean()
    assert page.execute_script("return window.csplab.run.events.some(e => e.kind === 'done')")


def test_path_escape_and_oversized_requests_are_refused(page: Any) -> None:
    script = """
    const done = arguments[arguments.length - 1];
    const json = {'content-type': 'application/json'};
    const post = (url, body) => fetch(url, {method: 'POST', headers: json, body})
        .then(async r => [r.status, (await r.json()).error]);
    Promise.all([
        post('/api/run', JSON.stringify({command: 'prove', model: '../../../etc/passwd'})),
        post('/api/world', JSON.stringify({model: '/etc/passwd'})),
        post('/api/world', '{"model": "' + 'x'.repeat(200000) + '"}'),
        fetch('/static/../../pyproject.toml').then(r => [r.status, null]),
    ]).then(done);
    """
    got = page.execute_async_script(script)
    assert got[0][0] == 403 and "outside the served directory" in got[0][1]
    assert got[1][0] == 403
    assert got[2][0] == 413
    assert got[3][0] == 404
