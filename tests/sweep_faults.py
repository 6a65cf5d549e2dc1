"""Jobs that fail on purpose, for the sweep tests (imported by Dask workers and job processes).

``faulty_job(job, keep)`` runs :func:`~swarmtopo.experiments.sweep.run_job` except for
replicates 0-2 of a sweep whose salt is "poison": replicate 0 kills its own process
(as the kernel's out-of-memory killer would), 1 raises a bug, 2 hangs.
"""

import os
import signal
import time

from swarmtopo.experiments.sweep import run_job


def faulty_job(job, keep):
    if job.salt == "poison" and job.replicate == 0:
        os.kill(os.getpid(), signal.SIGKILL)
    if job.salt == "poison" and job.replicate == 1:
        raise ZeroDivisionError("a bug\nover two lines")
    if job.salt == "poison" and job.replicate == 2:
        time.sleep(3600)
    return run_job(job, keep)


def slow_job(job, keep):
    """run_job after 1 s: a sweep that lasts long enough to be disturbed."""
    time.sleep(1.0)
    return run_job(job, keep)


def worker_killer(job, keep):
    """Kills the Dask worker that runs it (the job process's parent)."""
    os.kill(os.getppid(), signal.SIGKILL)
    time.sleep(60)


def add_one(x):
    return x + 1


def raise_value_error(x):
    raise ValueError(f"bad value {x}")


def die(x):
    os.kill(os.getpid(), signal.SIGKILL)


def sleep_for(seconds):
    time.sleep(seconds)
    return seconds


def shout(x):
    print("a library printing to stdout")
    return x


def kills_worker_at_15(job, keep):
    """run_job, except replicate 15 of a "chunk-kill" sweep, which kills its Dask worker."""
    if job.salt == "chunk-kill" and job.replicate == 15:
        worker_killer(job, keep)
    return run_job(job, keep)


def thread_settings(_):
    """The thread-count variables the job process runs with."""
    from swarmtopo.experiments.isolation import ONE_THREAD

    return {name: os.environ.get(name) for name in ONE_THREAD}
