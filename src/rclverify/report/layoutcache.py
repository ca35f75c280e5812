"""A content-addressed cache of Graphviz layouts (``dot -Tsvg`` output).

The report lays out three graphs on every run (the system diagram and the
assurance argument, the latter twice: inline in the HTML and as
``reports/argument.svg``).  For a large system ``dot`` is the costliest
part of a report run, yet after a one-contract edit the DOT text is
usually the same as last time (a diagram shows statuses and connections,
not constants).  ``dot`` is deterministic, so its SVG for a given DOT text
and a given ``dot`` program can be reused byte for byte.

Keys are the sha256 of the DOT text together with the path, size and
modification time of the ``dot`` executable (an upgraded Graphviz misses).
Entries live in memory for the process and, once :func:`use_directory` has
named one (``artifacts/cache/layout/`` of the workspace, set by the report
task), as ``<key>.svg`` files written atomically.  Only successful layouts
are cached; a failure is computed again next time.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Callable

from ..evidence.store import atomic_write_text

_memory: dict[str, str] = {}
_directory: Path | None = None


def use_directory(path: Path | None) -> None:
    """Keep layouts in ``path`` as well as in memory (``None``: memory only).

    The directory is created on the first write; raises nothing here."""
    global _directory
    _directory = path


def key(dot: str, exe: str) -> str:
    """Hex sha256 naming the layout of ``dot`` by the program at ``exe``."""
    try:
        st = os.stat(exe)
        stamp = f"{exe}\0{st.st_size}\0{st.st_mtime_ns}"
    except OSError:
        stamp = exe
    return hashlib.sha256(f"{stamp}\0{dot}".encode("utf-8")).hexdigest()


def lookup(dot: str, exe: str, compute: Callable[[], str | None]) -> str | None:
    """The SVG for ``dot`` from the cache, else ``compute()`` (which returns
    the SVG or ``None`` on failure) stored when it succeeded."""
    k = key(dot, exe)
    hit = _memory.get(k)
    if hit is None and _directory is not None:
        try:
            hit = (_directory / f"{k}.svg").read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            hit = None
    if hit is not None:
        _memory[k] = hit
        return hit
    svg = compute()
    if svg is not None:
        _memory[k] = svg
        if _directory is not None:
            try:
                _directory.mkdir(parents=True, exist_ok=True)
                atomic_write_text(_directory / f"{k}.svg", svg)
            except OSError:
                pass  # a cache that cannot be written only costs time
    return svg
