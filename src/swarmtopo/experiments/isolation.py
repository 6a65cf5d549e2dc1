"""Run one function call at a time in a child process that may crash, hang or raise.

A sweep's Dask task does not run its job in the worker itself: it hands the call to a
child process of the worker (:class:`JobProcess`) and waits at most the job timeout.
So a job that dies (out of memory, a crash inside a compiled library) kills only the
child, and one that hangs is killed at its deadline; either way the worker lives on
and reports what happened.  The child is a plain ``python -m`` subprocess (Dask workers
are daemonic processes, which ``multiprocessing`` may not fork from), started on first
use, warmed up before any timed call, and started again after it died or was killed.

Protocol: length-prefixed pickles on duplicates of the child's stdin and stdout (its
stdout then goes to stderr and its stdin reads an empty file, so a call's prints or
reads cannot garble the protocol).  The child exits when its requests end or its
parent dies; every BLAS, OpenMP and numba pool in it has one thread.
"""

from __future__ import annotations

import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from typing import Any, Callable

STARTUP_SECONDS = 900.0
"""Most seconds the child may take to start and warm up (a cold numba cache compiles
every kernel, about a minute) before the worker reports it crashed."""


class JobProcess:
    """A child process that runs calls one at a time (:meth:`call`).

    Parameters
    ----------
    warm_up
        Called in the child once it starts, before any timed call (compile kernels,
        import modules), with :data:`STARTUP_SECONDS` to finish.
    """

    def __init__(self, warm_up: Callable[[], Any] | None = None):
        self._warm_up = warm_up
        self._proc: subprocess.Popen | None = None

    def call(self, fn: Callable[[Any], Any], arg: Any, timeout: float | None) -> tuple[str, Any]:
        """Run ``fn(arg)`` in the child: ``("ok", result)``, ``("error", message)`` if it raised,
        ``("crashed", message)`` if the child died, ``("timeout", message)`` if it ran past
        ``timeout`` seconds (the child is then killed)."""
        if self._proc is None or self._proc.poll() is not None:
            started = self._start()
            if started is not None:
                return started
        outcome = self._exchange((fn, arg), timeout)
        if outcome[0] == "timeout":
            outcome = ("timeout", f"ran past the job timeout of {timeout:g} s; its process was killed")
        return outcome

    def close(self) -> None:
        """Stop the child (it would also stop by itself when this process ends)."""
        if self._proc is not None and self._proc.poll() is None:
            self._proc.kill()
            self._proc.wait()
        self._proc = None

    def _start(self) -> tuple[str, str] | None:
        """Start the child and warm it up; None if it is ready, else the failure."""
        # one core per job, whatever the worker's settings: numba's threads and any BLAS / OpenMP pool
        env = {**os.environ, **dict.fromkeys(ONE_THREAD, "1")}
        self._proc = subprocess.Popen([sys.executable, "-m", __name__, str(os.getpid())], stdin=subprocess.PIPE,
                                      stdout=subprocess.PIPE, env=env)
        if self._warm_up is None:
            return None
        kind, message = self._exchange((_call, self._warm_up), STARTUP_SECONDS)
        if kind == "ok":
            return None
        self.close()
        if kind == "timeout":
            message = f"its warm-up took more than {STARTUP_SECONDS:g} s"
        return "crashed", f"the job process could not start ({message})"

    def _exchange(self, message, timeout: float | None) -> tuple[str, Any]:
        proc = self._proc
        try:
            _send(proc.stdin, pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL))
            reply = _receive(proc.stdout, None if timeout is None else time.monotonic() + timeout)
        except TimeoutError:  # before OSError, its base class
            self.close()
            return "timeout", None
        except (EOFError, OSError):  # the child died (a broken pipe, or end of file)
            try:
                code = proc.wait(timeout=10)
            except subprocess.TimeoutExpired:  # it closed its pipes but lives on
                proc.kill()
                code = proc.wait()
            self._proc = None
            return "crashed", _death(code)
        return pickle.loads(reply)


def _death(code: int) -> str:
    """What a child's exit code says about how it died."""
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        cause = ", the kernel's out-of-memory killer or a kill -9" if -code == signal.SIGKILL else ""
        return f"its process was killed by {name}{cause}"
    return f"its process exited with code {code}"


def _send(stream, payload: bytes) -> None:
    stream.write(struct.pack("<Q", len(payload)) + payload)
    stream.flush()


def _receive(stream, deadline: float | None) -> bytes:
    """One length-prefixed message; TimeoutError past ``deadline``, EOFError if the writer died."""
    fd = stream.fileno()
    readable = select.poll()
    readable.register(fd, select.POLLIN)
    chunks, need, header = [], 8, None
    while need:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0 or not readable.poll(1000 * left):
                raise TimeoutError
        chunk = os.read(fd, min(need, 1 << 20))
        if not chunk:
            raise EOFError
        chunks.append(chunk)
        need -= len(chunk)
        if need == 0 and header is None:
            header = b"".join(chunks)
            (need,) = struct.unpack("<Q", header)
            chunks = []
    return b"".join(chunks)


def _call(fn):
    return fn()


ONE_THREAD = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
"""Environment variables set to 1 in the job process."""


def _die_with_parent() -> None:
    """Be killed when the thread that started this process ends, with its worker (Linux:
    PR_SET_PDEATHSIG), even in a call that holds the GIL; elsewhere :func:`_watch_parent`."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)
    except (OSError, AttributeError):
        pass


def _watch_parent(parent: int) -> None:
    """Exit as soon as the parent is gone (a hung call would otherwise outlive its worker)."""
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)


def _serve(parent: int) -> None:
    """The child's loop: read (fn, arg), reply ("ok", fn(arg)) or ("error", one line)."""
    _die_with_parent()
    if os.getppid() != parent:  # the parent died before this process could follow it
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the sweep's client alone handles Ctrl-C
    # the protocol's pipes on descriptors of their own: a call's prints go to stderr, and
    # a call that reads stdin (or a program it starts) reads an empty file
    replies = os.fdopen(os.dup(1), "wb")
    requests = os.fdopen(os.dup(0), "rb", buffering=0)
    os.dup2(2, 1)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.close(null)
    sys.stdout = sys.stderr
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()
    while True:
        try:
            request = _receive(requests, None)
        except EOFError:
            return
        try:
            fn, arg = pickle.loads(request)
            outcome = ("ok", fn(arg))
            payload = pickle.dumps(outcome, protocol=pickle.HIGHEST_PROTOCOL)
        except BaseException as exc:  # noqa: BLE001 - any failure of the call (SystemExit too) is its message
            payload = pickle.dumps(("error", one_line(exc)), protocol=pickle.HIGHEST_PROTOCOL)
        _send(replies, payload)


def one_line(exc: BaseException) -> str:
    """``Type: message`` on one line (the message's whitespace collapsed)."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


if __name__ == "__main__":
    _serve(int(sys.argv[1]))
