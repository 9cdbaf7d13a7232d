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
from collections.abc import Iterable, Iterator
from typing import TypeVar

__all__ = ["DELAY_S", "progress_bar"]

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
