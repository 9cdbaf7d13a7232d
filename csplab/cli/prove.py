"""``csplab prove``: decide whether Alg. 3.1 can fail on a model (Alg. 3.6, Thm. 3.3.6).

Enumerate every window state Alg. 3.6 can reach with a region size (Sec. 3.3.7) and check
that its catalog is never empty; then Alg. 3.1 never fails on the model, at any output size
(Theorem 3.3.6). By default (``--region auto``) it runs
:func:`~csplab.analysis.decide.decide_infallibility`: regions of growing size and reach,
refined by Alg. 3.6's real failures, and a search for a failing run of Alg. 3.1, within
``--time-limit``. With ``--region RxS`` it runs that one region proof. Examples (open grids)
and tilesets (not periodic; their face rules apply). ``--certificate`` writes what the
verdict rests on, for ``csplab check-certificate``.

Exit codes: 0 proven infallible, 1 refuted (fallible; the failing run is printed and can
be saved with ``--out``), 3 undecided (not provable with this region, or the state budget
or time ran out; the state count is printed), 2 bad input.
"""

from __future__ import annotations

import argparse

from csplab.analysis import corner_condition, prove_infallible
from csplab.analysis.decide import decide_infallibility
from csplab.cli._analysis import (
    ORDER_HELP,
    add_witness_out,
    open_analysis,
    print_verdict,
    report_run,
    save_certificate,
)
from csplab.cli.common import add_model_args, check_output_path, check_time_limit
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_args(p)
    p.add_argument(
        "--region", default="auto",
        help="region size per axis, e.g. 3x2, or auto (default): growing regions and a "
        "failure search",
    )  # fmt: skip
    p.add_argument(
        "--back", default="1",
        help="with --region: how far each region reaches before its point, per axis "
        "(default 1, Alg. 3.7's region)",
    )  # fmt: skip
    p.add_argument(
        "--time-limit", type=float, default=600.0,
        help="with --region auto: seconds for the decision (default 600)",
    )  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of the failure search (auto)")
    p.add_argument("--order", default="scanline", help=ORDER_HELP)
    p.add_argument("--history", default="1", help="extra frame cells per axis (default 1)")
    p.add_argument("--max-states", type=int, default=5_000_000, help="state budget")
    p.add_argument("--corner", action="store_true", help="only check Eq. 3.11 (corner test)")
    p.add_argument(
        "--boundary",
        help="an example's boundary: auto (ground and empty space), none (default) or "
        "face=label,...; a tileset's is its file's own",
    )
    p.add_argument("--expect-hash", help="re-check a proof: exit 3 unless the hash matches")
    add_witness_out(p)
    p.add_argument(
        "--certificate",
        metavar="FILE",
        help="write a certificate (JSON) of a proved or refuted verdict",
    )
    p.add_argument("--json", action="store_true", help="print the verdict as JSON")


def run(args: argparse.Namespace) -> int:
    if args.certificate:
        check_output_path(args.certificate, "--certificate")
    E = open_analysis(args)
    if args.corner:
        v = corner_condition(E, args.order)
        print_verdict(v, args.json)
        return 0 if v.holds else 3
    hist = [int(t) for t in str(args.history).lower().split("x")] if args.history else [1]
    history: int | list[int] = hist[0] if len(hist) == 1 else hist
    if args.max_states < 1:
        raise InputError("--max-states must be positive")
    if str(args.region).lower() == "auto":
        check_time_limit(args.time_limit)
        if not isinstance(history, int):
            raise InputError("--region auto takes one --history value for every axis")
        v = decide_infallibility(
            E, order=args.order, boundary=args.boundary, time_limit=args.time_limit,
            history=history, max_states=args.max_states, rng=args.seed,
            certificate=bool(args.certificate),
        )  # fmt: skip
    else:
        try:
            bk = [int(t) for t in str(args.back).lower().split("x")]
        except ValueError:
            raise InputError(f"--back {args.back!r} is not of the form 2 or 2x1") from None
        v = prove_infallible(
            E, args.region, order=args.order, history=history, max_states=args.max_states,
            certificate=bool(args.certificate), boundary=args.boundary,
            back=bk[0] if len(bk) == 1 else bk, classes=True,  # as --region auto: one hash
        )  # fmt: skip
    cert = (v.witness or {}).pop("certificate", None) if args.certificate else None
    print_verdict(v, args.json)
    if "method" in v.stats and not args.json:
        print(f"  method: {v.stats['method']} ({v.stats['time_s']:.2f} s, "
              f"{len(v.stats['attempts'])} regions tried)")  # fmt: skip
    if cert is not None:
        save_certificate(cert, args.certificate)
        if not args.json:
            print(f"  wrote certificate {args.certificate} ({cert['claim']})")
    elif args.certificate and not args.json:
        print(f"  no certificate written to {args.certificate}: the verdict is undecided")
    if v.holds is True:
        if not args.json:
            print(f"  scope: {(v.witness or {}).get('scope')}")
            print(f"  proof sha256 {v.witness['sha256']}")
            print(f"  re-check: {v.witness['recheck']}")
        if args.expect_hash and args.expect_hash != v.witness["sha256"]:
            print("  the proof hash differs from --expect-hash")
            return 3
        return 0
    w = (v.witness or {}).get("alg31") if v.holds is False else (v.witness or {}).get("alg36")
    if w is not None and v.holds is False:
        report_run(w, E, args, "failing run of Alg. 3.1:")
    elif w is not None:
        report_run(w.get("run", w), E, args,
                   "failing run of Alg. 3.6 (Alg. 3.1 does not fail on it):",
                   describe=bool(w.get("realized")))  # fmt: skip
    if v.holds is None and not args.json and "method" not in v.stats:
        print(f"  states enumerated: {v.stats.get('states', 0)}")
    elif v.holds is None and not args.json:
        for line in v.stats["attempts"][-3:]:
            print(f"  last regions tried: {line}")
    return 1 if v.holds is False else 3
