"""The web app through Starlette's TestClient: chunks equal World.chunk cell by cell, edits
change only the chunks around them (and undo), runs stream progress, and the server refuses
path escapes, oversized and cross-site requests with one line."""

from __future__ import annotations

import io
import json
import os
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx")
from PIL import Image
from starlette.testclient import TestClient

from csplab.render import palette
from csplab.web.app import create_app
from csplab.web.safety import Limits
from csplab.world import World

J = {"content-type": "application/json"}


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("served")
    (d / "mine.grid").write_text((Path("csplab/examples/fig3_4a_column.grid")).read_text())
    paths = ["path_x", "path_y", "corner_+x+y", "corner_-x+y", "corner_+x-y", "corner_-x-y"]
    (d / "one_loop.json").write_text(json.dumps({"constraints": [
        {"type": "connected", "labels": paths},
        {"type": "count", "labels": ["path_x"], "min": 4, "max": 6},
    ]}))  # fmt: skip
    outside = tmp_path_factory.mktemp("outside")
    (outside / "secret.grid").write_text("secret")
    os.symlink(outside / "secret.grid", d / "link.grid")
    return d


@pytest.fixture(scope="module")
def client(root: Path) -> TestClient:
    return TestClient(create_app(root, Limits(cells=64 * 64, body_bytes=4096)))


def _cells(png: bytes, shape: tuple[int, int], scale: int = 8) -> np.ndarray:
    """The colour at the centre of every cell ``[x, y]`` of a chunk picture (y up)."""
    a = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    X, Y = shape
    return np.array([[a[(Y - 1 - y) * scale + scale // 2, x * scale + scale // 2]
                      for y in range(Y)] for x in range(X)])  # fmt: skip


def _world(client: TestClient, **kw: object) -> dict:
    r = client.post("/api/world", json={"model": "loops", "seed": 5, "chunk": "16x16", **kw})
    assert r.status_code == 200, r.text
    return r.json()


def test_meta_form_comes_from_the_solver_declarations(client: TestClient) -> None:
    from csplab.solvers import available_solvers

    m = client.get("/api/meta").json()
    want = {s["name"]: [o["name"] for o in s.get("options", [])] for s in available_solvers()}
    got = {s["name"]: [o["name"] for o in s.get("options", [])] for s in m["solvers"]}
    assert got == want
    assert "mine.grid" in m["files"] and "link.grid" not in m["files"]
    assert ".npy" in m["formats"] and ".png" in m["formats"]


def test_a_world_takes_the_alg31_orders_not_catalogs_auto(client: TestClient) -> None:
    """The world form offers the catalog solver's orders; ``auto`` (catalog's default, by
    a whole problem's global constraints) is refused in one line, the others accepted."""
    assert _world(client, order="min-entropy")["order"] == "min-entropy"
    r = client.post("/api/world", json={"model": "loops", "chunk": "16x16", "order": "auto"})
    assert r.status_code == 400 and "not auto" in r.json()["error"]


def test_chunk_pictures_are_world_chunks_cell_by_cell(client: TestClient) -> None:
    w = _world(client)
    ref = World("loops", seed=5, chunk=(16, 16))
    cols = palette(ref.K)
    assert w["colors"] == ["#" + "".join(f"{v:02x}" for v in c) for c in cols]
    for i, j in [(0, 0), (-3, 2), (7, -1)]:
        png = client.get(f"/api/world/{w['id']}/chunk/{i}/{j}.png").content
        assert (_cells(png, (16, 16)) == cols[ref.chunk(i, j)]).all()


def test_an_edit_changes_only_the_chunks_around_it_and_undo_restores(client: TestClient) -> None:
    w = _world(client, seed=7)
    wid = w["id"]
    around = [(i, j) for i in range(-2, 4) for j in range(-2, 4)]
    before = {c: client.get(f"/api/world/{wid}/chunk/{c[0]}/{c[1]}.png").content for c in around}
    r = client.post(f"/api/world/{wid}/edit", json={"brush": "label", "label": 1, "x0": 20,
                                                     "x1": 21, "y0": 20, "y1": 21})  # fmt: skip
    e = r.json()
    assert e["status"] == "solved", e
    after = {c: client.get(f"/api/world/{wid}/chunk/{c[0]}/{c[1]}.png").content for c in around}
    changed = {c for c in around if before[c] != after[c]}
    assert changed == {tuple(c) for c in e["changed"]}
    assert changed <= {tuple(c) for c in e["touched"]} and (1, 1) in changed
    # the painted cell holds the label, and the edited world is consistent
    g = client.get(f"/api/world/{wid}/download?region=0:48,0:48&format=.npy").content
    grid = np.load(io.BytesIO(g))
    assert grid[20, 20] == 1
    ref = World("loops", seed=7, chunk=(16, 16))
    assert len(ref.problem((48, 48)).violations(grid)) == 0
    assert (grid != ref.region((0, 48), (0, 48))).any()
    u = client.post(f"/api/world/{wid}/undo", json={}).json()
    assert u["edits"] == 0
    again = {c: client.get(f"/api/world/{wid}/chunk/{c[0]}/{c[1]}.png").content for c in around}
    assert again == before


def test_a_freehand_stroke_fixes_only_its_cells(client: TestClient) -> None:
    wid = _world(client, seed=9)["id"]
    stroke = [[10, 10], [11, 10], [12, 10]]
    e = client.post(f"/api/world/{wid}/edit", json={"brush": "label", "label": 1, "x0": 10,
                                                    "x1": 13, "y0": 10, "y1": 11,
                                                    "cells": stroke}).json()  # fmt: skip
    assert e["status"] == "solved", e
    g = np.load(io.BytesIO(client.get(f"/api/world/{wid}/download?region=0:32,0:32&format=.npy")
                           .content))  # fmt: skip
    assert [int(g[x, y]) for x, y in stroke] == [1, 1, 1]
    bad = client.post(f"/api/world/{wid}/edit", json={"brush": "label", "label": 1, "x0": 10,
                                                      "x1": 13, "y0": 10, "y1": 11,
                                                      "cells": [[30, 30]]})  # fmt: skip
    assert bad.status_code == 400 and "outside the rectangle" in bad.json()["error"]


def test_an_impossible_edit_is_refused_with_its_unsat_core(client: TestClient) -> None:
    wid = _world(client, seed=2)["id"]
    before = client.get(f"/api/world/{wid}/chunk/0/0.png").content
    # a 2x2 square of one corner piece: corners cannot touch that way
    e = client.post(f"/api/world/{wid}/edit", json={"brush": "label", "label": 3, "x0": 4,
                                                    "x1": 6, "y0": 4, "y1": 6}).json()  # fmt: skip
    assert e["status"] == "unsat" and e["core"], e
    assert all(4 <= x < 6 and 4 <= y < 6 for x, y in e["core"]) and len(e["core"]) < 4
    assert client.get(f"/api/world/{wid}/chunk/0/0.png").content == before


def test_path_escapes_are_refused(client: TestClient) -> None:
    for name in ["../x.grid", "/etc/passwd", "link.grid", "a/../../x.grid"]:
        r = client.post("/api/run", json={"command": "prove", "model": name})
        assert r.status_code == 403, (name, r.text)
        assert "outside the served directory" in r.json()["error"]
    r = client.post("/api/world", json={"model": "nothere.grid"})
    assert r.status_code == 400 and "no such model file" in r.json()["error"]
    assert client.get("/static/../../../etc/passwd").status_code == 404
    assert client.get("/static/%2e%2e/%2e%2e/app.py").status_code == 404


def test_oversized_and_bad_requests_get_one_line(client: TestClient) -> None:
    r = client.post("/api/world", content=b"{" + b" " * 10000 + b"}", headers=J)
    assert r.status_code == 413
    wid = _world(client)["id"]
    r = client.get(f"/api/world/{wid}/download?region=0:1000,0:1000&format=.npy")
    assert r.status_code == 400 and "more than the limit" in r.json()["error"]
    r = client.post("/api/run", json={"command": "synthesize", "model": "loops", "size": "500x500"})
    assert r.status_code == 400 and "limit" in r.json()["error"]
    r = client.post("/api/world", content=b"not json", headers=J)
    assert r.status_code == 400 and r.json() == {"error": "the request body is not JSON"}
    r = client.post(f"/api/world/{wid}/edit", json={"brush": "paint", "x0": 0, "x1": 1,
                                                    "y0": 0, "y1": 1})  # fmt: skip
    assert r.status_code == 400 and "brush must be one of" in r.json()["error"]
    r = client.get(f"/api/world/{wid}/download?region=0:8,0:8&format=.exe")
    assert r.status_code == 400 and "\n" not in r.json()["error"]
    assert client.get("/api/world/w999/chunk/0/0.png").status_code == 404


def test_cross_site_edits_are_refused(client: TestClient) -> None:
    wid = _world(client)["id"]
    body = json.dumps({"brush": "reroll", "x0": 0, "x1": 2, "y0": 0, "y1": 2})
    for headers in [{**J, "origin": "http://evil.example"}, {**J, "sec-fetch-site": "cross-site"},
                    {"content-type": "text/plain"}]:  # fmt: skip
        r = client.post(f"/api/world/{wid}/edit", content=body, headers=headers)
        assert r.status_code == 403, headers
    same = {**J, "origin": "http://testserver", "sec-fetch-site": "same-origin"}
    r = client.post(f"/api/world/{wid}/edit", content=body, headers=same)
    assert r.status_code == 200


def _finish(client: TestClient, body: dict) -> dict:
    jid = client.post("/api/run", json=body).json()["id"]
    with client.stream("GET", f"/api/run/{jid}/events") as s:
        events = [json.loads(line[6:]) for line in s.iter_lines() if line.startswith("data: {\"")]
    r = client.get(f"/api/run/{jid}").json()
    r["events"] = events
    return r


def test_runs_stream_their_progress_and_give_files(client: TestClient) -> None:
    r = _finish(client, {"command": "synthesize", "model": "loops", "size": "12x12", "seed": 3,
                         "solver": "backtrack"})  # fmt: skip
    assert r["state"] == "done" and r["result"]["status"] == "solved", r
    assert [e["kind"] for e in r["events"]][:2] == ["queued", "running"]
    assert r["events"][-1]["kind"] == "done"
    png = client.get(f"/api/run/{r['id']}/result.png")
    assert png.content[:4] == b"\x89PNG"
    g = np.load(io.BytesIO(client.get(f"/api/run/{r['id']}/download?format=.npy").content))
    from csplab import from_example, load_example

    assert g.shape == (12, 12) and from_example(load_example("loops"), (12, 12)).is_solution(g)
    bad = _finish(client, {"command": "synthesize", "model": "loops", "size": "8x8",
                           "solver": "catalog", "options": {"order": "nonsense"}})  # fmt: skip
    assert bad["state"] == "error" and "nonsense" in bad["error"]
    assert "Traceback" not in bad["error"]


def test_a_3d_result_is_a_glb_of_the_model(client: TestClient) -> None:
    trimesh = pytest.importorskip("trimesh")
    r = _finish(client, {"command": "synthesize", "model": "castle", "size": "8x8x6", "seed": 1})
    assert r["state"] == "done" and r["result"]["status"] == "solved", r
    data = client.get(f"/api/run/{r['id']}/result.glb").content
    scene = trimesh.load(io.BytesIO(data), file_type="glb")
    assert data[:4] == b"glTF" and len(scene.geometry) >= 1


def test_witness_replay_empties_the_catalog(client: TestClient) -> None:
    r = _finish(client, {"command": "witness", "model": "fig3_5a", "order": "scan:yx",
                         "max_size": "4x4", "time_limit": 30})  # fmt: skip
    assert r["result"]["holds"] is False, r
    rep = client.get(f"/api/run/{r['id']}/replay").json()
    steps = rep["steps"]
    assert len(steps) == len(rep["witness"]["choices"]) + 1
    assert steps[0]["wiped"] == [] and steps[-1]["wiped"] != []
    sizes = [sum(map(sum, s["sizes"])) for s in steps]
    assert sizes == sorted(sizes, reverse=True)  # the catalog only shrinks
    p = _finish(client, {"command": "prove", "model": "fig3_15"})
    assert p["result"]["holds"] is True and "infallible" in p["result"]["message"]


def test_progress_events_of_a_world_region(client: TestClient) -> None:
    from csplab.progress import listen, progress_bar

    seen: list[tuple[str, int, int | None]] = []
    t0 = time.monotonic()
    with listen(lambda d, n, t: seen.append((d, n, t))):
        World("fig3_4a", seed=1, chunk=(8, 8)).region((0, 24), (0, 16), progress=True)
        list(progress_bar(range(3), total=3, desc="x", enabled=False))  # off: not reported
    assert seen[0] == ("chunks", 0, 6) and seen[-1] == ("chunks", 6, 6)
    assert time.monotonic() - t0 < 60


def test_global_constraints_are_shown_on_the_result(client: TestClient) -> None:
    r = _finish(client, {"command": "synthesize", "model": "loops", "size": "10x10", "seed": 2,
                         "solver": "sat", "constraints": "one_loop.json"})  # fmt: skip
    assert r["state"] == "done" and r["result"]["status"] == "solved", r
    g = np.load(io.BytesIO(client.get(f"/api/run/{r['id']}/download?format=.npy").content))
    rows = client.get(f"/api/run/{r['id']}/constraints").json()["constraints"]
    assert [(c["kind"], c["holds"]) for c in rows] == [("connected", True), ("count", True)]
    assert rows[0]["cells"] == int((g > 0).sum()) and 4 <= rows[1]["cells"] == int((g == 1).sum())
    plain = np.asarray(Image.open(io.BytesIO(client.get(f"/api/run/{r['id']}/result.png").content)))
    shown = np.asarray(Image.open(io.BytesIO(
        client.get(f"/api/run/{r['id']}/constraints.png").content)).convert("RGB"))
    s = plain.shape[1] // 10
    for x, y in [(x, y) for x in range(10) for y in range(10)]:
        at = ((9 - y) * s + s // 2, x * s + s // 2)
        same = (plain[at][:3] == shown[at]).all()
        assert same == bool(g[x, y] > 0), (x, y)  # the empty cells are faded
    bad = client.post("/api/run", json={"command": "synthesize", "model": "loops",
                                        "constraints": "../../etc/passwd"})  # fmt: skip
    assert bad.status_code == 403


def test_a_continuous_result_downloads_in_its_formats(client: TestClient) -> None:
    r = _finish(client, {"command": "synthesize", "model": "two_objects", "size": "8x6",
                         "seed": 1})  # fmt: skip
    assert r["state"] == "done" and r["result"]["status"] == "solved", r
    assert ".svg" in r["formats"] and ".npy" not in r["formats"]
    svg = client.get(f"/api/run/{r['id']}/download?format=.svg")
    assert svg.status_code == 200 and b"<svg" in svg.content
    assert client.get(f"/api/run/{r['id']}/result.png").content[:4] == b"\x89PNG"
    assert client.get(f"/api/run/{r['id']}/download?format=.npy").status_code == 400


def test_a_world_region_streams_its_chunks(client: TestClient) -> None:
    r = _finish(client, {"command": "world", "model": "fig3_4a", "chunk": "8x8", "seed": 3,
                         "region": "-8:24,0:16"})  # fmt: skip
    assert r["state"] == "done" and r["result"]["violations"] == 0, r
    got = [(e["done"], e["total"]) for e in r["events"] if e["kind"] == "progress"]
    assert got and got[-1] == (8, 8) and all(t == 8 for _, t in got)
    g = np.load(io.BytesIO(client.get(f"/api/run/{r['id']}/download?format=.npy").content))
    assert (g == World("fig3_4a", seed=3, chunk=(8, 8)).region((-8, 24), (0, 16))).all()
