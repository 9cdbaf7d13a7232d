"""Helpers shared by the analysis commands ``prove``, ``witness`` and ``refine``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from csplab.cli.common import check_output_path, load_model, model_options
from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.io.common import write_atomic
from csplab.io.ruleset import RuleSet
from csplab.result import Verdict

ORDER_HELP = (
    "scan order: scanline (x outermost, Alg. 3.1's loop; default) or scan:AXES, outermost "
    "first (scan:yx = the thesis' 2D figures: left to right, then bottom to top)"
)


def load_analysis_model(spec: str, options: list[str] | None = None) -> ExampleModel | RuleSet:
    """An example or a tileset's rule set, loaded as ``synthesize`` loads it (continuous
    models are refused in one line)."""
    model = load_model(spec, model_options(options))
    if not isinstance(model, ExampleModel | RuleSet):
        raise InputError(f"{spec}: a continuous (polygon) model has no grid analysis")
    return model


def save_certificate(cert: dict[str, Any], path: str) -> None:
    """Write a certificate as JSON, atomically (a temporary file, then renamed): a reader
    never sees half a certificate."""
    write_atomic(path, json.dumps(cert, default=_plain))


def load_example_model(
    spec: str, options: list[str] | None = None, needs: str = "an example grid"
) -> ExampleModel:
    """An example model; anything else is refused in one line saying what ``needs`` it."""
    model = load_model(spec, model_options(options))
    if not isinstance(model, ExampleModel):
        kind = "a tileset" if isinstance(model, RuleSet) else "a continuous model"
        raise InputError(f"{spec}: {needs}; this is {kind}, which has none")
    return model


def witness_grid(w: dict[str, Any]) -> np.ndarray:
    """The partial model of a witness (``-1`` = unassigned)."""
    g = np.full(tuple(w["shape"]), -1, dtype=np.int32)
    for c, b in w.get("choices", []):
        if b is not None:
            g[tuple(c)] = b
    return g


def add_witness_out(p: argparse.ArgumentParser) -> None:
    """``--out FILE``: where ``prove`` and ``witness`` save a failing run."""
    p.add_argument("--out", help="save the failing run as a .png picture or .json")


def check_witness_out(path: str | None) -> None:
    """Refuse a bad ``--out`` (not ``.png`` or ``.json``, or not writable) before the work."""
    if path:
        if Path(path).suffix not in (".png", ".json"):
            raise InputError(f"--out {path}: use a .png picture or a .json file")
        check_output_path(path, "--out")


def open_analysis(args: argparse.Namespace) -> ExampleModel | RuleSet:
    """What ``prove`` and ``witness`` do before their work: refuse a bad ``--out``, then
    load ``MODEL`` with its ``--model-option`` values (:func:`load_analysis_model`)."""
    check_witness_out(args.out)
    return load_analysis_model(args.model, args.model_option)


def report_run(
    run: dict[str, Any],
    example: ExampleModel | RuleSet,
    args: argparse.Namespace,
    heading: str | None = None,
    describe: bool = True,
) -> None:
    """Show a failing run (``heading``, then :func:`describe_run`; nothing with ``--json``
    or ``describe=False``) and save it to ``--out`` when given (:func:`save_witness`)."""
    if describe and not args.json:
        if heading:
            print(heading)
        print(describe_run(run, example))
    if args.out:
        save_witness(run, args.out, example)


def save_witness(w: dict[str, Any], path: str, example: ExampleModel | RuleSet) -> None:
    """Write a failing run to ``path`` (checked by :func:`check_witness_out`): its JSON, or
    a picture of its grid (atomically)."""
    p = Path(path)
    if p.suffix == ".json":
        write_atomic(p, json.dumps(w, default=_plain, indent=1).encode("utf-8"))
        return
    from csplab.render import save_png

    save_png(witness_grid(w), p, names=example.names)


def _plain(x: Any) -> Any:
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, ExampleModel):
        return x.labels.tolist()
    raise TypeError(type(x))


def print_verdict(v: Verdict, as_json: bool) -> None:
    if as_json:
        d = v.to_dict()
        if isinstance(v.witness, dict):
            d["witness"] = json.loads(json.dumps(v.witness, default=_plain))
        print(json.dumps(d))
    else:
        print(v.message)


def describe_run(w: dict[str, Any], example: ExampleModel | RuleSet) -> str:
    """Lines describing a failing run: size, seed, choices, first step outside C*."""
    lines = [f"  output {'x'.join(map(str, w['shape']))}, order {w.get('order', 'scanline')}"]
    if w.get("seed") is not None:
        lines[0] += f", seed {w['seed']}"
    ch = w.get("choices", [])
    shown = ch if len(ch) <= 30 else ch[-30:]
    if len(ch) > 30:
        lines.append(f"  ... {len(ch) - 30} earlier choices")
    for i, (c, b) in enumerate(shown, start=len(ch) - len(shown) + 1):
        lab = "(empty catalog)" if b is None else example.label_name(int(b))
        lines.append(f"  {i:4d}. {tuple(c)} <- {lab}")
    if w.get("first_outside_cstar") is not None:
        lines.append(
            f"  the model became inconsistent at choice {w['first_outside_cstar']} (label "
            f"outside C*); C was wiped out {w.get('detection_delay', 0)} choices later"
        )
    return "\n".join(lines)
