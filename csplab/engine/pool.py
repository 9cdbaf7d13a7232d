"""Independent tasks on worker processes: a local process pool or a Dask cluster.

The one executor of csplab's parallel parts -- the waves of modify-in-blocks
(:mod:`csplab.engine.waves`) and the sweeps of the experiments
(:mod:`csplab.experiments.runner`). :class:`Workers` hides which of the two runs the tasks:

* :meth:`Workers.local`: a :class:`~concurrent.futures.ProcessPoolExecutor` whose workers
  exit when their parent dies (:func:`exit_with_parent`: a SIGKILL of the parent leaves no
  chance to shut the pool down) and ignore Ctrl-C (it reaches the whole process group; the
  parent decides what stops);
* :meth:`Workers.dask`: a Dask ``distributed`` client (an address such as
  ``tcp://host:8786``, ``"local"`` for a ``LocalCluster`` of single-threaded processes, or
  a ``distributed.Client`` that the caller owns; the optional extra ``csplab[dask]``).

Both give futures with ``result()`` and ``exception()``; :meth:`Workers.wait` waits for
them, :meth:`Workers.close` stops the workers (``kill=True``: now, killing running tasks).

Examples
--------
>>> w = Workers.local(1)
>>> f = w.submit(pow, 2, 10)
>>> [x.result() for x in w.wait([f])], w.size
([1024], 1)
>>> w.close()
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, FIRST_EXCEPTION, ProcessPoolExecutor, wait
from typing import Any

from csplab.errors import InputError

__all__ = ["Workers", "exit_with_parent"]


def exit_with_parent(parent: int) -> None:
    """Make this worker process exit as soon as its parent ``parent`` dies, and ignore
    Ctrl-C: ``PR_SET_PDEATHSIG`` on Linux, and a thread polling ``os.getppid()``
    everywhere."""
    import signal

    try:  # Ctrl-C reaches the whole process group: the parent decides what stops
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (ValueError, OSError):
        pass
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:
        os._exit(1)

    def poll() -> None:
        while True:
            if os.getppid() != parent:
                os._exit(1)
            time.sleep(0.5)

    threading.Thread(target=poll, name="csplab-parent-watch", daemon=True).start()


def _init_worker(parent: int, init: Callable[..., None] | None, args: tuple[Any, ...]) -> None:
    exit_with_parent(parent)
    if init is not None:
        init(*args)


class Workers:
    """Tasks on a local process pool or a Dask cluster (build with :meth:`local` or
    :meth:`dask`); ``size`` is the number of tasks that run at once."""

    def __init__(
        self,
        size: int,
        *,
        pool: ProcessPoolExecutor | None = None,
        client: Any = None,
        cluster: Any = None,
        own: bool = False,
    ) -> None:
        self.size = size
        self.pool = pool
        self.client = client
        self.cluster = cluster
        self.own = own  # close the client (and cluster) with the workers
        self.closed = False
        self.dask_wait: Any = None  # distributed.wait

    @classmethod
    def local(
        cls,
        n: int,
        *,
        start: str | None = None,
        initializer: Callable[..., None] | None = None,
        initargs: tuple[Any, ...] = (),
    ) -> Workers:
        """``n`` local processes, started by ``start`` (default: ``"fork"`` on Linux,
        ``"spawn"`` elsewhere); each runs ``initializer(*initargs)`` once."""
        import multiprocessing as mp

        method = start or ("fork" if sys.platform.startswith("linux") else "spawn")
        pool = ProcessPoolExecutor(
            max_workers=n, mp_context=mp.get_context(method), initializer=_init_worker,
            initargs=(os.getpid(), initializer, initargs),
        )  # fmt: skip
        return cls(n, pool=pool)

    @classmethod
    def dask(cls, scheduler: Any, *, purpose: str, local_workers: int = 1) -> Workers:
        """A Dask cluster: ``scheduler`` is an address, ``"local"`` (a ``LocalCluster``
        of ``local_workers`` processes) or a ``distributed.Client`` (left open by
        :meth:`close`); ``purpose`` names what needs Dask when it is not installed. Waits
        up to 120 s for a worker."""
        from csplab.deps import require

        distributed: Any = require("distributed", "dask", purpose)
        w: Workers
        if isinstance(scheduler, distributed.Client):
            w = cls(1, client=scheduler)
        elif scheduler == "local":
            cluster = distributed.LocalCluster(
                n_workers=local_workers, threads_per_worker=1, processes=True,
                dashboard_address=":0",
            )  # fmt: skip
            w = cls(1, client=distributed.Client(cluster), cluster=cluster, own=True)
        elif not isinstance(scheduler, str) or not scheduler:
            raise InputError(
                f"scheduler must be an address such as tcp://host:8786, not {scheduler!r}"
            )
        else:
            try:
                w = cls(1, client=distributed.Client(scheduler, timeout=30), own=True)
            except OSError as e:
                raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        w.dask_wait = distributed.wait
        try:
            try:
                w.client.wait_for_workers(1, timeout=120)
            except TimeoutError:
                raise InputError("the Dask cluster has no workers (waited 120 s)") from None
            w.size = max(1, sum(w.client.nthreads().values()))
        except BaseException:
            w.close()
            raise
        return w

    def share(self, obj: Any) -> Any:
        """``obj`` as a task argument that reaches each worker once (Dask: scattered to
        every worker under a key of its own; a local pool: ``obj`` itself).

        The key is not the object's hash: a second client of the same scheduler scattering
        an equal object would get the key the first client's release is still dropping, and
        its tasks would fail with "lost dependencies"."""
        if self.client is None:
            return obj
        return self.client.scatter(obj, broadcast=True, hash=False)

    def submit(self, fn: Callable[..., Any], *args: Any, key: str | None = None) -> Any:
        """A future of ``fn(*args)``; ``key`` names the task on a Dask cluster."""
        if self.pool is not None:
            return self.pool.submit(fn, *args)
        extra = {} if key is None else {"key": key}
        return self.client.submit(fn, *args, pure=False, **extra)

    def wait(
        self, futures: Sequence[Any], timeout: float | None = None, *, first: bool = False
    ) -> list[Any]:
        """The futures among ``futures`` that are done (in their order) once all are, one
        has raised (a local pool), ``first`` and one is, or ``timeout`` seconds passed."""
        if self.pool is not None:
            done, _ = wait(futures, timeout, FIRST_COMPLETED if first else FIRST_EXCEPTION)
        else:
            try:
                done, _ = self.dask_wait(
                    list(futures), timeout, "FIRST_COMPLETED" if first else "ALL_COMPLETED"
                )
            except TimeoutError:
                done = {f for f in futures if f.status in ("finished", "error")}
        return [f for f in futures if f in done]

    def cancel(self, futures: Sequence[Any]) -> None:
        """Cancel the futures that have not started (Dask: all of them)."""
        if self.client is not None:
            self.client.cancel(list(futures))
        for f in futures if self.pool is not None else ():
            f.cancel()

    def close(self, kill: bool = False) -> None:
        """Shut the workers down: after the running tasks, or now (``kill``, a local pool:
        queued tasks are cancelled and the worker processes killed)."""
        if self.closed:
            return
        self.closed = True
        if self.pool is not None:
            procs = list((getattr(self.pool, "_processes", None) or {}).values())
            self.pool.shutdown(wait=not kill, cancel_futures=True)
            for p in procs if kill else ():
                try:
                    p.kill()
                    p.join(timeout=5)
                except (OSError, ValueError, AttributeError, AssertionError):
                    pass
        elif self.own:
            try:
                self.client.close()
            finally:
                if self.cluster is not None:
                    self.cluster.close()
