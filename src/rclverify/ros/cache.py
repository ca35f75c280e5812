"""A per-file parse cache keyed by the file's sha256 (issue 22: incremental
re-scan).  One pickle under ``artifacts/cache/ros-scan.pickle`` maps
``(parser, version, sha256) -> result``; an unchanged file is not re-parsed.
A missing, stale or unreadable cache is simply rebuilt: deleting it is always safe.
"""
from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from pathlib import Path
from typing import Any, Callable

VERSION = 1


class ParseCache:
    """``get(kind, data, fn)``: ``fn(data)`` once per distinct file content."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self.hits = 0
        self.misses = 0
        self._data: dict[tuple[str, int, str], Any] = {}
        self._used: set[tuple[str, int, str]] = set()
        if path is not None and path.is_file():
            try:
                with path.open("rb") as f:
                    loaded = pickle.load(f)
                if isinstance(loaded, dict):
                    self._data = loaded
            except Exception:  # a torn or foreign file: start afresh
                self._data = {}

    @staticmethod
    def digest(data: bytes) -> str:
        return hashlib.sha256(data).hexdigest()

    def get(self, kind: str, sha: str, fn: Callable[[], Any]) -> Any:
        key = (kind, VERSION, sha)
        self._used.add(key)
        if key in self._data:
            self.hits += 1
            return self._data[key]
        self.misses += 1
        value = fn()
        self._data[key] = value
        return value

    def save(self) -> None:
        """Write the entries used by this scan, atomically (others are dropped)."""
        if self.path is None or (self.misses == 0 and set(self._data) == self._used):
            return
        data = {k: v for k, v in self._data.items() if k in self._used}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=".ros-scan.")
            with os.fdopen(fd, "wb") as f:
                pickle.dump(data, f, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(tmp, self.path)
        except (OSError, pickle.PicklingError):
            pass  # a cache that cannot be written only costs time
