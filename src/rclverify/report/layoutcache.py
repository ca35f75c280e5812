"""Graphviz layouts (``dot -Tsvg`` output), kept between runs.

The report lays out three graphs on every run (the system diagram and the
assurance argument, the latter twice: inline in the HTML and as
``reports/argument.svg``).  For a large system ``dot`` is the costliest
part of a report run, yet after a one-contract edit the DOT text is
usually the same as last time (a diagram shows statuses and connections,
not constants).  ``dot`` is deterministic, so its SVG for a given DOT text
and a given ``dot`` program can be reused byte for byte.

The layouts are :class:`~rclverify.core.cache.store.Blobs` of kind ``layout``
(one file per layout, ``artifacts/cache/layout/<key>.svg``, since the two
report processes may lay out at once), keyed by the DOT text together with
the path, size and modification time of the ``dot`` executable (an
upgraded Graphviz misses).  Until :func:`use_directory` names the directory
(the report task does), layouts are kept in memory only.  Only successful
layouts are kept; a failure is computed again next time.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

from rclverify.core.cache import Blobs

KIND = "layout"
_blobs = Blobs(None, KIND, "svg")


def use_directory(path: Path | None) -> None:
    """Keep layouts in ``path`` as well as in memory (``None``: memory only).

    The directory is created on the first write; raises nothing here."""
    _blobs.directory = path


def forget() -> None:
    """Drop the layouts held in memory (as in a new process; the files stay)."""
    _blobs.forget()


def _exe_stamp(exe: str) -> str:
    try:
        st = os.stat(exe)
        return f"{exe}\0{st.st_size}\0{st.st_mtime_ns}"
    except OSError:
        return exe


def lookup(dot: str, exe: str, compute: Callable[[], str | None]) -> str | None:
    """The SVG for ``dot`` laid out by the program at ``exe``: the kept one,
    else ``compute()`` (which returns the SVG or ``None`` on failure), kept
    when it succeeded."""
    return _blobs.text(_blobs.key("svg", _exe_stamp(exe), dot), compute)
