"""What keeps ``csplab serve`` safe by default: paths under the served directory only, size
and time limits, and no edits from other sites.

Examples
--------
>>> import tempfile
>>> root = Path(tempfile.mkdtemp())
>>> (root / "a.txt").write_text("x")
1
>>> inside(root, "a.txt").name
'a.txt'
>>> inside(root, "../etc/passwd")
Traceback (most recent call last):
...
csplab.web.safety.Refused: '../etc/passwd' is outside the served directory
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

from csplab.errors import InputError

__all__ = ["Limits", "Refused", "cross_site", "inside"]


class Refused(InputError):
    """A request the server will not serve (HTTP 403): a path outside the served directory,
    a cross-site edit."""


@dataclass(frozen=True)
class Limits:
    """The limits of one server.

    Attributes
    ----------
    body_bytes : int
        Largest request body.
    cells : int
        Largest grid a request may ask for (synthesis output, downloaded region, edit).
    edit_cells : int
        Largest edited rectangle (the cells re-synthesized around an edit).
    seconds : float
        Longest run (passed to the solvers' time limits).
    output_bytes : int
        Largest file a response may carry.
    jobs : int
        Runs kept in memory (the oldest finished ones are forgotten).
    """

    body_bytes: int = 64 * 1024
    cells: int = 256 * 256
    edit_cells: int = 48 * 48
    seconds: float = 120.0
    output_bytes: int = 64 * 2**20
    jobs: int = 32


def inside(root: Path, relative: str) -> Path:
    """The file ``relative`` names under ``root``, symlinks resolved.

    Parameters
    ----------
    root : Path
        The served directory.
    relative : str
        A path relative to it, as a page sends it.

    Returns
    -------
    Path
        The resolved path, inside ``root``.

    Raises
    ------
    Refused
        When the path is absolute, or it (or a symlink on the way) leads outside ``root``.
    """
    if "\x00" in relative or relative.startswith(("/", "\\")) or Path(relative).is_absolute():
        raise Refused(f"{relative!r} is outside the served directory")
    base = root.resolve()
    p = (base / relative).resolve()
    if p != base and base not in p.parents:
        raise Refused(f"{relative!r} is outside the served directory")
    return p


def cross_site(headers: dict[str, str], host: str) -> str | None:
    """Why a state-changing request comes from another site, or ``None`` when it does not.

    A browser sends ``Sec-Fetch-Site`` and ``Origin`` with every ``fetch``; a page of another
    site that posts to the server (a form, a script) gets one of them wrong. The page of
    ``csplab serve`` also sends its JSON as ``application/json``, which another site cannot
    send without the browser asking the server first (a preflight this server never allows).

    Parameters
    ----------
    headers : dict
        The request's headers, lower-case names.
    host : str
        The ``Host`` the request was sent to.

    Returns
    -------
    str or None
        One line saying what is wrong.

    Examples
    --------
    >>> cross_site({"origin": "http://127.0.0.1:8000", "content-type": "application/json"},
    ...            "127.0.0.1:8000") is None
    True
    >>> cross_site({"origin": "http://evil.example", "content-type": "application/json"},
    ...            "127.0.0.1:8000")
    "cross-site request refused (Origin 'http://evil.example')"
    """
    site = headers.get("sec-fetch-site")
    if site is not None and site not in ("same-origin", "none"):
        return f"cross-site request refused (Sec-Fetch-Site {site!r})"
    origin = headers.get("origin")
    if origin is not None and urlsplit(origin).netloc != host:
        return f"cross-site request refused (Origin {origin!r})"
    if headers.get("content-type", "").split(";")[0].strip() != "application/json":
        return "edit requests must be sent as application/json"
    return None
