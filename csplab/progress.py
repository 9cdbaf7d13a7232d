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
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import TypeVar

__all__ = ["DELAY_S", "listen", "notice_after", "progress_bar"]

T = TypeVar("T")
DELAY_S = 2.0  # seconds before a bar appears
Listener = Callable[[str, int, "int | None"], None]
_LOCAL = threading.local()  # the listener of this thread (a web page following a run)


@contextmanager
def listen(callback: Listener) -> Iterator[None]:
    """Send the bars of this thread to ``callback(desc, done, total)`` instead of stderr.

    A web page follows a long run this way (:mod:`csplab.web` streams the counts as
    server-sent events): while the ``with`` block runs, every :func:`progress_bar` that is
    ``enabled`` in this thread calls ``callback`` once per item and draws nothing.

    Parameters
    ----------
    callback : callable
        ``callback(desc, done, total)``; ``total`` is ``None`` when unknown.

    Examples
    --------
    >>> seen = []
    >>> with listen(lambda d, n, t: seen.append((d, n, t))):
    ...     _ = list(progress_bar("ab", total=2, desc="cells", enabled=True))
    >>> seen
    [('cells', 0, 2), ('cells', 1, 2), ('cells', 2, 2)]
    """
    old = getattr(_LOCAL, "callback", None)
    _LOCAL.callback = callback
    try:
        yield
    finally:
        _LOCAL.callback = old


def progress_bar(
    items: Iterable[T], *, total: int | None, desc: str, enabled: bool, unit: str = "cell"
) -> Iterator[T]:
    """``items`` with a bar on stderr when ``enabled`` (shown after :data:`DELAY_S`)."""
    if not enabled:
        yield from items
        return
    callback = getattr(_LOCAL, "callback", None)
    if callback is not None:
        callback(desc, 0, total)
        for n, item in enumerate(items, start=1):
            yield item
            callback(desc, n, total)
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
