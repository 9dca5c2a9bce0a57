"""Writing output files so that no command can lose or half-write a file: one helper for every command.

Every file a command writes (``plan -o``, ``facts -o``, ``fmt --write``, ``generate -o``, ``compile --emit``,
and any command added later) goes through :func:`write_text` / :func:`write_bytes`, or through
:func:`atomic_path` for libraries that write by file name (solver exports).  They promise:

- **The target is checked first**, before any work is spent: an output that is one of the command's
  inputs (the problem file, its domain, its includes, meshes and URDFs; compared by device and inode, so
  hard links, symlinks and ``./x`` spellings are caught) is refused with E005; a folder, a FIFO, a device,
  a path under a missing or unwritable folder with E006.  :func:`check_output` is the check alone, for
  commands that want to fail before a long computation; :func:`check_folder` the same for a folder a
  command writes into (made at once).
- **Atomic replacement.**  The text goes to a temp file created with ``O_EXCL`` in the target's own folder
  (:func:`tempfile.mkstemp`: a random name, never following a planted symlink), is flushed and fsynced,
  gets the target's permission bits (and owner, where allowed; a new file gets ``0666 & ~umask``), and is
  renamed over the target with :func:`os.replace`; the folder is fsynced after.  A reader sees the old
  file or the new one, never a part.
- **Symlinks are written through**: when the target is a symlink, the file it points to is replaced (the
  link stays, and now shows the new content), as a shell's ``>`` does.  The link is resolved once, before
  writing; the temp file lives beside the real file.
- **Hard links are kept**: a target with several names is rewritten in place (its inode, and so every
  name, gets the new content) after the complete text is in the temp file; that rewrite is not atomic.
- **Nothing is written after a signal**: the final rename is skipped when SIGINT or SIGTERM was received
  (:mod:`mrgc.signals`); the temp file is removed on that and every other error path.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from typing import BinaryIO, Iterable, Iterator

from mrgc import signals
from mrgc.errors import Diagnostic, InputError, InternalError, file_kind

#: the error codes of this module (docs/errors.md)
E_IS_INPUT = "E005"
E_UNWRITABLE = "E006"


def _refuse(code: str, message: str) -> InputError:
    return InputError([Diagnostic(code, message)])


def _identity(path: str) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def check_output(path: str, inputs: Iterable[str] = (), *, option: str = "-o") -> str:
    """The real file ``path`` will replace (symlinks resolved), or InputError E005/E006 saying why
    ``path`` cannot be written (see the module docstring).  ``option`` names it in messages."""
    if not path:
        raise _refuse(E_UNWRITABLE, f"{option}: the output path is empty")
    if path.endswith(os.sep) or os.path.basename(path) in (".", ".."):
        raise _refuse(E_UNWRITABLE, f"{option} {path}: names a folder; name a file inside it")
    try:
        real = os.path.realpath(path)
        st: os.stat_result | None = os.stat(real)
    except FileNotFoundError:
        st = None
    except (OSError, ValueError) as exc:
        raise _refuse(
            E_UNWRITABLE, f"{option} {path}: cannot be written: {getattr(exc, 'strerror', None) or exc}"
        ) from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise _refuse(E_UNWRITABLE, f"{option} {path}: is a folder; name a file inside it")
        if not stat.S_ISREG(st.st_mode):
            raise _refuse(
                E_UNWRITABLE,
                f"{option} {path}: is not a regular file ({file_kind(st.st_mode)}); "
                f"leave out {option} to write to standard output",
            )
        me = (st.st_dev, st.st_ino)
        for inp in inputs:
            if _identity(inp) == me:
                same = "" if os.path.abspath(inp) == os.path.abspath(path) else f" (the same file as {inp})"
                raise _refuse(
                    E_IS_INPUT,
                    f"{option} {path}: is an input of this command{same}; "
                    f"writing it would destroy the input: choose another output file",
                )
    folder = os.path.dirname(real)
    if not os.path.isdir(folder):
        raise _refuse(E_UNWRITABLE, f"{option} {path}: folder {os.path.dirname(path) or '.'} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise _refuse(E_UNWRITABLE, f"{option} {path}: folder {os.path.dirname(path) or '.'} is not writable")
    return real


def check_folder(path: str, *, option: str) -> str:
    """The folder ``path`` a command writes its files into (``--figures DIR``, ``bench run --work DIR``),
    made now (with its parents) if it does not exist, before any work is spent; InputError E006 when it is
    not a folder (a file, a device) or cannot be made.  Its absolute path."""
    if not path:
        raise _refuse(E_UNWRITABLE, f"{option}: the folder path is empty")
    try:
        st: os.stat_result | None = os.stat(path)
    except FileNotFoundError:
        st = None
    except (OSError, ValueError) as exc:
        raise _refuse(E_UNWRITABLE, f"{option} {path}: {getattr(exc, 'strerror', None) or exc}") from None
    if st is not None and not stat.S_ISDIR(st.st_mode):
        what = "a file" if stat.S_ISREG(st.st_mode) else file_kind(st.st_mode)
        raise _refuse(E_UNWRITABLE, f"{option} {path}: is {what}, not a folder; name a folder")
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as exc:
        raise _refuse(E_UNWRITABLE, f"{option} {path}: cannot be made: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise _refuse(E_UNWRITABLE, f"{option} {path}: is not writable")
    return os.path.abspath(path)


def write_text(path: str, text: str, inputs: Iterable[str] = (), *, option: str = "-o") -> None:
    """Write ``text`` (UTF-8) to ``path`` safely (see the module docstring)."""
    write_bytes(path, text.encode("utf-8"), inputs, option=option)


def write_bytes(path: str, data: bytes, inputs: Iterable[str] = (), *, option: str = "-o") -> None:
    """Write ``data`` to ``path`` safely (see the module docstring)."""
    with open_atomic(path, inputs, option=option) as fh:
        fh.write(data)


@contextlib.contextmanager
def open_atomic(path: str, inputs: Iterable[str] = (), *, option: str = "-o") -> Iterator[BinaryIO]:
    """A binary file to write ``path``'s new content into (wrap it in :class:`io.TextIOWrapper` for text);
    it replaces ``path`` when the block ends without an exception (see the module docstring)."""
    real = check_output(path, inputs, option=option)
    fd, tmp = _temp_file(real, path, option)
    try:
        with os.fdopen(os.dup(fd), "wb") as fh:
            yield fh
        _commit(fd, tmp, real, path, option)
    except OSError as exc:
        raise _refuse(E_UNWRITABLE, f"{option} {path}: cannot be written: {exc.strerror or exc}") from None
    finally:
        with signals.shielded():
            os.close(fd)
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)


@contextlib.contextmanager
def atomic_path(path: str, inputs: Iterable[str] = (), *, option: str = "-o") -> Iterator[str]:
    """A temp file's path (same folder and extension as ``path``) for a library that writes by file name;
    when the block ends without an exception it replaces ``path`` (see the module docstring).

    The library must have written something: an empty temp file (a writer that failed silently) is
    :class:`~mrgc.errors.InternalError`, and ``path`` is left as it was.
    """
    real = check_output(path, inputs, option=option)
    fd, tmp = _temp_file(real, path, option)
    os.close(fd)
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDWR | getattr(os, "O_NOFOLLOW", 0))  # the writer may have made a new inode
        try:
            if os.fstat(fd).st_size == 0:
                raise InternalError(f"{option} {path}: the writer wrote nothing; {path} is unchanged")
            _commit(fd, tmp, real, path, option)
        finally:
            os.close(fd)
    except OSError as exc:
        raise _refuse(E_UNWRITABLE, f"{option} {path}: cannot be written: {exc.strerror or exc}") from None
    finally:
        with signals.shielded():
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)


def _temp_file(real: str, path: str, option: str) -> tuple[int, str]:
    folder, base = os.path.split(real)
    try:
        return tempfile.mkstemp(prefix=f".{base}.", suffix=f".mrgc-tmp{os.path.splitext(base)[1]}", dir=folder)
    except OSError as exc:
        raise _refuse(
            E_UNWRITABLE, f"{option} {path}: cannot create a file in {folder}: {exc.strerror or exc}"
        ) from None


def _commit(fd: int, tmp: str, real: str, path: str, option: str) -> None:
    """Give the complete temp file (open as ``fd``) the target's mode and put it in the target's place."""
    try:
        st: os.stat_result | None = os.stat(real)
    except FileNotFoundError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):  # replaced by something else while we worked
        raise _refuse(E_UNWRITABLE, f"{option} {path}: is no longer a regular file")
    if st is not None:
        with contextlib.suppress(PermissionError):
            os.fchown(fd, st.st_uid, st.st_gid)
    os.fchmod(fd, stat.S_IMODE(st.st_mode) if st is not None else 0o666 & ~_umask())
    os.fsync(fd)
    signals.raise_if_received()  # an interrupted run writes nothing
    if st is not None and st.st_nlink > 1:
        _rewrite_in_place(fd, real)
        return
    os.replace(tmp, real)
    _fsync_folder(os.path.dirname(real))


def _rewrite_in_place(src: int, real: str) -> None:
    """Copy the complete temp file (open as ``src``) into ``real``'s own inode: every hard link sees it."""
    out = os.open(real, os.O_WRONLY | getattr(os, "O_NOFOLLOW", 0))
    try:
        os.lseek(src, 0, os.SEEK_SET)
        size = 0
        while chunk := os.read(src, 1 << 20):
            os.write(out, chunk)
            size += len(chunk)
        os.ftruncate(out, size)
        os.fsync(out)
    finally:
        os.close(out)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_folder(folder: str) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover - some file systems refuse
        pass
    finally:
        os.close(fd)
