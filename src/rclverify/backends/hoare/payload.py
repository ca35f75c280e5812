"""The Hoare backend's evidence payload, defined once: :class:`HoarePayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The Hoare backend (:mod:`.backend`)
builds a :class:`HoarePayload` and writes :meth:`HoarePayload.details`: the
proof outline, each verification condition's status, the program, the
triple as printed, and for a refuted triple the first refuted condition; a
pending obligation's record holds the reason and the conjunct's parts the
triple does not cover.  A reader decodes the record's ``details`` once, by
its ``backend`` (``backends/payloads.py`` :func:`~rclverify.backends.payloads.payload_of`),
and reads attributes mypy checks.  A field at its default is left out of the
JSON (``omit_defaults``); a key no field declares is refused.
"""
from __future__ import annotations

from rclverify.backends.shapes import HoareTriple
from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.timing_scope import TimingNote


class HoarePayload(EvidencePayload, frozen=True, tag="hoare"):
    """A Hoare triple's evidence payload (module docstring)."""

    outline: str = ""  #: the proof outline, cut at 8,000 characters
    vcs: dict[str, str] = {}  #: verification condition id -> ``valid``/``invalid``/``unknown``
    program: str = ""  #: the program the triple is over, as the plan names it
    triple: HoareTriple | None = None  #: the pre- and postcondition as printed
    failed_vc: str = ""  #: the first refuted verification condition's id (a failed triple)
    notes: list[str] = []  #: why refuted conditions show no run that breaks the triple
    reason: str = ""  #: why the obligation is pending
    uncovered: list[str] = []  #: the parts of a pending conjunct the triple does not cover
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["HoarePayload"]
