"""Long runs of the page: a ``csplab`` command run in this process, its progress collected
for the page (server-sent events) and its files kept until the run is forgotten.

A run is the command line's own command (``synthesize``, ``prove``, ``witness``) with the
arguments the page's form gives: the same options, checks and messages as in a terminal;
its ``--json`` summary is the result. Runs go one at a time (a lock): the solvers' bars
and the commands' output are per process.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["Job", "Jobs"]

_RUN_LOCK = threading.Lock()


@dataclass
class Job:
    """One run: its command line, state, progress events, result and files."""

    id: str
    argv: list[str]
    kind: str
    folder: Path
    info: dict[str, Any] = field(default_factory=dict)
    state: str = "queued"  # queued, running, done, error
    events: list[dict[str, Any]] = field(default_factory=list)
    result: dict[str, Any] | None = None
    error: str | None = None
    code: int | None = None
    started: float = field(default_factory=time.monotonic)

    def event(self, **data: Any) -> None:
        """Record one event for the page (appended; the page reads them in order)."""
        data.setdefault("t", round(time.monotonic() - self.started, 3))
        self.events.append(data)

    @property
    def finished(self) -> bool:
        return self.state in ("done", "error")


class Jobs:
    """The runs of one server (at most ``keep``; the oldest finished ones are forgotten)."""

    def __init__(self, keep: int = 32) -> None:
        self.keep = keep
        self.jobs: dict[str, Job] = {}
        self._n = 0
        self._lock = threading.Lock()

    def start(self, kind: str, argv: list[str], info: dict[str, Any] | None = None) -> Job:
        """Run ``csplab ARGV`` in a thread; ``{OUT}`` in ``argv`` is the run's folder."""
        with self._lock:
            self._n += 1
            folder = Path(tempfile.mkdtemp(prefix="csplab-run-"))
            argv = [a.replace("{OUT}", str(folder)) for a in argv]
            job = Job(f"r{self._n}", argv, kind, folder, dict(info or {}))
            self.jobs[job.id] = job
            done = [j for j in self.jobs.values() if j.finished]
            while len(self.jobs) > self.keep and done:
                old = done.pop(0)
                self.jobs.pop(old.id, None)
                shutil.rmtree(old.folder, ignore_errors=True)
        threading.Thread(target=self._run, args=(job,), daemon=True).start()
        return job

    def get(self, job_id: str) -> Job | None:
        return self.jobs.get(job_id)

    def _run(self, job: Job) -> None:
        from csplab.cli import main
        from csplab.progress import listen

        last = [0.0]

        def progress(desc: str, done: int, total: int | None) -> None:
            now = time.monotonic()
            if now - last[0] >= 0.2 or (total is not None and done >= total):
                last[0] = now
                job.event(kind="progress", desc=desc, done=done, total=total)

        job.event(kind="queued")
        with _RUN_LOCK:
            job.state = "running"
            job.event(kind="running", command=job.argv[0])
            out, err = io.StringIO(), io.StringIO()
            try:
                with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                        listen(progress):  # fmt: skip
                    job.code = main(job.argv, announce=False)
            except SystemExit as e:  # argparse: a bad option (one line on stderr)
                job.code = int(e.code) if isinstance(e.code, int) else 2
            except Exception as e:  # a bug: a line for the page, the details in the log
                import traceback

                traceback.print_exc()
                job.code = 2
                err.write(f"csplab: error: internal error ({type(e).__name__})\n")
        lines = [ln for ln in out.getvalue().splitlines() if ln.strip()]
        try:
            job.result = json.loads(lines[-1]) if lines else None
        except json.JSONDecodeError:
            job.result = None
        if isinstance(job.result, dict) and isinstance(job.result.get("out"), str):
            job.result["out"] = Path(job.result["out"]).name  # not the server's folders
        if job.code == 2 or job.result is None:
            msg = [ln for ln in err.getvalue().splitlines() if "error" in ln]
            job.error = (msg[0] if msg else err.getvalue().strip()[:300]) or "the run failed"
            job.error = job.error.replace(str(job.folder), "<out>")
            job.state = "error"
            job.event(kind="error", message=job.error)
        else:
            job.state = "done"
            job.event(kind="done", code=job.code)
