"""The review backend's evidence payload, defined once: :class:`ReviewPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The review backend (:mod:`.backend`,
judged by :func:`.record.judge`) writes who reviewed what and when (the
reviewer, the author, the stated independence, the date, the scope), the
files with their sha256 at the review, the verdict, each checklist question
with its answer, the record's path and the rows the report shows
(``figures_table``).  The producer checks its JSON object through the
Struct (:meth:`~rclverify.backends.payload_base.EvidencePayload.checked`)
and writes it unchanged.  A reader decodes the record's ``details`` once, by
its ``backend`` (``backends/payloads.py``
:func:`~rclverify.backends.payloads.payload_of`), and reads attributes mypy
checks.  A key no field declares is refused.
"""
from __future__ import annotations

from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.shapes import ChecklistAnswer, ReviewedFile
from rclverify.backends.timing_scope import TimingNote


class ReviewPayload(EvidencePayload, frozen=True, tag="review"):
    """A review record's evidence payload (module docstring)."""

    reviewer: str = ""
    author: str = ""  #: who wrote what was reviewed (``""``: not named)
    independence: str = ""  #: the record's stated level (``""``: not stated)
    date: str = ""
    scope: str = ""
    files: list[ReviewedFile] = []  #: the reviewed files and their sha256 at the review
    verdict: str | None = None  #: ``pass``/``fail``; ``None``: none given
    checklist: list[ChecklistAnswer] = []  #: each question of the guarantee and its answer
    record: str = ""  #: the review record, relative to the workspace
    figures_table: list[list[str]] = []  #: the rows the report shows
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["ReviewPayload"]
