"""Confined file reads for the ROS scan (docs/ros.md, "Hostile workspaces").

Every file the scan reads goes through :func:`read_bytes`: only regular
files (``os.stat`` + ``S_ISREG``: never a FIFO, device or socket), at most
:data:`MAX_FILE_BYTES`, and, while a scan is confined with :func:`confined`,
only files whose real path (symlinks resolved) lies under one of the
allowed roots (the workspace root's real path, plus the installed standard
message directory).  A refusal raises :class:`Refused`, an ``OSError``, so
the callers' existing ``cannot read`` handling turns it into a located note.
"""
from __future__ import annotations

import contextlib
import contextvars
import os
import stat
from pathlib import Path
from typing import Iterator, Sequence

MAX_FILE_BYTES = 8 * 1024 * 1024  # per source / launch / manifest / interface file

_ROOTS: contextvars.ContextVar[tuple[str, ...] | None] = contextvars.ContextVar("ros_roots", default=None)


class Refused(OSError):
    """A file the scan will not read (not regular, too large, or outside the workspace)."""


def _real(p: str | Path) -> str:
    return os.path.realpath(os.fsdecode(p))


def inside(path: str | Path) -> bool:
    """Whether ``path``'s real path lies under an allowed root (always true when unconfined)."""
    roots = _ROOTS.get()
    if roots is None:
        return True
    real = _real(path)
    return any(real == r or real.startswith(r.rstrip(os.sep) + os.sep) for r in roots)


@contextlib.contextmanager
def confined(roots: Sequence[str | Path]) -> Iterator[None]:
    """Within the block, reads are limited to files under ``roots`` (real paths)."""
    tok = _ROOTS.set(tuple(_real(r) for r in roots))
    try:
        yield
    finally:
        _ROOTS.reset(tok)


def read_bytes(path: str | Path, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of regular file ``path``; raises :class:`Refused` for a
    non-regular file, one over ``limit`` bytes, or one (or a link to one)
    outside the allowed roots; ``OSError`` when it cannot be read."""
    if not inside(path):
        raise Refused(f"{os.fsdecode(path)!r} resolves outside the workspace: skipped")
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise Refused("not a regular file (FIFO, device or socket): skipped")
    if st.st_size > limit:
        raise Refused(f"larger than {limit // (1024 * 1024)} MiB: skipped")
    with open(path, "rb") as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise Refused(f"larger than {limit // (1024 * 1024)} MiB: skipped")
    return data


def read_text(path: str | Path, limit: int = MAX_FILE_BYTES) -> str:
    """:func:`read_bytes` decoded as UTF-8 (bad bytes replaced)."""
    return read_bytes(path, limit).decode("utf-8", errors="replace")


def utf8_name(name: str) -> bool:
    """Whether a file or directory name (as ``os`` gives it) is valid UTF-8."""
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def escaped(path: str | Path) -> str:
    """``path`` with bytes that are not UTF-8 shown as ``\\xNN`` escapes."""
    return os.fsencode(path).decode("utf-8", errors="backslashreplace")


def keep_names(dirpath: str, names: list[str], skipped: list[str] | None) -> list[str]:
    """The ``names`` in ``dirpath`` that are valid UTF-8; each other one is
    appended (joined to ``dirpath``, escaped) to ``skipped``."""
    out = []
    for n in names:
        if utf8_name(n):
            out.append(n)
        elif skipped is not None:
            skipped.append(escaped(os.path.join(dirpath, n)))
    return out
