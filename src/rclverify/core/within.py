"""Where a file rclverify reads or writes may lie, and what kind of file it may be.

One rule for every path the user did not name on the command line (a
plan's paths, a NoDL include, a report under ``reports/``): it lies inside
the workspace.  A path leaves the workspace when it is absolute, climbs
out with ``..``, or resolves -- every symbolic link followed -- to a place
outside the workspace's own resolved root (:func:`escape_reason` for a
workspace-relative value as a plan writes it, :func:`outside` for a path
already joined).  The plan's check (docs/plan.md, "Paths"), the assessor's
bundle, the NoDL reader and the one writer (:mod:`rclverify.core.atomic`)
all ask these two functions.

A file rclverify reads because a document or the plan names it is a
regular file: :func:`read_regular` opens it without blocking and refuses a
FIFO, device, socket or directory with one line (:class:`Refused`), where a
plain ``read`` of a FIFO would wait for a writer forever.
"""
from __future__ import annotations

import errno
import os
import re
import stat
from pathlib import Path, PurePosixPath

__all__ = ["Refused", "escape_reason", "kind_of", "outside", "read_regular"]

_DRIVE = re.compile(r"^[A-Za-z]:[\\/]")


class Refused(OSError):
    """A path rclverify will not read or write: a special file it was not
    told to use, or a path leading out of the workspace.  ``strerror`` is
    the one-line reason, ``filename`` the path as given; ``errno`` is
    ``EINVAL`` (``ENXIO`` for a FIFO no process reads)."""

    def __init__(self, path: os.PathLike[str] | str, why: str, code: int = errno.EINVAL) -> None:
        super().__init__(code, why, os.fspath(path))


def kind_of(mode: int) -> str:
    """The name of the file kind of ``st_mode`` (``"a FIFO"``, ``"a character device"``, ...)."""
    for test, name in ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISDIR, "a directory"), (stat.S_ISREG, "a regular file")):
        if test(mode):
            return name
    return "not a regular file"


def outside(root: Path, path: Path) -> Path | None:
    """The real path ``path`` leads to (every symbolic link followed, a
    missing tail kept as written: :func:`os.path.realpath`) when it lies
    outside the real path of ``root``; ``None`` when it lies inside (or is
    ``root`` itself)."""
    base = Path(os.path.realpath(root))
    real = Path(os.path.realpath(path))
    return None if real == base or base in real.parents else real


def escape_reason(root: Path, value: str) -> str | None:
    """Why the workspace-relative ``value`` leaves ``root`` (``None`` if it does not).
    A backslash counts as a separator; a drive letter (``C:\\``) or a UNC
    name (``\\\\host``) is absolute; an existing path is resolved
    (:func:`outside`)."""
    slashed = value.replace("\\", "/")
    pure = PurePosixPath(slashed)
    if pure.is_absolute() or Path(value).is_absolute() or _DRIVE.match(value):
        return "is an absolute path"
    if os.path.normpath(slashed).split("/")[0] == "..":
        return "climbs out of the workspace with '..'"
    target = root / value
    if os.path.lexists(target):
        real = outside(root, target)
        if real is not None:
            return f"resolves to {real}, outside the workspace (through a symbolic link)"
    return None


def read_regular(path: Path, limit: int | None = None) -> bytes:
    """The bytes of the regular file ``path``, read without ever blocking on it.

    The file is opened with ``O_NONBLOCK`` (a FIFO with no writer opens at
    once) and checked with ``fstat`` on the open descriptor, so what is read
    is what was checked.  Raises :class:`Refused` for a FIFO, device, socket
    or directory ("is a FIFO, not a regular file") and for a file longer
    than ``limit`` bytes when a limit is given; ``OSError`` as ``open`` does
    (``FileNotFoundError`` for a missing file)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise Refused(path, f"is {kind_of(st.st_mode)}, not a regular file; rclverify reads only regular files")
        if limit is not None and st.st_size > limit:
            raise Refused(path, f"is {st.st_size} bytes, above the limit of {limit} bytes", errno.EFBIG)
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read() if limit is None else fh.read(limit + 1)
    finally:
        os.close(fd)
    if limit is not None and len(data) > limit:  # grew since the fstat
        raise Refused(path, f"is more than {limit} bytes, above the limit", errno.EFBIG)
    return data
