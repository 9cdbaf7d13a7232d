"""The :class:`Experiment` base class, reports, and helpers shared by the experiments.

An experiment is a grid of trials (example × size × solver × parameters × seed) plus a
report that turns the stored outcomes into tables and figures. Its configuration is a plain
JSON dict: the class' ``defaults``, updated by ``quick`` for ``--quick`` runs and by the
user's overrides. The same configuration always yields the same trials (and trial keys).

Examples
--------
>>> parse_sizes("5:20:5")
[5, 10, 15, 20]
>>> parse_sizes("4,8,16")
[4, 8, 16]
>>> from csplab.examples import load_example
>>> size_for(load_example("castle"), 12, nz=10), size_for(load_example("line"), 12, nz=10)
((12, 12, 10), (12, 12))
"""

from __future__ import annotations

import argparse
import copy
import json
import math
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, TypeVar

import numpy as np

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.experiments.trial import Trial, build_problem

__all__ = [
    "Experiment",
    "Report",
    "background_labels",
    "example_names",
    "group_rows",
    "load_examples",
    "parse_sizes",
    "provenance_note",
    "setting_of",
    "size_for",
    "split_solver",
    "sweep_defaults",
]

#: The defaults of the options most sweeps share (solver settings and the problem's
#: boundary); an experiment's ``defaults`` start from them (:func:`sweep_defaults`).
SWEEP_DEFAULTS: dict[str, Any] = {
    "seed0": 0,
    "order": "scanline",
    "choice": "uniform",
    "boundary": "auto",
    "periodic": False,
    "options": {},
    "time_limit": None,
}


def sweep_defaults(*, omit: Iterable[str] = (), **own: Any) -> dict[str, Any]:
    """An experiment's ``defaults``: :data:`SWEEP_DEFAULTS` but the keys in ``omit``,
    then the experiment's own keys and values ``own`` (which may override them).

    Examples
    --------
    >>> d = sweep_defaults(omit=("order", "choice"), seeds=4, boundary="none")
    >>> d["seeds"], d["boundary"], "order" in d, d["time_limit"]
    (4, 'none', False, None)
    """
    skip = set(omit)
    return copy.deepcopy({**{k: v for k, v in SWEEP_DEFAULTS.items() if k not in skip}, **own})


def parse_sizes(text: str | Sequence[int]) -> list[int]:
    """``"5:50:5"`` (inclusive range), ``"5,10,20"`` or a list -> sorted unique sizes."""
    if not isinstance(text, str):
        vals = [int(v) for v in text]
    elif ":" in text:
        parts = text.split(":")
        try:
            nums = [int(p) for p in [*parts, "1"][:3]] if len(parts) in (2, 3) else [0, 0, 0]
            lo, hi, step = nums
        except ValueError:
            raise InputError(f"sizes {text!r}: use START:STOP[:STEP] or a comma list") from None
        if len(parts) not in (2, 3) or step < 1 or lo > hi:
            raise InputError(f"sizes {text!r}: use START:STOP[:STEP] with START <= STOP")
        vals = list(range(lo, hi + 1, step))
    else:
        try:
            vals = [int(v) for v in text.replace(" ", "").split(",") if v]
        except ValueError:
            raise InputError(f"sizes {text!r}: use START:STOP[:STEP] or a comma list") from None
    if not vals or min(vals) < 1:
        raise InputError(f"sizes {text!r} must be positive integers")
    return sorted(set(vals))


def size_for(example: ExampleModel, s: int, nz: int) -> tuple[int, ...]:
    """The output size ``nx = ny = s`` (and ``nz`` for 3D examples that are more than one
    layer thick) for an example."""
    if example.ndim == 1:
        return (s,)
    if not isinstance(example, ExampleModel):  # a tileset: its axes
        return (s, s) if example.ndim == 2 else (s, s, nz)
    if example.ndim == 2 or (example.ndim == 3 and example.shape[2] == 1):
        return (s, s) if example.ndim == 2 else (s, s, 1)
    return (s, s, nz, *example.shape[3:])


def load_examples(specs: Sequence[str], tilesets: bool = False) -> list[tuple[str, Any]]:
    """Built-in names or model files -> ``(spec, model)``: example models, and tilesets
    (:class:`~csplab.io.ruleset.RuleSet`) for experiments that take them; bad input raises
    one line."""
    from csplab.examples import load_model
    from csplab.io.ruleset import RuleSet

    if not specs:
        raise InputError("no example model given")
    out: list[tuple[str, Any]] = []
    for s in specs:
        m = load_model(s)
        if not isinstance(m, ExampleModel) and not (tilesets and isinstance(m, RuleSet)):
            raise InputError(
                f"{s}: this experiment takes example models (grids), not "
                f"{type(m).__name__} files (fig3_8 and constraints also take tilesets)"
            )
        out.append((s, m))
    return out


def example_names(specs: Iterable[str]) -> dict[str, str]:
    """Short names for example specs in tables, legends and axis labels: a built-in name
    as it is, a model file by its stem (the full path stays in the report's configuration
    block); files whose stems collide keep as many parent folders as tell them apart.

    Examples
    --------
    >>> example_names(["city", "/home/me/models/Castle.txt", "a/x.txt", "b/x.txt"])
    {'city': 'city', '/home/me/models/Castle.txt': 'Castle', 'a/x.txt': 'a/x', 'b/x.txt': 'b/x'}
    """
    specs = list(dict.fromkeys(specs))
    parts = {s: Path(s).with_suffix("").parts or (s,) for s in specs}
    depth = dict.fromkeys(specs, 1)
    while True:
        names = {s: "/".join(parts[s][-depth[s] :]) for s in specs}
        seen: dict[str, list[str]] = {}
        for s, n in names.items():
            seen.setdefault(n, []).append(s)
        grow = [s for group in seen.values() if len(group) > 1 for s in group
                if depth[s] < len(parts[s])]  # fmt: skip
        if not grow:
            break
        for s in grow:
            depth[s] += 1
    # an unchanged collision (the same path written twice, or a file named like a
    # built-in example) keeps the spec as it was given
    return {s: (n if len(seen[n]) == 1 else s) for s, n in names.items()}


K = TypeVar("K", bound=Hashable)


def group_rows(
    rows: Iterable[dict[str, Any]], key: Callable[[dict[str, Any]], K]
) -> dict[K, list[dict[str, Any]]]:
    """Stored rows grouped by ``key(row)``, the groups in the order of their first row.

    Examples
    --------
    >>> group_rows([{"e": "a", "t": 1}, {"e": "b", "t": 2}, {"e": "a", "t": 3}], lambda r: r["e"])
    {'a': [{'e': 'a', 't': 1}, {'e': 'a', 't': 3}], 'b': [{'e': 'b', 't': 2}]}
    """
    out: dict[K, list[dict[str, Any]]] = {}
    for r in rows:
        out.setdefault(key(r), []).append(r)
    return out


def background_labels(example: ExampleModel) -> list[int]:
    """Labels that count as 'nothing built': the empty space and ground labels of
    ``boundary="auto"``, else the most frequent label (tilesets:
    :meth:`~csplab.io.ruleset.RuleSet.background`)."""
    from csplab.grids import auto_boundary

    if not isinstance(example, ExampleModel):
        return list(example.background())
    try:
        return sorted(set(auto_boundary(example).values()))
    except InputError:
        return [int(np.argmax(example.counts()))]


def provenance_note(rows: Sequence[dict[str, Any]]) -> str | None:
    """A report note naming the code revisions that computed ``rows`` when there are
    several (``None`` when one revision computed them all).

    The note depends only on the stored rows, so redrawing a report at another commit
    gives the same text; whether the running code is one of them is said on stderr by
    ``csplab experiment`` (see :meth:`~csplab.experiments.runner.RunSummary.stale_line`).
    """
    from collections import Counter

    from csplab.experiments.store import code_label, same_code

    found = Counter((str(r["git_rev"]), str(r["csplab_version"])) for r in rows)
    if len(found) <= 1:
        return None
    revs = found.most_common()
    parts = ", ".join(f"{n} by {code_label(*rv)}" for rv, n in revs)
    first_rev, first_ver = revs[0][0]
    same = all(ver == first_ver and same_code(rev, first_rev) for (rev, ver), _ in revs)
    tail = (
        " (their csplab/ sources are identical)"
        if same
        else "; `--rerun-stale` runs again those not computed by the running code"
    )
    return f"The trials were computed by {len(revs)} revisions of csplab: {parts}{tail}."


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return "–"
        if v == 0:
            return "0"
        if abs(v) >= 100:
            return f"{v:.0f}"
        if abs(v) >= 1:
            return f"{v:.3g}" if abs(v) < 10 else f"{v:.1f}"
        return f"{v:.3g}"
    if v is None:
        return "–"
    return str(v)


def _csv_value(v: Any) -> Any:
    """Floats with 6 significant digits (the CSVs are read by people too)."""
    if isinstance(v, float) and math.isfinite(v):
        return float(f"{v:.6g}")
    return v


def markdown_table(rows: Sequence[dict[str, Any]], columns: Sequence[str] | None = None) -> str:
    """Rows of dicts -> a GitHub markdown table."""
    if not rows:
        return "(no rows)"
    cols = list(columns or dict.fromkeys(k for r in rows for k in r))
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(c)) for c in cols) + " |")
    return "\n".join(lines)


@dataclass
class Report:
    """Tables (name -> rows), figures and notes produced from stored outcomes."""

    experiment: str
    title: str
    config: dict[str, Any]
    tables: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    figures: list[Path] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    missing: int = 0
    trials: int = 0

    def markdown(self, relative_to: Path | None = None) -> str:
        out = [f"# {self.title}", ""]
        cfg = json.dumps(self.config, sort_keys=True)
        out += [f"Configuration: `{cfg}`", ""]
        if self.missing:
            out += [f"**{self.missing} of {self.trials} trials are not in the store yet.**", ""]
        for note in self.notes:
            out += [note, ""]
        for name, rows in self.tables.items():
            out += [f"## {name}", "", markdown_table(rows), ""]
        for f in self.figures:
            if f.suffix == ".png":
                rel = f.relative_to(relative_to) if relative_to else f
                out += [f"![{f.stem}]({rel.as_posix()})", ""]
        return "\n".join(out)

    def write(self, out: Path, stem: str) -> list[Path]:
        """Write ``stem.md`` and one CSV per table into ``out``; returns the paths."""
        import csv

        out.mkdir(parents=True, exist_ok=True)
        paths = []
        for name, rows in self.tables.items():
            if not rows:
                continue
            p = out / f"{stem}_{name.lower().replace(' ', '_').replace('.', '')}.csv"
            cols: dict[str, None] = {}
            for r in rows:
                for k in r:
                    cols.setdefault(k, None)
            with open(p, "w", newline="", encoding="utf-8") as f:
                w = csv.DictWriter(f, fieldnames=list(cols))
                w.writeheader()
                for r in rows:
                    w.writerow({k: _csv_value(r.get(k, "")) for k in cols})
            paths.append(p)
        md = out / f"{stem}.md"
        md.write_text(self.markdown(out) + "\n", encoding="utf-8")
        paths.append(md)
        self.files += paths
        return paths


def split_solver(entry: str) -> tuple[str, dict[str, Any]]:
    """``"catalog@order=random,choice=weighted"`` -> ``("catalog", {"order": "random", ...})``.

    A solver *entry* is a solver spec optionally followed by ``@`` and options (values
    parsed as JSON when possible), so one sweep can compare variants of one solver.

    Examples
    --------
    >>> split_solver("blocks@block=4,retries=0")
    ('blocks', {'block': 4, 'retries': 0})
    >>> split_solver("sat:glucose4")
    ('sat:glucose4', {})
    """
    spec, _, rest = str(entry).partition("@")
    opts: dict[str, Any] = {}
    for kv in filter(None, (p.strip() for p in rest.split(","))):
        k, sep, v = kv.partition("=")
        if not sep or not k:
            raise InputError(f"solver entry {entry!r}: options must be key=value")
        try:
            opts[k.strip()] = json.loads(v)
        except json.JSONDecodeError:
            opts[k.strip()] = v.strip()
    if not spec:
        raise InputError(f"solver entry {entry!r} has no solver name")
    return spec.strip(), opts


def setting_of(row: dict[str, Any]) -> str:
    """The solver entry a stored trial was run with (its ``label``, else its solver spec)."""
    return str(row["params"].get("label", row["solver"]))


def check_boundary(example: ExampleModel, boundary: str, spec: str) -> None:
    """Fail early (one line) when ``boundary="auto"`` cannot label this example (a tileset
    brings its own boundary conditions)."""
    if boundary == "auto" and isinstance(example, ExampleModel):
        from csplab.grids import auto_boundary

        try:
            auto_boundary(example)
        except InputError as e:
            raise InputError(f"example {spec}: {e}; use --boundary none") from None


class Experiment:
    """Base class: subclasses set the class attributes and implement :meth:`build` and
    :meth:`report`.

    ``uses`` names the common options (``examples``, ``sizes``, ``size``, ``solvers``,
    ``seeds``, ``seed0``, ``boundary``, ``order``, ``choice``, ``options``,
    ``time_limit``, ``periodic``) the experiment reads; the CLI rejects the others.
    """

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    description: ClassVar[str] = ""
    defaults: ClassVar[dict[str, Any]] = {}
    quick: ClassVar[dict[str, Any]] = {}
    uses: ClassVar[frozenset[str]] = frozenset()
    tilesets: ClassVar[bool] = False  # whether examples may be tilesets (RuleSet files)
    default_out: ClassVar[str] = ""  # report directory when none is given (results/NAME)
    draw_figures: bool = True  # draw figures in :meth:`report` (tests switch them off)

    def add_arguments(self, p: argparse.ArgumentParser) -> None:
        """Experiment-specific command-line options (their ``dest`` is the config key)."""

    def make_config(self, quick: bool = False, **overrides: Any) -> dict[str, Any]:
        """Defaults, then the ``--quick`` values, then non-``None`` overrides."""
        cfg: dict[str, Any] = json.loads(json.dumps(self.defaults))
        if quick:
            cfg.update(json.loads(json.dumps(self.quick)))
        unknown = set(overrides) - set(cfg)
        if unknown:
            raise InputError(
                f"experiment {self.name!r} has no option(s) {', '.join(sorted(unknown))}; "
                f"it has {', '.join(sorted(cfg))}"
            )
        for k, v in overrides.items():
            if v is not None:
                cfg[k] = v
        cfg["quick"] = bool(quick)
        self.validate(cfg)
        return cfg

    def validate(self, config: dict[str, Any]) -> None:
        """Raise :class:`InputError` for a bad configuration (subclasses extend)."""
        if "seeds" in config and int(config["seeds"]) < 1:
            raise InputError("seeds must be >= 1")
        if "sizes" in config:
            config["sizes"] = parse_sizes(config["sizes"])

    def build(self, config: dict[str, Any]) -> tuple[list[Trial], dict[str, ExampleModel]]:
        """The trials of the sweep and the example models they use (by hash)."""
        raise NotImplementedError

    def trials(self, quick: bool = False, **overrides: Any) -> list[Trial]:
        """The trials of the sweep configured by :meth:`make_config` (``quick`` and
        ``overrides`` as there)."""
        return self.build(self.make_config(quick=quick, **overrides))[0]

    def report(
        self, rows: list[dict[str, Any]], config: dict[str, Any], out: Path
    ) -> Report:  # pragma: no cover - abstract
        """Tables and figures from the stored outcomes of the sweep's trials."""
        raise NotImplementedError

    # helpers ------------------------------------------------------------------------
    def load_examples(
        self, config: dict[str, Any]
    ) -> tuple[list[tuple[str, ExampleModel]], dict[str, ExampleModel]]:
        """The configured examples as ``(spec, model)`` pairs, each checked against the
        boundary, and the same models by content hash (what :meth:`build` returns)."""
        loaded = load_examples(config["examples"], tilesets=self.tilesets)
        for spec, E in loaded:
            check_boundary(E, config["boundary"], spec)
        return loaded, {E.hash(): E for _, E in loaded}

    def seeds(self, config: dict[str, Any]) -> range:
        s0 = int(config.get("seed0", 0))
        return range(s0, s0 + int(config["seeds"]))

    def solver_trials(
        self, config: dict[str, Any], spec: str, example: ExampleModel, size: tuple[int, ...]
    ) -> list[Trial]:
        """One trial per configured solver entry and seed for ``example`` at ``size``."""
        out: list[Trial] = []
        cons = self.constraint_entries(config, example, size)
        for entry in config["solvers"]:
            solver, params = self.solver_params(config, entry)
            if cons:
                params["constraints"] = cons
            for seed in self.seeds(config):
                out.append(
                    Trial(
                        self.name, spec, example.hash(), size, solver, params, seed,
                        config["boundary"], bool(config["periodic"]),
                    )
                )  # fmt: skip
        return out

    def constraint_entries(
        self, config: dict[str, Any], example: ExampleModel, size: tuple[int, ...]
    ) -> list[dict[str, Any]]:
        """The global constraints of the trials of ``example`` at ``size``: the entries of
        every ``--constraints FILE`` (checked against the problem here, so a bad file is one
        line before anything runs)."""
        paths = config.get("constraints") or []
        if not paths:
            return []
        from csplab.constraints import parse_constraints
        from csplab.io.constraints import read_entries

        entries = [e for path in paths for e in read_entries(path)]
        P = build_problem(example, size, str(config.get("boundary", "none")),
                          bool(config.get("periodic")))  # fmt: skip
        parse_constraints(entries, P, ", ".join(map(str, paths)))
        return entries

    def solver_params(self, config: dict[str, Any], entry: str) -> tuple[str, dict[str, Any]]:
        """``(solver spec, params)`` for a solver entry: params hold the ``options``, the
        ``restarts`` of :func:`csplab.solvers.solve` (``catalog@restarts=20``), its
        ``fallback`` (``catalog@restarts=10,fallback=sat``; none unless asked, so the
        experiments measure single solvers) and, for
        entries with ``@`` options, the entry as ``label``."""
        spec, extra = split_solver(entry)
        opts = self.solver_options(config, spec)
        restarts = extra.pop("restarts", None)  # solve(..., restarts=N), not a solver option
        fallback = extra.pop("fallback", None)  # solve(..., fallback=...): only when asked
        opts.update(extra)
        params: dict[str, Any] = {"options": opts}
        if restarts is not None:
            if isinstance(restarts, bool) or not isinstance(restarts, int) or restarts < 0:
                raise InputError(f"solver entry {entry!r}: restarts must be an integer >= 0")
            params["restarts"] = restarts
        if fallback is not None:
            from csplab.solvers.chain import check_fallback

            try:
                params["fallback"] = check_fallback(str(fallback))
            except InputError as e:
                raise InputError(f"solver entry {entry!r}: {e}") from None
        if extra or restarts is not None or fallback is not None:
            params["label"] = entry
        return spec, params

    def solver_options(self, config: dict[str, Any], solver: str) -> dict[str, Any]:
        """Common options for a solver: order/choice for solvers that declare ``alg31`` (they run
        Alg. 3.1 and take its vocabulary), the time limit,
        and ``options``."""
        from csplab.solvers import solver_class

        opts: dict[str, Any] = {}
        name = solver.partition(":")[0]
        if solver_class(name).alg31:
            if config.get("order"):
                opts["order"] = config["order"]
            if config.get("choice"):
                opts["choice"] = config["choice"]
        if config.get("time_limit") is not None:
            opts["time_limit"] = float(config["time_limit"])
        for k, v in (config.get("options") or {}).items():
            target, dot, key = k.rpartition(".")
            if not dot:
                opts[k] = v
            elif target == name:
                opts[key] = v
        return opts
