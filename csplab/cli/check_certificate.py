"""``csplab check-certificate``: re-verify an infallibility certificate without the prover.

A certificate of ``csplab prove --certificate`` for a proved verdict holds the closed set of
Alg. 3.6 frame states: the check re-verifies the closure, the soundness of what each state
records, every configuration and that no catalog is empty at a point. One for a refuted
verdict holds a failing run of Alg. 3.1, which is replayed. With ``--model``, the
certificate's rules must be that model's. The check runs :mod:`csplab.certcheck`, which
shares no code with the prover.

Exit codes: 0 valid, 1 invalid (the first defect is printed), 2 bad file (missing, not
JSON, not a certificate) or a ``--model`` whose rules differ from the certificate's.
"""

from __future__ import annotations

import argparse
import time

from csplab.certcheck import check_certificate, load_certificate
from csplab.cli.common import add_model_option
from csplab.errors import InputError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE", help="certificate (JSON) from csplab prove")
    p.add_argument("--model", help="also require the certificate's rules to be this model's")
    p.add_argument("--boundary", help="with --model: the example's boundary given to prove")
    add_model_option(p)


def run(args: argparse.Namespace) -> int:
    cert = load_certificate(args.file)
    if args.model:
        _same_rules(cert, args.file, args.model, args.model_option, args.boundary)
    t0 = time.perf_counter()
    ok, msg = check_certificate(cert)
    dt = time.perf_counter() - t0
    model = cert.get("model") or {}
    print(f"{args.file}: {cert.get('claim')} claim for {model.get('name') or 'a model'}")
    print(f"  {msg}")
    prover = cert.get("prover") or {}
    if isinstance(prover.get("time_s"), int | float):
        print(f"  checked in {dt:.3f} s (the prover took {prover['time_s']:.3f} s)")
    else:
        print(f"  checked in {dt:.3f} s")
    return 0 if ok else 1


def _same_rules(
    cert: dict[str, object], path: str, spec: str, options: list[str] | None, boundary: str | None
) -> None:
    import numpy as np

    from csplab.analysis.infallible import face_rules_of
    from csplab.cli._analysis import load_analysis_model
    from csplab.example import ExampleModel

    M = load_analysis_model(spec, options)
    T = M.transitions()
    used = M.counts() > 0 if isinstance(M, ExampleModel) else np.ones(T.shape[1], dtype=bool)
    rules = cert.get("rules")
    mine = {
        "labels": int(T.shape[1]),
        "used": [int(b) for b in used],
        "pairs": [np.argwhere(T[d]).tolist() for d in range(T.shape[0])],
        "faces": [list(f) for f in face_rules_of(M, boundary)],
    }
    if rules != mine:
        raise InputError(f"{path}: the certificate's rules are not those of {spec}")
