"""The records the cache keeps beside its data, as types.

:class:`KeptHeader` heads every kept file (:func:`.store.header`),
:class:`KeptFile` is a row of ``rclverify cache`` (:func:`.store.kept_files`),
:class:`WorkspaceInputs` what a workspace's cache was computed from
(:mod:`.workspace`).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import TypedDict


class KeptHeader(TypedDict):
    """The file format, the kind of file, the code stamp it was written by, the salt (hex)."""
    format: int
    kind: str
    code: str
    salt: str


class KeptFile(TypedDict):
    """A kept file or directory: path relative to the workspace (a directory's ends in ``/``),
    its kind (the header's, unpickled; a directory's name; ``None`` without a header), its bytes,
    its files' count (a directory; else ``None``), whether this code wrote it (``None``: a directory)."""
    file: str
    kind: object
    bytes: int
    entries: int | None
    current: bool | None


class WorkspaceInputs(TypedDict):
    """What a workspace's cache was computed from: its root (resolved), plan file and the plan's
    sha256, each contract (and own profile) file's sha256, what each kept plan path resolves to."""
    root: str
    plan_file: str
    plan: str
    contracts: dict[str, str]
    paths: dict[str, str] | None


__all__ = ["KeptFile", "KeptHeader", "WorkspaceInputs"]
