"""A small, defensive XML reader with line numbers (for tileset files).

Built on :mod:`xml.parsers.expat`; refuses DOCTYPE declarations and entities (no
"billion laughs", no external entities) and reports every problem as a
:class:`~csplab.errors.FormatError` naming the file and line.

Examples
--------
>>> root = parse_xml('<set>\\n  <tile name="a" weight="2"/>\\n</set>', path="t.xml")
>>> root.tag, root.children[0].attrib["name"], root.children[0].line
('set', 'a', 2)
>>> parse_xml('<!DOCTYPE x [<!ENTITY a "b">]><x/>', path="t.xml")
Traceback (most recent call last):
...
csplab.errors.FormatError: t.xml, line 1: DOCTYPE declarations are not allowed (csplab reads \
XML without DTDs or entities)
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from xml.parsers import expat

from csplab.errors import FormatError

__all__ = ["Node", "parse_xml"]

MAX_XML_BYTES = 20_000_000


@dataclass
class Node:
    """An XML element: tag, attributes, children and the line it starts on."""

    tag: str
    attrib: dict[str, str]
    line: int
    children: list[Node] = field(default_factory=list)
    text: str = ""  #: the character data directly inside the element

    def find(self, tag: str) -> Node | None:
        """First child with this tag (case-insensitive)."""
        for c in self.children:
            if c.tag.lower() == tag.lower():
                return c
        return None

    def iter(self, tag: str) -> Iterator[Node]:
        """Children with this tag (case-insensitive)."""
        return (c for c in self.children if c.tag.lower() == tag.lower())

    def get(self, key: str, default: str | None = None) -> str | None:
        return self.attrib.get(key, default)


def parse_xml(text: str | bytes, *, path: object = "<string>") -> Node:
    """Parse XML text into a :class:`Node` tree, refusing DOCTYPE and entities."""
    if len(text) > MAX_XML_BYTES:
        raise FormatError("XML file is too large", path=path)
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[Node] = []
    root: list[Node] = []

    def refuse(what: str) -> None:
        raise FormatError(
            f"{what} are not allowed (csplab reads XML without DTDs or entities)",
            path=path,
            line=parser.CurrentLineNumber,
        )

    def start(tag: str, attrs: dict[str, str]) -> None:
        node = Node(tag, dict(attrs), parser.CurrentLineNumber)
        if stack:
            stack[-1].children.append(node)
        else:
            root.append(node)
        stack.append(node)

    def end(tag: str) -> None:
        stack.pop()

    def chars(data: str) -> None:
        if stack:
            stack[-1].text += data

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.StartDoctypeDeclHandler = lambda *a: refuse("DOCTYPE declarations")
    parser.EntityDeclHandler = lambda *a: refuse("entity declarations")
    parser.ExternalEntityRefHandler = lambda *a: refuse("external entities")  # type: ignore[assignment]
    try:
        parser.Parse(text, True)
    except expat.ExpatError as e:
        raise FormatError(
            f"not well-formed XML: {expat.ErrorString(e.code)}", path=path, line=e.lineno
        ) from None
    except RecursionError:
        raise FormatError("XML nesting is too deep", path=path) from None
    except LookupError as e:  # expat asks Python's codecs for an encoding it does not know
        raise FormatError(f"unknown XML encoding ({e})", path=path) from None
    if not root:
        raise FormatError("no XML root element", path=path)
    return root[0]
