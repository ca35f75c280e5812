"""Writing generated RCL/LaTeX text to a file given with ``-o FILE``.

``write_atomic(path, text)``: write ``text`` (UTF-8) to ``path`` through a
temporary file in the same directory and ``os.replace``, so that an existing
file is either left as it was or fully replaced.  Raises
:class:`~rclverify.lang.errors.RclError` (code ``E-io``) when the file cannot
be written.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error


def write_atomic(path: Path, text: str) -> None:
    """See the module docstring."""
    tmp: str | None = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=str(path.parent or Path(".")))
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
        tmp = None
    except OSError as exc:
        raise RclError([error(ast.Loc(str(path), 1, 1), f"cannot write output file: {exc.strerror or exc}",
                              "E-io")]) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
