"""The context-manager protocol of objects that hold a resource until :meth:`close`.

Examples
--------
>>> class Held(Closing):
...     def close(self) -> None:
...         print("closed")
>>> with Held() as h:
...     isinstance(h, Held)
True
closed
"""

from __future__ import annotations

from typing import Self

__all__ = ["Closing"]


class Closing:
    """A base class: ``with obj:`` gives ``obj`` and calls ``obj.close()`` at the end (also
    on an exception, which is not suppressed)."""

    def close(self) -> None:
        """Release what the object holds (subclasses define it)."""

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
