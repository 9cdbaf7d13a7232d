"""The new-user audit of issue 30, as a script: bad inputs and contract cases through the
``csplab`` command line, each in a fresh folder, with its exit code, time and last line.

    python benchmarks/audit_cli.py            # print the table
    python benchmarks/audit_cli.py --write    # and put it in README.md (reliability section)

Every case runs as a subprocess with a 180 s timeout and a 6 GB address-space limit (a
memory blow-up is a failure, not a frozen machine). ``expect`` is the exit code the
contract asks for: 2 for bad input (one line on stderr), 1 for a failed run, 0 for success.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "csplab" / "examples"
TETRA = (EX / "continuous3d" / "tetrahedron.obj").read_text()


@dataclass
class Case:
    row: str
    argv: list[str]
    expect: int
    #: name -> text, or "copy:PATH", "npy", "stl:ico", "stl:cube", "gon:N"
    files: dict[str, str] = field(default_factory=dict)
    after: str = ""  # a file that must NOT exist afterwards, or "same:NAME" unchanged


def _deep(n: int, key: str) -> str:
    return '{"' + key + '": ' + "[" * n + "]" * n + "}"


def _poly(label: str) -> str:
    return '{"polygons": [{"label": ' + label + ', "points": [[0, 0], [4, 0], [4, 4]]}]}'


def _stl(shape: str) -> str:
    """An ASCII STL of float triangles, as a CAD package exports them: ``ico`` (an
    icosphere of radius 1, 1,280 faces) or ``cube`` (a box with random float corners)."""
    import numpy as np
    import trimesh

    if shape == "ico":
        m = trimesh.creation.icosphere(subdivisions=3)
    else:
        lo = np.random.default_rng(30).random(3)
        m = trimesh.creation.box(bounds=[lo, lo + 1 + np.random.default_rng(31).random(3)])
    return str(m.export(file_type="stl_ascii"))


def _gon(n: int, radius: float) -> str:
    import math

    pts = [[radius * math.cos(2 * math.pi * k / n), radius * math.sin(2 * math.pi * k / n)]
           for k in range(n)]  # fmt: skip
    return json.dumps({"polygons": [{"label": 1, "points": pts}]})


CASES = [
    Case(
        "1",
        ["synthesize", "X.json", "--size", "10x10", "--out", "X.json"],
        2,
        {"X.json": "copy:continuous/triangle.json"},
        "same:X.json",
    ),
    Case(
        "1",
        ["synthesize", "X.obj", "--size", "3x3x3", "--out", "X.obj"],
        2,
        {"X.obj": "copy:continuous3d/tetrahedron.obj"},
        "same:X.obj",
    ),
    Case(
        "1",
        ["synthesize", "X.npy", "--size", "6x6", "--out", "./X.npy"],
        2,
        {"X.npy": "npy"},
        "same:X.npy",
    ),
    Case(
        "2",
        ["synthesize", "big.json", "--size", "6x6", "--out", "r.svg"],
        2,
        {"big.json": _poly("2000000000")},
        "r.svg",
    ),
    Case(
        "2",
        ["show", "big.obj", "--out", "r.png"],
        2,
        {"big.obj": TETRA.replace("usemtl label_1", "usemtl label_2000000000")},
        "r.png",
    ),
    Case(
        "3",
        ["synthesize", "huge.json", "--size", "6x6", "--out", "r.png"],
        2,
        {"huge.json": _poly("1" + "0" * 30)},
        "r.png",
    ),
    Case("4", ["synthesize", "triangle", "--size", "10x10", "--spacing", "1e-9"], 2),
    Case("4", ["synthesize", "houses", "--size", "10x10x6", "--spacing", "1e-9"], 2),
    Case(
        "5",
        ["synthesize", "ico.stl", "--size", "6x6x6", "--out", "r.obj"],
        0,
        {"ico.stl": "stl:ico"},
    ),
    Case(
        "6",
        ["synthesize", "gon.json", "--size", "300x300", "--spacing", "10", "--snap",
         "--out", "r.svg"],
        2,
        {"gon.json": "gon:64"},
        "r.svg",
    ),
    Case(
        "7",
        ["synthesize", "cube.stl", "--size", "3x3x3", "--spacing", "0.5", "--snap",
         "--out", "r.obj"],
        0,
        {"cube.stl": "stl:cube"},
    ),
    Case(
        "14",
        ["synthesize", "houses", "--size", "10x10x4", "--spacing", "1000", "--snap", "--out",
         "r.obj"],
        2,
        after="r.obj",
    ),
    Case(
        "14",
        ["synthesize", "ico.stl", "--size", "6x6x6", "--spacing", "1", "--snap", "--out",
         "r.obj"],
        2,
        {"ico.stl": "stl:ico"},
        "r.obj",
    ),
    Case(
        "14",
        ["synthesize", "triangle", "--size", "10x10", "--spacing", "1000", "--snap", "--out",
         "r.svg"],
        2,
        after="r.svg",
    ),
    Case(
        "8",
        ["synthesize", "fig3_5a", "--size", "6x6", "--constraints", "deep.json"],
        2,
        {"deep.json": _deep(50000, "constraints")},
    ),
    Case(
        "8",
        ["check", "tetrahedron", "t.obj", "--constraints", "deep.json"],
        2,
        {"deep.json": _deep(50000, "constraints"), "t.obj": TETRA},
    ),
    Case(
        "9",
        [
            "synthesize",
            "houses",
            "--size",
            "6x6x3",
            "--constraints",
            "conn.json",
            "--out",
            "r.obj",
            "--restarts",
            "0",
            "--seed",
            "1",
            "--fallback",
            "none",
            "--time-limit",
            "0.001",
        ],
        1,
        {"conn.json": '{"constraints": [{"type": "connected", "labels": [1]}]}'},
        "r.obj",
    ),
    Case(
        "10",
        ["synthesize", "houses", "--size", "6x6x3", "--constraints", "c7.json", "--out", "r.obj"],
        2,
        {"c7.json": '{"constraints": [{"type": "connected", "labels": [7]}]}'},
        "r.obj",
    ),
    Case("11", ["baseline", "texture", "castle", "--size", "10x10x8", "--window", "999"], 2),
    Case("12", ["synthesize", "triangle", "--size", "3000x3000"], 2),
    Case("12", ["synthesize", "houses", "--size", "300x300x100"], 2),
    Case("13", ["baseline", "texture", "castle", "--size", "10x10x8", "--out", "r.svg"], 2),
    Case(
        "13", ["synthesize", "castle", "--size", "6x6x4", "--out", "r.obj"], 2, {"r.mtl/keep": ""}
    ),
    Case("15", ["synthesize", "triangle", "--size", "10x10", "--grid", "hex:odd-r"], 2),
    Case("16", ["explain", "fig3_5a", "--size", "8x8"], 0),
    Case("17", ["synthesize", "castle", "--size", "-5x5x5"], 2),
    Case("17", ["synthesize", "triangle", "--size", "10x10", "--spacing", "abc"], 2),
    Case(
        "19",
        ["synthesize", "fig3_5a", "--size", "6x6", "--constraints", "nan.json"],
        2,
        {"nan.json": '{"constraints": [{"type": "count", "labels": [1], "min": NaN}]}'},
    ),
    Case("19", ["synthesize", "triangle", "--size", "10x10", "--spacing", "0.3"], 2),
    Case(
        "19",
        ["show", "d.svg", "--out", "d.png"],
        2,
        {"d.svg": '<?xml version="1.0"?>\n<!DOCTYPE svg [<!ENTITY a "b">]>\n<svg/>'},
    ),
    Case("-", ["synthesize", "fig3_5a", "--size", "6x6", "--memory-limit", "0"], 2),
    Case("12", ["synthesize", "fig3_5a", "--size", "600x600", "--memory-limit", "0.01"], 2),
    Case("-", ["synthesize", "line", "--size", "12x6", "--seed", "2", "--out", "line.grid"], 0),
    Case("-", ["synthesize", "triangle", "--size", "40x30", "--seed", "1", "--out", "t.svg"], 0),
]


def _limit() -> None:  # the child's address space: a blow-up fails, the machine stays up
    resource.setrlimit(resource.RLIMIT_AS, (6 * 2**30, 6 * 2**30))


def run(case: Case) -> dict[str, object]:
    with tempfile.TemporaryDirectory() as t:
        d = Path(t)
        for name, text in case.files.items():
            p = d / name
            p.parent.mkdir(parents=True, exist_ok=True)
            if text == "npy":
                import numpy as np

                np.save(p, np.array([[0, 0, 1], [0, 1, 1]], dtype=np.int32))
            elif text.startswith("copy:"):
                shutil.copy(EX / text[5:], p)
            elif text.startswith("stl:"):
                p.write_text(_stl(text[4:]))
            elif text.startswith("gon:"):
                p.write_text(_gon(int(text[4:]), 1000.0))
            else:
                p.write_text(text)
        before = {n: (d / n).read_bytes() for n in case.files if (d / n).is_file()}
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        t0 = time.perf_counter()
        try:
            p = subprocess.run([sys.executable, "-m", "csplab", *case.argv], cwd=d, env=env,
                               capture_output=True, text=True, timeout=180,
                               preexec_fn=_limit)  # fmt: skip
            code, out, err = p.returncode, p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            code, out, err = -9, "", "timeout after 180 s"
        dt = time.perf_counter() - t0
        ok = code == case.expect and "Traceback" not in err
        errors = [ln for ln in err.splitlines() if ln.startswith("csplab: error:")]
        if code == 2:
            ok = ok and len(errors) == 1
        if case.after.startswith("same:"):
            name = case.after[5:]
            ok = ok and (d / name).read_bytes() == before[name]
        elif case.after:
            ok = ok and not (d / case.after).exists()
        said = [ln for ln in err.strip().splitlines() if not ln.endswith(" ...")]  # notices
        text = said or out.strip().splitlines()
        last = errors[-1] if errors else (text[-1] if text else "")
        return {"row": case.row, "command": "csplab " + " ".join(case.argv), "exit": code,
                "expect": case.expect, "ok": ok, "time_s": round(dt, 1), "last": last}  # fmt: skip


def table(results: list[dict[str, object]]) -> str:
    lines = ["| row | command | exit | ok | s | last line |", "|---|---|---|---|---|---|"]
    for r in results:
        cmd = str(r["command"]).replace("|", "\\|")
        last = str(r["last"]).replace("|", "\\|")
        if len(last) > 160:
            last = last[:157] + "..."
        lines.append(f"| {r['row']} | `{cmd}` | {r['exit']} | {'yes' if r['ok'] else 'NO'} "
                     f"| {r['time_s']} | {last} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def main() -> int:
    results = [run(c) for c in CASES]
    text = table(results)
    print(text, end="")
    if "--json" in sys.argv:
        print(json.dumps(results, indent=1))
    if "--write" in sys.argv:
        readme = ROOT / "README.md"
        s = readme.read_text(encoding="utf-8")
        a, b = "<!-- audit:begin -->\n", "<!-- audit:end -->"
        head, _, rest = s.partition(a)
        _, _, tail = rest.partition(b)
        readme.write_text(head + a + text + b + tail, encoding="utf-8")
    return 0 if all(r["ok"] for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
