"""Faults of the machine, worded for the user: one line, no traceback.

A read-only ``reports/`` or ``artifacts/``, a full disk, a missing
directory: every write of the pipeline is atomic (a temporary file renamed
into place, :mod:`rclverify.records.store`), so such a fault leaves the
reports and evidence of the last run as they were; what is left is to say
so plainly.  :func:`describe_os_error` turns an ``OSError`` into
``error: cannot write reports/: Permission denied`` (the temporary file's
name is replaced by its directory; paths are given relative to the
workspace when they lie in it).  The doit actions
(:mod:`rclverify.app.tasks`) return it as their failure and the CLI prints it
with exit code 1.
"""
from __future__ import annotations

import errno
import os
from pathlib import Path

#: What a fault leaves behind, said after every message.
UNTOUCHED = "the reports and evidence of the last run are unchanged"


def _where(filename: object, root: Path | None) -> str:
    name = os.fsdecode(filename) if isinstance(filename, (str, bytes, os.PathLike)) else ""
    if not name:
        return ""
    base = os.path.basename(name)
    if base.startswith(".") and base.endswith(".tmp"):  # the atomic writer's temporary file: name its directory
        name = os.path.dirname(name) + os.sep
    if root is not None:
        try:
            rel = os.path.relpath(name, root)
            if not rel.startswith(".."):
                name = rel + (os.sep if name.endswith(os.sep) and not rel.endswith(os.sep) else "")
        except ValueError:
            pass
    return name


#: Errors that can only come from writing.
_WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EROFS, errno.EDQUOT, errno.EFBIG})


def describe_os_error(exc: OSError, root: Path | None = None, doing: str | None = None,
                      place: str = "") -> str:
    """One line saying which file or directory the fault hit and why, e.g.
    ``error: cannot write reports/: Permission denied; the reports and
    evidence of the last run are unchanged``.  ``root`` (the workspace) makes
    the path relative; ``doing`` is the verb phrase (default: ``cannot
    write`` for an error only a write gives -- a full disk, a read-only file
    system -- or a temporary file, ``cannot access`` otherwise); ``place``
    names where the caller was writing, for an error that carries no file
    name (a ``write`` on a full disk)."""
    where = _where(exc.filename, root) or place
    if doing is None:
        name = os.fsdecode(exc.filename) if isinstance(exc.filename, (str, bytes, os.PathLike)) else ""
        tmp = os.path.basename(name).endswith(".tmp")
        doing = "cannot write" if exc.errno in _WRITE_ERRORS or tmp or not name else "cannot access"
    why = exc.strerror or str(exc)
    hint = ""
    if exc.errno == errno.ENOSPC:
        hint = " (free some space and run again)"
    elif exc.errno == errno.EROFS or (exc.errno in (errno.EACCES, errno.EPERM) and doing == "cannot write"):
        hint = " (make it writable and run again)"
    elif exc.errno in (errno.EACCES, errno.EPERM):
        hint = " (check its permissions and run again)"
    return f"error: {doing} {where or 'a file'}: {why}{hint}; {UNTOUCHED}"
