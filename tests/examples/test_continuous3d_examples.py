"""The built-in polyhedral examples (csplab.examples.continuous3d): they load with the
polygon counts their descriptions give, the files are what the build script writes, and
every one synthesizes with catalog, blocks and sat without violations."""

from __future__ import annotations

import re
import warnings
from importlib import resources
from pathlib import Path

import pytest

from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.synthesis import synthesize
from csplab.errors import InputError
from csplab.examples.build_continuous3d import EXAMPLES, write_all
from csplab.examples.continuous3d import (
    POLYHEDRAL_EXAMPLES,
    load_polyhedral_example,
    polyhedral_example_names,
)

pytest.importorskip("trimesh")
pytest.importorskip("manifold3d")

NAMES = polyhedral_example_names()
SIZE = (8, 8, 5)


def test_names_and_files() -> None:
    assert NAMES == [
        "tetrahedron", "houses", "skyscrapers", "arches", "terrain", "fractals", "pentagons",
    ]  # fmt: skip
    assert [e.name for e in EXAMPLES] == NAMES
    assert all(f == f"{n}.obj" for n, (f, _) in POLYHEDRAL_EXAMPLES.items())


def test_unknown_name_lists_the_examples() -> None:
    with pytest.raises(InputError, match=r"'cube'.*tetrahedron, houses, .*pentagons"):
        load_polyhedral_example("cube")


@pytest.mark.parametrize("name", NAMES)
def test_loads_with_the_described_polygon_count(name: str) -> None:
    E = load_polyhedral_example(name)
    desc = POLYHEDRAL_EXAMPLES[name][1]
    m = re.search(r"(\d+) polygons", desc)
    assert m is not None, desc
    assert E.n_polygons == int(m.group(1))
    assert E.name == name and E.meta["description"] == desc
    assert "reoriented" not in E.meta  # written outward, nothing fixed on reading


def test_files_are_what_the_build_script_writes(tmp_path: Path) -> None:
    written = write_all(tmp_path)
    pkg = resources.files("csplab.examples").joinpath("continuous3d")
    for p in written:
        assert p.read_text(encoding="utf-8") == pkg.joinpath(p.name).read_text(encoding="utf-8")
        head = [ln for ln in p.read_text(encoding="utf-8").splitlines() if ln.startswith("#")]
        for part in ("# Stands for:", "# The paper pins down:", "# Chosen here:"):
            assert any(ln.startswith(part) for ln in head), (p.name, part)


def test_tetrahedron_top_vertex_has_the_nine_states_of_fig9() -> None:
    E = load_polyhedral_example("tetrahedron")
    C = ContinuousCSP3(E, SIZE)
    assert C.states_at_planes([(1, 0, 0), (0, 1, 0), (1, 1, 1)]) == 9
    assert len(C.signatures) == 16  # Sec. 4.5.3: the tetrahedron's 16 labels


@pytest.mark.parametrize("solver", ["catalog", "blocks", "sat"])
@pytest.mark.parametrize("name", NAMES)
def test_synthesizes_without_violations(name: str, solver: str) -> None:
    E = load_polyhedral_example(name)
    restarts = 5 if solver == "catalog" else 0
    s = synthesize(E, SIZE, solver=solver, rng=1, restarts=restarts)
    assert s.result.status == "solved"
    assert s.model is not None
    assert len(s.violations) == 0, s.violations
    assert set(s.model.labels) <= set(E.labels)
    # the output (built without re-validation) passes every check of a model read from a file
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        V = PolyhedralModel([x.to_json() for x in s.model.solids])
    assert V.n_polygons == s.model.n_polygons
    assert V.volume() == pytest.approx(sum(x.volume for x in s.model.solids))


def test_terrain_on_a_ground_layer() -> None:
    E = load_polyhedral_example("terrain")
    s = synthesize(E, SIZE, solver="catalog", rng=2, restarts=5, boundary={"z-": 1})
    assert s.ok and s.model is not None
    assert 1 in s.model.labels  # the ground continues along the bottom


@pytest.mark.slow
@pytest.mark.parametrize("solver", ["catalog", "blocks", "sat"])
@pytest.mark.parametrize("name", NAMES)
def test_synthesizes_at_the_issue_size(name: str, solver: str) -> None:
    E = load_polyhedral_example(name)
    restarts = 5 if solver == "catalog" else 0
    s = synthesize(E, (10, 10, 6), solver=solver, rng=3, restarts=restarts)
    assert s.ok, (s.result.status, s.violations)
