"""The files a recorded run is made of, and their digest for staleness.

A trace is one file (a JSONL log, a ROS 1 ``.bag``) or a ROS 2 bag's
directory (``metadata.yaml`` and its storage files); evidence judged on it is
stale once any of them changes (docs/integrity.md).  Kept apart from the
monitors backend so that what only digests traces (the temporal requirements'
evidence) does not load the monitors and numpy.
"""
from __future__ import annotations

import hashlib
from pathlib import Path


def trace_files(root: Path, rel: str) -> list[str]:
    """The regular files making up a trace (a bag directory's files, sorted),
    workspace-relative; a FIFO, device or socket is never among them (hashing
    it would block: :mod:`rclverify.traces.guard`)."""
    p = root / rel
    if p.is_dir():
        return sorted(f.relative_to(root).as_posix() for f in p.rglob("*") if f.is_file())
    return [rel] if p.is_file() else []


def trace_sha256(root: Path, rel: str) -> str:
    """sha256 (hex) over the trace's files, each name then its bytes, in :func:`trace_files`'s order."""
    h = hashlib.sha256()
    for f in trace_files(root, rel):
        h.update(f.encode())
        h.update((root / f).read_bytes())
    return h.hexdigest()
