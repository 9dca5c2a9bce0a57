"""Reading user files safely: regular files only, never blocking, never beyond a size limit.

Every reader of a file the user names (.mrg files and their includes, URDFs, meshes) goes through
:func:`read_regular`, so a FIFO, a device or a socket given as input is refused at once instead of
blocking the command or streaming forever, and a huge file is refused before it is read.  Which geometry files
may be read at all is the loader's rule (:mod:`mrgc.language.loader`: the problem's own folder tree, else
E236); :func:`add_allow_outside` is its command-line option, for every command that reads a problem file.
"""

from __future__ import annotations

import os
import stat
from typing import TYPE_CHECKING

from mrgc.errors import file_kind

if TYPE_CHECKING:
    import argparse


class FileTooLarge(OSError):
    """A file above the size limit of the reader (``size``: its size in bytes)."""

    def __init__(self, path: str, size: int) -> None:
        super().__init__(f"{path} is {size} bytes")
        self.size = size


class NotRegularFile(OSError):
    """A path that names a FIFO, a device, a socket or a folder instead of a regular file."""


def read_regular(path: str, limit: int) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit``, else :class:`FileTooLarge`).

    The file is opened non-blocking and checked with ``fstat`` before anything is read, so a FIFO or a
    device is refused (:class:`NotRegularFile`, an ``OSError`` whose ``strerror`` says what it is)
    instead of blocking or streaming forever.  Every reader of user files (.mrg, URDF, meshes) uses it.
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            what = file_kind(st.st_mode)
            raise NotRegularFile(0, "Is a directory" if what == "a folder" else f"not a regular file: {what}", path)
        if st.st_size > limit:
            raise FileTooLarge(path, st.st_size)
        os.set_blocking(fd, True)
        chunks, size = [], 0
        while chunk := os.read(fd, 1 << 20):
            chunks.append(chunk)
            size += len(chunk)
            if size > limit:  # grew while being read
                raise FileTooLarge(path, size)
        return b"".join(chunks)
    finally:
        os.close(fd)


def add_allow_outside(p: "argparse.ArgumentParser") -> None:
    """``--allow-outside PATH``, the command-line form of :func:`~mrgc.language.loader.parse_file`'s
    ``allow_outside``: a folder tree meshes and URDFs may come from besides the problem's own."""
    p.add_argument(
        "--allow-outside",
        action="append",
        metavar="PATH",
        help="also read mesh and URDF files under this folder (default: only the problem file's "
        "folder tree and pybullet_data; repeatable)",
    )
