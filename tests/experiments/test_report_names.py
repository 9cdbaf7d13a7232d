"""Reports name a model file by its stem (the path stays in the configuration block),
figures keep their legends off the data, and the summary line is a sentence."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from csplab.examples import load_example
from csplab.experiments import run
from csplab.experiments.base import example_names
from csplab.io import write_example


@pytest.fixture
def deep_2d(tmp_path: Path) -> Path:
    p = tmp_path / "on" / "my" / "machine" / "fallible.npy"
    p.parent.mkdir(parents=True)
    np.save(p, np.array([[0, 0, 0], [1, 2, 2], [0, 1, 2]]))
    return p


@pytest.fixture
def deep_3d(tmp_path: Path) -> Path:
    p = tmp_path / "on" / "my" / "machine" / "castle_copy.npy"
    p.parent.mkdir(parents=True, exist_ok=True)
    write_example(load_example("castle"), p)
    return p


def _only_in_configuration(md: str, path: Path) -> None:
    lines = [ln for ln in md.splitlines() if str(path.parent) in ln]
    assert lines and all(ln.startswith("Configuration: ") for ln in lines), lines


def test_example_names() -> None:
    assert example_names(["castle", "/a/b/m.txt", "x/k.npy", "y/k.npy"]) == {
        "castle": "castle", "/a/b/m.txt": "m", "x/k.npy": "x/k", "y/k.npy": "y/k",
    }  # fmt: skip
    assert example_names(["castle", "dir/castle.txt"]) == {
        "castle": "castle", "dir/castle.txt": "dir/castle",
    }  # fmt: skip


_RUNS: list[tuple[str, str, dict[str, Any]]] = [
    ("fig3_8", "2d", {"sizes": [4], "seeds": 2, "boundary": "none"}),
    ("catalog_gap", "2d", {"sizes": [4], "seeds": 3, "boundary": "none"}),
    ("table3_1", "2d", {"seeds": 1, "boundary": "none", "displayed": "4x4", "compare": "5x5x2"}),
    ("sampling_bias", "2d", {"seeds": 2, "boundary": "none"}),
    ("blocksize", "3d", {"size": "8x8x4", "seeds": 1, "blocks": "4,full"}),
]


@pytest.mark.parametrize(("name", "dim", "opts"), _RUNS, ids=[r[0] for r in _RUNS])
def test_reports_name_model_files_by_stem(
    tmp_path: Path, deep_2d: Path, deep_3d: Path, name: str, dim: str, opts: dict[str, Any]
) -> None:
    path = deep_2d if dim == "2d" else deep_3d
    s, rep = run(name, quick=True, examples=[str(path)], store=tmp_path / "r.sqlite",
                 out=tmp_path / "out", jobs=1, progress=False, figures=False, **opts)  # fmt: skip
    assert not s.errors
    assert rep.tables and any(rep.tables.values())
    for rows in rep.tables.values():
        for row in rows:
            if "example" in row:
                assert row["example"] == path.stem
    _only_in_configuration(rep.markdown(), path)


_FIGS = [
    ("fig3_8", "2d", {"sizes": [4, 5], "seeds": 2, "boundary": "none"}),
    ("catalog_gap", "2d", {"sizes": [4, 5], "seeds": 15, "boundary": "none"}),
    ("table3_1", "2d", {"seeds": 1, "boundary": "none", "displayed": "4x4", "compare": "5x5x2"}),
    ("blocksize", "3d", {"size": "8x8x4", "seeds": 1, "blocks": "2,4,full"}),
]


@pytest.mark.parametrize(("name", "dim", "opts"), _FIGS, ids=[r[0] for r in _FIGS])
def test_figure_legends_sit_outside_the_data_and_use_stems(
    tmp_path: Path,
    deep_2d: Path,
    deep_3d: Path,
    monkeypatch: pytest.MonkeyPatch,
    name: str,
    dim: str,
    opts: dict[str, Any],
) -> None:
    import importlib

    mod = importlib.import_module(f"csplab.experiments.{name}")
    figs: list[Any] = []
    real = mod.save_figure

    def keep(fig: Any, stem: Path) -> list[Path]:
        figs.append(fig)
        return list(real(fig, stem))

    monkeypatch.setattr(mod, "save_figure", keep)
    path = deep_2d if dim == "2d" else deep_3d
    s, _ = run(name, quick=True, examples=[str(path)], store=tmp_path / "r.sqlite",
               out=tmp_path / "out", jobs=1, progress=False, **opts)  # fmt: skip
    assert not s.errors and figs
    legends = 0
    for fig in figs:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        axes = [ax for ax in fig.axes if ax.get_visible() and ax.axison]
        found = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
        for leg in found:
            legends += 1
            box = leg.get_window_extent(renderer)
            for ax in axes:
                assert not box.overlaps(ax.get_window_extent(renderer)), (name, ax.get_title())
            texts = [t.get_text() for t in leg.get_texts()]
            assert not any(str(tmp_path) in t for t in texts), texts
        for ax in fig.axes:
            labels = [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
            labels += [t.get_text() for t in ax.get_xticklabels()]
            assert not any(str(tmp_path) in t for t in labels), labels
    assert legends >= 1
