"""Where the window tasks of one map run: this process's threads, or a Dask cluster.

An engine has three verbs: ``share`` (a value every task reads: sent to the workers
once), ``submit`` (a task whose arguments may be earlier tasks' futures: on Dask they
stay where they were computed) and ``gather``.  Every task is a pure function of its
arguments, so a map is the same bytes on every engine and any number of workers.

:class:`ThreadEngine` (the default) runs tasks on one thread per numba thread, each
limited to one numba thread so that the compiled kernels run serially without the GIL
side by side.  :func:`dask_engine` runs them on a Dask cluster: an embedded
``LocalCluster`` of ``workers`` processes, or the scheduler at an address; its
workers get one numba thread each from a worker plugin
(:class:`swarmtopo._dask_plugin.OneNumbaThread`), so workers started by hand (``dask worker
ADDRESS``) are set up the same way, and every task limits its own thread too.
"""

from __future__ import annotations

import logging
import os
import signal
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from ..errors import SwarmtopoError

CONNECT_TIMEOUT = 10.0
"""Seconds a client waits for the scheduler at a given address."""
WORKER_WAIT = 120.0
"""Seconds a client waits for the first worker of an existing scheduler."""
POLL_SECONDS = 0.05
"""How often a client waiting on Dask tasks looks for Ctrl-C (and for finished tasks)."""


def one_numba_thread() -> None:
    """Limit the calling thread's numba kernels to one thread (numba's setting is per thread)."""
    import numba

    numba.set_num_threads(1)


def in_one_numba_thread(function: Callable, *args):
    """``function(*args)`` with the calling thread limited to one numba thread (a Dask
    worker's thread: whatever the worker's numba pool, the task's kernels run serially)."""
    one_numba_thread()
    return function(*args)


class ThreadEngine:
    """Tasks on ``threads`` threads of this process (numba.get_num_threads() by default)."""

    def __init__(self, threads: int | None = None):
        import numba

        self.threads = threads or numba.get_num_threads()
        self._pool = ThreadPoolExecutor(self.threads, initializer=one_numba_thread,
                                        thread_name_prefix="swarmtopo-window")

    def share(self, value: Any) -> Any:
        return value

    def submit(self, function: Callable, *args) -> Future:
        # tasks are queued in submission order and a task's future arguments were all
        # submitted before it, so waiting on them in a pool thread cannot deadlock
        return self._pool.submit(lambda: function(*(a.result() if isinstance(a, Future) else a for a in args)))

    def gather(self, futures: list[Future]) -> list:
        return [f.result() for f in futures]

    def close(self, wait: bool = True) -> None:
        """Shut the threads down; ``wait=False`` (after an error or Ctrl-C) returns at once,
        the running tasks ending in the background."""
        self._pool.shutdown(wait=wait, cancel_futures=True)


class DaskEngine:
    """Tasks on a Dask ``client``'s workers; shared values are scattered to every worker once."""

    def __init__(self, client):
        self.client = client

    def share(self, value: Any):
        return self.client.scatter(value, broadcast=True, hash=False)

    def submit(self, function: Callable, *args):
        return self.client.submit(in_one_numba_thread, function, *args, pure=False)

    def gather(self, futures: list) -> list:
        """The futures' results; Ctrl-C cancels them and raises KeyboardInterrupt between
        Dask's calls, never inside one (see :func:`deferred_interrupt`)."""
        with deferred_interrupt() as interrupted:
            while not all(future.done() for future in futures):
                if interrupted():
                    self.client.cancel(futures)
                    raise KeyboardInterrupt
                time.sleep(POLL_SECONDS)
        return self.client.gather(futures)


@contextmanager
def quiet_logs(*names: str) -> Iterator[None]:
    """The named loggers at CRITICAL for the block's duration (their levels restored after)."""
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


@contextmanager
def connected_client(address: str):
    """A ``distributed.Client`` on the scheduler at ``address`` with at least one worker,
    every worker set up by :class:`~swarmtopo._dask_plugin.OneNumbaThread`; closed on exit.
    An unreachable scheduler, or one without workers, is a one-line SwarmtopoError."""
    from distributed import Client

    from .._dask_plugin import OneNumbaThread

    try:
        client = Client(address, timeout=CONNECT_TIMEOUT)
    except (OSError, ValueError, TypeError) as exc:
        raise SwarmtopoError(f"cannot connect to the Dask scheduler at {address!r} ({exc})") from None
    # a lost scheduler is the caller's one-line error: not the client's reconnection tracebacks
    with quiet_logs("distributed.client", "distributed.utils"):
        try:
            try:
                client.wait_for_workers(1, timeout=WORKER_WAIT)
            except TimeoutError:
                raise SwarmtopoError(f"the Dask scheduler at {address} has had no worker for "
                                     f"{WORKER_WAIT:g} s; start some with: dask worker {address}") from None
            client.register_plugin(OneNumbaThread())
            yield client
        finally:
            client.close()


@contextmanager
def local_client(workers: int | None = None):
    """A ``distributed.Client`` on a new local cluster of ``workers`` processes (default:
    one per core) of one thread each, every worker set up by
    :class:`~swarmtopo._dask_plugin.OneNumbaThread`; both closed on exit.

    One core per worker: numba's parallel kernels would otherwise start one thread per
    core in every worker (BLAS / OpenMP threads are already 1 under Dask's nanny).  The
    scheduler's HTTP server takes any free port (8787 may be another cluster's).  The
    workers preload swarmtopo._dask_plugin (its dask_setup: they ignore SIGINT, which the
    client alone handles).  Only CRITICAL logs: a task's own exception reaches the client
    through its future, and after Ctrl-C a worker may log an ERROR with a traceback while
    the cluster shuts down, and the scheduler, which runs in this process, may race a
    scatter (asyncio's "Task exception was never retrieved").
    """
    from distributed import Client, LocalCluster

    from .._dask_plugin import OneNumbaThread

    with quiet_logs("asyncio"), \
            LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                         dashboard_address=":0", silence_logs=logging.CRITICAL, env={"NUMBA_NUM_THREADS": "1"},
                         preload=["swarmtopo._dask_plugin"]) as cluster, Client(cluster) as client:
        client.register_plugin(OneNumbaThread())
        yield client


@contextmanager
def dask_engine(workers: int | None = None, scheduler: Any = None) -> Iterator[DaskEngine]:
    """A :class:`DaskEngine` on the scheduler at ``scheduler`` (an address, or a
    ``distributed.Client`` the caller keeps), else on a new local cluster of ``workers``
    processes of one thread each (closed on exit)."""
    from .._dask_plugin import OneNumbaThread

    if scheduler is not None and not isinstance(scheduler, str):
        scheduler.register_plugin(OneNumbaThread())
        yield DaskEngine(scheduler)
        return
    with (connected_client(scheduler) if scheduler is not None else local_client(workers)) as client:
        yield DaskEngine(client)


@contextmanager
def engine_for(workers: int | None = None, scheduler: Any = None) -> Iterator[ThreadEngine | DaskEngine]:
    """The engine of a map: Dask when ``workers`` or ``scheduler`` is given, else threads."""
    if workers is None and scheduler is None:
        engine = ThreadEngine()
        try:
            yield engine
        except BaseException:
            engine.close(wait=False)
            raise
        engine.close()
        return
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SwarmtopoError(f"workers must be a whole number >= 1, got {workers!r}")
    with dask_engine(workers, scheduler) as engine:
        yield engine


@contextmanager
def deferred_interrupt():
    """Turn SIGINT into a flag the caller polls (yields ``interrupted() -> bool``).

    A KeyboardInterrupt raised inside one of distributed's blocking calls makes its
    event loop log a traceback (a NameError in ``distributed.utils.sync``'s cancel
    callback, seen with distributed 2026.8); raised by the caller between calls, it
    leaves distributed in a clean state.  Outside the main thread signals cannot be
    caught, so nothing changes there.
    """
    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return
    flag = threading.Event()
    previous = signal.signal(signal.SIGINT, lambda signum, frame: flag.set())
    try:
        yield flag.is_set
    finally:
        signal.signal(signal.SIGINT, previous)
