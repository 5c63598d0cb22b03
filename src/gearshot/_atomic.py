"""The one way gearshot writes files: never half-written, failures named.

Every file gearshot writes (recordings, database blocks, predictions, reports, figures,
JSON, estimators, FRFs, sweep results) goes through :func:`atomic_path` (one file) or
:func:`atomic_dir` (a folder such as a Zarr block): the content is written to a temporary
name in the target's own folder, flushed to disk (``fsync``), then renamed onto the target.
A reader therefore sees the old file or the whole new one, never a part; a failure removes
the temporary and leaves the target untouched.

:func:`check_writable` is the early check: commands call it on their outputs before the long
work starts, so that a missing or read-only folder, a parent that is a file, or a target
that is not a regular file (``/dev/full``) fails in a second rather than after the fit.

Operating-system errors while writing (disk full, file too large, permission) become a
:class:`~gearshot.GearshotError` that names the path.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import socket
import tempfile
import zlib
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from ._errors import GearshotError

__all__ = [
    "atomic_path",
    "atomic_dir",
    "staging_dir",
    "commit_staged",
    "write_text_atomic",
    "write_json_atomic",
    "check_writable",
    "remove_tree",
    "os_error_text",
    "remove_stale_temporaries",
]


def os_error_text(exc: BaseException) -> str:
    """A short description of an OS-level failure (``'No space left on device'``)."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


def _is_io_error(exc: BaseException) -> bool:
    """An OS-level failure, or a file library's wrapping of one (h5py raises RuntimeError)."""
    if isinstance(exc, GearshotError):
        return False
    return isinstance(exc, OSError) or type(exc) is RuntimeError


def _fail(path: Path, exc: BaseException, what: str = "write") -> GearshotError:
    text = " ".join(os_error_text(exc).split())     # libraries' messages may span lines
    return GearshotError(f"cannot {what} {str(path)!r}: {text}")


def check_writable(path: str | os.PathLike, name: str, *, folder: bool = False) -> Path:
    """Raise unless ``path`` can be created or replaced; return it as a :class:`Path`.

    Parameters
    ----------
    path : str or path-like
        The output (a file, or with ``folder=True`` a folder that may not exist yet).
    name : str
        How the caller calls it (``"--out"``, ``"store"``), quoted in the message.
    folder : bool
        The output is a folder (created if missing) rather than a file.

    Missing intermediate folders are fine (they are created later) as long as the nearest
    existing one is a writable folder.
    """
    path = Path(path).expanduser()
    if path.exists() or path.is_symlink():
        if folder and not path.is_dir():
            raise GearshotError(f"{name} {str(path)!r} must be a folder; it is a file")
        if not folder and not path.is_file():
            kind = "a folder" if path.is_dir() else "a device or other special file"
            raise GearshotError(f"{name} {str(path)!r} must be a regular file; it is {kind}")
    start = path if (folder and path.is_dir()) else path.parent
    parent = start
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise GearshotError(f"{name} {str(path)!r} cannot be written: {str(parent)!r} is a "
                            f"file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise GearshotError(f"{name} {str(path)!r} cannot be written: no write permission "
                            f"on {str(parent)!r}")
    return path


def _umask() -> int:
    """The process's file-creation mask: from ``/proc/self/status`` where there is one (no
    race with other threads), else by setting and restoring it."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _user_mode(path: Path, *, folder: bool = False) -> None:
    """Give a temporary file (0600 from :func:`tempfile.mkstemp`) or folder (0700 from
    :func:`tempfile.mkdtemp`) the mode a plain ``open``/``mkdir`` would have: 0666 or 0777
    less the user's umask, so that the renamed result is as readable as any other file."""
    os.chmod(path, (0o777 if folder else 0o666) & ~_umask())


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system allows it
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


_HOST = format(zlib.crc32(socket.gethostname().encode()), "08x")[:6]
_STALE = re.compile(r"^\..+\.g(\d+)@([0-9a-f]{6})-[^/]*\.tmp")


def _temp_prefix(path: Path) -> str:
    """``.<name>.g<pid>@<host>-``: the temporaries of this process, recognisable later."""
    return f".{path.name}.g{os.getpid()}@{_HOST}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:          # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove temporaries in ``folder`` left by killed processes of this host.

    A temporary of :func:`atomic_path` / :func:`atomic_dir` carries its process id and a
    host tag in its name; it is removed when that process no longer exists (a process of
    another host, or one still alive, keeps its temporaries). Returns what was removed.
    """
    removed = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(os.fspath(folder)):
            m = _STALE.match(entry.name)
            if m is None or m.group(2) != _HOST or _alive(int(m.group(1))):
                continue
            target = Path(entry.path)
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(target, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    target.unlink()
            removed.append(target)
    return removed


def _make_folder(folder: Path, target: Path) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise GearshotError(f"cannot write {str(target)!r}: {str(folder)!r} is a file, not "
                            f"a folder") from None
    except OSError as exc:
        raise _fail(target, exc) from None
    if not folder.is_dir():
        raise GearshotError(f"cannot write {str(target)!r}: {str(folder)!r} is not a folder")


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, *, make_parents: bool = False) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; fsync and rename it onto ``path`` on success.

    The temporary name ends with ``path``'s suffix (writers that choose a format by suffix
    keep working). On any exception the temporary is removed, ``path`` is untouched, and an
    OS-level error (or a library's wrapped one, e.g. h5py's) is re-raised as a
    :class:`~gearshot.GearshotError` naming ``path``.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if make_parents:
        _make_folder(folder, path)
    elif not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise GearshotError(f"cannot write {str(path)!r}: folder {str(folder)!r} {what}")
    if path.exists() and not path.is_file():
        raise GearshotError(f"cannot write {str(path)!r}: it exists and is not a regular file")
    remove_stale_temporaries(folder)
    try:
        fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path), suffix=".tmp" + path.suffix,
                                   dir=folder)
    except OSError as exc:
        raise _fail(path, exc) from None
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        _user_mode(tmp_path)
        yield tmp_path
        _fsync_file(tmp_path)
        os.replace(tmp_path, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        if _is_io_error(exc):
            raise _fail(path, exc) from exc
        raise
    _fsync_dir(folder)


def write_text_atomic(path: str | os.PathLike, text: str, *,
                      make_parents: bool = False) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path, make_parents=make_parents) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)


def write_json_atomic(data: Mapping[str, Any] | list, path: str | os.PathLike, *,
                      make_parents: bool = False, indent: int = 1, sort_keys: bool = True,
                      default: Callable[[Any], Any] | None = None) -> None:
    """Write ``data`` as JSON to ``path`` atomically (encoding errors write nothing)."""
    text = json.dumps(data, indent=indent, sort_keys=sort_keys, default=default)
    write_text_atomic(path, text, make_parents=make_parents)


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike, *, exist_ok: bool = False) -> Iterator[Path]:
    """Yield a hidden temporary folder beside ``path``; fsync its files and rename it onto
    ``path`` when the block exits without error.

    ``exist_ok=True``: if ``path`` appeared meanwhile (another worker finished the same
    folder), the temporary one is discarded and the existing one kept. On any exception the
    temporary folder is removed; OS errors become a :class:`~gearshot.GearshotError`.
    Leftovers of killed processes are named ``.<name>.g<pid>@<host>-<random>.tmp`` and
    removed by the next write into the same folder (:func:`remove_stale_temporaries`).
    """
    path = Path(path)
    folder = path.parent
    _make_folder(folder, path)
    remove_stale_temporaries(folder)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=_temp_prefix(path), suffix=".tmp", dir=folder))
    except OSError as exc:
        raise _fail(path, exc) from None
    try:
        _user_mode(tmp, folder=True)
        yield tmp
        for root, _dirs, files in os.walk(tmp):
            for f in files:
                _fsync_file(Path(root) / f)
            _fsync_dir(Path(root))
        try:
            os.rename(tmp, path)
        except OSError as exc:
            if not (exist_ok and path.is_dir() and exc.errno in (errno.EEXIST, errno.ENOTEMPTY)):
                raise
            shutil.rmtree(tmp, ignore_errors=True)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if _is_io_error(exc):
            raise _fail(path, exc) from exc
        raise
    _fsync_dir(folder)


@contextlib.contextmanager
def staging_dir(folder: str | os.PathLike) -> Iterator[Path]:
    """A hidden temporary folder inside ``folder`` (created), always removed afterwards.

    For outputs made of several files: write them all into the staging folder (each with
    :func:`atomic_path`), then move them into place with :func:`commit_staged`.
    """
    folder = Path(folder)
    _make_folder(folder, folder)
    remove_stale_temporaries(folder)
    try:
        staging = Path(tempfile.mkdtemp(prefix=f".staging.g{os.getpid()}@{_HOST}-",
                                        suffix=".tmp", dir=folder))
    except OSError as exc:
        raise _fail(folder, exc) from None
    try:
        yield staging      # the writes inside use atomic_path, which names failures
    except OSError as exc:
        raise _fail(folder, exc) from exc
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def commit_staged(staging: str | os.PathLike, folder: str | os.PathLike,
                  names: Sequence[str]) -> None:
    """Move the finished files ``names`` of a :func:`staging_dir` into ``folder``.

    Each file is moved by one rename (same file system: a reader sees the old file or the
    new one), in the order given -- put a file that names the others (an index) last, so
    that it never names a file not yet in place -- and ``folder`` is synced afterwards. An
    OS error becomes a :class:`~gearshot.GearshotError` naming the destination.
    """
    staging, folder = Path(staging), Path(folder)
    for name in names:
        try:
            os.replace(staging / name, folder / name)
        except OSError as exc:
            raise _fail(folder / name, exc) from None
    _fsync_dir(folder)


def remove_tree(path: str | os.PathLike) -> None:
    """Remove the folder ``path`` as one step: rename it to a hidden name, then delete."""
    path = Path(path)
    if not path.exists():
        return
    trash = path.with_name(f"{_temp_prefix(path)}removed.tmp")
    try:
        os.rename(path, trash)
    except OSError as exc:
        raise _fail(path, exc, "remove") from None
    shutil.rmtree(trash, ignore_errors=True)
