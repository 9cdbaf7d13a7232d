"""Progress bars for long runs: one tqdm bar on stderr that appears only after 2 seconds.

Library functions take ``progress=False`` and the CLI turns it on, so a short command prints
nothing extra and a long one (``perfect`` on a large output, exact counting) shows how far it
got.

Examples
--------
>>> sum(progress_bar(range(5), total=5, desc="cells", enabled=False))
10
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import TypeVar

__all__ = ["DELAY_S", "notice_after", "progress_bar"]

T = TypeVar("T")
DELAY_S = 2.0  # seconds before a bar appears


def progress_bar(
    items: Iterable[T], *, total: int | None, desc: str, enabled: bool, unit: str = "cell"
) -> Iterator[T]:
    """``items`` with a bar on stderr when ``enabled`` (shown after :data:`DELAY_S`)."""
    if not enabled:
        yield from items
        return
    from tqdm import tqdm

    yield from tqdm(
        items, total=total, desc=desc, unit=unit, file=sys.stderr, delay=DELAY_S,
        leave=False, mininterval=0.5, dynamic_ncols=True,
    )  # fmt: skip


@contextmanager
def notice_after(message: str, *, enabled: bool = True) -> Iterator[None]:
    """One line ``csplab: MESSAGE ...`` on stderr when the ``with`` block is still running
    after :data:`DELAY_S` (a step that has no count to show a bar of: parsing a large
    file); a quick block prints nothing.

    Examples
    --------
    >>> with notice_after("reading big.json (50 MB)"):
    ...     pass
    """
    if not enabled:
        yield
        return

    def say() -> None:
        print(f"csplab: {message} ...", file=sys.stderr, flush=True)

    timer = threading.Timer(DELAY_S, say)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
