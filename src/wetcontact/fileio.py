"""Safe file names and atomic writes for everything the package writes.

A case or study name comes from a user's file and may hold path separators, ``..``, control
characters or thousands of characters; :func:`safe_stem` turns it into a file stem that
stays inside the folder it is joined to. :func:`atomic_write_text` writes through a
temporary sibling, fsyncs it and renames it over the target, so a reader (or a process
killed mid-write, or a full disk) sees either the old complete file or the new one.
:func:`read_input` and :func:`read_toml` read the files a user hands in (case, study and
coefficient files) with a size limit, refusing anything that is not a regular file.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import re
import stat
import tempfile
import tomllib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any, TextIO

from wetcontact.errors import CaseError, InputError

MAX_STEM = 100
#: largest case, study or coefficient file read (bytes); the shipped ones are a few kB
MAX_INPUT_BYTES = 10 * 1024 * 1024
#: deepest nesting of tables and arrays in a case or study file (their formats use 3)
MAX_NESTING = 32


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


# ---- reading the files a user hands in -------------------------------------------------

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


def read_input(path: str | Path, missing: str, allowed: str,
               limit: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of a case, study or coefficient file, read with a size limit.

    Anything but a regular file is refused before a byte is read: a FIFO would block the
    read until a writer appears (forever), a device such as ``/dev/zero`` would never end.
    The file is opened non-blocking (so opening a FIFO cannot hang either) and then
    checked with ``fstat``, so the check and the read are of the same file.

    Parameters
    ----------
    path
        The file.
    missing
        The allowed text when the file does not exist (``"an existing TOML case file"``).
    allowed
        What the file should be (``"a readable UTF-8 TOML file"``), said in every other
        refusal.
    limit
        Largest size read (bytes), :data:`MAX_INPUT_BYTES` by default.

    Returns
    -------
    bytes
        The file's content.

    Raises
    ------
    CaseError
        Field ``(file)`` with ``path``: missing, not a regular file (naming what it is),
        larger than ``limit``, or unreadable (naming the system's reason).
    """
    src = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)
                     | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise CaseError(src, "(file)", None, missing) from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the path
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else type(exc).__name__
        raise CaseError(src, "(file)", why, allowed) from None
    try:
        mode, size = (st := os.fstat(fd)).st_mode, st.st_size
        if not stat.S_ISREG(mode):
            what = next((name for test, name in _KINDS if test(mode)), "not a regular file")
            raise CaseError(src, "(file)", what, f"a regular file, {allowed}")
        if size > limit:
            raise CaseError(src, "(file)", f"{size} bytes", f"at most {limit} bytes "
                            f"({limit / 2**20:g} MiB), {allowed}")
        with os.fdopen(os.dup(fd), "rb") as fh:
            data = fh.read(limit + 1)  # a file still growing stops at the limit too
    except OSError as exc:
        raise CaseError(src, "(file)", exc.strerror or type(exc).__name__, allowed) from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise CaseError(src, "(file)", f"more than {limit} bytes", f"at most {limit} bytes "
                        f"({limit / 2**20:g} MiB), {allowed}")
    return data


def read_toml(path: str | Path, missing: str, allowed: str = "a readable UTF-8 TOML file"
              ) -> dict[str, Any]:
    """A case or study file's TOML tables, read by :func:`read_input` and parsed.

    Newlines are read as :meth:`pathlib.Path.read_text` reads them. Tables and arrays
    nested deeper than :data:`MAX_NESTING` are refused here, in one short line, before
    any part of the file is shown in an error (a 1000-level ``[a.a.a...]`` table used to
    exhaust the recursion limit while its value was printed).

    Parameters
    ----------
    path
        The file.
    missing
        The allowed text when the file does not exist.
    allowed
        What the file should be, said when it cannot be read or decoded.

    Returns
    -------
    dict
        The parsed tables.

    Raises
    ------
    CaseError
        As :func:`read_input`; field ``(file)`` for a file that is not UTF-8, ``(syntax)``
        for invalid TOML or nesting deeper than :data:`MAX_NESTING`.
    """
    import io

    src = str(path)
    raw = read_input(path, missing, allowed)
    try:
        text = io.TextIOWrapper(io.BytesIO(raw), encoding="utf-8").read()
    except UnicodeDecodeError:
        raise CaseError(src, "(file)", "UnicodeDecodeError", allowed) from None
    deep = f"valid TOML with tables and arrays nested at most {MAX_NESTING} levels deep"
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(src, "(syntax)", str(exc), "valid TOML") from None
    except RecursionError:
        raise CaseError(src, "(syntax)", "nesting too deep", deep) from None
    depth = nesting_depth(data)
    if depth > MAX_NESTING:
        raise CaseError(src, "(syntax)", f"nesting too deep ({depth} levels)", deep)
    return data


def nesting_depth(value: object) -> int:
    """Levels of dicts and lists in ``value`` (0 for a scalar, 1 for a flat table),
    counted without recursion, so any depth can be measured."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, dict):
            deepest = max(deepest, level)
            stack.extend((v, level + 1) for v in item.values())
        elif isinstance(item, list | tuple):
            deepest = max(deepest, level)
            stack.extend((v, level + 1) for v in item)
    return deepest


def json_ready(value: Any) -> Any:
    """A JSON-ready copy of ``value``: mappings, lists and tuples walked; numpy arrays and
    scalars (anything with ``tolist``) as lists and Python numbers."""
    if isinstance(value, Mapping):
        return {k: json_ready(x) for k, x in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(x) for x in value]
    return value.tolist() if hasattr(value, "tolist") else value


def writable_file(path: str | Path, flag: str, make_folders: bool = True) -> Path:
    """``path`` as a file the command can write (create, or replace through a temporary
    sibling), checked before any work: a study whose rupture distances take 25 s to solve
    must not end in a path error.

    Refused with an :class:`InputError` naming ``flag`` and the path: a folder or a special
    file at ``path``; a file where a folder of the path should be; a folder the process
    cannot write in; a name too long for the temporary copy beside it. Missing folders are
    allowed when the command creates them (``make_folders``), else refused. Nothing is
    created.
    """
    path = Path(path)
    shown = repr(str(path)) if len(str(path)) <= 200 else repr(f"{str(path)[:200]}...")
    if path.is_dir():
        raise InputError(f"{flag} {shown}: a folder; allowed: a file name (in an existing "
                         "folder)")
    if path.exists() and not path.is_file():
        raise InputError(f"{flag} {shown}: exists and is not a regular file (a device, pipe "
                         "or socket); allowed: a regular file or a new path")
    folder = path.parent
    first = next((p for p in (folder, *folder.parents) if os.path.lexists(p)), Path("."))
    if not first.is_dir():
        raise InputError(f"{flag} {shown}: {str(first)!r} is a file, not a folder; allowed: a "
                         "path through folders")
    if first != folder and not make_folders:
        raise InputError(f"{flag} {shown}: the folder {str(folder)!r} does not exist; create "
                         "it first")
    if not os.access(first, os.W_OK | os.X_OK):
        raise InputError(f"{flag} {shown}: cannot write in {str(first)!r}; allowed: a path "
                         "in a folder you can write to")
    name_max = 255
    with contextlib.suppress(OSError, ValueError):
        name_max = os.pathconf(first, "PC_NAME_MAX")
    longest = max((len(part) for part in path.parts), default=0)
    if longest + len(".XXXXXXXX.tmp") > name_max:
        raise InputError(f"{flag} {shown}: a name of {longest} characters; allowed: at most "
                         f"{name_max - len('.XXXXXXXX.tmp')} (room for the temporary copy "
                         "beside it)")
    return path
