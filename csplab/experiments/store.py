"""The SQLite results store: one row per finished trial, written the moment it finishes.

A trial is identified by its *key*: a hash of everything that determines its outcome
(experiment, example content hash, size, boundary, periodicity, solver spec, parameters,
seed). The ``trials`` table has a unique index on ``(experiment, trial_key)``, so a trial is
stored at most once whatever happens; re-running a sweep asks :meth:`ResultsStore.done_keys`
which trials exist and runs only the others. Each insert is its own transaction (SQLite's
write-ahead log), so a run killed with SIGKILL leaves every finished trial intact and no
half-written row.

Every row carries the provenance a reader needs: the config hash of the sweep that produced
it, the example and its hash, the csplab version, the git revision of the code and the host
that ran it.

Examples
--------
>>> import tempfile, os
>>> from csplab.experiments.trial import Trial
>>> path = os.path.join(tempfile.mkdtemp(), "r.sqlite")
>>> st = ResultsStore(path)
>>> t = Trial("demo", "line", "h0", (6, 4), "catalog", {}, seed=3)
>>> st.add(t, {"status": "solved", "time_s": 0.01, "stats": {"assigned": 24}}, config_hash="c1")
True
>>> st.add(t, {"status": "solved", "time_s": 0.02, "stats": {}}, config_hash="c1")  # once only
False
>>> len(st.rows("demo")), st.rows("demo")[0]["stats"]["assigned"]
(1, 24)
>>> st.close()
"""

from __future__ import annotations

import csv
import gzip
import hashlib
import json
import os
import socket
import sqlite3
import subprocess
import time
from collections.abc import Iterable, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

from csplab._closing import Closing
from csplab.errors import CsplabError, FormatError, InputError
from csplab.experiments.trial import Trial

__all__ = [
    "ResultsStore",
    "code_label",
    "code_revision",
    "git_revision",
    "is_current",
    "same_code",
    "store_error",
]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS trials (
    id INTEGER PRIMARY KEY,
    experiment TEXT NOT NULL,
    trial_key TEXT NOT NULL,
    config_hash TEXT NOT NULL,
    example TEXT NOT NULL,
    example_hash TEXT NOT NULL,
    size TEXT NOT NULL,
    boundary TEXT NOT NULL,
    periodic INTEGER NOT NULL,
    solver TEXT NOT NULL,
    params TEXT NOT NULL,
    seed INTEGER NOT NULL,
    status TEXT NOT NULL,
    time_s REAL NOT NULL,
    stats TEXT NOT NULL,
    csplab_version TEXT NOT NULL,
    git_rev TEXT NOT NULL,
    host TEXT NOT NULL,
    finished_at REAL NOT NULL,
    UNIQUE (experiment, trial_key)
);
CREATE TABLE IF NOT EXISTS runs (
    id INTEGER PRIMARY KEY,
    experiment TEXT NOT NULL,
    config_hash TEXT NOT NULL,
    config TEXT NOT NULL,
    command TEXT NOT NULL,
    started_at REAL NOT NULL,
    finished_at REAL,
    trials INTEGER NOT NULL,
    skipped INTEGER NOT NULL,
    ran INTEGER,
    errors INTEGER,
    git_rev TEXT NOT NULL,
    host TEXT NOT NULL
);
"""

# columns of a trial row, in CSV order
COLUMNS: tuple[str, ...] = (
    "experiment", "trial_key", "config_hash", "example", "example_hash", "size", "boundary",
    "periodic", "solver", "params", "seed", "status", "time_s", "stats", "csplab_version",
    "git_rev", "host", "finished_at",
)  # fmt: skip


@lru_cache(maxsize=1)
def git_revision() -> str:
    """The git revision of the csplab source tree, else ``"-"`` (not a git checkout).

    ``REV`` (12 hex digits) when the files under ``csplab/`` are those of the commit;
    ``REV+dirty.HASH`` when they differ from it (uncommitted edits or new untracked files),
    with ``HASH`` a short hash of the differences, so two different sets of uncommitted
    edits are two different revisions.
    """
    pkg = Path(__file__).resolve().parents[1]  # the csplab package directory

    def git(*args: str) -> bytes:
        return subprocess.run(
            ["git", *args], cwd=pkg, capture_output=True, timeout=30, check=True
        ).stdout

    try:
        rev = git("rev-parse", "--short=12", "HEAD").decode().strip()
        diff = git("diff", "HEAD", "--binary", "--", ".")
        new = git("ls-files", "--others", "--exclude-standard", "-z", "--", ".")
    except (OSError, subprocess.SubprocessError, UnicodeDecodeError):
        return "-"
    if not rev:
        return "-"
    if not diff and not new:
        return rev
    h = hashlib.sha256(diff)
    for name in sorted(filter(None, new.split(b"\0"))):
        h.update(b"\0" + name + b"\0")
        try:
            h.update((pkg / os.fsdecode(name)).read_bytes())
        except OSError:
            pass
    return f"{rev}+dirty.{h.hexdigest()[:8]}"


def code_revision() -> tuple[str, str]:
    """``(git revision, csplab version)`` of the running code: what :meth:`ResultsStore.add`
    stores by default."""
    from csplab import __version__

    return git_revision(), __version__


def code_label(git_rev: str, version: str) -> str:
    """``"git REV (csplab VERSION)"``, how messages name a code revision."""
    return f"git {git_rev} (csplab {version})"


@lru_cache(maxsize=256)
def same_code(rev_a: str, rev_b: str) -> bool:
    """True when two stored git revisions hold the same ``csplab/`` sources.

    Equal strings are the same code; two different clean commits are compared with
    ``git diff --quiet A B -- csplab`` (so a commit that changes only documentation, tests
    or papers does not make stored trials stale). An uncommitted (``+dirty``) or unknown
    (``-``) revision equals only itself, and so does a commit this checkout does not have.
    """
    if rev_a == rev_b:
        return True
    if "-" in (rev_a, rev_b) or "+" in rev_a or "+" in rev_b:
        return False
    pkg = Path(__file__).resolve().parents[1]
    try:
        r = subprocess.run(
            ["git", "diff", "--quiet", rev_a, rev_b, "--", "."],
            cwd=pkg, capture_output=True, timeout=30,
        )  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return False
    return r.returncode == 0


def is_current(git_rev: str, version: str) -> bool:
    """Was a trial stored with this provenance computed by the running code?"""
    rev, ver = code_revision()
    return version == ver and same_code(git_rev, rev)


def store_error(path: Path, error: sqlite3.DatabaseError) -> CsplabError:
    """A one-line error naming the results store for an SQLite error."""
    text = str(error)
    if "not a database" in text:
        return FormatError("not an SQLite database (a results store is one)", path=path)
    if "malformed" in text:
        return FormatError(f"the SQLite database is damaged or truncated ({text})", path=path)
    return InputError(f"results store {path}: cannot open or write it ({text})")


def _check_store_file(path: Path) -> None:
    """Before SQLite opens ``path``: the folder can be created and written, the file (if
    any) is a regular file that starts like an SQLite database and is not shorter than its
    header says (a truncated copy)."""
    import stat

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(
            f"results store {path}: cannot create the folder {path.parent} ({e.strerror})"
        ) from None
    if not path.exists():
        if not os.access(path.parent, os.W_OK | os.X_OK):
            raise InputError(f"results store {path}: the folder {path.parent} is not writable")
        return
    st = path.stat()
    if not stat.S_ISREG(st.st_mode):
        raise FormatError("not a regular file (a results store is an SQLite file)", path=path)
    if st.st_size == 0:
        return  # a new, empty database
    with open(path, "rb") as fh:
        head = fh.read(100)
    if not head.startswith(b"SQLite format 3\x00"):
        raise FormatError("not an SQLite database (a results store is one)", path=path)
    if len(head) < 100:
        raise FormatError("the SQLite database is truncated (no complete header)", path=path)
    page = int.from_bytes(head[16:18], "big")
    page = 65536 if page == 1 else page
    pages = int.from_bytes(head[28:32], "big")
    header_valid = head[24:28] == head[92:96]  # the in-header size is current
    if header_valid and pages and st.st_size < page * pages:
        raise FormatError(
            f"the SQLite database is truncated ({st.st_size} bytes; its header says "
            f"{page * pages})",
            path=path,
        )
    if not os.access(path, os.R_OK | os.W_OK):
        raise InputError(f"results store {path}: the file is not writable")


def _process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this host (a zombie counts as gone)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


class ResultsStore(Closing):
    """A SQLite file holding the trials of any number of experiments.

    Parameters
    ----------
    path : str or Path
        The database file (created with its parent directory when missing).
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        if str(path) != ":memory:":
            _check_store_file(self.path)
        try:
            self._db = sqlite3.connect(str(path), timeout=60.0, isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")
            self._db.executescript(_SCHEMA)
            have = {r[1] for r in self._db.execute("PRAGMA table_info(runs)")}
            for col, typ in (("status", "TEXT"), ("pid", "INTEGER")):
                if col not in have:  # stores written before these columns existed
                    self._db.execute(f"ALTER TABLE runs ADD COLUMN {col} {typ}")
        except sqlite3.DatabaseError as e:  # OperationalError too: one line naming the file
            raise store_error(self.path, e) from None

    # ---------------------------------------------------------------- writing
    def add(
        self,
        trial: Trial,
        outcome: dict[str, Any],
        *,
        config_hash: str,
        git_rev: str | None = None,
        version: str | None = None,
    ) -> bool:
        """Store one finished trial; ``False`` when it was already there (kept unchanged).

        ``outcome`` has ``status``, ``time_s``, ``stats`` and optionally ``host``.
        """
        from csplab import __version__

        cur = self._db.execute(
            "INSERT OR IGNORE INTO trials (experiment, trial_key, config_hash, example, "
            "example_hash, size, boundary, periodic, solver, params, seed, status, time_s, "
            "stats, csplab_version, git_rev, host, finished_at) "
            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                trial.experiment, trial.key, config_hash, trial.example, trial.example_hash,
                trial.size_text, trial.boundary, int(trial.periodic), trial.solver,
                json.dumps(trial.params, sort_keys=True), int(trial.seed),
                str(outcome["status"]), float(outcome.get("time_s", 0.0)),
                json.dumps(outcome.get("stats", {}), sort_keys=True),
                version or __version__, git_rev or git_revision(),
                str(outcome.get("host") or socket.gethostname()), time.time(),
            ),
        )  # fmt: skip
        return cur.rowcount == 1

    def start_run(
        self,
        experiment: str,
        config: dict[str, Any],
        config_hash: str,
        *,
        trials: int,
        skipped: int,
        command: str = "",
    ) -> int:
        """Record the start of a sweep; returns its run id."""
        cur = self._db.execute(
            "INSERT INTO runs (experiment, config_hash, config, command, started_at, trials, "
            "skipped, git_rev, host, pid) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                experiment, config_hash, json.dumps(config, sort_keys=True), command, time.time(),
                trials, skipped, git_revision(), socket.gethostname(), os.getpid(),
            ),
        )  # fmt: skip
        return int(cur.lastrowid or 0)

    def mark_abandoned(self, experiment: str) -> int:
        """Mark the unfinished runs of ``experiment`` on this host whose process is gone
        (killed with SIGKILL, so it could not record its end) as ``"interrupted"``;
        returns how many. Their trials that finished are stored; the others are missing
        and run again."""
        host = socket.gethostname()
        cur = self._db.execute(
            "SELECT id, pid FROM runs WHERE experiment = ? AND finished_at IS NULL "
            "AND status IS NULL AND host = ? AND pid IS NOT NULL",
            (experiment, host),
        )
        gone = [rid for rid, pid in cur.fetchall() if not _process_alive(int(pid))]
        for rid in gone:
            self._db.execute("UPDATE runs SET status = 'interrupted' WHERE id = ?", (rid,))
        return len(gone)

    def finish_run(self, run_id: int, *, ran: int, errors: int, interrupted: bool = False) -> None:
        """Record the end of a sweep (``status`` ``"finished"`` or ``"interrupted"``)."""
        self._db.execute(
            "UPDATE runs SET finished_at = ?, ran = ?, errors = ?, status = ? WHERE id = ?",
            (time.time(), ran, errors, "interrupted" if interrupted else "finished", run_id),
        )

    def delete(self, experiment: str, keys: Iterable[str] | None = None) -> int:
        """Forget stored trials of ``experiment`` (those with the given keys, or all);
        returns how many were deleted."""
        if keys is None:
            cur = self._db.execute("DELETE FROM trials WHERE experiment = ?", (experiment,))
            return int(cur.rowcount)
        n = 0
        self._db.execute("BEGIN")
        for k in keys:
            cur = self._db.execute(
                "DELETE FROM trials WHERE experiment = ? AND trial_key = ?", (experiment, k)
            )
            n += int(cur.rowcount)
        self._db.execute("COMMIT")
        return n

    # ---------------------------------------------------------------- reading
    def done_keys(self, experiment: str) -> set[str]:
        """Keys of the trials of ``experiment`` already stored."""
        cur = self._db.execute("SELECT trial_key FROM trials WHERE experiment = ?", (experiment,))
        return {r[0] for r in cur.fetchall()}

    def provenance(
        self, experiment: str, keys: Iterable[str] | None = None
    ) -> dict[str, tuple[str, str]]:
        """``trial key -> (git_rev, csplab_version)`` of the stored trials of
        ``experiment`` (those with the given keys, or all)."""
        cur = self._db.execute(
            "SELECT trial_key, git_rev, csplab_version FROM trials WHERE experiment = ?",
            (experiment,),
        )
        wanted = None if keys is None else set(keys)
        return {k: (r, v) for k, r, v in cur.fetchall() if wanted is None or k in wanted}

    def stale(
        self, experiment: str, keys: Iterable[str] | None = None
    ) -> dict[str, tuple[str, str]]:
        """The stored trials (key -> ``(git_rev, csplab_version)``) computed by other code
        than the running one (see :func:`is_current`): a resumed sweep reports them, and
        ``--rerun-stale`` runs them again."""
        return {k: p for k, p in self.provenance(experiment, keys).items() if not is_current(*p)}

    def count(self, experiment: str | None = None) -> int:
        if experiment is None:
            return int(self._db.execute("SELECT COUNT(*) FROM trials").fetchone()[0])
        cur = self._db.execute("SELECT COUNT(*) FROM trials WHERE experiment = ?", (experiment,))
        return int(cur.fetchone()[0])

    def rows(
        self, experiment: str | None = None, keys: Iterable[str] | None = None
    ) -> list[dict[str, Any]]:
        """Stored trials as dicts (``params`` and ``stats`` decoded), oldest first.

        ``keys`` restricts the result to those trial keys (the trials of one sweep).
        """
        sql = f"SELECT {', '.join(COLUMNS)} FROM trials"
        args: tuple[Any, ...] = ()
        if experiment is not None:
            sql += " WHERE experiment = ?"
            args = (experiment,)
        cur = self._db.execute(sql + " ORDER BY id", args)
        wanted = None if keys is None else set(keys)
        out = []
        for r in cur.fetchall():
            d = dict(zip(COLUMNS, r, strict=True))
            if wanted is not None and d["trial_key"] not in wanted:
                continue
            d["params"] = json.loads(d["params"])
            d["stats"] = json.loads(d["stats"])
            d["periodic"] = bool(d["periodic"])
            out.append(d)
        return out

    def runs(self, experiment: str | None = None) -> list[dict[str, Any]]:
        sql = "SELECT * FROM runs" + (" WHERE experiment = ?" if experiment else "")
        cur = self._db.execute(sql + " ORDER BY id", (experiment,) if experiment else ())
        names = [c[0] for c in cur.description]
        return [dict(zip(names, r, strict=True)) for r in cur.fetchall()]

    def experiments(self) -> list[str]:
        cur = self._db.execute("SELECT DISTINCT experiment FROM trials ORDER BY experiment")
        return [r[0] for r in cur.fetchall()]

    def export_csv(
        self,
        path: str | os.PathLike[str],
        experiment: str | None = None,
        keys: Iterable[str] | None = None,
        stats_keys: Sequence[str] | None = None,
    ) -> int:
        """Write trials to CSV (gzip-compressed when ``path`` ends in ``.gz``; one column per
        stats key, keys starting with ``_`` left out); returns the number of rows."""
        rows = self.rows(experiment, keys)
        if stats_keys is None:
            seen: dict[str, None] = {}
            for r in rows:
                for k in r["stats"]:
                    if not k.startswith("_"):
                        seen.setdefault(k, None)
            stats_keys = list(seen)
        base = [c for c in COLUMNS if c != "stats"]
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        opener: Any = gzip.open if str(path).endswith(".gz") else open
        with opener(path, "wt", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(base + [f"stats.{k}" for k in stats_keys])
            for r in rows:
                vals = [json.dumps(r[c], sort_keys=True) if c == "params" else r[c] for c in base]
                for k in stats_keys:
                    v = r["stats"].get(k, "")
                    vals.append(json.dumps(v) if isinstance(v, list | dict) else v)
                w.writerow(vals)
        return len(rows)

    def close(self) -> None:
        self._db.close()
