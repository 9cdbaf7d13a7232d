import json

import numpy as np
import pytest

import csplab
from csplab.errors import FormatError
from csplab.io import model_format, read_model
from csplab.io.debroglie import parse_debroglie, read_debroglie

from ._helpers import DATA, anchor, installed_solvers


def load_tiny(**kw):
    with pytest.warns(UserWarning, match=r"no tile pictures \('roads.tsx' is not next to"):
        return read_debroglie(DATA / "tiny_debroglie.json", **kw)


def road_sides(name):
    return {"g": "", "ns": "ns", "ew": "ew"}.get(name, name)


def test_tiny_roads_rules_follow_the_geometry():
    rs = load_tiny()
    assert model_format(DATA / "tiny_debroglie.json") == "debroglie"
    assert rs.names == ("g", "ns", "ew", "ne", "se", "sw", "nw")
    assert rs.weights.tolist() == [2, 1, 1, 1, 1, 1, 2]
    assert rs.closure_violations() == []
    s = [road_sides(n) for n in rs.names]
    Tx = np.array([[("e" in a) == ("w" in b) for b in s] for a in s])
    Ty = np.array([[("n" in a) == ("s" in b) for b in s] for a in s])  # b above a
    assert np.array_equal(rs.relations[0], Tx)
    assert np.array_equal(rs.relations[1], Ty)


def test_tiny_constraints():
    rs = load_tiny()
    P = rs.problem()
    assert P.shape == (8, 6)
    assert [c.kind for c in P.constraints] == ["connected"]  # the path constraint
    r = csplab.solve(P, "catalog", rng=2, restarts=20)
    assert r.ok
    g = r.grid
    assert (g[0] == 0).all() and (g[-1] == 0).all()  # border xmin, xmax: grass
    assert rs.names[g[3, 5]] == "ew"  # fixedTile at DeBroglie (3, 0) = top row
    assert not P.violations(g)  # one road network
    assert read_debroglie(DATA / "tiny_debroglie.json", strict=True).constraints


def test_comments_inside_strings_are_kept():
    text = '{"tiles": [{"value": "a//b"}], "adjacencies": [{"left": ["a//b"], "right": ["a//b"]}]}'
    rs = parse_debroglie(text, path="c.json")
    assert rs.names == ("a//b",)


def test_inconsistent_rotations_are_an_error():
    cfg = {
        "symmetry": 8,
        "tiles": [{"value": 1, "rotateCw": 2}, {"value": 2, "rotateCw": 2}],
        "adjacencies": [{"left": [1], "right": [2]}],
    }
    with pytest.raises(FormatError, match="inconsistent"):
        parse_debroglie(json.dumps(cfg), path="r.json")


@pytest.mark.parametrize(
    ("cfg", "what"),
    [
        ({"adjacencies": [{"left": [1]}]}, "exactly one of"),
        ({"adjacencies": [{"left": [1], "right": [2]}], "symmetry": 3}, "symmetry"),
        ({"adjacencies": "x"}, "must be a list"),
        ({"adjacencies": [{"left": [1], "right": [2]}], "constraints": [{"type": "border"}]},
         "'tile' or 'tiles'"),
        ({"adjacencies": [{"left": [1], "right": [[2]]}]}, "number or string"),
        ({"model": {"type": "overlapping"}, "src": "missing.png"}, "not found"),
    ],
)  # fmt: skip
def test_errors(cfg, what):
    with pytest.raises(FormatError, match=what):
        parse_debroglie(json.dumps(cfg), path="bad.json")


def test_overlapping_config_uses_the_sample(tmp_path):
    import shutil

    shutil.copy(DATA / "sample.png", tmp_path / "sample.png")
    cfg = {"model": {"type": "overlapping", "n": 2}, "src": "sample.png", "width": 9,
           "height": 7, "symmetry": 2, "periodic": True}  # fmt: skip
    (tmp_path / "o.json").write_text(json.dumps(cfg))
    rs = read_model(tmp_path / "o.json")
    assert rs.meta["format"] == "overlapping" and rs.meta["N"] == 2 and rs.shape == (9, 7)


def test_shared_edged_path_file():
    p = anchor("DeBroglie/edged_path_constraint.json")
    with pytest.warns(UserWarning, match="no tile pictures"):
        rs = read_model(p)
    assert rs.K == 16 and rs.shape == (10, 10) and rs.closure_violations() == []
    assert not any("edgedPath" in w for w in rs.warnings)  # now a constraint, no warning
    assert [c["type"] for c in rs.constraints] == ["connected"]


@pytest.mark.parametrize("solver", installed_solvers())
def test_shared_edged_path_every_solver_30x30(solver):
    p = anchor("DeBroglie/edged_path_constraint.json")
    with pytest.warns(UserWarning):
        rs = read_model(p)
    P = rs.problem((30, 30)).without_constraints()  # the rules; the path: test_constraints
    r = csplab.solve(P, solver, rng=1)
    assert r.ok and P.is_solution(r.grid)
    assert (r.grid[0] == rs.names.index("1")).all()  # the border constraint


def test_missing_tile_pictures_are_reported(tmp_path):
    rs = load_tiny()  # warns: no tile pictures ('roads.tsx' is not next to the config)
    assert rs.images is None
    assert any("one colour per tile" in w for w in rs.warnings)
    text = '{"tiles": [{"value": 1}], "adjacencies": [{"left": [1], "right": [1]}]}'
    (tmp_path / "c.json").write_text(text)
    with pytest.warns(UserWarning, match="c.json: no tile pictures: pictures show one colour"):
        read_debroglie(tmp_path / "c.json")
    assert parse_debroglie(text, path="c.json").warnings == []  # text, not a file


def test_shared_edged_path_file_says_why_its_pictures_are_colours():
    p = anchor("DeBroglie/edged_path_constraint.json")
    with pytest.warns(UserWarning, match="'grass_biome.tsx' is not next to the config"):
        read_model(p)


def test_a_tiled_tsx_tileset_gives_pictures_and_properties(tmp_path):
    """Issue 30 row 26: DeBroglie configs name a Tiled ``.tsx``; its tiles (by gid, id + 1,
    or by their ``name`` property) give the pictures and properties."""
    import json

    from PIL import Image

    from csplab.io import read_model

    img = Image.new("RGBA", (8, 4))
    for i, c in enumerate([(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (9, 9, 9, 255)]):
        img.paste(c, ((i % 2) * 4, (i // 2) * 2, (i % 2) * 4 + 4, (i // 2) * 2 + 2))
    img = img.crop((0, 0, 8, 4))
    img.save(tmp_path / "t.png")
    (tmp_path / "t.tsx").write_text(
        '<tileset tilewidth="4" tileheight="2" tilecount="4" columns="2">'
        '<image source="t.png" width="8" height="4"/>'
        '<tile id="2"><properties><property name="name" value="water"/>'
        '<property name="cost" value="3"/></properties></tile></tileset>'
    )
    cfg = {"src": "t.tsx", "tiles": [{"value": 1}, {"value": "water"}],
           "adjacencies": [{"left": [1, "water"], "right": [1, "water"]},
                           {"up": [1, "water"], "down": [1, "water"]}]}  # fmt: skip
    (tmp_path / "c.json").write_text(json.dumps(cfg))
    rs = read_model(tmp_path / "c.json")
    assert rs.images is not None and rs.images.shape == (2, 2, 4, 4)
    assert tuple(rs.images[0, 0, 0]) == (255, 0, 0, 255)  # gid 1 = tile id 0
    assert tuple(rs.images[1, 0, 0]) == (0, 0, 255, 255)  # "water" = tile id 2
    assert rs.meta["tile_properties"]["water"] == {"name": "water", "cost": "3"}
    assert not any("no tile pictures" in w for w in rs.meta["warnings"])


@pytest.mark.parametrize("mtype", ["adjacent", "overlapping"])
def test_a_sample_model_without_a_sample_says_so_in_english(tmp_path, mtype):
    """The message reads "an adjacent model without adjacencies ..." (it said "a adjacent")."""
    p = tmp_path / "c.json"
    p.write_text(json.dumps({"model": {"type": mtype}, "src": "x.txt"}))
    with pytest.raises(FormatError) as e:
        read_model(p)
    assert f"an {mtype} model without adjacencies needs a PNG" in str(e.value)
