"""JSON in and out, and atomic file writes: shared by every layer, so that the simulator,
the pipeline and the readers write their records without importing the file-reading
package :mod:`swarmtopo.io`.

:func:`write_json` is byte-stable (sorted keys, 2-space indent, a final newline) and
atomic: the text goes to a temporary file in the target's folder, renamed over the
target with :func:`os.replace`, so a reader never sees half a file.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError


def read_json(path) -> Any:
    """Parse a JSON file; errors name the file and the line and column of a syntax error."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=str(path)) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({os_reason(exc)})", file=str(path)) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"invalid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})", file=str(path)) from None


def write_json(obj, path) -> Path:
    """Write JSON with sorted keys and 2-space indent (byte-stable), atomically; returns the path.

    numpy scalars and arrays are written as plain numbers and lists, paths as text;
    NaN and infinities are refused (they are not JSON: pass ``jsonable(obj)`` to
    write them as ``null`` / ``"inf"`` / ``"-inf"``).
    """
    path = Path(path)
    try:
        text = json.dumps(obj, sort_keys=True, indent=2, allow_nan=False, default=_builtin)
    except ValueError as exc:
        raise InputError(f"cannot write JSON: {exc}", file=str(path)) from None
    atomic_write(path, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"))
    return path


def jsonable(obj) -> Any:
    """``obj`` as plain JSON data: dict (keys made ``str``), list, str, int, float, bool, None.

    Recursively: dicts -> dicts with ``str(key)`` keys, lists / tuples / numpy arrays ->
    lists, numpy scalars -> int / float / bool, paths -> str, and non-finite floats ->
    ``"inf"``, ``"-inf"`` or ``None`` (NaN).  Anything else raises TypeError.  Use it
    for data that may hold infinities (``tau_stop = inf``, open intervals);
    :func:`write_json` alone refuses them.
    """
    if isinstance(obj, dict):
        return {k if isinstance(k, str) else str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (np.ndarray, np.generic, Path)):
        return jsonable(_builtin(obj))
    if obj is None or isinstance(obj, (str, bool)):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        if math.isfinite(obj):
            return float(obj)
        return None if math.isnan(obj) else ("inf" if obj > 0 else "-inf")
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serializable")


def atomic_write(path: Path, write) -> None:
    """Call ``write(tmp)`` on a temporary file in ``path``'s folder, then rename it over ``path``.

    Raises InputError naming ``path`` if the file system refuses (no such folder, a
    folder of that name, no permission, disk full); no temporary file is left behind.
    """
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        try:
            write(tmp)
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)
    except OSError as exc:
        raise InputError(f"cannot write file ({os_reason(exc)})", file=str(path)) from None


def os_reason(exc: OSError) -> str:
    """The operating system's words for ``exc`` (``No such file or directory``)."""
    return exc.strerror or str(exc)


def _builtin(obj):
    """numpy scalar / array or path -> the Python int, float, bool, list or str (the
    ``default`` of json.dumps: called only for objects json cannot write itself)."""
    if isinstance(obj, (np.ndarray, np.generic)):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serializable")
