"""Loaders only ever raise CsplabError on damaged files, and never hang.

Every readable format of the registry is fuzzed: its sample is the smallest file of
``tests/io/data`` detected as that format, else a small grid written by its own writer; a
new format without either fails here until it gets a sample.
"""

import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from csplab.errors import CsplabError, FormatError
from csplab.io import model_format, read_model
from csplab.io.registry import formats
from csplab.testing.strategies import corrupted, tile_rule_sets

from ._helpers import ANCHORS, copy_companions, format_sample

READABLE = [f.name for f in formats(readable=True)]
EXTRA = {  # larger real files, when the shared test data is there
    "knots.xml": ANCHORS / "MarkovJunior" / "Knots3D.xml",
    "edged.json": ANCHORS / "DeBroglie" / "edged_path_constraint.json",
}
EXTRA = {k: v for k, v in EXTRA.items() if v.is_file()}


def load(tmp_path, name, data):
    p = tmp_path / name
    p.write_bytes(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            m = read_model(p)
        except CsplabError:
            return None
    # whatever loads must also build a small problem or fail cleanly
    try:
        shape = (3,) * m.ndim
        m.problem(shape) if hasattr(m, "problem") else None
    except CsplabError:
        pass
    return m


@pytest.mark.parametrize("fmt", READABLE)
def test_every_readable_format_has_a_sample_that_loads(tmp_path, fmt):
    name, data = format_sample(fmt)
    (tmp_path / name).write_bytes(data)
    copy_companions(tmp_path)  # a WFC samples list names files beside it
    assert model_format(tmp_path / name) == fmt
    assert load(tmp_path, name, data) is not None


@pytest.mark.parametrize("fmt", READABLE)
@settings(deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_corrupted_files_raise_only_csplab_errors(tmp_path, fmt, data):
    name, good = format_sample(fmt)
    load(tmp_path, name, data.draw(corrupted(good)))


@pytest.mark.parametrize("name", sorted(EXTRA))
@settings(deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_corrupted_shared_files_raise_only_csplab_errors(tmp_path, name, data):
    load(tmp_path, name, data.draw(corrupted(EXTRA[name].read_bytes())))


@settings(
    max_examples=40, deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(xml=tile_rule_sets())
def test_random_wfc_tilesets_are_closed_and_solvable_or_fail_cleanly(tmp_path, xml):
    import csplab

    p = tmp_path / "r.xml"
    p.write_text(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rs = read_model(p)
    assert rs.closure_violations() == []
    r = csplab.solve(rs.problem((4, 3)), "catalog", rng=0)
    assert r.status in ("solved", "failed", "unsat")


@pytest.mark.parametrize("fmt", READABLE)
def test_special_files_are_refused_before_reading(tmp_path, fmt):
    """A FIFO (which would block the reader) and a device such as ``/dev/zero`` (endless)
    are refused with one FormatError line, whatever the format; so is a file beyond the
    size cap."""
    import os

    from csplab.io import common
    from csplab.io.registry import FORMATS

    ext = FORMATS[fmt].extensions[0]
    if hasattr(os, "mkfifo"):
        fifo = tmp_path / f"model{ext}"
        os.mkfifo(fifo)
        with pytest.raises(FormatError, match="FIFO"):
            read_model(fifo)
        with pytest.raises(FormatError, match="FIFO"):
            read_model(fifo, format=fmt)
    if os.path.exists("/dev/zero"):
        with pytest.raises(FormatError, match="regular file"):
            read_model("/dev/zero", format=fmt)
    big = tmp_path / f"big{ext}"
    big.write_bytes(b"0" * 64)
    old = common.MAX_FILE_BYTES
    common.MAX_FILE_BYTES = 16
    try:
        with pytest.raises(FormatError, match="MAX_FILE_BYTES"):
            read_model(big)
    finally:
        common.MAX_FILE_BYTES = old
