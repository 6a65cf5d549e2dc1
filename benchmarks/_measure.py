"""Shared measuring helpers of the benchmark scripts (wall time, peak memory, machine).

Peak memory is the process's peak resident set (Linux VmHWM) above its resident set
just before the call.  Freed memory is handed back to the OS first (malloc_trim) and
the peak is reset through /proc/self/clear_refs, so everything the call touches --
numpy, scipy's C code and numba's own allocations alike -- shows in the figure.
"""

from __future__ import annotations

import ctypes
import gc
import os
import platform
import subprocess
import time
from pathlib import Path

_LIBC = ctypes.CDLL("libc.so.6")


def _status_kb(field: str) -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"no {field} in /proc/self/status")


def run_measured(fn):
    """(result, wall seconds, peak bytes above the RSS before the call, CPU seconds)."""
    # freed memory goes back to the OS first (malloc_trim), so that what the call
    # allocates must take new pages and shows in the peak
    gc.collect()
    _LIBC.malloc_trim(0)
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")  # reset the peak RSS (VmHWM) to the current RSS
    baseline = _status_kb("VmRSS")
    start, cpu = time.perf_counter(), time.process_time()
    result = fn()
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    return result, seconds, (_status_kb("VmHWM") - baseline) * 1024, cpu


def machine() -> str:
    """One line naming the CPU, the cores and the current load."""
    model = platform.processor() or "unknown CPU"
    with open("/proc/cpuinfo") as info:
        for line in info:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{model}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}"


def revision() -> str:
    """``git describe --always --dirty`` of the repository holding this script."""
    try:
        return subprocess.run(["git", "describe", "--always", "--dirty"], cwd=Path(__file__).parent,
                              capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"
