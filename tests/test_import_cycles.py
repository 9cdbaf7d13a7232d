"""No import circle among csplab's modules, counting the imports inside functions.

``lint-imports`` and most module maps read module-level imports only, so a circle closed by
an import inside a function (``def load(): from csplab.io import read_example``) stays
invisible to them while it still ties the modules together. This test reads every ``import``
and ``from ... import`` statement of every module with :mod:`ast`, wherever it stands (module
level, functions, methods, conditionals, ``try``), and fails on any circle.

How an import statement becomes an arrow (importer -> imported module):

- ``import csplab.a.b`` -> ``csplab.a.b``;
- ``from csplab.a import b`` -> ``csplab.a.b`` when ``b`` is a submodule of ``csplab.a``,
  else ``csplab.a`` (the package's ``__init__``: a module that takes a name from its own
  parent package's ``__init__`` depends on that ``__init__``, which is a real arrow);
- relative imports are resolved against the importer's package first;
- the packages an import runs on the way (``csplab``, ``csplab.a`` for ``import
  csplab.a.b``) are not arrows: every submodule would otherwise depend on ``csplab`` itself;
- imports under ``if TYPE_CHECKING:`` are not arrows (they never run; their ``else`` branch
  does run and counts);
- modules loaded by name from a registry string (``importlib.import_module(modname)``) are
  plugins and not arrows;
- imports outside ``csplab`` are ignored.

The top package ``csplab/__init__.py`` re-exports the public names and is allowed to import
anything; nothing inside ``csplab`` imports the top package, so it closes no circle (an arrow
to ``csplab`` would, and is reported like any other).
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[1]


def _module_names(root: Path, package: str) -> dict[str, Path]:
    """Map every module name of the package under ``root`` to its file."""
    out: dict[str, Path] = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _import_nodes(tree: ast.AST) -> Iterator[ast.Import | ast.ImportFrom]:
    """Every import statement of the tree except those under ``if TYPE_CHECKING:``."""
    stack: list[ast.AST] = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
            continue
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def _targets(
    node: ast.Import | ast.ImportFrom, importer: str, is_package: bool, modules: dict[str, Path]
) -> Iterator[str]:
    """The modules of ``modules`` that one import statement in ``importer`` depends on."""
    if isinstance(node, ast.Import):
        for alias in node.names:
            if alias.name in modules:
                yield alias.name
        return
    base = node.module or ""
    if node.level:
        pkg = importer.split(".") if is_package else importer.split(".")[:-1]
        pkg = pkg[: len(pkg) - (node.level - 1)]
        base = ".".join(pkg + ([base] if base else []))
    for alias in node.names:
        sub = f"{base}.{alias.name}"
        if sub in modules:
            yield sub
        elif base in modules:
            yield base


def import_graph(root: Path, package: str) -> nx.DiGraph:
    """The import graph of ``package`` (a directory under ``root``), imports in functions too.

    Each edge carries ``where``: the ``file:line`` of every statement that makes it.
    """
    modules = _module_names(root, package)
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        rel = path.relative_to(root)
        is_package = path.name == "__init__.py"
        for node in _import_nodes(tree):
            for target in _targets(node, name, is_package, modules):
                if target == name:
                    continue
                if not graph.has_edge(name, target):
                    graph.add_edge(name, target, where=[])
                where = graph.edges[name, target]["where"]
                if (rel, node.lineno) not in where:
                    where.append((rel, node.lineno))
    for _, _, data in graph.edges(data=True):
        data["where"] = [f"{rel}:{line}" for rel, line in sorted(data["where"])]
    return graph


def circles(graph: nx.DiGraph) -> list[str]:
    """One report per circle: its modules and every arrow inside it with where it is made."""
    out = []
    for comp in nx.strongly_connected_components(graph):
        if len(comp) < 2:
            continue
        lines = [f"circle of {len(comp)} modules: {', '.join(sorted(comp))}"]
        for a, b in sorted(graph.subgraph(comp).edges):
            lines.append(f"  {a} -> {b}  ({', '.join(graph.edges[a, b]['where'])})")
        out.append("\n".join(lines))
    return sorted(out)


def test_no_import_circle_in_csplab():
    found = circles(import_graph(ROOT, "csplab"))
    assert found == [], "\n".join(found)


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return tmp_path


def test_a_circle_closed_inside_a_function_is_found(tmp_path):
    root = _package(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/low.py": "def f():\n    from pkg.high import g\n    return g\n",
            "pkg/high.py": "from pkg import low\n",
        },
    )
    found = circles(import_graph(root, "pkg"))
    assert len(found) == 1
    assert "pkg.high -> pkg.low  (pkg/high.py:1)" in found[0]
    assert "pkg.low -> pkg.high  (pkg/low.py:2)" in found[0]


def test_relative_imports_methods_and_parent_init_are_arrows(tmp_path):
    root = _package(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/sub/__init__.py": "from .a import A\n",
            # a method reaches the parent package's __init__ for a name: a real arrow
            "pkg/sub/a.py": "class A:\n    def m(self):\n        from . import A\n",
            "pkg/sub/b.py": "import os\nfrom ..sub import a\nfrom pkg.sub.a import A\n",
        },
    )
    graph = import_graph(root, "pkg")
    assert set(graph.edges) == {
        ("pkg.sub", "pkg.sub.a"),
        ("pkg.sub.a", "pkg.sub"),
        ("pkg.sub.b", "pkg.sub.a"),
    }
    assert graph.edges["pkg.sub.b", "pkg.sub.a"]["where"] == ["pkg/sub/b.py:2", "pkg/sub/b.py:3"]
    assert len(circles(graph)) == 1


def test_type_checking_imports_are_not_arrows_but_their_else_is(tmp_path):
    root = _package(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/a.py": "from pkg import b\n",
            "pkg/b.py": (
                "import typing\nif typing.TYPE_CHECKING:\n    from pkg import a\n"
                "else:\n    from pkg import c\n"
            ),
            "pkg/c.py": "",
        },
    )
    graph = import_graph(root, "pkg")
    assert set(graph.edges) == {("pkg.a", "pkg.b"), ("pkg.b", "pkg.c")}
    assert circles(graph) == []
