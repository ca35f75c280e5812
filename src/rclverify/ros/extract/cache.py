"""Parsed ROS source files, kept between scans (incremental re-scan).

A :class:`~rclverify.core.cache.store.Shelf` of kind ``ros-scan``
(``artifacts/cache/ros-scan.pickle``) maps ``(parser, sha256 of the file)``
to the parser's result, so an unchanged file is not parsed again; the kind's
salt holds the rclverify code, so a changed parser misses.  A missing,
stale or unreadable file is an empty cache: deleting it is always safe.
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any, Callable

from rclverify.core.cache import Shelf

KIND = "ros-scan"


class ParseCache:
    """``get(kind, sha, fn)``: ``fn()`` once per parser and distinct file content."""

    def __init__(self, path: Path | None) -> None:
        self._shelf = Shelf(path, KIND)

    @property
    def hits(self) -> int:
        return self._shelf.hits

    @property
    def misses(self) -> int:
        return self._shelf.misses

    @staticmethod
    def digest(data: bytes) -> str:
        """Hex sha256 of a file's bytes."""
        return hashlib.sha256(data).hexdigest()

    def get(self, kind: str, sha: str, fn: Callable[[], Any]) -> Any:
        """The result of parser ``kind`` on the file whose sha256 is ``sha``:
        the kept one, else ``fn()``, kept."""
        return self._shelf.get_or_make(self._shelf.key(kind, sha), lambda: (fn(),))[0]

    def save(self) -> None:
        """Write the entries used by this scan, atomically (others are dropped).  Never raises."""
        try:
            self._shelf.save()
        except Exception:  # noqa: BLE001 -- a cache that cannot be written only costs time
            pass
