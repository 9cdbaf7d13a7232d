"""JSON reading for tileset configs: line numbers in errors, ``//`` and ``/* */`` comments.

Examples
--------
>>> load_json('{"a": [1, 2] // two\\n}', path="c.json", comments=True)
{'a': [1, 2]}
>>> load_json('{"a": [1, 2}', path="c.json")
Traceback (most recent call last):
...
csplab.errors.FormatError: c.json, line 1: not valid JSON: Expecting ',' delimiter (column 12)
"""

from __future__ import annotations

import json
from typing import Any

from csplab.errors import FormatError

__all__ = ["load_json", "strip_comments"]

MAX_JSON_BYTES = 50_000_000


def strip_comments(text: str) -> str:
    """Remove ``//`` line and ``/* */`` block comments outside strings (newlines are kept, so
    line numbers stay right)."""
    out: list[str] = []
    i, n = 0, len(text)
    in_str = False
    while i < n:
        c = text[i]
        if in_str:
            out.append(c)
            if c == "\\" and i + 1 < n:
                out.append(text[i + 1])
                i += 2
                continue
            if c == '"':
                in_str = False
            i += 1
        elif c == '"':
            in_str = True
            out.append(c)
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            block = text[i : (n if j < 0 else j + 2)]
            out.append("\n" * block.count("\n"))
            i = n if j < 0 else j + 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


def load_json(text: str | bytes, *, path: object = "<string>", comments: bool = False) -> Any:
    """Parse JSON (optionally with comments) into Python objects, or a FormatError."""
    if len(text) > MAX_JSON_BYTES:
        raise FormatError("JSON file is too large", path=path)
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="replace")
    if comments:
        text = strip_comments(text)
    try:
        return json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as e:
        raise FormatError(
            f"not valid JSON: {e.msg} (column {e.colno})", path=path, line=e.lineno
        ) from None
    except RecursionError:
        raise FormatError("JSON nesting is too deep", path=path) from None


def _no_constant(name: str) -> Any:
    raise json.JSONDecodeError(f"{name} is not allowed", name, 0)
