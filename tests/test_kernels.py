"""The compiled kernels: the one-module cache rule, argument bundles and return codes."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

import csplab
from csplab import ExampleModel, grids
from csplab import _kernels as kern
from csplab.catalog import Code, Propagator, Run, Search
from csplab.engine.alg31 import run_alg31
from csplab.grids import from_example
from csplab.testing.synthetic import box_town

PKG = Path(csplab.__file__).resolve().parent
KERNELS = "csplab._kernels"
_JIT = {"njit", "jit"}


# ----------------------------------------------------------------------------- cache rule


def _is_jit(dec: ast.expr) -> bool:
    f = dec.func if isinstance(dec, ast.Call) else dec
    return (isinstance(f, ast.Name) and f.id in _JIT) or (
        isinstance(f, ast.Attribute) and f.attr in _JIT
    )


def _jitted(tree: ast.Module) -> dict[str, ast.FunctionDef]:
    return {
        node.name: node
        for node in tree.body
        if isinstance(node, ast.FunctionDef) and any(_is_jit(d) for d in node.decorator_list)
    }


def _resolve(module: str, is_pkg: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    parts = module.split(".")
    base = parts if is_pkg else parts[:-1]
    base = base[: len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _aliases(module: str, is_pkg: bool, tree: ast.Module) -> dict[str, str]:
    """Local name -> dotted target (a module, or ``module.function``)."""
    out: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                out[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom):
            src = _resolve(module, is_pkg, node)
            for a in node.names:
                out[a.asname or a.name] = f"{src}.{a.name}"
    return out


def _dotted(expr: ast.expr) -> str | None:
    if isinstance(expr, ast.Name):
        return expr.id
    if isinstance(expr, ast.Attribute):
        head = _dotted(expr.value)
        return None if head is None else f"{head}.{expr.attr}"
    return None


def njit_rule_violations(sources: dict[str, tuple[str, bool]]) -> list[str]:
    """``@njit`` functions outside :mod:`csplab._kernels` that call a csplab ``@njit`` function.

    ``sources`` maps a module name to ``(source, is_package)``. A call counts when its target
    resolves (through the module's imports, or to its own top level) to a jitted function of
    a csplab module.
    """
    trees = {m: ast.parse(src) for m, (src, _) in sources.items()}
    jitted = {f"{m}.{name}" for m, t in trees.items() for name in _jitted(t)}
    bad = []
    for m, tree in trees.items():
        if m == KERNELS:
            continue
        alias = _aliases(m, sources[m][1], tree)
        for fname, fn in _jitted(tree).items():
            for call in (n for n in ast.walk(fn) if isinstance(n, ast.Call)):
                name = _dotted(call.func)
                if name is None:
                    continue
                head, _, rest = name.partition(".")
                target = alias.get(head, f"{m}.{head}") + (f".{rest}" if rest else "")
                if target in jitted:
                    bad.append(f"{m}.{fname} calls @njit {target} (line {call.lineno})")
    return bad


def _package_sources() -> dict[str, tuple[str, bool]]:
    out = {}
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (path.read_text(encoding="utf-8"), is_pkg)
    return out


def test_njit_callers_of_csplab_kernels_live_in_kernels():
    """The kernel cache rule of :mod:`csplab._kernels` (numba caches per file)."""
    sources = _package_sources()
    assert KERNELS in sources and len(_jitted(ast.parse(sources[KERNELS][0]))) > 20
    assert njit_rule_violations(sources) == []


def test_architecture_names_every_module_with_numba_code():
    """ARCHITECTURE.md's "Compiled kernels" says where the numba code is: every module with a
    jitted function, and no module without one."""
    text = (PKG.parent / "ARCHITECTURE.md").read_text(encoding="utf-8")
    section = text.split("## Compiled kernels", 1)[1].split("\n## ", 1)[0]
    named = set(re.findall(r"`(csplab/[\w/]+\.py)`", section))
    with_numba = {
        m.replace(".", "/") + ("/__init__.py" if is_pkg else ".py")
        for m, (src, is_pkg) in _package_sources().items()
        if _jitted(ast.parse(src))
    }
    assert with_numba - named == set(), "numba code in modules ARCHITECTURE.md does not name"
    assert named - with_numba - {"csplab/_jit.py", "csplab/_interp.py"} == set(), (
        "ARCHITECTURE.md names modules without numba code"
    )


def test_njit_rule_checker_finds_cross_module_calls():
    helper = "from numba import njit\n\n@njit(cache=True)\ndef ctz(x):\n    return x\n"
    bad_imports = [
        "from csplab._kernels import ctz\n",
        "from csplab import _kernels as k\n",
        "from . import _kernels\n",
        "import csplab._kernels\n",
        "from .._kernels import ctz as c\n",
    ]
    calls = ["ctz(x)", "k.ctz(x)", "_kernels.ctz(x)", "csplab._kernels.ctz(x)", "c(x)"]
    for imp, call in zip(bad_imports, calls, strict=True):
        mod = imp + f"from numba import njit\n\n@njit\ndef f(x):\n    return {call}\n"
        where = "csplab.sub.m" if ".." in imp else "csplab.m"
        found = njit_rule_violations({KERNELS: (helper, False), where: (mod, False)})
        assert found == [f"{where}.f calls @njit csplab._kernels.ctz (line 6)"], (imp, found)
    # a jitted caller of a jitted function in its own (non-kernel) file breaks the rule too
    own = (
        "import numba\n\n@numba.njit\ndef g(x):\n    return x\n\n"
        "@numba.jit(nopython=True)\ndef f(x):\n    return g(x)\n"
    )
    assert njit_rule_violations({KERNELS: (helper, False), "csplab.m": (own, False)}) == [
        "csplab.m.f calls @njit csplab.m.g (line 9)"
    ]
    # allowed: plain Python calling a kernel; a kernel calling a ctypes pointer or numpy
    ok = (
        "import numpy as np\nfrom numba import njit\nfrom csplab._kernels import ctz\n\n"
        "def py(x):\n    return ctz(x)\n\n"
        "@njit\ndef feed(fn, x):\n    fn(x)\n    return np.sum(x)\n"
    )
    assert njit_rule_violations({KERNELS: (helper, False), "csplab.m": (ok, False)}) == []


def test_kernel_state_is_private_to_the_catalog():
    """Nothing outside catalog.py reaches into a Propagator's kernel state."""
    private = {"_queue", "_inq", "_ac", "_undo", "_save"}
    hits = []
    for path in sorted(PKG.rglob("*.py")):
        if path.name in ("catalog.py", "_kernels.py"):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr in private:
                hits.append(f"{path.relative_to(PKG)}:{node.lineno} .{node.attr}")
            if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("_search"):
                hits.append(f"{path.relative_to(PKG)}:{node.lineno} imports _search")
    assert hits == []


# ----------------------------------------------------------------------------- bundles, codes


def test_codes_are_distinct_and_match_the_kernel_constants():
    assert len({int(c) for c in Code}) == len(Code)
    for c in Code:
        assert getattr(kern, f"_{c.name}") == int(c)


def _fallible():
    return from_example(ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]]), (8, 8))


def _manual_run(P, seed, max_steps):
    """Alg. 3.1 (scanline) through Propagator.alg31 in chunks of ``max_steps``."""
    rng = np.random.default_rng(seed)
    ustream = rng.random(P.n)
    eng = Propagator(P)
    run = Run(
        order=np.arange(P.n, dtype=np.int64), ustream=ustream,
        grid=np.full(P.n, -1, dtype=np.int32), trace_cell=np.full(P.n, -1, dtype=np.int64),
        trace_label=np.full(P.n, -1, dtype=np.int64), state=np.array([0, 0, -1], dtype=np.int64),
    )  # fmt: skip
    calls = 0
    while True:
        code = eng.alg31(run, max_steps=max_steps)
        calls += 1
        assert isinstance(code, Code)
        if code is not Code.PAUSED:
            return code, run, eng, calls


@pytest.mark.parametrize("seed", range(6))
def test_alg31_in_chunks_equals_one_run(seed):
    P = _fallible()
    ref = run_alg31(P, np.random.default_rng(seed))
    for steps in (None, 1, 7):
        code, run, eng, calls = _manual_run(P, seed, steps)
        assert code is (Code.SOLVED if ref.status == "solved" else Code.FAILED)
        assert np.array_equal(run.grid.reshape(P.shape), ref.grid)
        assert run.steps == ref.stats["assigned"]
        if steps == 1:
            assert calls == run.steps  # one assignment per call
        if code is Code.FAILED:  # the engine records the wipe-out
            assert not eng.ok and eng.wiped == run.fail_cell
            assert list(P.coords(run.fail_cell)) == ref.stats["fail_cell"]


def test_alg31_time_limit_chunks_do_not_change_the_grid():
    P = from_example(box_town(1, rng=0), (20, 20, 12), boundary="auto")  # > 4096 cells
    for order in ("scanline", "min-entropy"):
        a = run_alg31(P, np.random.default_rng(3), order=order)
        b = run_alg31(P, np.random.default_rng(3), order=order, time_limit=1e6)
        assert a.status == b.status == "solved"
        assert np.array_equal(a.grid, b.grid) and np.array_equal(a.trace, b.trace)


def test_mac_search_codes_restart_and_resume():
    odd = grids.grid((7,), [[[False, True], [True, False]]], periodic=True)
    eng = Propagator(odd)
    root = eng.catalog()
    se = Search.new(odd.n, eng.c.W, seed=5)
    assert eng.mac_search(se, max_nodes=100, restart_fails=1) is Code.RESTART
    assert se.fails == 1 and not np.array_equal(eng.catalog(), root)
    eng.mac_restart(se)
    assert np.array_equal(eng.catalog(), root)  # back at the root
    assert eng.mac_search(se, max_nodes=100) is Code.EXHAUSTED
    assert np.array_equal(eng.catalog(), root) and se.nodes == 2
    # pausing after every decision and growing the trail change nothing
    P = _fallible()
    one = Propagator(P)
    s1 = Search.new(P.n, one.c.W, seed=11)
    assert one.mac_search(s1, scan=True, max_nodes=10**9) is Code.SOLVED
    two = Propagator(P)
    s2 = Search.new(P.n, two.c.W, seed=11)
    codes = []
    while (code := two.mac_search(s2, scan=True, max_nodes=1)) is not Code.SOLVED:
        codes.append(code)
        s2 = s2.grown() if len(codes) % 10 == 0 else s2
    assert set(codes) == {Code.PAUSED} and len(codes) == s1.nodes
    assert s2.tcell.size == s1.tcell.size * 2 ** (len(codes) // 10)
    assert np.array_equal(one.catalog(), two.catalog()) and one.catalog().sum() == P.n
    assert (s1.nodes, s1.fails, s1.counters.tolist()) == (s2.nodes, s2.fails, s2.counters.tolist())
    # the catalog left by the search is a valid starting point for propagation
    assert two.propagate(None) and np.array_equal(two.catalog(), one.catalog())


def test_trail_growth_code():
    P = from_example(box_town(1, rng=0), (12, 12, 6), boundary="auto")
    eng = Propagator(P)
    se = Search.new(P.n, eng.c.W, seed=2)
    se = se._replace(tcell=se.tcell[: P.n + 1], tbits=se.tbits[: P.n + 1])  # nearly full
    assert eng.mac_search(se, max_nodes=10**9) is Code.GROW
    while (code := eng.mac_search(se, max_nodes=10**9)) is Code.GROW:
        se = se.grown()
    assert code is Code.SOLVED and eng.catalog().sum() == P.n
