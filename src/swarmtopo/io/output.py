"""Output folders that are replaced whole or not at all.

A command that writes a folder (``map``, ``demo``, ``simulate``, ``ingest``,
``reproduce``, ``bench accuracy``) writes into a hidden staging folder and moves the
result into place only when it is complete (:func:`staged_folder`).  An error, a crash
or Ctrl-C before that leaves the folder exactly as it was, and the staging folder is
removed; a folder that did not exist is not left behind.

Staging.  A new folder is staged in its nearest existing parent folder
(``.NAME.partial-PID``) and renamed into place in one step (the parents it needs made
only then).  An existing folder is staged inside itself
(``.swarmtopo-partial-PID``, so on the same file system even when the folder is a
mount point); the switch moves the entries the command owns aside, moves the new
ones in, then deletes the old ones: a few renames, during which Ctrl-C is held back,
undone in reverse if one fails (only a kill or power cut within those microseconds
could leave a mix).  Only the entries the command owns are replaced or removed; files
it did not write stay (a log folder's notes, the map of a log in its ``map/``
subfolder).
"""

from __future__ import annotations

import os
import shutil
import signal
import threading
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, SwarmtopoError

Owned = Mapping[str, "Owned | Iterable[str] | None"]
"""The entries a command owns in its folder, by name: None replaces the entry whole;
names (or a nested mapping) merge the new subfolder into the old one, owning those
entries inside it."""

COMMITTED: list[Path] = []
"""Every folder :func:`staged_folder` moved into place in this process, in order (what
an interrupted command did write)."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C while a staged folder was being written; ``message`` says what was and
    was not written."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


@dataclass
class Staging:
    """Where to write (``path``) for ``final``.

    Attributes
    ----------
    path
        The staging folder: write every output here.
    final
        The folder as the caller named it.
    removed
        After the switch: entries of ``final`` the command owned that the new result
        does not have, deleted (as paths under ``final``).
    """

    path: Path
    final: Path
    removed: list[Path] = field(default_factory=list)

    def final_path(self, staged) -> Path:
        """Where the staged file ``staged`` is once the folder is in place."""
        return self.final / Path(staged).relative_to(self.path)


@contextmanager
def staged_folder(final, owned: Owned | Iterable[str], *, what: str, overwrite: bool,
                  note: str | None = None) -> Iterator[Staging]:
    """Stage the outputs of a command for the folder ``final``; move them into place
    when the block ends without an exception.

    Parameters
    ----------
    final
        The output folder (created with its parents when the result is complete).
    owned
        Names of the entries the command owns in ``final`` (see :data:`Owned`; an
        iterable of names replaces each whole).  Entries of the new result are
        owned too.  Owned entries the result lacks are deleted; the rest stay.
    what
        The result's name in messages ("log", "map").
    overwrite
        Whether owned entries already in ``final`` may be replaced; if not and there
        are some, a SwarmtopoError suggests ``--overwrite``.
    note
        What else an interruption leaves (e.g. a resumable store), for its message.

    Raises
    ------
    SwarmtopoError
        ``final`` is a file, holds owned entries without ``overwrite``, or cannot be
        written (naming the path).
    Interrupted
        Ctrl-C before the switch: the message says nothing was written and what
        ``final`` still holds.
    """
    final = Path(final)
    owned = dict(owned) if isinstance(owned, Mapping) else dict.fromkeys(owned)
    target = final.resolve()  # a symlinked folder is written where it points
    if target.exists() and not target.is_dir():
        raise SwarmtopoError(f"{final}: is a file; give a folder for the {what}")
    for name, inner in owned.items():  # an owned folder the user replaced by a file: never overwritten
        if inner is not None and (target / name).exists() and not (target / name).is_dir():
            raise SwarmtopoError(f"{final / name}: is a file where the {what} keeps a folder; move it away, or "
                                 "choose another --out")
    previous = sorted(name for name in owned if (target / name).exists())
    if previous and not overwrite:
        raise SwarmtopoError(f"{final}: already holds a {what} ({', '.join(previous)}); pass --overwrite to "
                             "replace it, or choose another --out")
    new = not target.exists()
    nearest = next(p for p in target.parents if p.exists()) if new else target  # the same file system
    stage = Staging(_new_folder(nearest, f".{target.name}.partial" if new else ".swarmtopo-partial", final), final)
    try:
        try:
            yield stage
        except KeyboardInterrupt:
            held = f"{final} still holds the previous {what}" if previous else None
            message = "interrupted: nothing written; " + held if held else f"interrupted: no {what} written"
            raise Interrupted(message + (f"; {note}" if note else "")) from None
        except (OSError, SwarmtopoError) as exc:  # name the file the user asked for, not the staged one
            _name_final(exc, stage)
            raise
        with _sigint_held():
            try:
                if new:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.rename(stage.path, target)
                else:
                    stage.removed = [final / p for p in _switch(stage.path, target, owned, what)]
            except OSError as exc:
                raise InputError(f"cannot move the new {what} into place ({exc.strerror or exc})",
                                 file=str(final)) from None
            COMMITTED.append(final)
    finally:
        shutil.rmtree(stage.path, ignore_errors=True)


def _name_final(exc: OSError | SwarmtopoError, stage: Staging) -> None:
    """Rewrite the staged paths an error names (message, ``filename``, ``file``) as
    their final paths."""
    def final(text):
        return text if text is None else str(text).replace(str(stage.path), str(stage.final))

    if isinstance(exc, OSError):
        exc.filename, exc.filename2 = final(exc.filename), final(exc.filename2)
    else:
        exc.args = tuple(final(a) if isinstance(a, str) else a for a in exc.args)
        if getattr(exc, "file", None) is not None:
            exc.file = final(exc.file)


def _new_folder(parent: Path, stem: str, final: Path) -> Path:
    """A new empty folder ``parent/STEM-PID[-k]``."""
    try:
        for k in range(1000):
            path = parent / f"{stem}-{os.getpid()}{f'-{k}' if k else ''}"
            try:
                path.mkdir()
                return path
            except FileExistsError:
                continue
        raise FileExistsError(f"{parent / stem}-{os.getpid()}-*: 1000 folders exist")
    except OSError as exc:
        raise InputError(f"cannot create the output folder ({exc.strerror or exc})", file=str(final)) from None


def _switch(staged: Path, final: Path, owned: dict, what: str) -> list[str]:
    """Replace ``final``'s owned entries by ``staged``'s (then empty); return the owned
    entries deleted without a replacement, relative to ``final``.  An entry the command
    does not own, or of another kind (a folder where it writes a file), is never
    replaced: a SwarmtopoError names it before anything moves.  A failed rename undoes
    the renames before it."""
    aside = _new_folder(final, ".swarmtopo-old", final)
    moves: list[tuple[Path, Path]] = []
    removed: list[str] = []

    def plan(new: Path, old: Path, owned: dict, prefix: str) -> None:
        incoming = {p.name for p in new.iterdir()}
        merged = {name for name, inner in owned.items()
                  if inner is not None and name in incoming and (old / name).is_dir() and (new / name).is_dir()}
        for entry in sorted(old.iterdir()):
            if entry in (staged, aside) or entry.name in merged:
                continue
            if entry.name in incoming and (entry.name not in owned or entry.is_dir() != (new / entry.name).is_dir()):
                kind = "folder" if entry.is_dir() else "file"
                raise SwarmtopoError(f"{final / prefix}{entry.name}: a {kind} swarmtopo did not write stands where "
                                     f"the new {what} puts its own; move it away, or choose another --out")
            if entry.name in owned or entry.name in incoming:
                moves.append((entry, aside / str(len(moves))))
                if entry.name not in incoming:
                    removed.append(prefix + entry.name)
        for name in sorted(incoming):
            if name in merged:
                plan(new / name, old / name, dict.fromkeys(owned[name]) if not isinstance(owned[name], Mapping)
                     else dict(owned[name]), f"{prefix}{name}/")
            else:
                moves.append((new / name, old / name))

    done: list[tuple[Path, Path]] = []
    try:
        plan(staged, final, owned, "")
        for source, destination in moves:
            os.rename(source, destination)
            done.append((source, destination))
    except BaseException:
        for source, destination in reversed(done):  # the previous result back in place
            os.rename(destination, source)
        aside.rmdir()
        raise
    shutil.rmtree(aside, ignore_errors=True)
    return removed


@contextmanager
def _sigint_held() -> Iterator[None]:
    """Hold back Ctrl-C (in the main thread) until the block ends, then deliver it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught and callable(previous):
        previous(signal.SIGINT, None)
