"""WaveFunctionCollapse's ``samples.xml``: entries, options, settings, errors, the notice."""

import time
import warnings

import numpy as np
import pytest
from PIL import Image

from csplab.cli import main
from csplab.errors import CsplabError, FormatError, InputError
from csplab.io import model_format, read_model
from csplab.io.overlap import OverlapModel

from ._helpers import DATA

SKY, PLANT, GROUND = (120, 180, 250), (40, 150, 40), (120, 80, 40)

TILESET = """<set>
  <tiles><tile name="sea"/><tile name="coast" symmetry="T"/><tile name="land"/></tiles>
  <neighbors>
    <neighbor left="sea" right="sea"/><neighbor left="land" right="land"/>
    <neighbor left="sea" right="coast 1"/><neighbor left="coast 1" right="land"/>
    <neighbor left="coast" right="coast"/>
  </neighbors>
  <subsets><subset name="water"><tile name="sea"/></subset></subsets>
</set>
"""

SAMPLES = """<samples>
  <overlapping name="Flowers" N="3" periodic="True" symmetry="2" ground="True"
               heuristic="Scanline" width="12" height="8"/>
  <simpletiled name="Coast" width="7" height="5" heuristic="MRV" limit="10" screenshots="1"/>
  <simpletiled name="Coast" size="6" periodic="True" subset="water"/>
  <overlapping name="Flat" N="2" symmetry="1" periodicInput="False" width="10" height="6"/>
</samples>
"""


def _sample_png(path):
    """A 6x5 picture: sky, a plant standing on a ground row."""
    rows = [[SKY] * 6 for _ in range(5)]
    rows[2][2] = rows[3][2] = PLANT
    rows[4] = [GROUND] * 6
    Image.fromarray(np.array(rows, dtype=np.uint8), "RGB").save(path)


@pytest.fixture
def wfc(tmp_path):
    """A WaveFunctionCollapse folder: samples.xml, samples/*.png, tilesets/*.xml."""
    (tmp_path / "samples").mkdir()
    (tmp_path / "tilesets").mkdir()
    _sample_png(tmp_path / "samples" / "Flowers.png")
    _sample_png(tmp_path / "samples" / "Flat.png")
    (tmp_path / "tilesets" / "Coast.xml").write_text(TILESET)
    (tmp_path / "samples.xml").write_text(SAMPLES)
    return tmp_path / "samples.xml"


def read(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the tileset has no pictures
        return read_model(path, **options)


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------------------- detection
def test_detected_by_the_samples_root_and_tilesets_keep_their_format(wfc):
    assert model_format(wfc) == "wfc-samples"
    assert model_format(wfc.parent / "tilesets" / "Coast.xml") == "wfc"
    assert model_format(DATA / "wfc_samples.xml") == "wfc-samples"
    assert model_format(DATA / "pipes.xml") == "wfc"
    assert model_format(DATA / "pipes3d.xml") != "wfc-samples"


# ---------------------------------------------------------------------------- entries
def test_overlapping_entry_takes_its_attributes(wfc):
    m = read(wfc, name="Flowers")
    assert isinstance(m, OverlapModel)
    assert (m.N, m.meta["symmetry"], m.meta["ground"]) == (3, 2, "wfc")
    assert m.shape == (12, 8) and m.periodic is True
    assert m.meta["heuristic"] == "Scanline" and m.meta["format"] == "overlapping"
    info = m.meta["wfc_samples"]
    assert (info["entry"], info["kind"], info["line"]) == ("Flowers", "overlapping", 2)


def test_non_periodic_overlapping_output_has_wfcs_picture_size(wfc):
    m = read(wfc, name="Flat")
    assert (m.N, m.meta["periodic_input"], m.periodic) == (2, False, False)
    assert m.shape == (9, 5)  # 10x6 pixels = (10 - N + 1) x (6 - N + 1) cells
    assert "heuristic" not in m.meta  # WFC's default: the format's own settings


def test_simpletiled_entry_and_subset(wfc):
    rs = read(wfc, name="Coast", index=0)
    assert rs.meta["format"] == "wfc" and rs.K == 6 and rs.name == "Coast"
    assert rs.shape == (7, 5) and rs.periodic is False and rs.meta["heuristic"] == "MRV"
    water = read(wfc, name="Coast", index=1)
    assert water.K == 1 and water.name == "Coast[water]"
    assert water.shape == (6, 6) and water.periodic is True


def test_selection_by_name_and_index(wfc):
    assert read(wfc, index=3).name == "Flat"
    assert read(wfc, index=2).name == "Coast[water]"
    assert read(wfc, name="Coast", index=1).name == "Coast[water]"
    with pytest.raises(InputError, match=r"lists 4 entries; choose one with name=NAME") as e:
        read(wfc)
    assert str(e.value).endswith(": Flowers, Coast (2), Flat") and "\n" not in str(e.value)
    with pytest.raises(InputError, match=r"2 entries are named 'Coast' \(lines 4, 5\).*0\.\.1"):
        read(wfc, name="Coast")
    with pytest.raises(InputError, match=r"index=2, but there are 2 entries named 'Coast'"):
        read(wfc, name="Coast", index=2)


def test_a_single_entry_needs_no_name(tmp_path):
    (tmp_path / "tilesets").mkdir()
    (tmp_path / "tilesets" / "Coast.xml").write_text(TILESET)
    (tmp_path / "samples.xml").write_text('<samples><simpletiled name="Coast"/></samples>')
    rs = read(tmp_path / "samples.xml")
    assert rs.shape == (24, 24) and rs.periodic is False  # WFC's default size


def test_older_wfc_layout_and_ground_index(tmp_path):
    (tmp_path / "samples" / "Coast").mkdir(parents=True)
    (tmp_path / "samples" / "Coast" / "data.xml").write_text(TILESET)
    _sample_png(tmp_path / "samples" / "Old.png")
    (tmp_path / "samples.xml").write_text(
        '<samples><simpletiled name="Coast"/>'
        '<overlapping name="Old" symmetry="1" ground="-1" periodic="True"/></samples>'
    )
    assert read(tmp_path / "samples.xml", name="Coast").name == "Coast"
    assert read(tmp_path / "samples.xml", name="Old").meta["ground"] == "wfc"


def test_options_override_the_entry(wfc):
    m = read(wfc, name="Flowers", N="2", symmetry=1, ground="false")
    assert (m.N, m.meta["symmetry"], m.meta["ground"]) == (2, 1, False)
    assert read(wfc, name="Flowers", ground="bottom").meta["ground"] == "bottom"
    assert read(wfc, name="Coast", index=1, subset=None).K == 1  # None: the entry's
    rs = read(wfc, name="Coast", index=0, images=False)
    assert rs.images is None
    with pytest.raises(InputError, match=r"\['N'\] do not apply to the simpletiled entry"):
        read(wfc, name="Coast", index=0, N=2)
    with pytest.raises(InputError, match="option N='x' of wfc-samples files must be an integer"):
        read(wfc, name="Flowers", N="x")


def test_unknown_attributes_warn_and_run_settings_are_ignored(tmp_path):
    (tmp_path / "tilesets").mkdir()
    (tmp_path / "tilesets" / "Coast.xml").write_text(TILESET)
    (tmp_path / "samples.xml").write_text(
        '<samples><!-- c --><simpletiled name="Coast" textOutput="True" colour="red"/>'
        "<note/></samples>"
    )
    with pytest.warns(UserWarning) as record:
        rs = read_model(tmp_path / "samples.xml")
    texts = [str(w.message) for w in record]
    assert any("ignored attribute(s) colour" in t for t in texts)
    assert any("ignored <note>" in t for t in texts)
    assert not any("textOutput" in t for t in texts)
    assert any("colour" in w for w in rs.warnings)


# ---------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ('<overlapping name="Gone"/>', r"entry 'Gone' \(overlapping\): its file samples/Gone"),
        ('<simpletiled name="Gone"/>', r"entry 'Gone' \(simpletiled\): its file tilesets/Gone"),
        ('<overlapping name="F" heuristic="Best"/>', "heuristic='Best' is not Entropy, MRV"),
        ('<overlapping name="F" N="three"/>', "N='three' is not an integer"),
        ('<overlapping name="F" periodicInput="maybe"/>', "periodicInput='maybe' is not True"),
        ('<overlapping name="F" periodic="maybe"/>', "periodic='maybe' is not True or False"),
        ('<overlapping name="F" ground="-4"/>', "ground='-4' is not True or False"),
        ('<overlapping name="F" size="x"/>', "size='x' is not an integer"),
        ('<overlapping name="F" width="2"/>', r"output size 0x46 \(cells\) is empty"),
        ('<overlapping name="F" symmetry="9"/>', "symmetry must be 1..8"),
        ('<simpletiled name="C" subset="none"/>', "no subset 'none'"),
    ],
)
def test_entry_errors_name_the_list_its_line_and_the_entry(tmp_path, entry, message):
    (tmp_path / "samples").mkdir()
    (tmp_path / "tilesets").mkdir()
    _sample_png(tmp_path / "samples" / "F.png")
    (tmp_path / "tilesets" / "C.xml").write_text(TILESET)
    p = tmp_path / "samples.xml"
    p.write_text(f"<samples>\n  {entry}\n</samples>\n")
    with pytest.raises(FormatError, match=message) as e:
        read(p)
    assert str(e.value).startswith(f"{p}, line 2: entry ") and "\n" not in str(e.value)


def test_malformed_lists(tmp_path):
    p = tmp_path / "samples.xml"
    p.write_text("<samples><note/></samples>")
    with pytest.raises(FormatError, match="no <overlapping> or <simpletiled> entries"):
        read(p)
    p.write_text('<samples><overlapping N="2"/></samples>')
    with pytest.raises(FormatError, match="line 1: <overlapping> has no name"):
        read(p)
    p.write_text("<samples><overlapping")
    with pytest.raises(FormatError, match="not well-formed"):
        read(p)


# ---------------------------------------------------------------------------- the CLI
def test_cli_prints_the_files_heuristic(wfc, capsys, tmp_path):
    out = tmp_path / "f.png"
    code, stdout, err = run(
        capsys, "synthesize", str(wfc), "--model-option", "name=Flowers", "--seed", "1",
        "--out", str(out),
    )  # fmt: skip
    assert code == 0 and out.is_file(), err
    assert "Flowers 12x8" in stdout
    assert "order=scanline (the file's heuristic Scanline)" in stdout
    with Image.open(out) as im:
        assert im.size[0] % 12 == 0 and im.size[1] % 8 == 0  # periodic: one pixel a cell
    code, stdout, _ = run(
        capsys, "synthesize", str(wfc), "--model-option", "name=Coast",
        "--model-option", "index=0", "--size", "4x3", "--seed", "1",
    )  # fmt: skip
    assert code == 0 and "Coast 4x3" in stdout
    assert "order=min-domain (the file's heuristic MRV)" in stdout
    assert "choice=weighted (wfc defaults)" in stdout
    code, stdout, _ = run(
        capsys, "synthesize", str(wfc), "--model-option", "name=Flowers", "--order", "random",
        "--seed", "1",
    )  # fmt: skip
    assert code == 0 and "order=random (given)" in stdout


def test_cli_bundled_sample_list(capsys):
    code, stdout, _ = run(capsys, "synthesize", str(DATA / "wfc_samples.xml"), "--seed", "1")
    assert code == 0 and "sample 48x24" in stdout and "heuristic Scanline" in stdout


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ([], "lists 4 entries; choose one with name=NAME"),
        (["name=Nope"], "no entry named 'Nope'; entries: Flowers, Coast (2), Flat"),
        (["name=Coast"], "2 entries are named 'Coast'"),
        (["index=9"], "index=9, but there are 4 entries"),
        (["name=Flowers", "N=x"], "option N='x' of wfc-samples files must be an integer"),
    ],
)
def test_cli_errors_are_one_line(wfc, capsys, options, message):
    argv = ["synthesize", str(wfc), "--seed", "1"]
    for o in options:
        argv += ["--model-option", o]
    code, stdout, err = run(capsys, *argv)
    assert code == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith("csplab: error: ") and message in err


def test_cli_missing_file_is_one_line(wfc, capsys):
    (wfc.parent / "samples" / "Flat.png").unlink()
    code, _, err = run(capsys, "synthesize", str(wfc), "--model-option", "name=Flat")
    assert code == 2 and err.count("\n") == 1
    assert f"{wfc}, line 6: entry 'Flat' (overlapping): its file samples/Flat.png" in err


# ---------------------------------------------------------------------------- notice
def test_slow_reads_get_one_notice_line_and_quick_ones_none(wfc, capsys, monkeypatch):
    import csplab.examples
    from csplab import progress
    from csplab.cli.common import load_model

    load_model(str(wfc), {"name": "Flowers"})
    assert capsys.readouterr().err == ""  # quick: nothing
    real = csplab.examples.load_model

    def slow(spec, options=None):
        time.sleep(0.5)
        return real(spec, options)

    monkeypatch.setattr(csplab.examples, "load_model", slow)
    monkeypatch.setattr(progress, "DELAY_S", 0.05)
    m = load_model(str(wfc), {"name": "Flowers"})
    assert m.name == "Flowers"
    assert capsys.readouterr().err == f"csplab: reading {wfc} ...\n"
    load_model("line")  # a built-in example: no file, no notice
    assert capsys.readouterr().err == ""


def test_the_library_stays_quiet(wfc, capsys):
    read(wfc, name="Flowers")
    assert capsys.readouterr() == ("", "")


def test_damaged_lists_raise_only_csplab_errors(wfc):
    text = SAMPLES.encode()
    for cut in range(0, len(text), 7):
        wfc.write_bytes(text[:cut])
        try:
            read(wfc, name="Flowers")
        except CsplabError:
            pass
