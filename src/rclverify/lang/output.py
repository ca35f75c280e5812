"""Writing generated RCL/LaTeX text to a file given with ``-o FILE``.

``write_atomic(path, text)``: write ``text`` (UTF-8) to ``path`` through the
one writer (:func:`rclverify.core.atomic.atomic_write_bytes`, as a path the
user named), so that an existing file is either left as it was or fully
replaced, and a device, FIFO or symbolic link named by ``-o`` is written
through, never replaced; a FIFO no process reads, or one whose reader stops
reading, fails instead of hanging.  Raises
:class:`~rclverify.lang.errors.RclError` (code ``E-io``, one line at
``FILE:1:1``) when the file cannot be written.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.core.atomic import atomic_write_bytes
from rclverify.lang import ast
from rclverify.lang.errors import RclError, error


def write_atomic(path: Path, text: str) -> None:
    """See the module docstring."""
    try:
        if not path.parent.is_dir():
            raise FileNotFoundError(2, "No such file or directory", str(path.parent))
        atomic_write_bytes(path, text.encode("utf-8"), named=True)
    except OSError as exc:
        raise RclError([error(ast.Loc(str(path), 1, 1), f"cannot write output file: {exc.strerror or exc}",
                              "E-io")]) from None
