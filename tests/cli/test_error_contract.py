"""Bad input ends in one line naming the file or argument (exit 2), checked before the work
(issue 12, item 8): output paths, results stores, model files that are not regular files or
too large, time limits; result grids with unassigned cells and csplab's own ``.vox`` files
are read by ``check`` and ``show``; ``show`` keeps existing pictures; ``count --time-limit``;
the one-time compilation notice."""

import os
import sqlite3
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from csplab.cli import main
from csplab.errors import CsplabError, FormatError, InputError
from csplab.io import common as io_common

LINUX = sys.platform.startswith("linux")


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err, *words):
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in lines[0], (w, err)
    return lines[0]


def bad(capsys, *argv, words=()):
    code, out, err = run(capsys, *argv)
    assert code == 2, (code, out, err)
    return one_line(err, *words)


# ---------------------------------------------------------------------------- --out paths
@pytest.mark.parametrize(
    "argv",
    [
        ["show", "line", "--out", "{missing}/line.png"],
        ["prove", "line", "--out", "{missing}/run.png"],
        ["refine", "line", "--out", "{missing}/ei.grid"],
        ["reduction", "planar3sat", "--seed", "1", "--png", "{missing}/m.png"],
        ["reduction", "planar3sat", "--seed", "1", "--solution-png", "{missing}/s.png"],
        ["reduction", "planar3sat", "--seed", "1", "--labels-png", "{missing}/l.png"],
        ["reduction", "lba", "anbncn", "--input", "ab", "--png", "{missing}/l.png"],
    ],
)
def test_out_into_a_missing_folder_is_one_line_before_the_work(capsys, tmp_path, argv):
    missing = tmp_path / "no" / "such"
    argv = [a.replace("{missing}", str(missing)) for a in argv]
    line = bad(capsys, *argv, words=(str(missing),))
    assert "does not exist" in line
    assert not missing.exists()


def test_out_is_a_folder_or_under_a_file(capsys, tmp_path):
    (tmp_path / "f").write_text("x")
    bad(capsys, "show", "line", "--out", str(tmp_path / "f" / "a.png"), words=("not a folder",))
    d = tmp_path / "d.png"
    d.mkdir()
    bad(capsys, "show", "line", "--out", str(d), "--force", words=("is a folder",))


@pytest.mark.skipif(not LINUX, reason="/proc is Linux's")
def test_out_into_an_unwritable_folder(capsys):
    # /proc/self exists and nobody (not even root) may create files in it
    bad(capsys, "show", "line", "--out", "/proc/self/line.png", words=("not writable",))
    bad(capsys, "prove", "line", "--out", "/proc/self/run.json", words=("not writable",))


def test_prove_out_extension_is_checked_first(capsys, tmp_path):
    bad(capsys, "prove", "line", "--out", str(tmp_path / "run.txt"), words=(".png", ".json"))


def test_refine_out_format_is_checked_first(capsys, tmp_path):
    bad(capsys, "refine", "line", "--out", str(tmp_path / "ei.xyz"), words=(".xyz",))


# ---------------------------------------------------------------------------- experiment
def _exp(tmp_path, *extra):
    return ["experiment", "fig3_8", "--quick", "--example", "line", "--seeds", "1",
            "--jobs", "1", "--no-progress", "--no-figures", *extra]  # fmt: skip


def test_experiment_out_under_a_file(capsys, tmp_path):
    (tmp_path / "f").write_text("x")
    argv = _exp(tmp_path, "--store", str(tmp_path / "r.sqlite"), "--out", str(tmp_path / "f" / "o"))
    bad(capsys, *argv, words=("--out", "is a file"))
    assert not (tmp_path / "r.sqlite").exists()  # nothing was run


def test_experiment_store_not_a_database(capsys, tmp_path):
    s = tmp_path / "notes.sqlite"
    s.write_text("hello, these are my notes\n")
    bad(capsys, *_exp(tmp_path, "--store", str(s), "--out", str(tmp_path / "o")),
        words=(str(s), "not an SQLite database"))  # fmt: skip
    assert s.read_text() == "hello, these are my notes\n"


def test_experiment_store_truncated(capsys, tmp_path):
    s = tmp_path / "r.sqlite"
    db = sqlite3.connect(s)
    db.execute("CREATE TABLE t (x TEXT)")
    db.executemany("INSERT INTO t VALUES (?)", [("x" * 200,)] * 2000)
    db.commit()
    db.close()
    data = s.read_bytes()
    s.write_bytes(data[: len(data) // 2])
    bad(capsys, *_exp(tmp_path, "--store", str(s), "--out", str(tmp_path / "o")),
        words=(str(s), "truncated"))  # fmt: skip
    s.write_bytes(data[:50])  # not even a whole header
    bad(capsys, *_exp(tmp_path, "--store", str(s), "--out", str(tmp_path / "o")),
        words=(str(s), "truncated"))  # fmt: skip


def test_experiment_store_unwritable_paths(capsys, tmp_path):
    (tmp_path / "f").write_text("x")
    bad(capsys, *_exp(tmp_path, "--store", str(tmp_path / "f" / "r.sqlite")),
        words=("--store", "is a file"))  # fmt: skip
    d = tmp_path / "dir.sqlite"
    d.mkdir()
    bad(capsys, *_exp(tmp_path, "--store", str(d)), words=("--store", "is a folder"))
    if LINUX:
        bad(capsys, *_exp(tmp_path, "--store", "/proc/self/r.sqlite"), words=("not writable",))


def test_results_store_opening_errors_are_csplab_errors(tmp_path):
    from csplab.experiments.store import ResultsStore

    (tmp_path / "x.sqlite").write_bytes(b"SQLite format 3\x00" + b"\xff" * 84)
    (tmp_path / "y.sqlite").write_text("not sqlite")
    for name in ("x.sqlite", "y.sqlite"):
        with pytest.raises(CsplabError, match=name):
            ResultsStore(tmp_path / name)
    ResultsStore(tmp_path / "new" / "r.sqlite").close()  # a new store in a new folder is fine


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_experiment_time_limit_must_be_positive(capsys, tmp_path, value):
    argv = _exp(tmp_path, "--store", str(tmp_path / "r.sqlite"), "--out", str(tmp_path / "o"))
    bad(capsys, *argv, f"--time-limit={value}", words=("--time-limit", "positive"))
    assert not (tmp_path / "r.sqlite").exists()


# ---------------------------------------------------------------------------- time limits
@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), "0", True])
def test_solver_time_limit_must_be_positive_and_finite(value):
    from csplab import load_example
    from csplab.grids import from_example
    from csplab.solvers import solve

    P = from_example(load_example("line"), (6, 4))
    with pytest.raises(InputError, match="time_limit must be a positive number of seconds"):
        solve(P, "catalog", rng=0, time_limit=value)
    assert solve(P, "catalog", rng=0, time_limit=5).status == "solved"


@pytest.mark.parametrize("value", ["0", "-2", "nan"])
def test_synthesize_time_limit_must_be_positive(capsys, tmp_path, value):
    bad(capsys, "synthesize", "line", "--size", "6x4", f"--time-limit={value}",
        words=("time_limit",))  # fmt: skip


@pytest.mark.parametrize("value", ["0", "-2", "nan"])
def test_count_time_limit_must_be_positive(capsys, value):
    bad(capsys, "count", "line", "--size", "6x4", f"--time-limit={value}",
        words=("--time-limit", "positive"))  # fmt: skip


# ---------------------------------------------------------------------------- model files
@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_dev_zero_is_refused_without_reading(capsys):
    bad(capsys, "synthesize", "/dev/zero", "--size", "4x4", words=("/dev/zero", "regular file"))
    bad(capsys, "show", "/dev/zero", "--out", "/dev/null/x.png", words=("/dev/null",))
    with pytest.raises(FormatError, match="character device"):
        io_common.read_bytes("/dev/zero")
    with pytest.raises(FormatError, match="character device"):
        io_common.read_bytes("/dev/zero", 16)  # not even a sniffer's head


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_fifo_is_refused_without_hanging(capsys, tmp_path):
    fifo = tmp_path / "grid.npy"
    os.mkfifo(fifo)
    result = {}

    def go():
        result["check"] = run(capsys, "check", "line", str(fifo))

    t = threading.Thread(target=go, daemon=True)
    t.start()
    t.join(30)
    if t.is_alive():  # unblock the reader so the test process can end, then fail
        with open(fifo, "wb"):
            pass
        pytest.fail("reading a FIFO hung")
    code, _, err = result["check"]
    assert code == 2
    one_line(err, str(fifo), "FIFO")
    txt = tmp_path / "model.txt"
    os.mkfifo(txt)
    bad(capsys, "synthesize", str(txt), "--size", "4x4", words=("FIFO",))


def test_size_cap(capsys, tmp_path, monkeypatch):
    p = tmp_path / "big.grid"
    p.write_text("0 1\n1 0\n")
    monkeypatch.setattr(io_common, "MAX_FILE_BYTES", 4)
    bad(capsys, "synthesize", str(p), "--size", "4x4", words=(str(p), "MiB"))
    with pytest.raises(FormatError, match="at most"):
        io_common.read_text(p)
    assert io_common.read_bytes(p, 3) == b"0 1"  # a sniffer's head is still fine
    monkeypatch.setattr(io_common, "MAX_FILE_BYTES", 256 * 2**20)
    assert run(capsys, "synthesize", str(p), "--size", "4x4", "--seed", "1")[0] == 0


def test_size_cap_is_documented():
    assert io_common.MAX_FILE_BYTES == 256 * 2**20
    assert "MAX_FILE_BYTES" in io_common.__all__


# ---------------------------------------------------------------------------- -1 grids and .vox
def _partial_grid(tmp_path, shape=(6, 4)):
    from csplab import load_example
    from csplab.grids import from_example
    from csplab.solvers import solve

    r = solve(from_example(load_example("line"), shape), "catalog", rng=0)
    g = np.array(r.grid, dtype=np.int32)
    g[0, 0] = -1
    g[2, 1] = -1
    p = tmp_path / "failed.npy"
    np.save(p, g)
    return p


def test_check_reports_unassigned_cells(capsys, tmp_path):
    p = _partial_grid(tmp_path)
    code, out, err = run(capsys, "check", "line", str(p))
    assert code == 1 and "Traceback" not in err and err == ""
    assert "2 of 24 cells are unassigned" in out
    code, out, _ = run(capsys, "check", "line", str(p), "--json")
    import json

    d = json.loads(out)
    assert code == 1 and d["unassigned"] == 2 and d["violations"] >= 2


def test_check_refuses_labels_below_minus_one(capsys, tmp_path):
    p = tmp_path / "bad.npy"
    np.save(p, np.full((6, 4), -2, dtype=np.int32))
    bad(capsys, "check", "line", str(p), words=(str(p), "-2"))


def test_show_draws_unassigned_cells(capsys, tmp_path):
    from PIL import Image

    p = _partial_grid(tmp_path)
    out = tmp_path / "failed.png"
    code, text, err = run(capsys, "show", str(p), "--out", str(out), "--scale", "4")
    assert code == 0 and err == "" and out.is_file()
    assert "2 unassigned cells" in text
    assert Image.open(out).size == (24, 16)
    g = np.zeros((4, 4, 3), dtype=np.int32)
    g[..., 0] = 1
    g[1, 1, 1] = -1
    np.save(tmp_path / "p3.npy", g)
    code, text, _ = run(capsys, "show", str(tmp_path / "p3.npy"), "--out", str(tmp_path / "p3.png"))
    assert code == 0 and "1 unassigned cells" in text


def test_check_reads_its_own_vox(capsys, tmp_path):
    from csplab import load_example
    from csplab.grids import from_example
    from csplab.io import write_labels
    from csplab.solvers import solve

    city = load_example("city")
    P = from_example(city, (6, 6, 5), boundary="auto")
    r = solve(P, "catalog", rng=1)
    assert r.status == "solved"
    v = tmp_path / "city.vox"
    write_labels(r.grid, v, model=city)
    code, out, err = run(capsys, "check", "city", str(v), "--boundary", "auto")
    assert code == 0 and err == "" and "0 violations" in out, (out, err)
    # a wrong label makes it fail: the labels were mapped back, not taken as colours
    g = np.array(r.grid)
    empty = int(g[0, 0, -1])  # the sky (what the .vox leaves out)
    for b in range(city.K):
        g[2, 2, 2] = b
        if b != empty and len(P.violations(g)):
            break
    assert len(P.violations(g))
    write_labels(g, v, model=city)
    assert run(capsys, "check", "city", str(v), "--boundary", "auto")[0] == 1


# ---------------------------------------------------------------------------- show --force
def test_show_keeps_an_existing_picture(capsys, tmp_path):
    out = tmp_path / "line.png"
    assert run(capsys, "show", "line", "--out", str(out))[0] == 0
    before = out.read_bytes()
    line = bad(capsys, "show", "line", "--out", str(out), "--scale", "3", words=(str(out),))
    assert "--force" in line and out.read_bytes() == before
    assert run(capsys, "show", "line", "--out", str(out), "--scale", "3", "--force")[0] == 0
    assert out.read_bytes() != before


def test_show_default_name_is_protected_too(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert run(capsys, "show", "line")[0] == 0
    bad(capsys, "show", "line", words=("line.png", "--force"))


# ---------------------------------------------------------------------------- count --time-limit
def test_count_time_limit_exit_3(capsys):
    code, out, err = run(capsys, "count", "line", "--size", "40x40", "--time-limit", "1e-6")
    assert code == 3 and err == ""
    assert len(out.strip().splitlines()) == 1 and "undecided" in out
    code, out, _ = run(capsys, "count", "line", "--size", "4x3", "--time-limit", "30")
    assert code == 0 and "= 625" in out.replace("D_E(4x3) = ", "= ")


@pytest.mark.parametrize("method", ["transfer", "enumerate", "ganak"])
def test_count_solutions_time_limit(method):
    from csplab import load_example
    from csplab.count import CountTimeoutError, count_solutions
    from csplab.deps import available
    from csplab.grids import from_example

    if method == "ganak" and not available("pyganak"):
        pytest.skip("pyganak not installed")
    line = load_example("line")
    small = from_example(line, (4, 3))
    assert count_solutions(small, method, time_limit=30) == 625
    big = from_example(line, (30, 30))
    with pytest.raises(CountTimeoutError, match=method) as e:
        count_solutions(big, method, time_limit=1e-6)
    assert isinstance(e.value, CsplabError) and isinstance(e.value, TimeoutError)
    with pytest.raises(InputError, match="time_limit"):
        count_solutions(small, method, time_limit=0)


# ---------------------------------------------------------------------------- compilation notice
def test_compilation_notice_only_when_numba_compiles_a_csplab_function(capsys):
    pytest.importorskip("numba")
    import types

    import csplab.cli as cli
    from csplab.cli.common import COMPILING

    def event(module, start=True):
        d = types.SimpleNamespace(py_func=types.SimpleNamespace(__module__=module))
        return types.SimpleNamespace(is_start=start, is_end=not start, data={"dispatcher": d})

    notice = cli._compile_listener()
    notice.notify(event("numpy_helpers"))  # another package's function: no notice
    notice.notify(event("csplab._kernels", start=False))
    assert capsys.readouterr().err == ""
    notice.notify(event("csplab._kernels"))
    notice.notify(event("csplab.solvers.ac"))  # once per process
    assert capsys.readouterr().err.splitlines() == [f"csplab: {COMPILING}"]


def test_sat_with_its_kernels_cached_prints_no_notice(tmp_path):
    """Alg. 3.1's kernels never compiled (its cache stays cold): a --solver sat run prints
    the notice when it compiles its own kernels, and not again once they are cached."""
    pytest.importorskip("numba")
    code = (
        "from csplab.cli import main; "
        "main(['synthesize', 'castle', '--size', '12x12x6', '--solver', 'sat', '--seed', '1', "
        f"'--out', {str(tmp_path / 'o.npy')!r}], announce=True)"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    errs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True)  # fmt: skip
        assert out.returncode == 0, out.stderr
        errs.append(out.stderr)
    assert "compiling csplab's kernels" in errs[0]
    assert "compiling" not in errs[1], errs[1]


def test_small_synthesis_needs_no_numba_and_prints_no_notice(tmp_path):
    """A cold numba cache and a small model: the interpreted engine solves it, so numba is
    never imported and the compiling notice is not printed."""
    code = (
        "import sys; from csplab.cli import main; "
        "rc = main(['synthesize', 'line', '--size', '12x8', '--seed', '1', '--out', "
        f"{str(tmp_path / 'o.npy')!r}], announce=True); "
        "print('numba' in sys.modules, rc)"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip().splitlines()[-1] == "False 0", out.stdout + out.stderr
    assert "compiling" not in out.stderr
    assert (tmp_path / "o.npy").is_file()


def test_show_tiles_draws_unassigned_cells_dark(capsys, tmp_path):
    from PIL import Image

    g = np.zeros((3, 3), dtype=np.int32)
    g[1, 1] = -1
    np.save(tmp_path / "t.npy", g)
    out = tmp_path / "t.png"
    xml = Path(__file__).resolve().parents[1] / "io" / "data" / "pipes.xml"
    code, text, err = run(capsys, "show", str(tmp_path / "t.npy"), "--tiles", str(xml),
                          "--out", str(out))  # fmt: skip
    assert code == 0 and err == "" and "1 unassigned cells" in text
    im = np.asarray(Image.open(out).convert("RGB"), dtype=int)
    h, w = im.shape[0] // 3, im.shape[1] // 3
    centre, corner = im[h : 2 * h, w : 2 * w], im[:h, :w]
    assert centre.mean() < 80 < corner.mean()  # the unassigned cell is dark, tile 0 is not
