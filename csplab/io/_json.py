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
import re
from typing import Any

from csplab.errors import FormatError

__all__ = ["MAX_DEPTH", "MAX_JSON_BYTES", "load_json", "strip_comments"]

MAX_JSON_BYTES = 50_000_000

#: The bracket depth named in a "nesting is too deep" error (where the parser gave up is
#: deeper; csplab's formats need fewer than 10 levels).
MAX_DEPTH = 100


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
        data = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as e:
        if e.doc in ("NaN", "Infinity", "-Infinity"):  # parse_constant: find it in the text
            m = re.search(r"-?\b" + re.escape(e.doc.lstrip("-")) + r"\b", text)
            line = text.count("\n", 0, m.start()) + 1 if m else None
            col = m.start() - text.rfind("\n", 0, m.start()) if m else None
            where = f" (column {col})" if col else ""
            raise FormatError(f"not valid JSON: {e.msg}{where}", path=path, line=line) from None
        raise FormatError(
            f"not valid JSON: {e.msg} (column {e.colno})", path=path, line=e.lineno
        ) from None
    except RecursionError:
        at = _depth_error(text)
        line = text.count("\n", 0, at) + 1 if at is not None else None
        raise FormatError("JSON nesting is too deep", path=path, line=line) from None
    return data


def _depth_error(text: str) -> int | None:
    """The offset where ``text``'s bracket nesting first exceeds :data:`MAX_DEPTH`
    (brackets inside strings do not count), or ``None``."""
    depth = 0
    in_str = False
    esc = False
    for i, c in enumerate(text):
        if in_str:
            if esc:
                esc = False
            elif c == "\\":
                esc = True
            elif c == '"':
                in_str = False
        elif c == '"':
            in_str = True
        elif c in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                return i
        elif c in "]}":
            depth -= 1
    return None


def _no_constant(name: str) -> Any:
    raise json.JSONDecodeError(f"{name} is not allowed", name, 0)
