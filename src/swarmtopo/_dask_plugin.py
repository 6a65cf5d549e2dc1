"""The Dask worker plugin of swarmtopo's clusters (imported only where Dask runs).

A module of its own, importing nothing of swarmtopo: a worker that unpickles the plugin
must not import numba before the plugin has set it up."""

from __future__ import annotations

import os
import signal
import sys

from distributed.diagnostics.plugin import WorkerPlugin


class OneNumbaThread(WorkerPlugin):
    """One numba thread per worker: numba's parallel kernels would otherwise start one
    thread per core in every worker process, oversubscribing the machine.

    Registered by the client on every worker, those of an existing cluster included.
    Before numba is imported in the worker (a fresh ``dask worker``) the environment
    variable fixes numba's pool at one thread; after, each task limits its own thread
    (``swarmtopo.pipeline.engine.in_one_numba_thread``), numba's setting being per thread.
    """

    name = "swarmtopo-one-numba-thread"
    idempotent = True

    def setup(self, worker) -> None:
        if "numba" not in sys.modules:
            os.environ["NUMBA_NUM_THREADS"] = "1"


def dask_setup(worker) -> None:
    """Dask preload hook of the local cluster's workers (``preload=["swarmtopo._dask_plugin"]``):
    ignore SIGINT.  Ctrl-C on a terminal reaches every process of the foreground group;
    the client alone handles it, so the workers must not die of it first with
    tracebacks of their own."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
