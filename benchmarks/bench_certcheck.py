"""Issue 26 target: certificates are checked in at most 1/10 of the time it took to find them.

    python benchmarks/bench_certcheck.py [MODEL[@BOUNDARY] ...]

For each model, in this process: the decision (``csplab prove``'s
:func:`~csplab.analysis.decide.decide_infallibility`, the time to find the certificate),
the winning region proof alone run again (the reference: one enumeration of the states),
and :func:`csplab.certcheck.check_certificate` on the JSON certificate (parsing included).
Prints each ratio with "meets" or the shortfall. Times are wall clock on a shared machine.
"""

from __future__ import annotations

import json
import sys
import time

from csplab.analysis import prove_infallible
from csplab.analysis.decide import decide_infallibility
from csplab.certcheck import check_certificate
from csplab.examples import load_model

DEFAULT = ["pillar", "tests/io/data/pipes.xml", "fig3_10", "fig3_6a", "pillar@auto", "castle"]


def main(specs: list[str]) -> int:
    print(f"{'model':24} {'verdict':8} {'find s':>8} {'one proof s':>11} {'check s':>8} "
          f"{'check/find':>10}  target <= 0.100")  # fmt: skip
    worst = 0.0
    for spec in specs:
        name, _, bnd = spec.partition("@")
        E = load_model(name)
        t0 = time.perf_counter()
        v = decide_infallibility(E, boundary=bnd or None, time_limit=600, certificate=True)
        find = time.perf_counter() - t0
        cert = v.witness.get("certificate") if isinstance(v.witness, dict) else None
        if cert is None:
            print(f"{spec:24} {'undecided':8} {find:8.2f}  (no certificate)")
            continue
        one = float("nan")
        if v.holds:
            t1 = time.perf_counter()
            prove_infallible(E, cert["region"], order=cert["order"], history=cert["history"],
                             back=cert.get("back", 1), boundary=bnd or None, refute=False,
                             certificate=True)  # fmt: skip
            one = time.perf_counter() - t1
        text = json.dumps(cert)
        t2 = time.perf_counter()
        ok, msg = check_certificate(json.loads(text))
        check = time.perf_counter() - t2
        assert ok, msg
        ratio = check / find
        worst = max(worst, ratio)
        verdict = "proved" if v.holds else "refuted"
        tag = "meets" if ratio <= 0.1 else f"shortfall x{ratio / 0.1:.1f}"
        ref = f"{one:11.2f}" if v.holds else " " * 11
        tail = f"  ({check / one:.2f} of one proof)" if v.holds else ""
        print(f"{spec:24} {verdict:8} {find:8.2f} {ref} {check:8.2f} {ratio:10.3f}  {tag}{tail}")
    print(f"worst check/find {worst:.3f}: " + ("meets" if worst <= 0.1 else "shortfall"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or DEFAULT))
