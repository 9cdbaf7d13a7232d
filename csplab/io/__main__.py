"""``python -m csplab.io [--write-readme | --check-readme] [README]``: print the formats
table of :mod:`csplab.io.registry`, or put it into the README between
``<!-- formats:begin -->`` and ``<!-- formats:end -->``."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from csplab.io.registry import README, markdown_table, update_readme


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m csplab.io", description=__doc__)
    ap.add_argument("readme", nargs="?", default=str(README))
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--write-readme", action="store_true", help="update the README table")
    g.add_argument("--check-readme", action="store_true", help="exit 1 if it is outdated")
    args = ap.parse_args(argv)
    if not (args.write_readme or args.check_readme):
        print(markdown_table(), end="")
        return 0
    changed = update_readme(args.readme, check=args.check_readme)
    if args.check_readme:
        print(f"{args.readme}: formats table {'outdated' if changed else 'up to date'}")
        return int(changed)
    print(f"{args.readme}: formats table {'updated' if changed else 'up to date'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
