"""Safe file names and atomic writes for everything the package writes.

A case or study name comes from a user's file and may hold path separators, ``..``, control
characters or thousands of characters; :func:`safe_stem` turns it into a file stem that
stays inside the folder it is joined to. :func:`atomic_write_text` writes through a
temporary sibling, fsyncs it and renames it over the target, so a reader (or a process
killed mid-write, or a full disk) sees either the old complete file or the new one.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import re
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import TextIO

from wetcontact.errors import InputError

MAX_STEM = 100


def safe_stem(name: str) -> str:
    """A file stem for ``name``: ``[A-Za-z0-9._-]`` only, no leading dot, at most 100 chars.

    Characters outside the set become ``_``; a stem that had to be changed or shortened
    gets an 8-character hash of the original name, so two different names never share
    a stem.
    """
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".") or "_"
    if stem == name and len(stem) <= MAX_STEM:
        return stem
    tag = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return f"{stem[:MAX_STEM - 9]}-{tag}"


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (temporary sibling, fsync, ``os.replace``).

    The file gets the mode a plain ``open(path, "w")`` would give (``0o666`` less the
    umask). On any error the temporary file is removed and the old file is untouched.
    """
    with atomic_open(path) as fh:
        fh.write(text)


@contextlib.contextmanager
def atomic_open(path: str | Path, newline: str | None = None) -> Iterator[TextIO]:
    """A text file to write that replaces ``path`` atomically when the block ends.

    Like :func:`atomic_write_text` for output written piece by piece (a large CSV);
    if the block raises, ``path`` is untouched and the temporary file removed.
    """
    path = Path(path)
    fd, tmp = _temporary_sibling(path, ".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline=newline) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        _forget(tmp, path, exc)
        raise


@contextlib.contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """A temporary sibling of ``path`` (same suffix) for a writer that wants a file name.

    For libraries that write by name (meshio, matplotlib): write to the yielded path; on a
    normal exit it is fsynced, given the umask mode and renamed over ``path``; on an error
    it is removed and ``path`` is untouched.
    """
    path = Path(path)
    fd, tmp = _temporary_sibling(path, f".tmp{path.suffix}")
    os.close(fd)
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        _forget(tmp, path, exc)
        raise


def _temporary_sibling(path: Path, suffix: str) -> tuple[int, str]:
    """Open a new temporary file beside ``path`` for an atomic replacement of it.

    Refuses a target that exists and is not a regular file: renaming over a folder fails
    anyway, and renaming over a device, pipe or socket (``/dev/null`` given as an output,
    as root) would replace the special file itself. An error creating the temporary names
    ``path``, the file the user asked for, not the hidden temporary.
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:  # e.g. a part of the path is a file: ENOTDIR
        exc.filename, exc.filename2 = str(path), None
        raise
    if mode is not None and stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    if mode is not None and not stat.S_ISREG(mode):
        raise InputError(f"{str(path)!r}: exists and is not a regular file (a device, pipe "
                         "or socket); allowed: a regular file or a new path")
    try:
        return tempfile.mkstemp(prefix=f".{path.name[:50]}.", suffix=suffix, dir=path.parent)
    except OSError as exc:
        exc.filename, exc.filename2 = str(path), None
        raise


def _forget(tmp: str, path: Path, exc: BaseException) -> None:
    """Remove the temporary; an error about it names the target the user asked for."""
    with contextlib.suppress(FileNotFoundError):
        os.unlink(tmp)
    if isinstance(exc, OSError) and exc.filename is not None and str(exc.filename) == str(tmp):
        exc.filename = str(path)
        if exc.filename2 is not None and str(exc.filename2) == str(path):
            exc.filename2 = None  # os.replace(tmp, path) names both: say the path once


def make_folder(path: str | Path) -> None:
    """``mkdir -p path``; a file in the way is ``NotADirectoryError`` naming that file.

    (``Path.mkdir(parents=True, exist_ok=True)`` reports a file where a folder should be as
    "File exists", which reads as if the folder were already there, or names the folder
    it could not make rather than the file in the way.)
    """
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        for part in (path, *path.parents):
            if part.exists() and not part.is_dir():
                raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR),
                                         str(part)) from None
        raise


def fsync_dir(path: str | Path) -> None:
    """Flush a folder's entries (a rename into it) to disk; a no-op where not supported."""
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
