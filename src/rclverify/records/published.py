"""Writing the files people read (``reports/``): atomic and readable by others.

:func:`rclverify.records.store.atomic_write_text` goes through
``tempfile.mkstemp``, which creates its file with mode 0600, so a report
renamed into place was readable by its owner only (an assessor's account, a
web server or a CI artifact upload under another user could not read it).
:func:`write_published` writes as atomically (a temporary file in the same
directory, renamed into place; skipped when the file already holds the
text) with the mode a plain ``open()`` would give: ``0666`` less the
process's umask (``0644`` under the usual umask ``022``).
"""
from __future__ import annotations

import os
from pathlib import Path

from rclverify.core.atomic import holds, output_target
from rclverify.records.store import atomic_write_bytes

_MODE: list[int] = []


def published_mode() -> int:
    """``0o666 & ~umask`` of this process (read once: ``os.umask`` can only be
    read by setting it)."""
    if not _MODE:
        mask = os.umask(0o022)
        os.umask(mask)
        _MODE.append(0o666 & ~mask)
    return _MODE[0]


def write_published(path: Path, text: str, within: Path | None = None) -> bool:
    """Write ``text`` (UTF-8) to ``path`` atomically with :func:`published_mode`;
    when the file already holds ``text``, only its mode is corrected (a file
    written by an earlier version with 0600).  ``within`` (the workspace):
    ``path`` must resolve inside it, so a symbolic link planted in
    ``reports/`` that leads out is refused; a FIFO, device or socket at
    ``path`` is refused, never opened (:func:`rclverify.core.atomic.output_target`).
    Returns ``True`` when the content changed.  Raises ``OSError`` when the
    directory cannot be written (``path`` is then left as it was) and
    :class:`~rclverify.core.within.Refused` for a target refused so."""
    mode = published_mode()
    data = text.encode("utf-8")
    output_target(path, within=within)
    if holds(path, data):
        if os.stat(path).st_mode & 0o777 != mode:
            os.chmod(path, mode)
        return False
    try:
        atomic_write_bytes(path, data, mode=mode, within=within)
    except OSError as exc:
        if exc.filename is not None:
            raise
        raise OSError(exc.errno, exc.strerror, str(path.parent) + os.sep) from None  # e.g. ENOSPC: name the place
    return True
